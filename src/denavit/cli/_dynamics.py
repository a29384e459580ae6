"""Subcommands on dynamics: ``dynamics`` (M, C, c, g, τ numeric or symbolic) and ``simulate``."""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from ..errors import MissingDependencyError, ParseError
from ._common import (MAX_SYMBOLIC_ANALYSIS_JOINTS, add_common, add_q, check_values, joint_values, load, matrix_text,
                      numbers_text, require_finite, require_symbolic_size)
from ._output import add_no_clobber, check_output, output_file
from ._shared import q_out

#: simulate: most output samples (--duration / --dt) and most evaluations of the dynamics in one run (about
#: half a minute on a 6-joint arm); beyond it the run is refused with a message, not left to run for hours.
MAX_SAMPLES = 100_000
MAX_EVALUATIONS = 50_000
PLOTS = (".png", ".svg", ".pdf")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("dynamics", help="equations of motion: M(q), C(q, qd), g(q), friction and joint torques")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("--qd", metavar="QD", help="joint rates (default zeros)")
    p.add_argument("--qdd", metavar="QDD", help="joint accelerations (default zeros)")
    p.add_argument("--symbolic", action="store_true", help="the symbolic equations of motion")
    p.add_argument("--derivatives", action="store_true",
                   help="also dtau/dq and dtau/dqd at -q/--qd/--qdd (per rad or m; friction included); with "
                        "--symbolic also as formulas, with dg/dq (arms of up to 6 joints)")
    p.add_argument("--method", choices=["lagrange", "newton-euler", "steps"], default="lagrange",
                   help="symbolic route: Lagrange in Jacobian form (fast), Newton-Euler, or the literal Lagrange steps")
    p.add_argument("--format", choices=["text", "latex", "markdown"], default="text", help="symbolic output format")
    p.add_argument("--simplify", choices=["none", "trig", "full"], default="trig", help="simplification policy")
    p.add_argument("--numeric-params", action="store_true", help="substitute the parameter values symbolically")
    p.add_argument("--no-cse", action="store_true", help="never pull out common subexpressions (default: only for long results)")
    p.add_argument("--coriolis", action="store_true", help="also print the matrix C (symbolic)")
    p.add_argument("--form", choices=["auto", "hand", "recursive"], default="auto",
                   help="symbolic M, c, g (lagrange): entry by entry ('hand'), or as recursions in named link "
                        "quantities ('recursive'); 'auto': hand for arms whose entries stay short (up to 6 joints, "
                        "twists multiples of 90 deg), recursive otherwise")
    p.set_defaults(handler=cmd_dynamics)

    p = sub.add_parser("simulate", help="simulate the arm's motion from an initial state")
    add_common(p)
    p.add_argument("--q0", required=True, metavar="Q", help="initial joint positions")
    p.add_argument("--qd0", metavar="QD", help="initial joint rates (default zeros)")
    p.add_argument("--duration", required=True, metavar="T", help="length of the run [s]")
    p.add_argument("--tau", metavar="TAU", help="constant joint torques [N m / N] (default zeros)")
    p.add_argument("--dt", default="0.01", metavar="DT", help="sampling interval of the output [s]")
    p.add_argument("--no-friction", action="store_true", help="ignore joint friction")
    p.add_argument("-o", "--output", metavar="PNG",
                   help="plot of the joint trajectories and energy: .png, .svg or .pdf (needs denavit[plot])")
    p.add_argument("--ignore-limits", action="store_true", help="accept q0 outside the joint limits")
    add_no_clobber(p)
    p.set_defaults(handler=cmd_simulate)


def _number(text: str, what: str, positive: bool = True) -> float:
    from ..io import parse_values

    value = float(check_values(parse_values(text, 1, what=what), what)[0])
    if positive and not value > 0:
        raise ParseError(f"{what}: must be positive, got {value:g}")
    return value


def _rates(args, robot, text, what):
    return np.zeros(robot.dof) if text is None else joint_values(args, robot, text, what, rates=True)


#: Seconds between two progress lines of one stage of the symbolic dynamics (its first and last are always shown).
PROGRESS_EVERY = 1.0


def _progress_printer():
    """A progress callback: ``denavit dynamics: <stage> k/n`` on stderr, at most every PROGRESS_EVERY seconds per
    stage (a 6-joint arm's 21 mass-matrix entries printed 22 lines)."""
    last: dict[str, float] = {}

    def show(stage: str, done: int, total: int) -> None:
        now = time.perf_counter()
        if stage not in last or done >= total or now - last[stage] >= PROGRESS_EVERY:
            last[stage] = now
            print(f"denavit dynamics: {stage} {done}/{total}", file=sys.stderr, flush=True)

    return show


def cmd_dynamics(args: argparse.Namespace):
    from ..numeric import require_dynamics

    robot = load(args)
    require_dynamics(robot)
    data: dict = {"robot": robot.name}
    lines: list[str] = []
    if args.derivatives and args.q is None and not args.symbolic:
        raise ParseError("--derivatives: give the joint values with -q (and --qd, --qdd), or --symbolic for the formulas")
    if args.derivatives and args.symbolic:
        _check_symbolic_derivatives(robot, args)
    if args.q is not None:  # bad values fail now, not after the symbolic work
        joint_values(args, robot, args.q)
        _rates(args, robot, args.qd, "qd")
        _rates(args, robot, args.qdd, "qdd")
    if args.symbolic:
        require_symbolic_size(robot, "dynamics --symbolic", MAX_SYMBOLIC_ANALYSIS_JOINTS)
        sdata, slines = _symbolic(robot, args)
        data.update(sdata)
        lines += slines
        if args.derivatives:
            ddata, dlines = _symbolic_derivatives(robot, args)
            data.update(ddata)
            lines += dlines
    elif args.q is None:
        raise ParseError("give joint values with -q (or --symbolic for the equations)")
    if args.q is not None:
        ndata, nlines = _numeric(robot, args)
        data.update(ndata)
        lines += ([""] if lines else []) + nlines
    return data, "\n".join(lines)


def _numeric(robot, args):
    from ..numeric import coriolis_matrix, friction_torques, gravity_torques, mass_matrix, rnea, rnea_derivatives

    q = joint_values(args, robot, args.q)
    qd = _rates(args, robot, args.qd, "qd")
    qdd = _rates(args, robot, args.qdd, "qdd")
    M, C = mass_matrix(robot, q), coriolis_matrix(robot, q, qd)
    c, g, f = C @ qd, gravity_torques(robot, q), friction_torques(robot, qd)
    tau = rnea(robot, q, qd, qdd)
    require_finite("dynamics", M, C, g, f, tau)
    show = lambda v: q_out(args, robot, v)  # noqa: E731  (--deg: revolute joints in degrees, prismatic in m)
    unit = "deg" if args.deg else "rad"
    vec = numbers_text
    lines = [f"{robot.name}: dynamics at q = [{vec(show(q))}] ({unit}{' for revolute joints' if args.deg else ''}), "
             f"qd = [{vec(show(qd))}], qdd = [{vec(show(qdd))}]",
             "M(q) [kg m^2 / kg] =", matrix_text(M), "C(q, qd) =", matrix_text(C),
             f"c = C qd: [{vec(c)}]", f"g(q): [{vec(g)}]", f"friction: [{vec(f)}]",
             f"tau = M qdd + c + g + friction [N m / N]: [{vec(tau)}]"]
    data = {"q": show(q), "qd": show(qd), "qdd": show(qdd), "angle_unit": unit,
            "M": M, "C": C, "c": c, "g": g, "friction": f, "tau": tau}
    if args.derivatives:
        dq, dqd = rnea_derivatives(robot, q, qd, qdd)
        require_finite("dynamics --derivatives", dq, dqd)
        lines += ["dtau/dq [N m/rad, N/m; rows tau, columns q] =", matrix_text(dq),
                  "dtau/dqd [N m s/rad, N s/m; rows tau, columns qd] =", matrix_text(dqd)]
        data.update(dtau_dq=dq, dtau_dqd=dqd)
    return data, lines


def _symbolic(robot, args):
    import sympy as sp

    from .. import symbolic as S

    t0 = time.perf_counter()
    if args.method == "lagrange" and S.dynamics_form(robot, args.form) == "recursive":
        if args.coriolis:
            raise ParseError("--coriolis: the matrix C is written in the hand form only (add --form hand)")
        rd = S.recursive_dynamics(robot, numeric=args.numeric_params)
        text = S.format_recursive(rd, args.format)
        elapsed = time.perf_counter() - t0
        data = {"form": "recursive", "definitions": {str(k): v for k, v, _ in rd.definitions},
                "M_symbolic": rd.M, "c_symbolic": rd.c, "g_symbolic": rd.g, "symbolic_text": text,
                "format": args.format, "method": args.method, "seconds": round(elapsed, 3)}
        return data, [f"{robot.name}: equations of motion ({args.method}, recursive form, {elapsed:.2f} s)",
                      _fitted(text, args)]
    kw = dict(simplify=args.simplify, numeric=args.numeric_params, progress=None if args.json else _progress_printer())
    if args.method == "newton-euler":
        terms = S.newton_euler_dynamics(robot, **kw).terms
    elif args.method == "steps":
        terms = S.lagrange_steps(robot, **kw).terms
    else:
        terms = S.lagrangian_dynamics(robot, coriolis=args.coriolis, **kw)
    include = ("M", "C", "c", "g", "friction") if args.coriolis else ("M", "c", "g", "friction")
    text = S.format_dynamics(terms, args.format, cse=False if args.no_cse else None, include=include,
                             gravity_symbol=True)
    elapsed = time.perf_counter() - t0
    data = {"form": terms.form, "M_symbolic": terms.M, "c_symbolic": terms.c, "g_symbolic": terms.g,
            "friction_symbolic": terms.friction, "symbolic_text": text, "format": args.format,
            "method": args.method, "seconds": round(elapsed, 3)}
    if args.coriolis and terms.C is not None:
        data["C_symbolic"] = terms.C
    data["M_latex"] = sp.latex(terms.M)
    return data, [f"{robot.name}: equations of motion ({args.method}, {elapsed:.2f} s)", _fitted(text, args)]


def _check_symbolic_derivatives(robot, args) -> None:
    from .. import symbolic as S

    require_symbolic_size(robot, "dynamics --derivatives --symbolic", S.DERIVATIVES_MAX_DOF)
    if args.method != "lagrange":
        raise ParseError(f"--derivatives --symbolic differentiates the Lagrangian equations: drop --method {args.method}")


def _symbolic_derivatives(robot, args):
    """dtau/dq, dtau/dqd and dg/dq as formulas (:func:`denavit.symbolic.rnea_derivatives_sym`), entry by entry in
    text (C12 = cos(q1 + q2) as the equations above), whole matrices in LaTeX and Markdown.  Gravity is the
    symbol g in the printed forms, its value in JSON."""
    import sympy as sp

    from .. import symbolic as S

    kw = dict(simplify=args.simplify, numeric=args.numeric_params, gravity_symbol=not args.json)
    dq, dqd = S.rnea_derivatives_sym(robot, **kw)
    dg = S.gravity_derivatives_sym(robot, **kw)
    q = S.joint_symbols(robot.dof).q
    blocks = (("dtau/dq", "dtau_dq", dq, "rows tau_i, columns q_k"),
              ("dtau/dqd", "dtau_dqd", dqd, "rows tau_i, columns qd_k; viscous friction on the diagonal, Coulomb friction 0 away "
                                    "from qd = 0"),
              ("dg/dq", "dg_dq", dg, "symmetric: the Hessian of the potential energy"))
    lines = ["", f"{robot.name}: derivatives of tau = M qdd + c + g + friction (dtau/dqdd = M)"]
    data: dict = {}
    for title, key, D, note in blocks:
        lines.append(f"{title} ({note}):")
        if args.format == "latex":
            lines.append(sp.latex(D))
        elif args.format == "markdown":
            lines.append("$$\n" + sp.latex(D) + "\n$$")
        else:
            lines.append(_fitted("\n".join(f"{title}[{i + 1},{k + 1}] = {S.shorthand(D[i, k], q, collapse=False)}"
                                           for i in range(D.rows) for k in range(D.cols)), args))
        data.update({f"{key}_symbolic": D, f"{key}_latex": sp.latex(D)})
    return data, lines


def _fitted(text: str, args) -> str:
    """Text equations broken to the terminal's width (LaTeX and Markdown are for other programs: kept whole)."""
    from ..display import equations_text

    return equations_text(text) if args.format == "text" else text


def cmd_simulate(args: argparse.Namespace):
    from ..numeric import require_dynamics

    check_output(args, args.output, PLOTS, kind="picture format")
    robot = load(args)
    require_dynamics(robot)
    q0 = joint_values(args, robot, args.q0, "q0")
    qd0 = _rates(args, robot, args.qd0, "qd0")
    duration = _number(args.duration, "--duration")
    dt = _number(args.dt, "--dt")
    if duration / dt > MAX_SAMPLES:
        raise ParseError(f"--duration/--dt gives {duration / dt:.3g} samples; at most {MAX_SAMPLES}")
    tau = np.zeros(robot.dof)
    if args.tau is not None:
        from ..io import parse_values

        tau = check_values(parse_values(args.tau, robot.dof, what="--tau"), "--tau")
    res = _budgeted(robot, q0, qd0, duration, tau, dt, not args.no_friction)
    require_finite("simulate", res.q, res.qd, res.energy)
    rev = np.array([t.value == "revolute" for t in robot.joint_types])
    conv = lambda a: q_out(args, robot, a)  # noqa: E731  (--deg: revolute joints in degrees)
    drift = float(np.abs(res.energy - res.energy[0]).max())
    data = {"robot": robot.name, "q0": conv(q0), "qd0": conv(qd0), "duration": duration, "dt": dt,
            "angle_unit": "deg" if args.deg else "rad", "t": res.t, "q": conv(res.q), "qd": conv(res.qd),
            "tau": res.tau, "kinetic": res.kinetic, "potential": res.potential, "energy": res.energy,
            "success": res.success, "message": res.message, "energy_drift": drift, "output": args.output}
    step = max(1, len(res.t) // 10)
    head = "   t [s]  " + "  ".join(f"{'q' + str(k + 1):>10}" for k in range(robot.dof)) + "      energy [J]"
    rows = [f"{t:8.3f}  " + "  ".join(f"{v:10.5f}" for v in conv(q)) + f"  {e:14.6g}"
            for t, q, e in list(zip(res.t, res.q, res.energy))[::step]]
    unit = ("deg" if args.deg else "rad") + (", m for prismatic joints" if not rev.all() else "")
    lines = [f"{robot.name}: simulated {duration:g} s, {len(res.t)} samples (q in {unit})", head, *rows,
             f"energy drift (max |E - E0|): {drift:.3g} J" + ("" if args.no_friction else " (friction dissipates)")]
    if args.output:
        with output_file(args.output) as tmp:
            _plot(res, robot, tmp, args.deg)
        lines.append(f"wrote {args.output}")
    if not res.success:
        lines.append(f"warning: the integrator stopped early: {res.message}")
    return data, "\n".join(lines)


class _OverBudget(Exception):
    pass


def _budgeted(robot, q0, qd0, duration, tau, dt, friction):
    """simulate() with at most MAX_EVALUATIONS evaluations of the dynamics (ParseError beyond: exit 2)."""
    from ..numeric import simulate

    count = [0]
    budget = MAX_EVALUATIONS + int(duration / dt) + 2  # + the torques recomputed at the output samples

    def torque(t, q, qd):
        count[0] += 1
        if count[0] > budget:
            raise _OverBudget
        return tau

    try:
        return simulate(robot, q0, qd0, duration, torque, dt=dt, friction=friction)
    except _OverBudget:
        raise ParseError(f"--duration {duration:g}: the integration needed more than {MAX_EVALUATIONS} evaluations "
                         "of the dynamics (a fast or stiff motion); shorten --duration or lower --tau") from None


def _plot(res, robot, path: str, deg: bool) -> None:
    try:
        import matplotlib
    except ImportError as exc:
        if exc.name != "matplotlib":
            raise
        raise MissingDependencyError("the plot needs matplotlib: pip install 'denavit[plot]'") from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for k in range(robot.dof):
        ax1.plot(res.t, np.degrees(res.q[:, k]) if deg and robot.joint_types[k].value == "revolute" else res.q[:, k],
                 label=f"q{k + 1}")
    ax1.set_ylabel("joint position [deg]" if deg else "joint position [rad, m]")
    ax1.legend(loc="best", fontsize="small")
    ax2.plot(res.t, res.kinetic, label="kinetic")
    ax2.plot(res.t, res.potential, label="potential")
    ax2.plot(res.t, res.energy, label="total", color="k")
    ax2.set_xlabel("t [s]")
    ax2.set_ylabel("energy [J]")
    ax2.legend(loc="best", fontsize="small")
    fig.suptitle(f"{robot.name}: simulation")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


