"""Symbolic M, C, c, g in hand form (lagrangian_dynamics(simplify="trig"), computed on polynomials) against the
numeric engine (CRBA, Christoffel C, RNEA, gravity — itself checked against Pinocchio in test_dynamics_numeric)
at random configurations, Ṁ − 2C skew by sympy's own differentiation, a textbook closed form, and the printed
form (angle sums, no decimals for symbolic data, gravity as g, LaTeX that compiles)."""

import functools
import re
import shutil
import subprocess

import numpy as np
import pytest
import sympy as sp

import denavit
from denavit import DHLink, JointType
from denavit import numeric as N
from denavit.model import LinkInertia
from denavit.symbolic import format_dynamics, joint_symbols, lagrangian_dynamics, parameter_symbols

from _evaluate import numeric_function
from test_jacobians import make_robot

ARMS = ["planar2r", "planar3r", "planar3r-lagrange"] + [pytest.param(n, marks=pytest.mark.slow)
                                                        for n in ("puma560", "puma560-mdh", "ur5")]


@functools.lru_cache(maxsize=2)  # the Panda's two checks share one evaluator of its ~2.6 MB of formulas
def _functions(robot, t):
    """M, c, g (and C) as functions of q, q̇ (each distinct sub-expression evaluated once: tests/_evaluate.py;
    lambdify spent ~30 CPU seconds printing the Panda's)."""
    js = joint_symbols(robot.dof)
    syms = list(js.q) + list(js.qd) + list(parameter_symbols(robot).values())
    mats = [t.M, t.c, t.g] + ([t.C] if t.C is not None else [])
    f = numeric_function(syms, mats)
    values = list(robot.parameter_values.values())
    return lambda q, qd: [np.array(x, dtype=float) for x in f(*q, *qd, *values)]


def _check_against_numeric(robot, t, rng, count=4):
    f = _functions(robot, t)
    for _ in range(count):
        q, qd, qdd = rng.uniform(-np.pi, np.pi, robot.dof), rng.uniform(-2, 2, robot.dof), rng.uniform(-2, 2, robot.dof)
        for k, jt in enumerate(robot.joint_types):
            if jt is JointType.PRISMATIC:
                q[k] = rng.uniform(-0.5, 0.5)
        M, c, g, *C = f(q, qd)
        scale = 1 + np.abs(N.mass_matrix(robot, q)).max()
        np.testing.assert_allclose(M, N.mass_matrix(robot, q), atol=1e-11 * scale)
        np.testing.assert_allclose(g.ravel(), N.gravity_torques(robot, q), atol=1e-10 * (1 + np.abs(g).max()))
        np.testing.assert_allclose(c.ravel(), N.coriolis_vector(robot, q, qd), atol=1e-10 * scale)
        if C:
            np.testing.assert_allclose(C[0], N.coriolis_matrix(robot, q, qd), atol=1e-10 * scale)
        tau = M @ qdd + c.ravel() + g.ravel()
        np.testing.assert_allclose(tau, N.rnea(robot, q, qd, qdd, friction=False), atol=1e-9 * scale)


@pytest.mark.parametrize("name", ARMS)
def test_catalogue_arms_match_the_numeric_engine(name):
    robot = denavit.load_robot(name)
    t = lagrangian_dynamics(robot)
    assert t.form == "hand"
    _check_against_numeric(robot, t, np.random.default_rng(80))


@pytest.mark.slow
def test_panda_matches_the_numeric_engine():
    """The Panda's hand form (~2.6 MB of formulas: one evaluator, shared) against the numeric engine and, when it is
    installed, Pinocchio (the Pinocchio test's Panda case, here so that the formulas are prepared once)."""
    robot = denavit.load_robot("panda")
    t = lagrangian_dynamics(robot, coriolis=False)
    _check_against_numeric(robot, t, np.random.default_rng(81), count=2)
    try:
        import pinocchio  # noqa: F401
    except ImportError:
        return
    _check_against_pinocchio(robot, t)


def _random_inertial_arm(rng, n_rows):
    rough = make_robot(rng, n_rows=n_rows)
    links = []
    for link in rough.links:
        I = np.concatenate([rng.uniform(0.05, 0.1, 3), rng.uniform(-0.002, 0.002, 3)])  # a body: triangle inequality
        links.append(DHLink(a=link.a, alpha=link.alpha, d=link.d, theta=link.theta, joint=link.joint,
                            inertia=LinkInertia(mass=float(rng.uniform(0.5, 3)), com=tuple(rng.uniform(-0.3, 0.3, 3)),
                                                inertia=tuple(float(x) for x in I),
                                                motor_inertia=float(rng.choice([0.0, 0.2])))))
    return rough.replace(links=tuple(links))


@pytest.mark.parametrize("seed", [0, 1] + [pytest.param(s, marks=pytest.mark.slow) for s in range(2, 8)])
def test_random_arms_with_generic_twists_match_the_numeric_engine(seed):
    """Random rows (generic float twists, prismatic joints, fixed rows with inertia, base and tool, both
    conventions) with random inertia: the polynomial route stays exact enough and quick."""
    rng = np.random.default_rng(300 + seed)
    robot = _random_inertial_arm(rng, int(rng.integers(2, 4)))
    if not any(l.inertia is not None and l.inertia.mass > 0 for l in robot.joints):
        pytest.skip("no moving mass")
    _check_against_numeric(robot, lagrangian_dynamics(robot), rng, count=3)


@pytest.mark.slow
def test_mdot_minus_2c_is_skew_by_sympy_differentiation():
    robot = denavit.load_robot("puma560")
    t = lagrangian_dynamics(robot)
    js = joint_symbols(6)
    params = {parameter_symbols(robot)[k]: v for k, v in robot.parameters}
    rng = np.random.default_rng(82)
    q, qd = rng.uniform(-np.pi, np.pi, 6), rng.uniform(-1, 1, 6)
    point = {**dict(zip(js.q, q)), **dict(zip(js.qd, qd)), **params}
    Mdot = sum((t.M.diff(js.q[i]) * js.qd[i] for i in range(6)), sp.zeros(6, 6))
    Nn = np.array((Mdot - 2 * t.C).subs(point).evalf(), dtype=float)
    np.testing.assert_allclose(Nn + Nn.T, 0, atol=1e-12)


def test_planar_3r_is_the_textbook_closed_form_in_relative_angles():
    """M of the planar 3R (point masses at Lc, rotational inertias I) written by hand, e.g. Spong sec. 7.4."""
    robot = denavit.load_robot("planar3r-lagrange")
    t = lagrangian_dynamics(robot)
    q1, q2, q3 = joint_symbols(3).q
    L1, L2, Lc1, Lc2, Lc3, m1, m2, m3, I1, I2, I3 = sp.symbols("L1 L2 Lc1 Lc2 Lc3 m1 m2 m3 I1 I2 I3", real=True)
    c2, c3, c23 = sp.cos(q2), sp.cos(q3), sp.cos(q2 + q3)
    M33 = I3 + m3 * Lc3 ** 2
    M23 = M33 + m3 * L2 * Lc3 * c3
    M22 = I2 + I3 + m2 * Lc2 ** 2 + m3 * (L2 ** 2 + Lc3 ** 2 + 2 * L2 * Lc3 * c3)
    M13 = M23 + m3 * L1 * Lc3 * c23
    M12 = M22 + m2 * L1 * Lc2 * c2 + m3 * (L1 * L2 * c2 + L1 * Lc3 * c23)
    M11 = (I1 + I2 + I3 + m1 * Lc1 ** 2 + m2 * (L1 ** 2 + Lc2 ** 2 + 2 * L1 * Lc2 * c2)
           + m3 * (L1 ** 2 + L2 ** 2 + Lc3 ** 2 + 2 * L1 * L2 * c2 + 2 * L1 * Lc3 * c23 + 2 * L2 * Lc3 * c3))
    expected = sp.Matrix([[M11, M12, M13], [M12, M22, M23], [M13, M23, M33]])
    names = {s.name: s for s in t.M.free_symbols}
    got = t.M.xreplace({names[k]: v for k, v in zip("L1 L2 Lc1 Lc2 Lc3 m1 m2 m3 I1 I2 I3".split(),
                                                     (L1, L2, Lc1, Lc2, Lc3, m1, m2, m3, I1, I2, I3)) if k in names})
    assert sp.expand(got - expected) == sp.zeros(3, 3)  # equal term by term, no trigonometric rewriting
    assert not t.M.has(sp.Float) and not t.c.has(sp.Float)


def test_printed_form_uses_angle_sums_gravity_symbol_and_no_decimals():
    robot = denavit.load_robot("planar3r-lagrange")  # every inertial value a named parameter
    text = format_dynamics(lagrangian_dynamics(robot), "text", gravity_symbol=True)
    body = [line for line in text.splitlines() if "] = " in line]
    assert body and not any("." in line for line in body)  # 9.81 only in the header, as g
    assert "g = 9.81 m/s^2" in text and any(line.startswith("g[1] = ") and "g*" in line for line in body)
    m22 = next(line for line in body if line.startswith("M[2,2] = "))
    assert "C3" in m22 and "C2" not in m22.replace("C23", "")  # row 2 in the angles after joint 2
    assert "S23" in text and not any("sin(" in line or "cos(" in line for line in body)


@pytest.mark.slow
def test_long_results_name_their_parameter_groups_and_stay_short():
    robot = denavit.load_robot("puma560")
    t = lagrangian_dynamics(robot)
    text = format_dynamics(t, "text", gravity_symbol=True)
    assert "P1 = " in text and "x0 = " not in text
    defs, entries = {}, {}
    for line in text.splitlines():
        if " = " in line and not line.startswith(" "):
            k, v = line.split(" = ", 1)
            (defs if k.startswith("P") else entries)[k] = v
    used = " ".join(entries.values())
    assert defs and all(any(f"{k}{e}" in used + " " for e in "* )+-") for k in defs)  # every group is used
    assert not any("P" in v for v in defs.values())  # groups are sums of parameters, not of other groups
    assert len(text) < 20_000


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="no LaTeX engine")
def test_latex_output_compiles(tmp_path):
    for name in ("planar3r-lagrange", "puma560"):
        t = lagrangian_dynamics(denavit.load_robot(name))
        tex = format_dynamics(t, "latex", include=("M", "C", "c", "g", "friction"), gravity_symbol=True)
        assert "\\tau_{f,1}" in tex and "\\mathcal{C}_{12}" in tex and "}_{" not in tex.replace("\\mathcal{C}_{", "")
        doc = ("\\documentclass{article}\\usepackage{amsmath}\\usepackage[paperwidth=200in,paperheight=200in]"
               "{geometry}\\begin{document}\\[" + tex + "\\]\\end{document}\n")
        (tmp_path / f"{name}.tex").write_text(doc)
        run = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", f"{name}.tex"],
                             cwd=tmp_path, capture_output=True, text=True, timeout=120)
        assert run.returncode == 0, run.stdout[-2000:]


@pytest.mark.slow
def test_a_generic_twist_stays_exact():
    """Puma 560 with α₂ = 0.7 rad instead of 0 (axes 2, 3 no longer parallel): M, c, g against the numeric engine."""
    import dataclasses

    robot = denavit.load_robot("puma560")
    links = list(robot.links)
    links[1] = dataclasses.replace(links[1], alpha=0.7, symbols=tuple(s for s in links[1].symbols if s[0] != "alpha"))
    robot = robot.replace(links=tuple(links))
    _check_against_numeric(robot, lagrangian_dynamics(robot, coriolis=False), np.random.default_rng(83), count=2)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["puma560", "ur5"])  # the Panda: in test_panda_matches_the_numeric_engine
def test_symbolic_terms_match_pinocchio(name):
    """M (crba, armature included), g (computeGeneralizedGravity) and c = C q̇ (computeCoriolisMatrix) of
    Pinocchio, the model built by denavit.peers.to_pinocchio."""
    pytest.importorskip("pinocchio")
    robot = denavit.load_robot(name)
    _check_against_pinocchio(robot, lagrangian_dynamics(robot, coriolis=False))


def _check_against_pinocchio(robot, t):
    import pinocchio as pin

    from denavit.peers import to_pinocchio

    f = _functions(robot, t)
    model, data, _ = to_pinocchio(robot)
    rng = np.random.default_rng(84)
    for _ in range(2):
        q, qd = rng.uniform(-np.pi, np.pi, robot.dof), rng.uniform(-2, 2, robot.dof)
        M, c, g = f(q, qd)
        Mp = pin.crba(model, data, q)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        np.testing.assert_allclose(M, Mp, atol=1e-10)
        np.testing.assert_allclose(g.ravel(), pin.computeGeneralizedGravity(model, data, q), atol=1e-9)
        np.testing.assert_allclose(c.ravel(), pin.computeCoriolisMatrix(model, data, q, qd) @ qd, atol=1e-9)


def _standard_parameters(robot):
    """π of every inertial piece from the robot's data, by the parallel axis theorem written here:
    (m, m c, I_c + m(|c|² 1 − c cᵀ)), then the motor inertias."""
    from denavit.model import inertial_rows

    vals = []
    for _row, _body, li in inertial_rows(robot):
        m, c = li.mass, np.array(li.com)
        I = np.array([[li.inertia[0], li.inertia[3], li.inertia[4]], [li.inertia[3], li.inertia[1], li.inertia[5]],
                      [li.inertia[4], li.inertia[5], li.inertia[2]]])
        J = I + m * (c @ c * np.eye(3) - np.outer(c, c))
        vals += [m, *(m * c), J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2]]
    return np.array(vals + [link.inertia.motor_inertia if link.inertia is not None else 0.0 for link in robot.joints])


def _check_regressor(robot, rng, count=3):
    from denavit.symbolic import regressor_sym

    Y, pi = regressor_sym(robot)
    js = joint_symbols(robot.dof)
    assert Y.shape == (robot.dof, len(pi)) and not (Y.free_symbols & set(pi))  # linear: π is not left in Y
    f = numeric_function(list(js.q) + list(js.qd) + list(js.qdd) + list(parameter_symbols(robot).values()), [Y])
    p = _standard_parameters(robot)
    for _ in range(count):
        q, qd, qdd = (rng.uniform(-2, 2, robot.dof) for _ in range(3))
        (Yv,) = f(*q, *qd, *qdd, *robot.parameter_values.values())
        np.testing.assert_allclose(Yv @ p, N.rnea(robot, q, qd, qdd, friction=False), atol=1e-9)


@pytest.mark.parametrize("name", ["planar2r", "planar3r-lagrange", pytest.param("puma560", marks=pytest.mark.slow),
                                  pytest.param("ur5", marks=pytest.mark.slow)])
def test_regressor_times_standard_parameters_is_the_rnea_torque(name):
    _check_regressor(denavit.load_robot(name), np.random.default_rng(85))


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(3))
def test_regressor_of_random_arms(seed):
    rng = np.random.default_rng(400 + seed)
    robot = _random_inertial_arm(rng, int(rng.integers(2, 4)))
    _check_regressor(robot, rng)


_NAME = re.compile(r"[A-Za-z_]\w*")
_LABEL = re.compile(r"^(M|c|g)\[(\d+)(?:,(\d+))?\]$")


def _parse_printed(text):
    """The lines 'name = formula' of a printed text, as (name, sympy expression, {word: symbol}), in order."""
    out = []
    for line in text.splitlines():
        name, _, formula = line.partition(" = ")
        if not re.fullmatch(r"\w+(\[\d+(,\d+)?\])?", name):  # the header and its notes
            continue
        local = {w: sp.Symbol(w) for w in set(_NAME.findall(formula)) if w not in ("cos", "sin")}
        out.append((name, sp.sympify(formula, locals=local), local))  # our own printed output, in a test
    return out


def _printed_values(text, robot, q, qd, parsed=None):
    """Evaluate the lines 'name = formula' of format_dynamics' (or format_recursive's) text one after the other
    at (q, q̇) and the robot's parameter values: Ci, Sij are cos, sin of q_i + q_j (one digit per joint),
    g = |g₀|, names defined earlier in the text are their values. Returns the printed M (both triangles from
    the upper one), c and g."""
    n = robot.dof
    env = {**{s: v for s, v in robot.parameters}, **{f"qd{k + 1}": qd[k] for k in range(n)},
           "g": float(np.linalg.norm(robot.gravity))}
    M, c, g = np.full((n, n), np.nan), np.full(n, np.nan), np.full(n, np.nan)
    q_subs = {sp.Symbol(f"q{k + 1}"): q[k] for k in range(n)}
    for name, e, local in parsed or _parse_printed(text):
        for word in local:
            if word not in env and re.fullmatch(r"[CS]\d+", word):
                angle = sum(q[int(d) - 1] for d in word[1:])
                env[word] = np.cos(angle) if word[0] == "C" else np.sin(angle)
        value = float(e.xreplace({**q_subs, **{local[w]: env[w] for w in local if w in env}}))
        m = _LABEL.match(name)
        if m is None:
            env[name] = value
        elif m.group(1) == "M":
            M[int(m.group(2)) - 1, int(m.group(3)) - 1] = M[int(m.group(3)) - 1, int(m.group(2)) - 1] = value
        else:
            (c if m.group(1) == "c" else g)[int(m.group(2)) - 1] = value
    return M, c, g


def _check_printed(robot, text, rng, count=2):
    parsed = _parse_printed(text)
    for _ in range(count):
        q, qd = rng.uniform(-np.pi, np.pi, robot.dof), rng.uniform(-2, 2, robot.dof)
        for k, jt in enumerate(robot.joint_types):
            if jt is JointType.PRISMATIC:
                q[k] = rng.uniform(-0.5, 0.5)
        M, c, g = _printed_values(text, robot, q, qd, parsed)
        scale = 1 + np.abs(N.mass_matrix(robot, q)).max()
        np.testing.assert_allclose(M, N.mass_matrix(robot, q), atol=1e-5 * scale)  # 6 printed digits
        np.testing.assert_allclose(c, N.coriolis_vector(robot, q, qd), atol=1e-5 * scale)
        np.testing.assert_allclose(g, N.gravity_torques(robot, q), atol=1e-5 * (1 + np.abs(g).max()))


@pytest.mark.parametrize("name", ["planar3r-lagrange", pytest.param("puma560", marks=pytest.mark.slow)])
def test_printed_text_evaluates_to_the_numeric_m_c_g(name):
    """The text a user reads (upper triangle of M, named groups P and rate coefficients B, g as a symbol),
    evaluated line by line, is the numeric CRBA, Christoffel c and gravity; the Puma's is under 10 k characters."""
    robot = denavit.load_robot(name)
    text = format_dynamics(lagrangian_dynamics(robot, coriolis=False), "text", gravity_symbol=True,
                           include=("M", "c", "g"))
    assert "M is symmetric" in text and "M[2,1] = " not in text
    _check_printed(robot, text, np.random.default_rng(86))
    if name == "puma560":
        assert len(text) <= 10_000


# --- the recursive form (arms whose expanded entries are unreadable: Panda, generic twists) -------------------

def _recursive_text(robot, style="text"):
    from denavit.symbolic import format_recursive, recursive_dynamics

    return format_recursive(recursive_dynamics(robot), style)


def test_recursive_form_of_the_panda_evaluates_to_the_numeric_m_c_g():
    """Panda: the printed recursions (body and composite parameters, momenta carried inward, Newton-Euler),
    evaluated line by line, are the numeric CRBA, Christoffel c and gravity; every line is short."""
    robot = denavit.load_robot("panda")
    text = _recursive_text(robot)
    _check_printed(robot, text, np.random.default_rng(87), count=3)
    try:  # and against Pinocchio (crba, computeGeneralizedGravity, computeCoriolisMatrix), when installed
        import pinocchio as pin
    except ImportError:
        pin = None
    if pin is not None:
        from denavit.peers import to_pinocchio

        model, data, _ = to_pinocchio(robot)
        rng, parsed = np.random.default_rng(89), _parse_printed(text)
        q, qd = rng.uniform(-np.pi, np.pi, 7), rng.uniform(-2, 2, 7)
        M, c, g = _printed_values(text, robot, q, qd, parsed)
        Mp = pin.crba(model, data, q)
        np.testing.assert_allclose(M, np.triu(Mp) + np.triu(Mp, 1).T, atol=1e-4)
        np.testing.assert_allclose(g, pin.computeGeneralizedGravity(model, data, q), atol=1e-4)
        np.testing.assert_allclose(c, pin.computeCoriolisMatrix(model, data, q, qd) @ qd, atol=1e-4)
    lines = text.splitlines()
    assert "recursive form" in lines[0] and len(lines) < 500 and max(map(len, lines)) < 300
    assert "M[1,1] = " in text and "c[7] = " in text and "g[7] = " in text and "friction[7] = " in text


@pytest.mark.parametrize("seed", range(4))
def test_recursive_form_of_random_arms(seed):
    """Random rows (generic float twists, prismatic joints, fixed rows with inertia, base and tool, both
    conventions): the printed recursive form equals the numeric M, c, g."""
    rng = np.random.default_rng(500 + seed)
    robot = _random_inertial_arm(rng, int(rng.integers(2, 5)))
    if not any(l.inertia is not None and l.inertia.mass > 0 for l in robot.joints):
        pytest.skip("no moving mass")
    _check_printed(robot, _recursive_text(robot), rng, count=2)


@pytest.mark.slow
def test_generic_twist_6r_recursive_form_is_quick_and_right():
    """Six revolute rows with every twist, length and offset a random float (no right angles) and full inertia:
    the recursive form in seconds (the expanded route takes more than ten minutes), equal to the numeric engine."""
    import time

    rng = np.random.default_rng(88)
    links = tuple(DHLink(a=float(rng.uniform(0.05, 0.4)), alpha=float(rng.choice([-1, 1]) * rng.uniform(0.3, 1.3)),
                         d=float(rng.uniform(0.05, 0.3)),
                         inertia=LinkInertia(mass=float(rng.uniform(0.5, 3)), com=tuple(rng.uniform(-0.1, 0.1, 3)),
                                             inertia=tuple(np.r_[rng.uniform(0.05, 0.1, 3), rng.uniform(-2e-3, 2e-3, 3)]),
                                             motor_inertia=0.1)) for _ in range(6))
    robot = denavit.DHRobot(name="generic6r", links=links)
    from denavit.symbolic import dynamics_form

    assert dynamics_form(robot) == "recursive" and dynamics_form(denavit.load_robot("puma560")) == "hand"
    t0 = time.process_time()
    text = _recursive_text(robot)
    assert time.process_time() - t0 < 120  # a generous bound on CPU seconds (a few when measured), not a benchmark
    _check_printed(robot, text, rng, count=2)
    from denavit.report import Equation, Text, derive  # the report writes this form too, and checks it

    sec = derive(robot, q=list(rng.uniform(-1, 1, 6)), qd=[1] * 6, topics=["dynamics"]).section("dynamics")
    assert "M_{11}" in [x.lhs for x in sec.steps if isinstance(x, Equation)]
    texts = " ".join(x.text for x in sec.steps if isinstance(x, Text))
    assert "these formulas at the case vs the numeric engine: M agree" in texts and "DISAGREE" not in texts


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="no LaTeX engine")
def test_recursive_form_latex_compiles(tmp_path):
    tex = _recursive_text(denavit.load_robot("panda"), "latex")
    assert "J^{b}_{2xy}" in tex and "\\omega_{2x}" in tex and "L^{3}_{2x}" in tex and "\\dot{q}_{1}" in tex
    doc = ("\\documentclass{article}\\usepackage{amsmath}\\usepackage[paperwidth=40in,paperheight=200in]"
           "{geometry}\\begin{document}\\[" + tex + "\\]\\end{document}\n")
    (tmp_path / "panda.tex").write_text(doc)
    run = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "panda.tex"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout[-2000:]


def test_cli_writes_the_recursive_form_for_the_panda(capsys):
    from denavit.cli import main

    assert main(["dynamics", "panda", "--symbolic"]) == 0
    out = capsys.readouterr().out
    assert "recursive form" in out and "M[1,7] = " in out
    assert main(["dynamics", "panda", "--symbolic", "--coriolis"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and len(captured.err.strip().splitlines()) == 1 and "--form hand" in captured.err
