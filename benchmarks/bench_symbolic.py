"""Symbolic engine: time and text size of M, c, g and of the singularity analysis, beside a peer, in one run.

Run:  python benchmarks/bench_symbolic.py [--arms puma560,ur5,...] [--timeout 600] [--markdown FILE]

Cases (each in a fresh process, so no cache is shared; a case over ``--timeout`` seconds is reported as such):

  dynamics       what ``denavit dynamics ROBOT --symbolic`` prints (``dynamics_form(robot)``): the hand form,
                 ``lagrangian_dynamics(robot, coriolis=False)`` then ``format_dynamics(..., "text",
                 gravity_symbol=True, include=("M", "c", "g"))``, or the recursive form, ``recursive_dynamics``
                 then ``format_recursive``: seconds to derive, seconds with the text, characters and lines
  hand           (``--hand``) the hand form also for the arms whose default is the recursive one
  singularities  ``singularity_analysis(robot)``: seconds, number of conditions
  kane           the peer: sympy.physics.mechanics' KanesMethod on the same arm (standard DH, revolute joints),
                 written here from the DH rows (frames by body-fixed Z–X rotations, bodies at their COMs,
                 gravity as forces), the named lengths kept as the same symbols; seconds to the mass matrix
                 and forcing vector (no trigsimp), characters of str() of both. Before it is timed, its
                 M and forcing are checked against denavit's numeric mass matrix and RNEA at random q.

Arms: the catalogue's puma560, ur5, stanford, jaco2-6dof, panda (stanford and jaco2-6dof carry no inertia:
singularities only) and ``generic6r``: six revolute rows whose lengths, offsets and twists are random floats
(twists like 0.7 rad, no zero or right angles) with a full random COM and inertia tensor (seed 0).
roboticstoolbox's symbolic RNE is not run (its own warning: ten minutes or more for the Puma).
The machine's load average is printed with the table: compare ratios from one run, not absolute times across runs.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time

ARMS = ("puma560", "ur5", "stanford", "jaco2-6dof", "panda", "generic6r")
ANCHOR = ("puma560", "kane")


def generic_6r(seed: int = 0):
    """A 6R arm with every length, offset and twist a random float and a full random inertia (module notes)."""
    import numpy as np
    from denavit import DHLink, DHRobot
    from denavit.model import LinkInertia

    rng = np.random.default_rng(seed)
    links = []
    for _ in range(6):
        alpha = float(rng.choice([-1, 1]) * rng.uniform(0.3, 1.3))
        I = np.concatenate([rng.uniform(0.05, 0.1, 3), rng.uniform(-0.002, 0.002, 3)])
        inertia = LinkInertia(mass=float(rng.uniform(0.5, 3)), com=tuple(float(x) for x in rng.uniform(-0.1, 0.1, 3)),
                              inertia=tuple(float(x) for x in I), motor_inertia=0.1)
        links.append(DHLink(a=float(rng.uniform(0.05, 0.4)), alpha=alpha, d=float(rng.uniform(0.05, 0.3)),
                            inertia=inertia))
    return DHRobot(name="generic6r", links=tuple(links))


def _robot(name: str):
    import denavit

    return generic_6r() if name == "generic6r" else denavit.load_robot(name)


def case_dynamics(name: str, form: str = "auto") -> dict:
    robot = _robot(name)
    if not any(j.inertia is not None for j in robot.joints):
        return {"skipped": "no inertial data"}
    from denavit.symbolic import (dynamics_form, format_dynamics, format_recursive, lagrangian_dynamics,
                                  recursive_dynamics)

    form = dynamics_form(robot, form)
    t0 = time.perf_counter()
    if form == "recursive":
        rd = recursive_dynamics(robot)
        t1 = time.perf_counter()
        text = format_recursive(rd, "text")
    else:
        terms = lagrangian_dynamics(robot, coriolis=False)
        t1 = time.perf_counter()
        text = format_dynamics(terms, "text", gravity_symbol=True, include=("M", "c", "g"))
    t2 = time.perf_counter()
    return {"derive": t1 - t0, "total": t2 - t0, "chars": len(text), "form": form,
            "lines": len(text.splitlines())}


def case_hand(name: str) -> dict:
    return case_dynamics(name, "hand")


def case_singularities(name: str) -> dict:
    from denavit.symbolic import singularity_analysis

    robot = _robot(name)
    t0 = time.perf_counter()
    a = singularity_analysis(robot)
    return {"total": time.perf_counter() - t0, "conditions": len(a.conditions)}


def kane_equations(robot):
    """(M, forcing, q, u, parameter values) of a standard-DH revolute arm by sympy.physics.mechanics' KanesMethod."""
    import sympy as sp
    from sympy.physics import mechanics as me

    from denavit import JointType
    from denavit.model import Convention

    if robot.convention is not Convention.STANDARD or any(t is not JointType.REVOLUTE for t in robot.joint_types):
        raise ValueError("the Kane peer here is written for standard-DH revolute arms")
    n = robot.dof
    q, u = me.dynamicsymbols(f"q1:{n + 1}"), me.dynamicsymbols(f"u1:{n + 1}")
    params = {name: sp.Symbol(name, real=True) for name, _ in robot.parameters}

    def value(link, field, x):
        text = dict(link.symbols).get(field)
        if text in params:
            return params[text]
        if field == "alpha" and abs(abs(x) - sp.pi.evalf() / 2) < 1e-12:
            return sp.sign(x) * sp.pi / 2
        return sp.Rational(repr(float(x))) if x else sp.Integer(0)

    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    frame, origin, bodies, loads = N, O, [], []
    g0 = [sp.Rational(repr(float(x))) for x in robot.gravity]
    for i, link in enumerate(robot.links):
        F = me.ReferenceFrame(f"F{i + 1}")
        F.orient_body_fixed(frame, (q[i] + value(link, "theta", link.theta), value(link, "alpha", link.alpha), 0),
                            "ZXZ")
        P = origin.locatenew(f"O{i + 1}", value(link, "d", link.d) * frame.z + value(link, "a", link.a) * F.x)
        li = link.inertia
        if li is not None and (li.mass or any(li.inertia)):
            m = sp.Rational(repr(li.mass))
            G = P.locatenew(f"G{i + 1}", sum((sp.Rational(repr(c)) * e for c, e in zip(li.com, (F.x, F.y, F.z))),
                                             sp.S(0) * F.x))
            G.set_vel(N, G.pos_from(O).dt(N))
            xx, yy, zz, xy, xz, yz = (sp.Rational(repr(v)) for v in li.inertia)
            body = me.RigidBody(f"B{i + 1}", G, F, m, (me.inertia(F, xx, yy, zz, xy, yz, xz), G))
            bodies.append(body)
            loads.append((G, m * (g0[0] * N.x + g0[1] * N.y + g0[2] * N.z)))
        frame, origin = F, P
    kde = [qi.diff() - ui for qi, ui in zip(q, u)]
    km = me.KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=kde)
    km.kanes_equations(bodies, loads)
    values = {params[k]: v for k, v in robot.parameters}
    return km.mass_matrix, km.forcing, q, u, values


def _check_kane(robot, M, F, q, u, values) -> None:
    import numpy as np
    import sympy as sp

    import denavit

    arm = np.array([j.inertia.motor_inertia if j.inertia else 0.0 for j in robot.joints])
    qs, us = sp.symbols(f"x1:{robot.dof + 1}"), sp.symbols(f"y1:{robot.dof + 1}")
    swap = {**dict(zip(q, qs)), **dict(zip(u, us)), **values}
    f = sp.lambdify([qs, us], [M.xreplace(swap), F.xreplace(swap)], "numpy")
    rng = np.random.default_rng(5)
    for _ in range(3):
        qq, uu = rng.uniform(-np.pi, np.pi, robot.dof), rng.uniform(-1, 1, robot.dof)
        Mk, Fk = (np.array(x, dtype=float) for x in f(qq, uu))
        np.testing.assert_allclose(Mk + np.diag(arm), denavit.mass_matrix(robot, qq), atol=1e-9)
        tau = denavit.rnea(robot, qq, uu, np.zeros(robot.dof), friction=False)
        np.testing.assert_allclose(-Fk.ravel(), tau, atol=1e-8)


def case_kane(name: str) -> dict:
    robot = _robot(name)
    t0 = time.perf_counter()
    M, F, q, u, values = kane_equations(robot)
    seconds = time.perf_counter() - t0
    _check_kane(robot, M, F, q, u, values)
    return {"total": seconds, "chars": len(str(M)) + len(str(F))}


CASES = {"dynamics": case_dynamics, "hand": case_hand, "singularities": case_singularities, "kane": case_kane}


def run_case(kind: str, name: str, timeout: float) -> dict:
    cmd = [sys.executable, __file__, "--case", kind, name]
    t0 = time.perf_counter()
    try:
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"timeout": timeout}
    if out.returncode != 0:
        return {"error": (out.stderr.strip().splitlines() or ["?"])[-1], "wall": time.perf_counter() - t0}
    return json.loads(out.stdout.strip().splitlines()[-1])


def _fmt(r: dict, key: str, unit: str = "") -> str:
    if "timeout" in r:
        return f"> {r['timeout']:.0f}{unit}" if key in ("derive", "total") else "—"
    if "skipped" in r:
        return "—"
    if "error" in r:
        return "error"
    x = r[key]
    return f"{x:,}" if isinstance(x, int) else f"{x:.2f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--arms", default=",".join(ARMS))
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per case (default 600)")
    ap.add_argument("--markdown", help="also write the table to this file")
    ap.add_argument("--hand", action="store_true",
                    help="also time the hand form where the default (auto) form is the recursive one")
    ap.add_argument("--case", nargs=2, metavar=("KIND", "ARM"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.case:
        print(json.dumps(CASES[args.case[0]](args.case[1])))
        return
    arms = [a.strip() for a in args.arms.split(",") if a.strip()]
    load0 = os.getloadavg()[0]
    results = {}
    for arm in arms:
        hand = ("hand",) if args.hand and arm in ("panda", "generic6r") else ()
        for kind in ("dynamics",) + hand + ("singularities",) + (("kane",) if arm == ANCHOR[0] else ()):
            results[arm, kind] = r = run_case(kind, arm, args.timeout)
            print(f"  {arm:12s} {kind:14s} {r}", file=sys.stderr, flush=True)
    load1 = os.getloadavg()[0]
    anchor = results.get(ANCHOR, {}).get("total")
    import sympy

    lines = [f"One run, {platform.machine()} {os.cpu_count()} cores, load average {load0:.2f} → {load1:.2f}, "
             f"Python {platform.python_version()}, sympy {sympy.__version__}; each case in a fresh process"
             + (f"; ratio = time / Kane's raw Puma 560 ({anchor:.2f} s)" if anchor else "") + ".", "",
             "| arm | form | M, c, g derive [s] | + text [s] | text [chars] | lines | ratio to Kane "
             "| singularities [s] | conditions |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for arm in arms:
        s = results[arm, "singularities"]
        for kind in ("dynamics", "hand"):
            if (arm, kind) not in results:
                continue
            d = results[arm, kind]
            ratio = f"{d['total'] / anchor:.2f}" if anchor and "total" in d else "—"
            sing = (f"{_fmt(s, 'total')} | {_fmt(s, 'conditions')}" if kind == "dynamics" else "— | —")
            lines.append(f"| {arm} | {d.get('form', 'hand' if kind == 'hand' else '—')} | {_fmt(d, 'derive')} "
                         f"| {_fmt(d, 'total')} | {_fmt(d, 'chars')} | {_fmt(d, 'lines')} | {ratio} | {sing} |")
        if (arm, "kane") in results:
            k = results[arm, "kane"]
            lines.append(f"| {arm}: sympy.physics.mechanics KanesMethod (raw, no trigsimp) | — | — | {_fmt(k, 'total')} "
                         f"| {_fmt(k, 'chars')} | — | 1 | — | — |")
    table = "\n".join(lines)
    print(table)
    if args.markdown:
        with open(args.markdown, "w") as fh:
            fh.write(table + "\n")


if __name__ == "__main__":
    main()
