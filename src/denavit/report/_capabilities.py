"""Report sections that plug in library capabilities when they exist: singularities and figures (IK and
dynamics: :mod:`._ik`, :mod:`._dynamics`).

Each section looks the functions it needs up at build time.  When one is missing from this
installation, the section says so (``status="unavailable"``) rather than faking a result.  Every
number taken from such a function is checked here by an independent route where one is cheap:
IK solutions by forward kinematics, singular values against the Jacobian's rank.
"""

from __future__ import annotations

import importlib
import re
from typing import Any, Callable

import numpy as np

from .. import numeric as N
from .._constants import TWIST_ROWS
from ._context import Context
from ._derivation import Equation, Figure, Numbers, Section, Table, Text
from ._sections import latex

__all__ = ["section_singularities", "section_figures", "capability", "arm_picture_name"]


def arm_picture_name(robot_name: str) -> str:
    r"""The file name of a report's picture of the arm: ``<name>-arm.png`` with every character of the robot's name
    other than letters, digits, ``_``, ``.`` and ``-`` written ``_`` (the name is free text; the file name lands in
    ``\includegraphics{...}`` and ``![...](...)``, where ``}``, ``)``, ``/`` or a newline would be syntax).

    >>> arm_picture_name("UR5e"), arm_picture_name("x}\\input{/etc/passwd")
    ('UR5e-arm.png', 'x__input__etc_passwd-arm.png')
    """
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", robot_name)[:80].lstrip(".-") or "robot"
    return f"{stem}-arm.png"


def capability(module: str, *names: str) -> tuple[str, Callable[..., Any]] | None:
    """The first of ``names`` that ``module`` provides, as (name, function); None if none does."""
    try:
        mod = importlib.import_module(module)
    except ImportError as exc:
        if exc.name and not exc.name.startswith("denavit"):
            return None
        return None
    for name in names:
        fn = getattr(mod, name, None)
        if callable(fn):
            return name, fn
    return None


def _unavailable(key: str, title: str, what: str, lead: tuple = ()) -> Section:
    return Section(key, title, lead, status="unavailable",
                   reason=f"{what} is not available in this installation of denavit")


def section_singularities(ctx: Context) -> Section:
    """Symbolic singular conditions with their classification when the library derives them;
    measures of the Jacobian at the numeric case otherwise."""
    robot = ctx.robot
    steps: list = [Text("A configuration is singular when $J_0$ loses rank: the arm cannot move (or resist) "
                        "in some direction.")]
    sym = capability("denavit.symbolic", "singularity_analysis", "singularities_sym", "singular_conditions")
    heavy = robot.dof > 6 or not ctx.symbolic_jacobian_ok
    rows = list(range(6))
    if sym is not None and heavy:
        steps.append(Text("The symbolic analysis is left out for this arm (more than six joints or a long pose "
                          "formula: it would take minutes); numeric measures at the numeric case follow."))
    elif sym is not None:
        try:
            result = sym[1](robot)
        except Exception as exc:  # another area's function: report, do not crash the report
            steps.append(Text(f"The symbolic analysis ({sym[0]}) failed: {type(exc).__name__}: {exc}."))
        else:
            steps += _singular_result_steps(result)
            rows = [TWIST_ROWS.index(r) for r in getattr(result, "rows", TWIST_ROWS) if r in TWIST_ROWS] or rows
    J = N.geometric_jacobian(robot, ctx.q)[rows, :]  # the task rows analysed (an arm of < 6 joints: its own)
    sv = np.linalg.svd(J, compute_uv=False)
    which = "" if len(rows) == 6 else " (rows " + ", ".join(TWIST_ROWS[i] for i in rows) + ")"
    steps.append(Numbers("\\sigma(J_0(q))", sv, note="singular values at the numeric case" + which))
    manip = capability("denavit.numeric", "manipulability")
    if manip is not None:
        steps.append(Numbers("w(q)", np.atleast_1d(manip[1](J)),
                             note="manipulability $\\sqrt{\\det(J J^T)}$ (Yoshikawa 1985)"))
    if sym is None:
        return Section("singularities", "Singularities", tuple(steps), status="unavailable",
                       reason="the symbolic singularity analysis (conditions and their classification) is not "
                              "available in this installation; numeric measures at q are shown")
    return Section("singularities", "Singularities", tuple(steps))


def _singular_result_steps(result: Any) -> list:
    """Present a singularity analysis: the measure, its factors, each condition solved and classified."""
    steps: list = []
    measure = getattr(result, "measure", "")
    det = getattr(result, "determinant", None)
    if det is not None and hasattr(det, "free_symbols") and len(str(det)) < 4000:
        steps.append(Text(f"Measure: {measure}." if measure else "Determinant:"))
        steps.append(Equation("\\det", det))
    if getattr(result, "reason", ""):
        steps.append(Text(f"Note: {result.reason}."))
    rows = []
    for c in getattr(result, "conditions", ()):
        sols = "; ".join(f"{s.variable} = " + ", ".join(f"{v:.4g}" for v in s.values)
                         for s in getattr(c, "solutions", ()))
        factor = getattr(c, "factor", getattr(c, "condition", ""))
        rows.append((latex(factor) + " = 0" if hasattr(factor, "free_symbols") else str(factor),
                     f"\\text{{{getattr(c, 'kind', '')}}}", f"\\text{{{sols or '-'}}}"))
        if getattr(c, "explanation", ""):
            kind = getattr(c, "kind", "")
            said = c.explanation.split(":", 1)[0].split("/")[0] == kind  # "shoulder: ..." names its kind already
            steps.append(Text(f"${latex(factor)} = 0$" + (f": {c.explanation}" if said else f" ({kind}): {c.explanation}")))
    if rows:
        steps.insert(len(steps) - sum(isinstance(s, Text) and s.text.startswith("$") for s in steps),
                     Table(("\\text{condition}", "\\text{kind}", "\\text{solutions [rad or m]}"), tuple(rows),
                           caption="singular configurations"))
    elif not getattr(result, "reason", ""):
        steps.append(Text("No singular configurations were found."))
    return steps


def section_figures(ctx: Context) -> Section:
    """The arm drawn at the numeric case with its frames, when pictures are available."""
    plot = capability("denavit.viz", "plot_robot")
    if plot is None:
        return _unavailable("figures", "Figures", "drawing the arm (denavit.viz.plot_robot)")
    try:
        import io

        out = plot[1](ctx.robot, ctx.q)
        fig = out if hasattr(out, "savefig") else getattr(out, "figure", None)
        if fig is None and isinstance(out, tuple):
            fig = next((o for o in out if hasattr(o, "savefig")), None)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110)
    except ImportError as exc:
        return Section("figures", "Figures", (), status="unavailable", reason=str(exc))
    except Exception as exc:
        return Section("figures", "Figures", (), status="unavailable",
                       reason=f"the picture could not be drawn ({type(exc).__name__}: {exc})")
    caption = "The arm at the numeric case, with its DH frames."
    return Section("figures", "Figures", (Figure(buf.getvalue(), caption, arm_picture_name(ctx.robot.name)),))
