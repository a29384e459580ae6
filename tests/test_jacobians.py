"""Jacobians by three routes (geometry, differentiation, propagation), numeric and symbolic.

Truth comes from outside the code under test: central finite differences of forward kinematics
(angular part from Ṙ Rᵀ), roboticstoolbox-python and Pinocchio, and the routes against each other.
"""

import numpy as np
import pytest

from denavit import Convention, DHLink, DHRobot, Frame, JointType, forward_kinematics, load_robot
from denavit import numeric as N

from conftest import REDUCED
N_ROBOTS = 120 if REDUCED else 300
H = 1e-6
ATOL_FD = 1e-6
ROUTES = {"geometric": N.geometric_jacobian, "differentiation": N.differentiation_jacobian,
          "propagation": N.propagation_jacobian}


def make_robot(rng, convention=None, n_rows=None):
    """A random arm built here with DHLink: ~25 % prismatic, ~12 % fixed rows, random base and tool."""
    conv = Convention(convention or rng.choice(["standard", "modified"]))
    n_rows = n_rows or int(rng.integers(1, 8))
    links = []
    for _ in range(n_rows):
        u = rng.random()
        joint = JointType.PRISMATIC if u < 0.25 else JointType.FIXED if u > 0.88 else JointType.REVOLUTE
        links.append(DHLink(a=float(rng.choice([0.0, rng.uniform(-1, 1)])),
                            alpha=float(rng.choice([0.0, np.pi / 2, -np.pi / 2, rng.uniform(-np.pi, np.pi)])),
                            d=float(rng.choice([0.0, rng.uniform(-1, 1)])), theta=float(rng.uniform(-np.pi, np.pi)),
                            joint=joint))
    if not any(link.is_joint for link in links):
        links[0] = DHLink(a=0.3, joint=JointType.REVOLUTE)
    base, tool = np.eye(4), np.eye(4)
    if rng.random() < 0.6:
        base = N.transform_from_xyz_rpy(rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, 3))
        tool = N.transform_from_xyz_rpy(rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, 3))
    return DHRobot(name="random", links=tuple(links), convention=conv, base=base, tool=tool)


def make_nice_robot(rng):
    """A random arm with the values people write in DH tables (α in multiples of π/2, lengths in tenths),
    so that the symbolic engine stays fast; both conventions, prismatic and fixed rows, base/tool in quarter turns."""
    rough = make_robot(rng, n_rows=int(rng.integers(1, 5)))
    links = tuple(DHLink(a=float(rng.integers(0, 6)) / 10, alpha=float(rng.choice([0, 1, -1, 2])) * np.pi / 2,
                         d=float(rng.integers(0, 6)) / 10, theta=float(rng.choice([0, 1])) * np.pi / 2, joint=link.joint)
                  for link in rough.links)
    base = N.transform_from_xyz_rpy(rng.integers(-3, 4, 3) / 10, rng.integers(-2, 3, 3) * np.pi / 2)
    tool = N.transform_from_xyz_rpy(rng.integers(-3, 4, 3) / 10, rng.integers(-2, 3, 3) * np.pi / 2)
    return rough.replace(links=links, base=np.round(base, 15), tool=np.round(tool, 15))


def vee(W):
    return 0.5 * np.stack([W[..., 2, 1] - W[..., 1, 2], W[..., 0, 2] - W[..., 2, 0], W[..., 1, 0] - W[..., 0, 1]], -1)


def fd_jacobian(robot, q, frame):
    """Central differences of FK: v = Δp/2h, ω = vee(ΔR/2h · Rᵀ) (base) or vee(Rᵀ ΔR/2h) (tool)."""
    n = robot.dof
    steps = np.concatenate([q + H * np.eye(n), q - H * np.eye(n)])  # (2n, n)
    T = forward_kinematics(robot, steps)
    T0 = forward_kinematics(robot, q)
    dT = (T[:n] - T[n:]) / (2 * H)  # (n, 4, 4)
    R = T0[:3, :3]
    if frame == "base":
        v, w = dT[:, :3, 3], vee(dT[:, :3, :3] @ R.T)
    else:
        v, w = dT[:, :3, 3] @ R, vee(R.T @ dT[:, :3, :3])
    return np.concatenate([v, w], axis=1).T  # (6, n)


@pytest.mark.parametrize("route", list(ROUTES))
@pytest.mark.parametrize("frame", ["base", "tool"])
def test_jacobian_random_robots_matches_finite_differences(route, frame):
    rng = np.random.default_rng(100 + len(route) + len(frame))
    worst = 0.0
    for _ in range(N_ROBOTS):
        robot = make_robot(rng)
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        J = ROUTES[route](robot, q, frame)
        assert J.shape == (6, robot.dof)
        err = np.abs(J - fd_jacobian(robot, q, frame)).max()
        worst = max(worst, err)
    assert worst < ATOL_FD


def test_routes_agree_on_both_conventions_and_all_joint_kinds():
    rng = np.random.default_rng(7)
    seen = set()
    for _ in range(N_ROBOTS):
        robot = make_robot(rng)
        seen |= {(robot.convention, t) for t in robot.joint_types}
        q = rng.uniform(-np.pi, np.pi, (4, robot.dof))
        for frame in ("base", "tool"):
            J = N.geometric_jacobian(robot, q, frame)
            np.testing.assert_allclose(N.differentiation_jacobian(robot, q, frame), J, atol=1e-10)
            np.testing.assert_allclose(N.propagation_jacobian(robot, q, frame), J, atol=1e-10)
    assert len(seen) == 4  # revolute and prismatic joints met in both conventions


def test_base_tool_conversion_roundtrip_and_definition():
    rng = np.random.default_rng(8)
    for _ in range(50):
        robot = make_robot(rng)
        q = rng.uniform(-np.pi, np.pi, (3, robot.dof))
        T = forward_kinematics(robot, q)
        J0, Je = N.geometric_jacobian(robot, q, "base"), N.geometric_jacobian(robot, q, "tool")
        np.testing.assert_allclose(N.jacobian_tool_from_base(J0, T), Je, atol=1e-12)
        np.testing.assert_allclose(N.jacobian_base_from_tool(Je, T[..., :3, :3]), J0, atol=1e-12)
        # The twist in tool axes has the same norms per block as in base axes (pure rotation).
        qd = rng.normal(size=robot.dof)
        t0, te = J0 @ qd, Je @ qd
        np.testing.assert_allclose(np.linalg.norm(t0[..., :3], axis=-1), np.linalg.norm(te[..., :3], axis=-1))


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
@pytest.mark.parametrize("route", list(ROUTES))
def test_batch_equals_loop(shape, route):
    rng = np.random.default_rng(9)
    for _ in range(8):
        robot = make_robot(rng)
        q = rng.uniform(-np.pi, np.pi, shape + (robot.dof,))
        for frame in ("base", "tool"):
            J = ROUTES[route](robot, q, frame)
            assert J.shape == shape + (6, robot.dof)
            flat = q.reshape(-1, robot.dof)
            loop = np.stack([ROUTES[route](robot, qi, frame) for qi in flat]).reshape(J.shape)
            np.testing.assert_allclose(J, loop, atol=1e-13)


def test_end_effector_twist_matches_motion_along_a_path():
    """v, ω of q(t) = q + t q̇ from finite differences of the pose over time."""
    rng = np.random.default_rng(10)
    for _ in range(60):
        robot = make_robot(rng)
        q, qd = rng.uniform(-np.pi, np.pi, robot.dof), rng.normal(size=robot.dof)
        Tp, Tm = forward_kinematics(robot, q + H * qd), forward_kinematics(robot, q - H * qd)
        R = forward_kinematics(robot, q)[:3, :3]
        dT = (Tp - Tm) / (2 * H)
        expected = np.concatenate([dT[:3, 3], vee(dT[:3, :3] @ R.T)])
        np.testing.assert_allclose(N.end_effector_twist(robot, q, qd, "base"), expected, atol=1e-6)
        np.testing.assert_allclose(N.end_effector_twist(robot, q, qd, "tool"),
                                   np.concatenate([R.T @ expected[:3], R.T @ expected[3:]]), atol=1e-6)
        prop = N.velocity_propagation(robot, q, qd)
        np.testing.assert_allclose(prop.twist("base"), expected, atol=1e-6)


def test_velocity_propagation_intermediate_frames_match_finite_differences():
    """Every ω_i, v_i of the propagation is the velocity of frame {i} in its own axes."""
    rng = np.random.default_rng(11)
    for _ in range(60):
        robot = make_robot(rng)
        q, qd = rng.uniform(-np.pi, np.pi, robot.dof), rng.normal(size=robot.dof)
        F = N.link_transforms(robot, q)  # (N+1, 4, 4) world
        dF = (N.link_transforms(robot, q + H * qd) - N.link_transforms(robot, q - H * qd)) / (2 * H)
        R = F[:, :3, :3]
        w_own = vee(np.swapaxes(R, -1, -2) @ dF[:, :3, :3])  # Rᵀ Ṙ = skew(ω in own axes)
        v_own = np.einsum("kji,kj->ki", R, dF[:, :3, 3])
        prop = N.velocity_propagation(robot, q, qd)
        assert prop.labels[-1] == "e" and prop.omega.shape == (robot.n_rows + 2, 3)
        np.testing.assert_allclose(prop.omega[:-1], w_own, atol=1e-6)
        np.testing.assert_allclose(prop.v[:-1], v_own, atol=1e-6)


@pytest.mark.filterwarnings("ignore:.*representation singularity")
@pytest.mark.parametrize("rep", ["rpy", "zyz"])
def test_analytic_jacobian_matches_finite_differences_of_angles(rep):
    extract = N.rpy_from_rotation if rep == "rpy" else N.zyz_from_rotation
    rng = np.random.default_rng(12)
    checked = 0
    for _ in range(80):
        robot = make_robot(rng)
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        Ja, phi = N.analytic_jacobian(robot, q, rep)
        mid = phi[1] if rep == "rpy" else phi[1] - np.pi / 2
        if abs(np.cos(mid)) < 0.2 or np.any(np.abs(np.abs(phi[[0, 2]]) - np.pi) < 0.1):
            continue  # near a representation singularity or the ±π wrap of an angle
        steps = np.concatenate([q + H * np.eye(robot.dof), q - H * np.eye(robot.dof)])
        T = forward_kinematics(robot, steps)
        ang = extract(T[:, :3, :3])
        d_ang = (ang[: robot.dof] - ang[robot.dof:]).T / (2 * H)
        dp = (T[: robot.dof, :3, 3] - T[robot.dof:, :3, 3]).T / (2 * H)
        np.testing.assert_allclose(Ja, np.concatenate([dp, d_ang]), atol=1e-5)
        checked += 1
    assert checked > 30


def test_analytic_jacobian_warns_at_representation_singularity():
    robot = DHRobot("wrist", (DHLink(joint=JointType.REVOLUTE),))  # rotation about z only: ZYZ θ = 0
    with pytest.warns(UserWarning, match="representation singularity"):
        Ja, _ = N.analytic_jacobian(robot, [0.3], "zyz")
    assert np.isnan(Ja[3:]).all()


def test_bad_inputs_raise_clear_errors():
    robot = load_robot("puma560")
    with pytest.raises(ValueError, match=r"expected shape \(\.\.\., 6\)"):
        N.geometric_jacobian(robot, np.zeros(5))
    with pytest.raises(ValueError, match="base, tool|'side'"):
        N.geometric_jacobian(robot, np.zeros(6), "side")
    with pytest.raises(ValueError, match="rpy, zyz"):
        N.analytic_jacobian(robot, np.zeros(6), "xyz")
    with pytest.raises(ValueError, match=r"\(\.\.\., 6, n\)"):
        N.jacobian_tool_from_base(np.zeros((5, 6)), np.eye(4))


# --- peers -----------------------------------------------------------------------------------------


def _to_rtb(rtb, robot):
    mdh = robot.convention is Convention.MODIFIED
    links = []
    for link in robot.links:
        if link.joint is JointType.PRISMATIC:
            cls = rtb.PrismaticMDH if mdh else rtb.PrismaticDH
            links.append(cls(theta=link.theta, a=link.a, alpha=link.alpha, offset=link.d))
        else:  # fixed rows: a revolute joint held at 0 (its column is dropped)
            cls = rtb.RevoluteMDH if mdh else rtb.RevoluteDH
            links.append(cls(d=link.d, a=link.a, alpha=link.alpha, offset=link.theta))
    peer = rtb.DHRobot(links)
    peer.base, peer.tool = robot.base_matrix, robot.tool_matrix
    return peer


@pytest.mark.peer
def test_random_robots_match_roboticstoolbox_jacob0_jacobe():
    rtb = pytest.importorskip("roboticstoolbox")
    rng = np.random.default_rng(13)
    for _ in range(40 if REDUCED else 100):
        robot = make_robot(rng)
        peer = _to_rtb(rtb, robot)
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        full = np.zeros(robot.n_rows)
        full[list(robot.joint_rows)] = q
        cols = list(robot.joint_rows)
        np.testing.assert_allclose(N.geometric_jacobian(robot, q, "base"), peer.jacob0(full)[:, cols], atol=1e-9)
        np.testing.assert_allclose(N.propagation_jacobian(robot, q, "tool"), peer.jacobe(full)[:, cols], atol=1e-9)


@pytest.mark.peer
def test_puma560_matches_roboticstoolbox_model():
    rtb = pytest.importorskip("roboticstoolbox")
    robot, peer = load_robot("puma560"), rtb.models.DH.Puma560()
    rng = np.random.default_rng(14)
    for q in rng.uniform(-np.pi, np.pi, (10, 6)):
        np.testing.assert_allclose(N.differentiation_jacobian(robot, q, "base"), peer.jacob0(q), atol=1e-9)
        np.testing.assert_allclose(N.geometric_jacobian(robot, q, "tool"), peer.jacobe(q), atol=1e-9)


def _to_pinocchio(pin, robot):
    """The same arm as a Pinocchio model: joint k placed at the frame whose z is its axis."""
    model = pin.Model()
    parent, pending = 0, robot.base_matrix
    std = robot.convention is Convention.STANDARD
    for k, link in enumerate(robot.links):
        head = N.dh_transform(robot.convention, link.theta, link.d, link.a, link.alpha)
        if not link.is_joint:
            pending = pending @ head
            continue
        if std:  # Rz(θ0) Tz(d0) | joint | Tx(a) Rx(α)
            place = pending @ N.dh_transform(robot.convention, link.theta, link.d, 0.0, 0.0)
            tail = N.dh_transform(robot.convention, 0.0, 0.0, link.a, link.alpha)
        else:  # Rx(α) Tx(a) Rz(θ0) Tz(d0) | joint
            place, tail = pending @ head, np.eye(4)
        jt = pin.JointModelRZ() if link.joint is JointType.REVOLUTE else pin.JointModelPZ()
        parent = model.addJoint(parent, jt, pin.SE3(place[:3, :3], place[:3, 3]), f"j{k}")
        model.appendBodyToJoint(parent, pin.Inertia.Random(), pin.SE3.Identity())
        pending = tail
    tip = pending @ robot.tool_matrix
    frame = model.addFrame(pin.Frame("ee", parent, 0, pin.SE3(tip[:3, :3], tip[:3, 3]), pin.FrameType.OP_FRAME))
    return model, frame


@pytest.mark.peer
def test_random_robots_match_pinocchio_frame_jacobians():
    pin = pytest.importorskip("pinocchio")
    rng = np.random.default_rng(15)
    for _ in range(40 if REDUCED else 100):
        robot = make_robot(rng)
        model, fid = _to_pinocchio(pin, robot)
        data = model.createData()
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        J_lwa = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED).reshape(6, robot.dof)
        J_local = pin.getFrameJacobian(model, data, fid, pin.LOCAL).reshape(6, robot.dof)
        np.testing.assert_allclose(data.oMf[fid].homogeneous, forward_kinematics(robot, q), atol=1e-9)
        np.testing.assert_allclose(N.geometric_jacobian(robot, q, "base"), J_lwa, atol=1e-9)
        np.testing.assert_allclose(N.geometric_jacobian(robot, q, "tool"), J_local, atol=1e-9)


# --- symbolic engine ---------------------------------------------------------------------------------

SYMBOLIC_ROBOTS = ["report004-1-planar2r", "report004-4-rrp", "report004-5-rpp-cylindrical", "report004-7-scara-rrrp",
                   "report000-6r", "stanford", "puma560"]


def _lambdify(robot, expr, extra=()):
    sp = pytest.importorskip("sympy")
    from denavit.symbolic import joint_symbols, parameter_symbols

    syms = list(joint_symbols(robot.dof).q) + list(parameter_symbols(robot).values()) + list(extra)
    f = sp.lambdify(syms, expr, "numpy")
    values = list(robot.parameter_values.values())
    return lambda q, *more: np.array(f(*q, *values, *more), dtype=float)


@pytest.mark.parametrize("name", SYMBOLIC_ROBOTS)
@pytest.mark.slow
def test_symbolic_routes_match_numeric_on_catalogue(name):
    from denavit.symbolic import jacobian_sym

    robot = load_robot(name)
    rng = np.random.default_rng(30)
    qs = rng.uniform(-np.pi, np.pi, (3, robot.dof))
    for method in ("geometric", "differentiation", "propagation"):
        for frame in ("base", "tool"):
            f = _lambdify(robot, jacobian_sym(robot, method, frame))
            for q in qs:
                np.testing.assert_allclose(f(q), N.geometric_jacobian(robot, q, frame), atol=1e-12)


def test_symbolic_routes_match_numeric_on_random_robots():
    from denavit.symbolic import jacobian_sym

    rng = np.random.default_rng(31)
    for _ in range(6 if REDUCED else 15):
        robot = make_nice_robot(rng)
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        for method in ("geometric", "differentiation", "propagation"):
            for frame in ("base", "tool"):
                J = _lambdify(robot, jacobian_sym(robot, method, frame))(q)
                np.testing.assert_allclose(J, fd_jacobian(robot, q, frame), atol=ATOL_FD)


def test_planar_2r_symbolic_jacobian_equals_hand_derivation():
    """Planar 2R (Craig Example 5.3 / seed 004 arm 1), rows vx, vy, wz in base axes, derived by hand:
    x = L1 c1 + L2 c12, y = L1 s1 + L2 s12, φ = q1 + q2."""
    sp = pytest.importorskip("sympy")
    from denavit.symbolic import jacobian_sym

    q1, q2, L1, L2 = sp.symbols("q1 q2 L1 L2", real=True)
    hand = sp.Matrix([[-L1 * sp.sin(q1) - L2 * sp.sin(q1 + q2), -L2 * sp.sin(q1 + q2)],
                      [L1 * sp.cos(q1) + L2 * sp.cos(q1 + q2), L2 * sp.cos(q1 + q2)], [0, 0], [0, 0], [0, 0], [1, 1]])
    robot = load_robot("report004-1-planar2r")
    for method in ("geometric", "differentiation", "propagation"):
        assert sp.simplify(jacobian_sym(robot, method, "base") - hand) == sp.zeros(6, 2)


@pytest.mark.parametrize("name", ["report004-3-articulated-rrr", "report004-4-rrp", "puma560", "report000-6r"])
@pytest.mark.slow
def test_symbolic_propagation_steps_match_numeric_steps(name):
    from denavit.symbolic import force_propagation_sym, joint_symbols, velocity_propagation_sym, wrench_symbols

    robot = load_robot(name)
    rng = np.random.default_rng(32)
    q, qd, F = rng.uniform(-np.pi, np.pi, robot.dof), rng.normal(size=robot.dof), rng.normal(size=6)
    vel = velocity_propagation_sym(robot)
    num = N.velocity_propagation(robot, q, qd)
    qds = joint_symbols(robot.dof).qd
    for step in vel.steps:
        k = num.labels.index(step.label)
        np.testing.assert_allclose(_lambdify(robot, step.omega, qds)(q, *qd).ravel(), num.omega[k], atol=1e-12)
        np.testing.assert_allclose(_lambdify(robot, step.v, qds)(q, *qd).ravel(), num.v[k], atol=1e-12)
    frc = force_propagation_sym(robot)
    nf = N.force_propagation(robot, q, F, "tool")
    for step in frc.steps:
        k = nf.labels.index(step.label)
        np.testing.assert_allclose(_lambdify(robot, step.f, wrench_symbols())(q, *F).ravel(), nf.f[k], atol=1e-12)
        np.testing.assert_allclose(_lambdify(robot, step.n, wrench_symbols())(q, *F).ravel(), nf.n[k], atol=1e-12)
    np.testing.assert_allclose(_lambdify(robot, frc.tau, wrench_symbols())(q, *F).ravel(),
                               N.geometric_jacobian(robot, q, "tool").T @ F, atol=1e-12)


def test_import_denavit_stays_light():
    import subprocess
    import sys

    code = "import sys, denavit, denavit.numeric; print('sympy' in sys.modules, 'matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]
