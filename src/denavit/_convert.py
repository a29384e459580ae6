"""Conversion of a DH table between the standard and the modified convention.

Standard rows Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i) and modified rows Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i)
describe the same chain when the (a, α) column is shifted by one row, because Tx(a) and Rx(α) commute:

    ∏ std_i = [Rz θ1 Tz d1] [Tx a1 Rx α1 Rz θ2 Tz d2] ⋯ [Tx a_{N-1} Rx α_{N-1} Rz θN Tz dN] · Tx aN Rx αN.

So standard → modified gives modified rows (a, α)_i = (a, α)_{i-1} with (0, 0) in the first row, plus a
fixed modified row Rx(α_N) Tx(a_N) at the end when (a_N, α_N) ≠ 0; modified → standard is the mirror
image, with a fixed standard row Tx(a_0) Rx(α_0) at the start.  θ, d, joint types, limits and the
base/tool transforms are unchanged, so the end-effector pose is identical for every q.  Intermediate
frames do move (standard frame i sits on axis i+1, modified frame i on axis i); both are fixed to the
same link i, with {i}_std = {i}_mod · Tx(a_i) Rx(α_i), so inertial data are carried over by that
constant transform (centre of mass moved, tensor rotated).
"""

from __future__ import annotations

import numpy as np

from .model import Convention, DHLink, DHRobot, JointType, LinkInertia

__all__ = ["convert_convention"]

#: Entries below this fraction of the largest one are rounding noise of the frame change and are set to 0.
_NOISE = 1e-12


def _move_inertia(inertia: LinkInertia | None, a: float, alpha: float, inverse: bool) -> LinkInertia | None:
    """Inertial data re-expressed through X = Tx(a) Rx(α): from the frame X maps into (inverse=False)."""
    if inertia is None:
        return None
    c, s = (0.0 if abs(v) < 1e-15 else float(v) for v in (np.cos(alpha), np.sin(alpha)))  # cos(pi/2) -> 0
    R = np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])
    p = np.array([a, 0.0, 0.0])
    com = np.array(inertia.com)
    I = inertia.inertia_matrix
    if inverse:
        com, I = R.T @ (com - p), R.T @ I @ R
    else:
        com, I = R @ com + p, R @ I @ R.T
    com = np.where(np.abs(com) < _NOISE * max(np.abs(com).max(), abs(a)), 0.0, com)  # rounding noise -> 0
    I = np.where(np.abs(I) < _NOISE * np.abs(I).max(), 0.0, I)
    return LinkInertia(
        mass=inertia.mass, com=tuple(com), inertia=(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]),
        motor_inertia=inertia.motor_inertia, viscous=inertia.viscous, coulomb=inertia.coulomb,
        symbols=tuple((k, v) for k, v in inertia.symbols if _kept(k, a, alpha)),
    )


def _kept(key: str, a: float, alpha: float) -> bool:
    """Whether a parameter expression of the inertial data still holds after the frame change Tx(a) Rx(α).

    Mass and actuator terms always do; with α = 0 the axes do not turn, so the tensor and the com's y and z
    keep their expressions too; with a = 0 as well the com's x does.
    """
    if key in ("mass", "motor_inertia", "viscous", "coulomb"):
        return True
    if alpha != 0.0:
        return False
    return key != "com0" or a == 0.0


def _with(link: DHLink, a: float, alpha: float, a_text: str | None, alpha_text: str | None,
          inertia: LinkInertia | None) -> DHLink:
    symbols = {k: v for k, v in link.symbols if k not in ("a", "alpha")}
    if a_text is not None:
        symbols["a"] = a_text
    if alpha_text is not None:
        symbols["alpha"] = alpha_text
    return DHLink(
        a=a, alpha=alpha, d=link.d, theta=link.theta, joint=link.joint, q_limits=link.q_limits,
        inertia=inertia, symbols=tuple(symbols.items()),
    )


def _fixed(a: float, alpha: float, a_text: str | None, alpha_text: str | None) -> DHLink:
    symbols = [(k, v) for k, v in (("a", a_text), ("alpha", alpha_text)) if v is not None]
    return DHLink(a=a, alpha=alpha, joint=JointType.FIXED, symbols=tuple(symbols))


def convert_convention(robot: DHRobot, target: Convention | str) -> DHRobot:
    """The same physical chain written in the other DH convention (end-effector pose identical).

    Inertial data move with their frames (see module notes).
    """
    target = Convention(target)
    if target is robot.convention:
        return robot
    links = robot.links
    ax = [(l.a, l.alpha, dict(l.symbols).get("a"), dict(l.symbols).get("alpha")) for l in links]
    zero = (0.0, 0.0, None, None)
    if target is Convention.MODIFIED:
        shifted = [zero] + ax[:-1]
        # std frame i = mod frame i · Tx(a_i) Rx(α_i), with (a_i, α_i) the std row's own values
        new = [_with(l, *s, _move_inertia(l.inertia, l.a, l.alpha, False)) for l, s in zip(links, shifted)]
        if ax[-1][0] != 0.0 or ax[-1][1] != 0.0:
            new.append(_fixed(*ax[-1]))
    else:
        shifted = ax[1:] + [zero]
        new = [_with(l, *s, _move_inertia(l.inertia, s[0], s[1], True)) for l, s in zip(links, shifted)]
        if ax[0][0] != 0.0 or ax[0][1] != 0.0:
            new.insert(0, _fixed(*ax[0]))
    return robot.replace(
        links=tuple(new), convention=target, name=robot.name, description=(robot.description + f" (converted to {target.value} DH)").strip()
    )
