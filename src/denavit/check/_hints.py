"""Hints for an incorrect claim: which typical slip would make it right.

Each hint is tested, not guessed: the claimed values are compared with the truth changed by one slip
(a sign, a transposition, two entries swapped, the other DH convention, another frame, another
parameter value, a joint angle's sign), at the same evaluation points.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ..model import Convention, Frame

__all__ = ["hints_for", "MAX_PARAMETER_HINTS"]

RTOL = 1e-9
MAX_HINTS = 6
#: Parameters tried by the "a wrong parameter value" hint (the first ones of the robot; keeps the search bounded).
MAX_PARAMETER_HINTS = 8


def _close(a: np.ndarray, b: np.ndarray, tol: Any = 0.0) -> bool:
    return a.shape == b.shape and bool(np.all(np.abs(a - b) <= RTOL * np.maximum(1.0, np.abs(b)) + tol))


def _alt(qty, spec, points, robot_map=None, spec_change=None) -> np.ndarray | None:
    """The truth with one change (a different robot per point, or a changed spec), or None if undefined."""
    mapped: dict[int, Any] = {}  # one changed robot per distinct robot (building one re-reads its table)

    def robot_of(r):
        if robot_map is None:
            return r
        if id(r) not in mapped:
            mapped[id(r)] = robot_map(r)
        return mapped[id(r)]

    try:
        s = {**spec, **(spec_change or {})}
        return np.array([np.asarray(qty.truth(replace(p, robot=robot_of(p.robot)), s), dtype=float)
                         for p in points])
    except Exception:  # e.g. an index out of range for the changed spec: no hint
        return None


def _entry_name(ix: tuple[int, ...]) -> str:
    return str(tuple(int(i) + 1 for i in ix)) if len(ix) > 1 else str(int(ix[0]) + 1)


def _entrywise(claimed, truth, bad, tol) -> list[str]:
    hints = []
    shape = truth.shape[1:]
    bad_ix = [tuple(ix) for ix in zip(*np.nonzero(bad))] if bad.ndim else []
    signs = [ix for ix in bad_ix if _close(claimed[(slice(None),) + ix], -truth[(slice(None),) + ix], tol[ix])]
    if not shape and _close(claimed, -truth, tol) and not _close(claimed, truth, tol):
        hints.append("sign slip: the value has the opposite sign")
    elif not shape and _close(np.abs(claimed), np.abs(truth), tol) and not _close(claimed, truth, tol):
        hints.append("right up to its sign, which changes with q: an absolute value is missing (or one too many)")
    if signs:
        hints.append("sign slip: entr" + ("y " if len(signs) == 1 else "ies ") + ", ".join(map(_entry_name, signs))
                     + " ha" + ("s" if len(signs) == 1 else "ve") + " the opposite sign")
    for n, a in enumerate(bad_ix):
        for b in bad_ix[n + 1:]:
            sa, sb = (slice(None),) + a, (slice(None),) + b
            if _close(claimed[sa], truth[sb], tol[a]) and _close(claimed[sb], truth[sa], tol[b]):
                hints.append(f"entries {_entry_name(a)} and {_entry_name(b)} are swapped")
    if len(shape) == 2 and shape[0] == shape[1] and _close(claimed, np.swapaxes(truth, -1, -2), tol.T):
        hints.append("the matrix is transposed")
    elif len(shape) == 2 and shape == (4, 4):
        Rt = truth.copy()
        Rt[:, :3, :3] = np.swapaxes(truth[:, :3, :3], -1, -2)
        if _close(claimed, Rt, tol):
            hints.append("the rotation part is transposed (that is the inverse rotation)")
        elif _close(claimed, np.linalg.inv(truth), tol):
            hints.append("this is the inverse transform (the pose of the first frame in the second)")
    return hints


def _structural(robot, qty, spec, claimed, truth, tol) -> list[str]:
    hints = []
    points = spec["_points"]
    if qty.fk_like:
        other = Convention.MODIFIED if robot.convention is Convention.STANDARD else Convention.STANDARD
        alt = _alt(qty, spec, points, robot_map=lambda r: r.replace(convention=other))
        if alt is not None and _close(claimed, alt, tol):
            hints.append(f"it matches the {other.value} DH link formula, but this table is {robot.convention.value} "
                         "(a swapped convention)")
    if qty.name in ("transform", "end_effector"):
        n = robot.n_rows
        for j in range(1, n + 1):
            if qty.name == "transform" and j == spec.get("to", n):
                continue
            alt = _alt(qty, spec, points, spec_change={"from": 0, "to": j}) if qty.name == "transform" else None
            if qty.name == "end_effector":
                from ._quantities import QUANTITIES
                alt = _alt(QUANTITIES["transform"], {}, points, spec_change={"from": 0, "to": j})
            if alt is not None and _close(claimed, alt, tol):
                hints.append(f"this is the pose of frame {{{j}}} in {{0}} (T_0_{j})"
                             + (" - a fixed row or the tool is missing" if j < n else ""))
                break
    if qty.name in ("omega", "velocity", "force", "moment") and truth.ndim == 2:
        hints += _propagation(qty, spec, points, claimed, tol)
    if qty.name in ("kinetic_energy", "lagrangian", "equations_of_motion", "mass_matrix") and truth.ndim >= 1:
        hints += _dynamics_slips(qty, spec, points, claimed, truth, tol)
    if qty.name in ("jacobian", "twist", "torques"):
        from ._quantities import axes_frame

        f = axes_frame(spec)
        written = f"frame {{{f}}}'s" if isinstance(f, int) else f.value
        for other in ("base", "tool") if isinstance(f, int) else ("tool" if f is Frame.BASE else "base",):
            alt = _alt(qty, spec, points, spec_change={"frame": other})
            if alt is not None and _close(claimed, alt, tol):
                hints.append(f"it is expressed in {other} axes (J{'e' if other == 'tool' else '0'}), not "
                             f"{written} axes")
        if truth.ndim >= 2 and truth.shape[1] == 6:  # not for one entry (truth is 1-D then)
            perm = [3, 4, 5, 0, 1, 2]
            if _close(claimed, truth[:, perm], tol[perm]):
                hints.append("the rows are in (ω, v) order; denavit's twists and Jacobians are (v, ω)")
    return hints


def _propagation(qty, spec, points, claimed, tol) -> list[str]:
    """ⁱωᵢ … written in base axes ({0}) instead of frame i's own, or the vector of a neighbouring frame."""
    from .. import numeric as N
    from ._quantities import frame_index

    out = []
    try:
        i = frame_index(points[0], spec)
        in_base = []
        for p in points:
            F = N.link_transforms(p.robot, p.q)
            R0i = np.linalg.solve(F[0][:3, :3], F[min(i, len(F) - 1)][:3, :3])
            if i == len(F):  # "e": the tool frame
                R0i = R0i @ np.asarray(p.robot.tool_matrix, dtype=float)[:3, :3]
            in_base.append(R0i @ np.asarray(qty.truth(p, spec), dtype=float))
        if _close(claimed, np.array(in_base), tol):
            out.append(f"it is expressed in base axes ({{0}}); propagation gives each vector in its own frame {{{i}}}'s axes")
    except Exception:  # noqa: BLE001 - no hint when the frames cannot be computed
        pass
    for j in (i - 1, i + 1):
        alt = _alt(qty, spec, points, spec_change={"index": j}) if j >= 0 else None
        if alt is not None and _close(claimed, alt, tol):
            out.append(f"it is the vector of frame {{{j}}}, not {{{i}}}")
    return out


def _no_rotational_inertia(r):
    from dataclasses import replace as dc_replace

    links = tuple(dc_replace(lk, inertia=dc_replace(lk.inertia, inertia=(0.0,) * 6)) if lk.inertia is not None else lk
                  for lk in r.links)
    return r.replace(links=links)


def _dynamics_slips(qty, spec, points, claimed, truth, tol) -> list[str]:
    """The rotational term ½ ωᵀ I ω missing; the factor ½ of K missing; L written K + V."""
    out = []
    alt = _alt(qty, spec, points, robot_map=_no_rotational_inertia)
    if alt is not None and not _close(alt, truth, 0.0) and _close(claimed, alt, tol):
        out.append("it leaves out the rotational energy ½ ωᵀ I ω of the links (their inertia about the centre of mass)")
    if qty.name == "kinetic_energy" and _close(claimed, 2 * truth, tol):
        out.append("it is 2K: the factor ½ is missing")
    if qty.name == "lagrangian":
        from ._quantities import QUANTITIES

        K = _alt(QUANTITIES["kinetic_energy"], spec, points)
        if K is not None and _close(claimed, 2 * K - truth, tol):
            out.append("it is K + V; the Lagrangian is L = K − V")
    return out


def _parameter(robot, qty, spec, claimed, truth, tol) -> list[str]:
    """A named parameter (or a length) with another value that makes the claim right."""
    from ..io import with_parameters

    points = [p for p in spec["_points"] if p.robot is robot]
    sel = [k for k, p in enumerate(spec["_points"]) if p.robot is robot]
    if not points or not robot.parameters:
        return []
    hints = []
    own_truth = truth[sel]
    for name, value in robot.parameters[:MAX_PARAMETER_HINTS]:
        probes = [_alt(qty, spec, points, robot_map=lambda r, x=x: with_parameters(r, **{name: x}))
                  for x in (value + 0.37, -1.3 * value - 0.11)]
        if all(p is not None and np.all(np.abs(p - own_truth) <= 1e-14 * np.maximum(1.0, np.abs(own_truth)))
               for p in probes):
            continue  # the quantity does not depend on this parameter (a mass in a Jacobian): no value helps
        span = max(1.0, 3 * abs(value))
        grid = np.unique(np.concatenate([np.linspace(-span, span, 121), [v for _, v in robot.parameters[:MAX_PARAMETER_HINTS]]]))
        best, best_err = None, np.inf
        for x in grid:
            alt = _alt(qty, spec, points, robot_map=lambda r, x=x: with_parameters(r, **{name: float(x)}))
            if alt is None:
                return []
            e = float(np.max(np.abs(claimed[sel] - alt)))
            if e < best_err:
                best, best_err = x, e
        if best is None or abs(best - value) < 1e-9:
            continue
        from scipy.optimize import minimize_scalar

        step = 2 * span / 120
        res = minimize_scalar(lambda x: float(np.sum((claimed[sel] - _alt(  # smooth: converges tightly
            qty, spec, points, robot_map=lambda r: with_parameters(r, **{name: float(x)}))) ** 2)),
            bounds=(best - step, best + step), method="bounded", options={"xatol": 1e-13})
        for x in [round(float(res.x), d) for d in (2, 3, 4, 6, 8)] + [float(res.x)]:
            alt = _alt(qty, spec, points, robot_map=lambda r, x=x: with_parameters(r, **{name: x}))
            if alt is not None and _close(claimed[sel], alt, tol) and abs(x - value) > 1e-6:
                hints.append(f"it would be right with {name} = {x:.6g} (this robot has {name} = {value:g})")
                break
    return hints


def _joint_sign(robot, qty, spec, claimed, truth, tol) -> list[str]:
    if "q" not in spec:
        return []
    points = spec["_points"]
    for k in range(robot.dof):
        flipped = [replace(p, q=p.q * np.where(np.arange(robot.dof) == k, -1, 1)) for p in points]
        alt = _alt(qty, spec, flipped)
        if alt is not None and _close(claimed, alt, tol):
            return [f"it is right for the opposite sign of joint {k + 1} (q{k + 1} = {-points[0].q[k]:.6g})"]
    return []


def hints_for(robot, qty, spec, cells, points, claimed, truth, ok, tol, rng) -> tuple[str, ...]:
    """Tested explanations of an incorrect claim (at most a few, the most specific first)."""
    bad = ~ok.all(axis=0)
    spec = {**spec, "_points": points}
    hints = _structural(robot, qty, spec, claimed, truth, tol)
    hints += _entrywise(claimed, truth, bad, tol)
    if not hints:
        hints += _parameter(robot, qty, spec, claimed, truth, tol)
    if not hints:
        hints += _joint_sign(robot, qty, spec, claimed, truth, tol)
    return tuple(hints[:MAX_HINTS])
