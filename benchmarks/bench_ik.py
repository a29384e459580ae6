"""Benchmark of inverse kinematics: denavit (numeric LM batched, analytic all-solutions batched) against peers.

Run:  python benchmarks/bench_ik.py [--n 10000] [--peer-n 500] [--robot puma560] [--markdown docs/ik_bench.md]
      python benchmarks/bench_ik.py --per-pose [--n 2000] [--robot ur5]   (compiled one-pose IK vs ik-geo, EAIK)

Targets: FK of random joint values uniformly within the joint limits (seeded).  For Pieper arms of the elbow and
Stanford classes a row "general resultant route" times the same analytic pipeline forced onto the resultant
route those arms used before the direct closed forms (same run, for comparison).  Success = the returned q is
within the joint limits and reproduces the target to 1e-6 m and 1e-6 rad, checked with denavit's FK (the same
check for every library).  Times are wall-clock per solve: for denavit the batch time divided by the number of
targets (median and p95 over repeated batches of 1,000); for the peers one call per target.
Peers (skipped when not importable or when they do not model the arm): roboticstoolbox-python ``ets().ik_LM``
(C++), IKPy (scipy optimiser, seeded at mid-limits), ik-geo (all solutions of 6R arms by subproblems, Rust;
``gen_six_dof``, a 2-D search, for arms with no special structure such as jaco2-6dof).  A row "general 6R
eigenvalue route" times analytic_ik forced onto the Raghavan–Roth / Manocha–Canny solver on arms that have a
closed form (on jaco2-6dof it is analytic_ik's own route).  "solutions / target" is the mean number of distinct
verified solutions returned by the all-solution solvers.

``--per-pose`` (issue 30): ``denavit.compile(robot).analytic_ik``, one pose per call, against ik-geo and EAIK (C++)
on the same poses in interleaved rounds (CPU time, pinned to one core; median µs/pose, median ratio denavit/peer), after counting the poses whose
solution sets differ (1e-6, modulo 2π); then 10⁵ poses through the compiled kernel's own loop on one core.  After
its first call ``analytic_ik`` is a CPython built-in (codegen/_ik_fastcall.py: check, kernel and result in machine
code); the result holds its solutions built, its other fields are made when first read: "denavit, solutions read"
times the call and one read of ``solutions`` (the peers return their solutions built).  "denavit kernel" is numba's
own entry of the kernel alone, into one reused output vector.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

import denavit
from denavit import analytic_ik, forward_kinematics, load_robot, solve_ik

TOL = 1e-6


def _targets(robot, n, seed=0):
    rng = np.random.default_rng(seed)
    lim = np.clip(robot.q_limits, -np.pi, np.pi)  # continuous joints: one turn
    q = rng.uniform(lim[:, 0], lim[:, 1], (n, robot.dof))
    return q, forward_kinematics(robot, q)


def _ok(robot, q, T):
    q = np.asarray(q, dtype=float)
    if q.shape[-1] != robot.dof or not np.all(np.isfinite(q)):
        return False
    lim = robot.q_limits
    if np.any(q < lim[:, 0] - 1e-9) or np.any(q > lim[:, 1] + 1e-9):
        return False
    F = forward_kinematics(robot, q)
    R = F[:3, :3].T @ T[:3, :3]
    v = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    ang = np.arctan2(np.linalg.norm(v) / 2, (np.trace(R) - 1) / 2)
    return np.linalg.norm(F[:3, 3] - T[:3, 3]) <= TOL and ang <= TOL


def _stats(times):
    t = np.asarray(times) * 1e6
    return float(np.median(t)), float(np.percentile(t, 95))


def bench_denavit_numeric(robot, T, chunk=1000):
    rng = np.random.default_rng(1)
    per, qs = [], []
    for i in range(0, len(T), chunk):
        t0 = time.perf_counter()
        res = solve_ik(robot, T[i:i + chunk], rng=rng)
        per.append((time.perf_counter() - t0) / len(T[i:i + chunk]))
        qs.append(res.q)
    q = np.concatenate(qs)
    succ = np.mean([_ok(robot, a, b) for a, b in zip(q, T)])
    return succ, *_stats(per)


def _time_all_solutions(robot, q_true, T, solve, chunk=1000):
    """Time an all-solutions solver over batches; success = the generating q is among the solutions.

    Returns (success, median µs, p95 µs, mean number of solutions per target)."""
    per, found, count = [], [], []
    rev = np.array([t.value == "revolute" for t in robot.joint_types])
    for i in range(0, len(T), chunk):
        t0 = time.perf_counter()
        res = solve(T[i:i + chunk])
        per.append((time.perf_counter() - t0) / len(T[i:i + chunk]))
        d = res.solutions - q_true[i:i + chunk, None]
        d = np.where(rev, np.abs((d + np.pi) % (2 * np.pi) - np.pi), np.abs(d))
        found.append(np.nanmin(np.where(res.valid, d.max(axis=-1), np.inf), axis=1) < 1e-6)
        count.append(res.count)
    return float(np.mean(np.concatenate(found))), *_stats(per), float(np.mean(np.concatenate(count)))


def bench_denavit_analytic(robot, q_true, T):
    return _time_all_solutions(robot, q_true, T, lambda Tb: analytic_ik(robot, Tb))


def bench_denavit_resultant(robot, q_true, T):
    """The same pipeline forced onto the general resultant route (companion-matrix roots + polish) that Pieper arms
    used before the direct closed forms; None for arms the closed forms do not cover."""
    from denavit.ik._analytic import _plan, _solve

    if not _plan(robot, True).route.startswith("closed form"):
        return None
    plan = _plan(robot, False)
    return _time_all_solutions(robot, q_true, T, lambda Tb: _solve(robot, Tb, plan))[:3]


def bench_denavit_general(robot, q_true, T):
    """The general 6R eigenvalue route (Raghavan–Roth / Manocha–Canny), forced on any 6R arm (on arms without a
    closed form it is what analytic_ik uses anyway)."""
    from denavit.errors import UnsupportedRobotError
    from denavit.ik._analytic import _plan, _solve

    try:
        plan = _plan(robot, True, True)
    except UnsupportedRobotError:
        return None
    return _time_all_solutions(robot, q_true, T, lambda Tb: _solve(robot, Tb, plan))


def rtb_ets(robot, name):
    """roboticstoolbox's ETS of the very same DH table (standard DH, no fixed rows; else None)."""
    import roboticstoolbox as rtb

    if robot.convention.value != "standard" or any(not l.is_joint for l in robot.links):
        return None
    links = []
    for link in robot.links:  # the same DH table, so both libraries solve the very same arm
        kw = dict(a=link.a, alpha=link.alpha, qlim=list(link.q_limits) if link.q_limits else None)
        if link.joint.value == "revolute":
            links.append(rtb.RevoluteDH(d=link.d, offset=link.theta, **kw))
        else:
            links.append(rtb.PrismaticDH(theta=link.theta, offset=link.d, **kw))
    return rtb.DHRobot(links, name=name).ets()


def bench_rtb(robot, name, T):
    try:
        import roboticstoolbox as rtb
    except ImportError:
        return None
    ets = rtb_ets(robot, name)
    if ets is None:
        return None
    times, ok = [], []
    for Tk in T:
        t0 = time.perf_counter()
        sol = ets.ik_LM(Tk, tol=1e-12, joint_limits=True, ilimit=100, slimit=100)
        times.append(time.perf_counter() - t0)
        ok.append(bool(sol.success) and _ok(robot, sol.q, Tk))
    return float(np.mean(ok)), *_stats(times)


def _fold_limits(robot, q):
    """Revolute angles shifted by whole turns into the limits where that helps (the same for every library)."""
    q = np.array(q, dtype=float)
    lim = robot.q_limits
    for k, t in enumerate(robot.joint_types):
        if t.value == "revolute":
            q[k] = (q[k] + np.pi) % (2 * np.pi) - np.pi
            for sh in (2 * np.pi, -2 * np.pi):
                if not lim[k, 0] <= q[k] <= lim[k, 1] and lim[k, 0] <= q[k] + sh <= lim[k, 1]:
                    q[k] += sh
    return q


def bench_ikpy(robot, T):
    """IKPy (scipy least squares on its own chain): the joint-screw form C0 J1 C1 ⋯ Jn Cn as URDF links."""
    try:
        from ikpy.chain import Chain
        from ikpy.link import OriginLink, URDFLink
    except ImportError:
        return None
    from denavit.numeric import rpy_from_rotation
    from denavit.chain import screws_of as chain_of

    ch = chain_of(robot)
    lim = robot.q_limits
    links = [OriginLink()]
    for k in range(ch.n):
        C = ch.consts[k]
        kw = {"translation": [0, 0, 1]} if ch.prismatic[k] else {"rotation": [0, 0, 1]}
        links.append(URDFLink(f"j{k + 1}", C[:3, 3], rpy_from_rotation(C[:3, :3]), bounds=tuple(lim[k]),
                              joint_type="prismatic" if ch.prismatic[k] else "revolute", **kw))
    C = ch.consts[-1]
    links.append(URDFLink("tool", C[:3, 3], rpy_from_rotation(C[:3, :3]), rotation=None, joint_type="fixed"))
    chain = Chain(links, active_links_mask=[False] + [True] * ch.n + [False])
    finite = np.isfinite(lim)
    mid = np.where(finite.all(axis=1), lim.mean(axis=1), 0.0)
    seed = np.concatenate([[0.0], mid, [0.0]])
    times, ok = [], []
    for Tk in T:
        t0 = time.perf_counter()
        q = chain.inverse_kinematics_frame(Tk, initial_position=seed, orientation_mode="all")
        times.append(time.perf_counter() - t0)
        ok.append(_ok(robot, _fold_limits(robot, q[1:-1]), Tk))
    return float(np.mean(ok)), *_stats(times)


def ikgeo_robot(robot):
    """ik-geo's model of ``robot`` and M = FK(0), or None: axes h_i and points on them at q = 0 (the point shared by
    intersecting axes); R(M) is taken off the target (ik-geo's home rotation is I; its binding reads R transposed)."""
    try:
        from ik_geo import Robot
    except ImportError:
        return None
    from denavit.ik import ik_structure
    from denavit.chain import screw_axes as axis_lines, screws_of as chain_of

    ch = chain_of(robot)
    kind = ik_structure(robot)
    if ch.n != 6 or ch.prismatic.any() or kind not in ("pieper", "parallel", "general"):
        return None
    pts, h = axis_lines(ch, np.zeros(6))

    def meet(idx):  # least-squares common point of the axes idx
        A = sum(np.eye(3) - np.outer(h[i], h[i]) for i in idx)
        b = sum((np.eye(3) - np.outer(h[i], h[i])) @ pts[i] for i in idx)
        return np.linalg.lstsq(A, b, rcond=None)[0]
    P = pts.copy()
    if kind == "pieper":
        P[3] = P[4] = P[5] = meet((3, 4, 5))
        make = Robot.spherical_two_parallel if abs(abs(h[1] @ h[2]) - 1) < 1e-9 else Robot.spherical
    elif kind == "parallel":
        P[4] = P[5] = meet((4, 5))
        make = Robot.three_parallel_two_intersecting
    else:
        make = Robot.gen_six_dof  # no special structure: ik-geo's 2-D search
    M = forward_kinematics(robot, np.zeros(6))
    p = np.vstack([P[0], np.diff(P, axis=0), M[:3, 3] - P[5]])  # p01, p12, …, p56, p6T
    return make(h, p), M


def eaik_robot(robot):
    """EAIK's model of ``robot`` (C++, subproblem decomposition; Ostermeier et al. 2024), or None: axes h_i and
    offsets between points on them at q = 0 (H-P form), R(FK(0)) as its tool rotation: our targets and q unchanged."""
    try:
        import eaik.pybindings.EAIK as EAIK
    except ImportError:
        return None
    from denavit.chain import screw_axes, screws_of

    ch = screws_of(robot)
    if ch.n != 6 or ch.prismatic.any():
        return None
    pts, h = screw_axes(ch, np.zeros(6))
    M = forward_kinematics(robot, np.zeros(6))
    P = np.vstack([pts[0], np.diff(pts, axis=0), M[:3, 3] - pts[5]])
    bot = EAIK.Robot(h.T, P.T, M[:3, :3], [], True)
    return bot if bot.has_known_decomposition() else None


def bench_ikgeo(robot, T):
    """ik-geo (Elias & Wen 2022, Rust): all solutions of 6R arms it has a class for; success: some returned solution
    (folded into the limits) reproduces the target within the limits."""
    made = ikgeo_robot(robot)
    if made is None:
        return None
    bot, M = made
    times, ok, count = [], [], []
    for Tk in T:
        R = (Tk[:3, :3] @ M[:3, :3].T).T  # the Python binding reads the 3x3 in column-major order
        t0 = time.perf_counter()
        sols = bot.get_ik(R, Tk[:3, 3])
        times.append(time.perf_counter() - t0)
        good = [q for q, ls in sols if not ls and _ok(robot, _fold_limits(robot, q), Tk)]
        ok.append(bool(good))
        count.append(len(_distinct(np.array([_fold_limits(robot, q) for q in good]))) if good else 0)
    return float(np.mean(ok)), *_stats(times), float(np.mean(count))


def _distinct(qs, tol=1e-6):
    out = []
    for q in qs:
        if all(np.abs((q - p + np.pi) % (2 * np.pi) - np.pi).max() > tol for p in out):
            out.append(q)
    return out


def _same_set(A, B, rev, tol=1e-6):
    """Every row of A is within tol of some row of B (revolute angles modulo 2π), and the other way round."""

    def covered(X, Y):
        if len(X) == 0 or len(Y) == 0:
            return len(X) == 0
        d = np.abs(X[:, None] - Y[None])
        d = np.where(rev, np.abs((d + np.pi) % (2 * np.pi) - np.pi), d)
        return bool(np.all(d.max(-1).min(-1) < tol))
    return covered(A, B) and covered(B, A)


def _pin_one_core():
    """Pin this process to one core (CPU time measures the solver's own work; the machine is shared)."""
    try:
        import os

        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    except (AttributeError, OSError):
        pass


def per_pose(name, n, rounds=7, batch=100_000):
    """Compiled analytic_ik (one pose per call) against ik-geo and EAIK on the same n poses, after checking that the
    three return the same solution sets (denavit's inside and outside the limits: the peers ignore limits)."""
    robot = load_robot(name)
    fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
    _, T = _targets(robot, n, seed=7)
    rev = np.array([t.value == "revolute" for t in robot.joint_types])
    geo, eaik = ikgeo_robot(robot), eaik_robot(robot)
    Rg = [(Tk[:3, :3] @ geo[1][:3, :3].T).T.copy() for Tk in T] if geo else None
    Ts = [np.ascontiguousarray(Tk) for Tk in T]
    solvers = {"denavit": lambda k: fast.analytic_ik(Ts[k]),
               "denavit, solutions read": lambda k: fast.analytic_ik(Ts[k]).solutions,
               "EAIK": eaik and (lambda k: eaik.calculate_IK(Ts[k])),
               "ik-geo": geo and (lambda k: geo[0].get_ik(Rg[k], T[k, :3, 3]))}
    solvers = {who: f for who, f in solvers.items() if f}
    differ = dict.fromkeys(list(solvers)[2:], 0)
    kern = fast._analytic_solver()
    if kern:  # the machine-code entry alone, into one reused output vector (no Python around it)
        fast.analytic_ik(Ts[0])
        one, K, o1 = next(iter(kern[2].overloads.values())).entry_point, kern[0], np.empty(kern[4])
        solvers["denavit kernel"] = lambda k: one(Ts[k], K, o1)
    for k in range(n):  # completeness, against each other
        res = fast.analytic_ik(Ts[k])
        mine = np.concatenate([res.solutions, np.reshape(res.outside_limits, (-1, robot.dof))])
        peers = {}
        if geo:
            peers["ik-geo"] = np.array([x for x, ls in solvers["ik-geo"](k) if not ls]).reshape(-1, 6)
        if eaik:
            s = solvers["EAIK"](k)
            peers["EAIK"] = np.asarray(s.Q)[~np.asarray(s.is_LS, bool)].reshape(-1, 6)
        for who, Q in peers.items():
            differ[who] += not _same_set(mine, Q, rev)
    times = {who: [] for who in solvers}
    for _ in range(rounds):  # interleaved rounds: the machine's load hits every solver alike
        for who, f in solvers.items():
            t0 = time.process_time()
            for k in range(n):
                f(k)
            times[who].append((time.process_time() - t0) / n * 1e6)
    med = {who: float(np.median(t)) for who, t in times.items()}
    ratios = {f"{me} / {who}": float(np.median(np.array(times[me]) / np.array(times[who])))
              for who in differ for me in [*list(solvers)[:2], "denavit kernel"] if me in times}
    return med, ratios, differ, _batch_rates(fast, eaik, _targets(robot, batch, seed=8)[1])


def _batch_rates(fast, eaik, Tb, rounds=3):
    """Poses per second of the compiled kernel's own loop over the batch Tb (one thread: its batch entry, blocks of
    poses, into the plain solver's batched layout), of the public batched ``analytic_ik`` (that loop, the
    hand-overs to the plain solver, the result) and of EAIK's batched call with one worker thread, each the best of
    ``rounds`` interleaved rounds (CPU time); the share of poses the kernel hands to the plain solver."""
    kern, B = fast._analytic_solver(), len(Tb)
    Tb = np.ascontiguousarray(Tb)
    best = {}
    if kern:
        K, many, n = kern[0], kern[3], fast.dof

        def layout():  # the batched layout the kernel writes (as codegen._solvers._batch)
            return (np.empty((B, 8, n)), np.empty((B, 8)), np.empty((B, 8)), np.empty((B, 8), dtype=bool),
                    np.empty((B, 8), dtype=np.int8), np.empty(B, dtype=np.int64), np.empty(B, dtype=np.int8))
        many(Tb[:10], K, *(a[:10] for a in layout()))
        fast.analytic_ik(Tb[:10])
        outs = layout()
        runs = {"kernel": lambda: many(Tb, K, *outs), "analytic_ik(batch)": lambda: fast.analytic_ik(Tb)}
    else:
        runs = {}
    if eaik:
        Tl = list(Tb)
        runs["EAIK batched (1 thread)"] = lambda: eaik.calculate_IK_batched(Tl, 1)
    for _ in range(rounds):
        for who, f in runs.items():
            t0 = time.process_time()
            f()
            best[who] = min(best.get(who, np.inf), time.process_time() - t0)
    out = {f"{who} poses/s": B / dt for who, dt in best.items()}
    if kern:
        out["kernel µs/pose"], out["handed over"] = best["kernel"] / B * 1e6, (outs[-1] == 1).mean()
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10000, help="targets for denavit (default 10000)")
    ap.add_argument("--peer-n", type=int, default=500, help="targets for the per-call peers (default 500)")
    ap.add_argument("--robot", action="append", help="catalogue arm (repeatable; default puma560, ur5, stanford)")
    ap.add_argument("--markdown", help="also write the table to this Markdown file")
    ap.add_argument("--per-pose", action="store_true", help="only the compiled one-pose analytic IK against ik-geo "
                    "and EAIK (puma560, ur5, offset-6r unless --robot), and a 1e5-pose batch of the compiled kernel")
    args = ap.parse_args(argv)
    if args.per_pose:
        _pin_one_core()
        for name in args.robot or ["puma560", "ur5", "offset-6r"]:
            parts = per_pose(name, min(args.n, 2000))  # µs/pose, denavit/peer, poses whose sets differ, batch
            print(name, " | ".join(", ".join(f"{w} {v:.3g}" for w, v in d.items()) for d in parts))
        return
    rows = []
    for name in args.robot or ["puma560", "ur5", "stanford", "jaco2-6dof"]:
        robot = load_robot(name)
        q, T = _targets(robot, args.n)
        s, med, p95 = bench_denavit_numeric(robot, T)
        rows.append((name, "denavit solve_ik (LM, batched)", args.n, s, med, p95))
        rows.append((name, "denavit analytic_ik (all solutions, batched)", args.n, *bench_denavit_analytic(robot, q, T)))
        start = len(rows) - 2
        r = bench_denavit_resultant(robot, q, T)
        if r is not None:
            rows.append((name, "denavit analytic_ik, general resultant route", args.n, *r))
        r = bench_denavit_general(robot, q, T)
        if r is not None and denavit.ik.ik_structure(robot) != "general":
            rows.append((name, "denavit analytic_ik, general 6R eigenvalue route", args.n, *r))
        for label, fn in (("roboticstoolbox ets().ik_LM (per call)", lambda: bench_rtb(robot, name, T[: args.peer_n])),
                          ("IKPy inverse_kinematics_frame (per call)", lambda: bench_ikpy(robot, T[: args.peer_n])),
                          ("ik-geo get_ik (all solutions, per call)", lambda: bench_ikgeo(robot, T[: args.peer_n]))):
            r = fn()
            if r is not None:
                rows.append((name, label, args.peer_n, *r))
        for row in rows[start:]:
            print(f"{row[0]:10s} {row[1]:48s} n={row[2]:6d} success {row[3]:.4f}  median {row[4]:8.1f} us  "
                  f"p95 {row[5]:8.1f} us" + (f"  solutions/target {row[6]:.2f}" if len(row) > 6 else ""))
    table = ["| arm | solver | targets | success (in limits, 1e-6) | median / solve [µs] | p95 / solve [µs] "
             "| solutions / target |", "|---|---|---:|---:|---:|---:|---:|"]
    table += [f"| {r[0]} | {r[1]} | {r[2]} | {r[3]:.4f} | {r[4]:.1f} | {r[5]:.1f} | "
              f"{f'{r[6]:.2f}' if len(r) > 6 else '—'} |" for r in rows]
    head = f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()} / Python {platform.python_version()} " \
           f"/ numpy {np.__version__} / denavit {denavit.__version__}."
    text = head + "\n\n" + "\n".join(table) + "\n"
    print(text)
    if args.markdown:
        with open(args.markdown, "w", encoding="utf-8") as fh:
            fh.write(text)


if __name__ == "__main__":
    main()
