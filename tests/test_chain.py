"""The chain layer (denavit.chain): one definition of the arm, walked on floats, numpy batches and sympy.

Oracles written here, independent of the library: the product of elementary 4×4 motions per DH row
(Rz Tz Tx Rx standard, Rx Tx Rz Tz modified, q added to θ or d), base in front, tool behind; and the
geometric Jacobian's columns by central differences of that product.
"""

from __future__ import annotations

import gc

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings

import denavit
from denavit import Convention, JointType
from denavit.chain import COMPONENTS, FLOATS, Batch, Symbolic, chain_of, pack, walk
from denavit.symbolic import joint_symbols

from _random_robots import random_q, random_robot
from test_fk import elementary_fk as oracle  # T_w_e and frames {0}…{N} by 4×4 elementary products
from conftest import robots

ATOL = 1e-10


def _batch_walk(robot, Q):
    """Frames of a batch Q (B, n) by the Batch walker, shape (B, N+1, 4, 4)."""
    qT = np.ascontiguousarray(Q.T)
    return pack(walk(chain_of(robot), qT, Batch(len(Q)), frames=True), (len(Q),))


@settings(max_examples=60)
@given(robots())
def test_float_and_batch_walkers_equal_the_elementary_product(robot):
    rng = np.random.default_rng(robot.n_rows)
    Q = random_q(rng, robot, (4,))
    chain = chain_of(robot)
    batch = _batch_walk(robot, Q)
    for b, q in enumerate(Q):
        _, frames = oracle(robot, q)
        single = pack(walk(chain, q.tolist(), FLOATS, frames=True), None)
        assert np.allclose(single, frames, atol=ATOL)
        assert np.allclose(batch[b], frames, atol=ATOL)
        last = pack([walk(chain, q.tolist(), FLOATS)], None)[0]
        assert np.allclose(last, frames[-1], atol=ATOL)


@settings(max_examples=60)
@given(robots())
def test_components_walker_equals_the_elementary_product(robot):
    """Components: floats and (B,) arrays mixed (constants stay floats), one configuration or a batch."""
    rng = np.random.default_rng(robot.n_rows + 3)
    Q = random_q(rng, robot, (3,))
    chain = chain_of(robot)
    poses = walk(chain, list(np.ascontiguousarray(Q.T)), COMPONENTS, frames=True)
    for b, q in enumerate(Q):
        _, frames = oracle(robot, q)
        one = walk(chain, q.tolist(), COMPONENTS, frames=True)
        for f, (pose_b, pose_1) in enumerate(zip(poses, one)):
            got_b = np.array([[np.broadcast_to(c, (len(Q),))[b] for c in col] for col in pose_b]).T  # (3, 4)
            assert np.allclose(got_b, frames[f][:3, :], atol=ATOL)
            assert np.allclose(np.array(pose_1).T, frames[f][:3, :], atol=ATOL)


@settings(max_examples=60)
@given(robots())
def test_constants_and_joint_motions_compose_to_the_pose(robot):
    """T_w_e = C0 · J1(q1) · C1 ⋯ Jn(qn) · Cn, base and tool inside C0 and Cn."""
    chain = chain_of(robot)
    q = random_q(np.random.default_rng(robot.dof), robot)
    assert len(chain.constants) == robot.dof + 1
    T = chain.constants[0]
    for k in range(robot.dof):
        T = T @ chain.joint_matrix(k, q[k]) @ chain.constants[k + 1]
    assert np.allclose(T, oracle(robot, q)[0], atol=ATOL)
    with pytest.raises(ValueError):
        chain.constants[0][0, 0] = 2.0  # shared constants are read-only


@pytest.mark.parametrize("seed", range(6))
def test_symbolic_walker_and_constants_equal_the_numeric_ones(seed):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng, convention=["standard", "modified"][seed % 2], n_rows=4)
    chain = chain_of(robot)
    q = random_q(rng, robot)
    qs = joint_symbols(robot.dof).q
    at = dict(zip(qs, q))
    frames = walk(chain, qs, Symbolic(chain), frames=True)
    _, expected = oracle(robot, q)
    for T, E in zip(frames, expected):
        assert np.allclose(np.array(T.subs(at).evalf(), dtype=float), E, atol=1e-9)
    for C, Cn in zip(chain.constants_sym(), chain.constants):
        assert np.allclose(np.array(C.evalf(), dtype=float), Cn, atol=1e-9)


@pytest.mark.parametrize("name", ["puma560", "puma560-mdh", "stanford", "scara"])
def test_symbolic_walker_keeps_parameter_symbols(name):
    """Named parameters stay symbols (values put in with numeric=True), and both agree with the numbers."""
    robot = denavit.load_robot(name)
    chain = chain_of(robot)
    qs = joint_symbols(robot.dof).q
    params = {sp.Symbol(k, real=True): sp.Rational(repr(v)) for k, v in robot.parameters}
    T = walk(chain, qs, Symbolic(chain))
    Tn = walk(chain, qs, Symbolic(chain, numeric=True))
    if params:
        assert T.free_symbols & set(params)
    assert not Tn.free_symbols & set(params)
    q = random_q(np.random.default_rng(1), robot)
    at = dict(zip(qs, q))
    _, frames = oracle(robot, q)
    for M in (T.subs(params), Tn):
        assert np.allclose(np.array(M.subs(at).evalf(), dtype=float), frames[-1], atol=1e-9)


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
@pytest.mark.parametrize("seed", range(8))
def test_public_fk_batch_shapes(shape, seed):
    rng = np.random.default_rng(100 + seed)
    robot = random_robot(rng)
    q = random_q(rng, robot, shape)
    T, F = denavit.forward_kinematics(robot, q), denavit.link_transforms(robot, q)
    assert T.shape == shape + (4, 4) and F.shape == shape + (robot.n_rows + 1, 4, 4)
    for idx in np.ndindex(*shape):
        E, frames = oracle(robot, q[idx])
        assert np.allclose(T[idx], E, atol=ATOL)
        assert np.allclose(F[idx], frames, atol=ATOL)


def _jacobian_by_differences(robot, q, h=1e-6):
    J = np.zeros((6, robot.dof))
    T = oracle(robot, q)[0]
    for k in range(robot.dof):
        dq = np.zeros(robot.dof)
        dq[k] = h
        Tp, Tm = oracle(robot, q + dq)[0], oracle(robot, q - dq)[0]
        J[:3, k] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        W = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ T[:3, :3].T  # skew(ω)
        J[3:, k] = (W[2, 1], W[0, 2], W[1, 0])
    return J


@settings(max_examples=40)
@given(robots())
def test_axis_frames_give_the_jacobian_columns(robot):
    """z and origin of the axis frame of each joint: revolute (z × (p_e − o), z), prismatic (z, 0)."""
    chain = chain_of(robot)
    q = random_q(np.random.default_rng(robot.n_rows + 7), robot)
    T_e, frames = oracle(robot, q)
    J = np.zeros((6, robot.dof))
    for k, f in enumerate(chain.axis_frame):
        z, o = frames[f][:3, 2], frames[f][:3, 3]
        J[:, k] = np.r_[np.cross(z, T_e[:3, 3] - o), z] if chain.revolute[k] else np.r_[z, 0, 0, 0]
    assert np.allclose(J, _jacobian_by_differences(robot, q), atol=1e-6)
    assert np.allclose(J, denavit.geometric_jacobian(robot, q), atol=1e-9)


@settings(max_examples=40)
@given(robots())
def test_masks_and_axis_frame_rule(robot):
    chain = chain_of(robot)
    types = robot.joint_types
    assert chain.revolute == tuple(t is JointType.REVOLUTE for t in types)
    assert chain.prismatic == tuple(t is JointType.PRISMATIC for t in types)
    shift = 0 if robot.convention is Convention.STANDARD else 1
    assert chain.axis_frame == tuple(r + shift for r in robot.joint_rows)
    assert [row.joint for row in chain.rows if row.joint >= 0] == list(range(robot.dof))


def test_chain_is_built_once_per_robot_and_dropped_with_it():
    from denavit.chain import _chain

    robot = random_robot(np.random.default_rng(5))
    chain = chain_of(robot)
    assert chain_of(robot) is chain
    twin = robot.replace()
    assert chain_of(twin) is not chain and chain_of(twin).rows == chain.rows
    key = id(robot)
    del robot
    gc.collect()
    assert key not in _chain._CACHE


def test_import_chain_stays_light():
    """The chain's numeric side loads without sympy; the symbolic constants load it on use."""
    import subprocess
    import sys

    code = ("import sys, denavit.chain as c; r = c.chain_of(__import__('denavit').load_robot('puma560')); "
            "c.walk(r, [0.0] * 6, c.FLOATS); r.constants; print('sympy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False"]


# ---- the joint-screw form C0 J1(q1) C1 ⋯ (chain.Screws, screw_walk) ---------------------------------------------

@settings(max_examples=40)
@given(robots())
def test_screw_walk_equals_the_elementary_product(robot):
    """Pose (tool applied) and joint axes by the screw walker, against the row-by-row 4×4 oracle."""
    from denavit.chain import screw_axes, screw_pose, screws_of
    from denavit.numeric import joint_axes

    rng = np.random.default_rng(robot.n_rows + 11)
    Q = random_q(rng, robot, (2, 3))
    screws = screws_of(robot)
    T = screw_pose(screws, Q)
    pts, dirs = screw_axes(screws, Q)
    assert T.shape == (2, 3, 4, 4) and pts.shape == dirs.shape == (2, 3, robot.dof, 3)
    for i in range(2):
        for j in range(3):
            T_ref, frames = oracle(robot, Q[i, j])
            np.testing.assert_allclose(T[i, j], T_ref, atol=ATOL)
            z, o = joint_axes(robot, np.array(frames))
            np.testing.assert_allclose(dirs[i, j], z, atol=ATOL)
            # a point of the same line (a prismatic joint of a modified row moves its frame's origin along it)
            np.testing.assert_allclose(np.cross(pts[i, j] - o, z), 0.0, atol=ATOL)


@settings(max_examples=40)
@given(robots())
def test_screw_walk_pieces_and_reverse_compose_to_the_whole(robot):
    """pose(C0 ⋯ J_k C_k) · C_k⁻¹ · pose(C_k J_k+1 ⋯) = pose; the reversed chain at −q reversed is the inverse."""
    from denavit.chain import reverse_screws, screw_pose, screws_of

    rng = np.random.default_rng(robot.n_rows + 13)
    q = random_q(rng, robot, (4,))
    screws = screws_of(robot)
    T = screw_pose(screws, q)
    k = int(rng.integers(0, robot.dof + 1))
    pre = screw_pose(screws, q[..., :k], upto=k)
    post = screw_pose(screws, q[..., k:], start=k)
    np.testing.assert_allclose(pre @ np.linalg.inv(screws.consts[k]) @ post, T, atol=ATOL)
    back = screw_pose(reverse_screws(screws), -q[..., ::-1])
    np.testing.assert_allclose(back @ T, np.broadcast_to(np.eye(4), T.shape), atol=ATOL)


@settings(max_examples=40)
@given(robots())
def test_screw_walk_in_floats_equals_the_batched_one(robot):
    from denavit.chain import screw_walk, screw_walk_floats, screws_of

    q = random_q(np.random.default_rng(robot.n_rows + 17), robot)
    screws = screws_of(robot)
    rows, axes = screw_walk_floats(screws, q.tolist())
    x, y, z, p, zs, os = screw_walk(screws, q, axes=True)
    np.testing.assert_allclose(np.array(rows), np.stack([x, y, z, p], axis=1), atol=1e-12)
    for k, (z0, z1, z2, o0, o1, o2) in enumerate(axes):
        np.testing.assert_allclose([z0, z1, z2], zs[k], atol=1e-12)
        np.testing.assert_allclose([o0, o1, o2], os[k], atol=1e-12)
