"""Singular configurations, symbolic: factor the Jacobian determinant and solve each factor.

The matrix analysed is the Jacobian, or the square sub-Jacobian of the rows a task uses (``rows="vx,vy,wz"``
for a planar arm). For a square 6×6 Jacobian the determinant does not change when the axes are rotated or
the reference point is moved (both are block-triangular maps with determinant 1, Siciliano et al. sec. 3.3),
so it is computed in the axes of a middle frame with the reference point on the last joint axis, where the
entries are shortest (Craig sec. 5.9 does the same with ³J). For a non-square m×k matrix the measure is the
Gram determinant det(JᵀJ) (m > k) or det(J Jᵀ) (m < k), a sum of squared k×k minors (Cauchy–Binet); their
common factor is what is factorized and solved. The algebra (frames, determinants, gcds, factorization) is done
on polynomials in sin qᵢ, cos qᵢ (:class:`~denavit.symbolic._rings.TrigRing`): a Panda's seven 6×6 minors take
seconds. Arms of fewer than six joints are analysed on their task rows (:func:`task_rows`).

Each factor becomes a :class:`SingularCondition`: closed-form solutions when it involves one joint variable
(a cos q + b sin q + c = 0, or a polynomial in a prismatic d), the equation itself otherwise, plus a
classification checked numerically at points of its zero set (wrist: two wrist axes line up; shoulder: the
wrist centre / end point is at a critical distance from the first axis; elbow: one arm joint stretches or
folds the arm; prismatic at zero extension).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Callable

import numpy as np
import sympy as sp

from ..model import DHRobot, Frame
from ..numeric import RANK_RTOL, TWIST_ROWS, geometric_jacobian, jacobian_rank, select_rows
from ._jacobians import geometric_jacobian_sym
from ._singular_classify import ZERO_TOL, aligned_pairs, classify_factor, factor_solutions, random_q
from ._singular_ring import analysis_ring, common_factors, measure_minors, wrist_frame_jacobian
from ._singular_types import SingularCondition, SingularityAnalysis
from ._symbols import joint_symbols, parameter_symbols

__all__ = ["singularity_analysis", "task_rows", "TASK_ROW_SAMPLES"]

TASK_ROW_SAMPLES = 5  # random configurations that decide the task rows of an arm with fewer than 6 joints


# --- the analysis ------------------------------------------------------------------------------------


def _everywhere_reason(robot: DHRobot, rows: list[int], frame: Frame, rng) -> tuple[int, str]:
    ranks, common = [], None
    for _ in range(5):
        x = random_q(robot, rng)
        ranks.append(int(jacobian_rank(geometric_jacobian(robot, x, frame)[rows, :], RANK_RTOL)))
        pairs = set(aligned_pairs(robot, x))
        common = pairs if common is None else common & pairs
    text = [f"joints {i + 1} and {j + 1} are {kind} for every q" for i, j, kind in sorted(common or ())]
    return max(ranks), "; ".join(text) or "the columns are dependent for every q"


def task_rows(robot: DHRobot, frame: Frame | str = Frame.BASE, seed: int = 0) -> tuple[str, ...]:
    """The task rows an arm of fewer than six joints is analysed on (all six for six or more joints).

    The rows of J that are not zero for every q (a planar arm in the xy plane has wx = wy = 0, and vz = 0
    unless it also moves along z); when there are as many of them as joints, those. Otherwise the position
    rows (vx, vy, vz) that are not always zero, then the angular rows, whichever has generic rank equal to
    the number of joints: a positioning arm is analysed on (x, y, z), a planar 2R on (x, y), a 3-axis wrist
    on (wx, wy, wz). Decided numerically on :data:`TASK_ROW_SAMPLES` random configurations.
    """
    if robot.dof >= 6:
        return TWIST_ROWS
    frame = Frame(frame)
    rng = np.random.default_rng(seed)
    Js = [geometric_jacobian(robot, random_q(robot, rng), frame) for _ in range(TASK_ROW_SAMPLES)]
    scale = max(1.0, max(float(np.abs(J).max()) for J in Js))
    live = [i for i in range(6) if max(float(np.abs(J[i]).max()) for J in Js) > 1e-9 * scale]

    def rank(rows):
        return max(int(jacobian_rank(J[rows, :], RANK_RTOL)) for J in Js) if rows else 0

    candidates = [live] if len(live) == robot.dof else []
    candidates += [[i for i in live if i < 3], [i for i in live if i >= 3]]
    for rows in candidates:
        if len(rows) >= robot.dof and rank(rows) == robot.dof:
            return tuple(TWIST_ROWS[i] for i in rows)
    return tuple(TWIST_ROWS[i] for i in live) or TWIST_ROWS


@lru_cache(maxsize=32)
def singularity_analysis(robot: DHRobot, rows: str | None = "auto", frame: Frame | str = Frame.BASE,
                         simplify: str = "trig", progress: Callable[[str], None] | None = None
                         ) -> SingularityAnalysis:
    """Singular configurations of an arm: the factorized determinant and each factor solved and classified.

    Parameters
    ----------
    robot : DHRobot
    rows : str or None, optional
        Comma-separated task rows, e.g. ``"vx,vy,wz"``; ``None`` for all six; ``"auto"`` (default): all six
        for arms of six or more joints, the rows of :func:`task_rows` for fewer (a positioning arm on
        vx, vy, vz, a planar arm on vx, vy, wz).
    frame : Frame or {"base", "tool"}
        Axes of the Jacobian whose ``rows`` are taken (ignored for all six rows: the rank does not depend on it).
    simplify : {"none", "trig", "full"}
        Display form of the matrix entries and factors (the algebra is done on polynomials either way).
    progress : callable, optional
        Called with a short message at each stage (Jacobian, minors, factors, each condition).

    Returns
    -------
    SingularityAnalysis

    Notes
    -----
    With all six rows the Jacobian is taken in the axes of a middle frame with the reference point on the
    last joint axis (its determinant, or the minors of a 7-joint arm, equal those of J0: Siciliano et al.
    sec. 3.3); determinants and common factors are computed on polynomials in sin qᵢ, cos qᵢ (see the
    module notes). A 7-joint arm's 6×6 minors usually share no factor: its singular configurations are then
    where all seven vanish together, which is reported as such, not solved.

    Examples
    --------
    >>> import denavit, denavit.symbolic as S
    >>> a = S.singularity_analysis(denavit.load_robot("report004-1-planar2r"))
    >>> a.rows, [str(c.factor) for c in a.conditions], [s.values for s in a.conditions[0].solutions]
    (('vx', 'vy'), ['sin(q2)'], [(0.0,), (3.141592653589793,)])
    """
    frame = Frame(frame)
    q = joint_symbols(robot.dof).q
    if rows == "auto":
        auto = task_rows(robot, frame)
        rows = None if auto == TWIST_ROWS else ",".join(auto)
    idx = select_rows(rows)
    params = {parameter_symbols(robot)[k]: sp.Float(v) for k, v in robot.parameters}
    say = progress or (lambda msg: None)
    say("symbolic Jacobian")
    if rows is None:
        M, note, rg, J = wrist_frame_jacobian(robot, simplify)
    else:
        M = sp.ImmutableMatrix(geometric_jacobian_sym(robot, frame, simplify).extract(idx, list(range(robot.dof))))
        note = f"rows {', '.join(TWIST_ROWS[i] for i in idx)} of J{'0' if frame is Frame.BASE else 'e'}"
        rg = analysis_ring(list(M), q, robot)
        vals = rg.elements()
        J = [vals[i * M.shape[1]:(i + 1) * M.shape[1]] for i in range(M.shape[0])]
    say(f"determinant / minors of the {M.shape[0]}x{M.shape[1]} matrix")
    name, minors = measure_minors(rg, J, M.shape)
    rng = np.random.default_rng(0)
    full = min(M.shape)
    if all(rg.reduce(m) == 0 for m in minors):
        rank, reason = _everywhere_reason(robot, idx, frame, rng)
        return SingularityAnalysis(robot.name, tuple(TWIST_ROWS[i] for i in idx), M, note, name, sp.Integer(0),
                                   (), (), True, rank, full, reason)
    say("factoring")
    const, facs = common_factors(rg, minors)
    conds = []
    for k, (f, _) in enumerate(facs, start=1):
        say(f"solving and classifying factor {k}/{len(facs)}")
        variables = sorted(int(str(s)[1:]) - 1 for s in f.free_symbols if s in q)
        sols = factor_solutions(f, variables[0], robot, q, params) if len(variables) == 1 else []
        kind, text = classify_factor(f, variables, sols, robot, q, params, rng)
        conds.append(SingularCondition(f, tuple(f"q{k + 1}" for k in variables), tuple(sols), kind, text))
    det = sp.Mul(const, *[f ** m for f, m in facs])  # for m ≠ k: the common factor of the minors
    # a numeric factor is zero only when it is 0 (a generic float arm's content can be 1e-37); a factor in
    # the parameters is zero when it vanishes at their values (a2 = 0)
    everywhere = any(f == 0 or (f.free_symbols and abs(complex(sp.N(f.subs(params)))) < ZERO_TOL)
                     for f in sp.Mul.make_args(const))
    const_list = tuple(x for x in sp.Mul.make_args(const) if x not in (1, -1))
    reason = "a constant factor is zero at these parameter values" if everywhere else ""
    return SingularityAnalysis(robot.name, tuple(TWIST_ROWS[i] for i in idx), M, note, name, det, const_list,
                               tuple(conds), bool(everywhere), full - int(everywhere), full, reason)
