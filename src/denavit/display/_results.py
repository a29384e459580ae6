"""IK results, equations of motion, singularity analyses and reports for Jupyter."""

from __future__ import annotations

import base64
import html
from typing import Any

import numpy as np

from ._cells import _g

#: Rows shown at most in the HTML table of a batch of IK results (the rest is counted, not shown).
MAX_HTML_ROWS = 50


# --------------------------------------------------------------------------------------------------
# results


def _ik_header(n: int) -> list[str]:
    return [f"q{k + 1}" for k in range(n)]


def _table_html(caption: str, header: list[str], rows: list[list[str]], more: int = 0) -> str:
    e = html.escape
    out = [f'<table class="denavit-ik"><caption>{e(caption)}</caption>',
           "<thead><tr>" + "".join(f"<th>{e(h)}</th>" for h in header) + "</tr></thead><tbody>"]
    out += ["<tr>" + "".join(f"<td>{e(c)}</td>" for c in r) + "</tr>" for r in rows]
    out.append("</tbody></table>")
    if more:
        out.append(f"<p>… and {more} more rows (at most {MAX_HTML_ROWS} are shown)</p>")
    return "\n".join(out)


def _res(x: Any) -> str:
    return f"{float(x):.1e}"


def _analytic_html(r: Any) -> str:
    sol = np.asarray(r.solutions, dtype=float)
    n = sol.shape[-1]
    has_free = bool(np.any(r.continuum))
    header = ["#"] + (["pose"] if sol.ndim > 2 else []) + ["branch"] + (["free"] if has_free else []) \
        + _ik_header(n) + ["position error [m]", "orientation error [rad]"]
    rows: list[list[str]] = []
    total = 0
    if sol.ndim == 2:
        picks = [((), k) for k in range(sol.shape[0])]
    else:
        valid = np.asarray(r.valid)
        picks = [(idx[:-1], idx[-1]) for idx in zip(*np.nonzero(valid))]
    branches = np.asarray(r.branches, dtype=object)
    free = np.asarray(r.free, dtype=object)
    for pose, k in picks:
        total += 1
        if len(rows) >= MAX_HTML_ROWS:
            continue
        at = (*pose, k)
        row = [str(total)] + ([str(tuple(int(i) for i in pose))] if sol.ndim > 2 else [])
        row.append(str(branches[at]))
        if has_free:
            row.append(str(free[at]))
        row += [_g(float(v)) for v in sol[at]]
        row += [_res(np.asarray(r.position_error)[at]), _res(np.asarray(r.orientation_error)[at])]
        rows.append(row)
    out_lim = r.outside_limits
    outside = int(np.sum(out_lim)) if sol.ndim > 2 else int(np.asarray(out_lim).reshape(-1, n).shape[0])
    caption = (f"{total} closed-form solution{'s' if total != 1 else ''} ({r.method}; controls {r.controlled}); "
               f"{outside} more outside the joint limits; q in rad (revolute) and m (prismatic)")
    return _table_html(caption, header, rows, max(0, total - MAX_HTML_ROWS))


def _numeric_html(r: Any) -> str:
    q = np.asarray(r.q, dtype=float)
    n = q.shape[-1]
    flat_q = q.reshape(-1, n)
    fields = [np.asarray(getattr(r, f)).reshape(-1) for f in
              ("success", "position_error", "orientation_error", "iterations", "restarts", "reason")]
    batch = q.ndim > 1
    header = (["target"] if batch else []) + _ik_header(n) + [
        "success", "position error [m]", "orientation error [rad]", "iterations", "restarts", "reason"]
    rows = []
    for i in range(min(flat_q.shape[0], MAX_HTML_ROWS)):
        idx = [str(tuple(int(j) for j in np.unravel_index(i, q.shape[:-1])))] if batch else []
        ok, pe, oe, it, rs, why = (f[i] for f in fields)
        rows.append(idx + [_g(float(v)) for v in flat_q[i]]
                    + ["yes" if ok else "no", _res(pe), _res(oe), str(int(it)), str(int(rs)), str(why)])
    good = int(np.sum(fields[0]))
    caption = (f"numeric IK: {good} of {flat_q.shape[0]} target{'s' if flat_q.shape[0] != 1 else ''} solved; "
               "q in rad (revolute) and m (prismatic)")
    return _table_html(caption, header, rows, max(0, flat_q.shape[0] - MAX_HTML_ROWS))


def ik_html(result: Any) -> str:
    """An IK result (:class:`~denavit.AnalyticIKResult` or :class:`~denavit.IKResult`) as an HTML table:
    one row per solution (per target for a batch) with its branch label and residuals."""
    if hasattr(result, "branches"):
        return _analytic_html(result)
    return _numeric_html(result)


def dynamics_latex(terms: Any) -> str:
    """Equations of motion (:class:`~denavit.symbolic.DynamicsTerms`) as display LaTeX for Jupyter: the
    entries of M, c, g and τ_f as :func:`denavit.symbolic.format_dynamics` writes them."""
    from ..symbolic import format_dynamics

    return "$$" + format_dynamics(terms, style="latex") + "$$"


def derivation_markdown(derivation: Any) -> str:
    """A report (:class:`~denavit.report.Derivation`) as Markdown for Jupyter: the report's own Markdown
    renderer, with its pictures embedded as data URIs instead of files beside it."""
    from ..report import render_markdown

    text, files = render_markdown(derivation)
    for name, data in files.items():
        uri = "data:image/png;base64," + base64.b64encode(data).decode("ascii")
        text = text.replace(f"]({name})", f"]({uri})")
    return text


def singularities_markdown(analysis: Any) -> str:
    """A singularity analysis (:class:`~denavit.symbolic.SingularityAnalysis`) as Markdown with typeset
    formulas: the measure, its factored form, and each condition with its kind, explanation and solutions."""
    import sympy as sp

    a = analysis
    out = [f"**Singularities of {a.robot}**: {a.matrix_note}; measure: {a.measure}", "",
           f"$$ {sp.latex(a.determinant)} $$", ""]
    if a.constant_factors:
        out += ["Constant factors (assumed non-zero): "
                + ", ".join(f"${sp.latex(c)}$" for c in a.constant_factors), ""]
    if a.everywhere:
        out.append(f"**Singular everywhere**: rank {a.generic_rank} of {a.full_rank} for every q ({a.reason}).")
    elif a.conditions:
        out.append("Singular when:")
        for c in a.conditions:
            sols = "; ".join(
                (f"${sp.latex(sp.Symbol(s.variable))} = {sp.latex(s.expression)}$" if s.expression is not None
                 else f"{s.variable} numerically")
                + (" at " + ", ".join(_g(v) for v in s.values) if s.values else "")
                for s in c.solutions)
            out.append(f"- ${sp.latex(c.factor)} = 0$ ({c.kind}): {c.explanation.rstrip('.')}."
                       + (f" Solutions: {sols}." if sols else ""))
    elif "minors" in a.measure:
        out.append("The minors share no factor: singular configurations, if any, lie where all the minors vanish "
                   "together, which is not solved symbolically here.")
    else:
        out.append("No singular configuration: the determinant never vanishes.")
    return "\n".join(out)
