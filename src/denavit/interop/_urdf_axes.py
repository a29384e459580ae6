"""The DH rows of a chain of joint axes (URDF in): each pair of consecutive axis lines and its common normal.

The method
----------
At q = 0 every moving joint k of the chain has an axis line L_k (a point p_k and the unit direction z_k of the
URDF axis, in the base link's frame).  Consecutive lines L_k, L_{k+1} have a common normal N_k: a unit
direction x_k perpendicular to both, from a foot f_k on L_k to a foot g_{k+1} on L_{k+1}, of length a_k ≥ 0,
and the twist α_k from z_k to z_{k+1} about x_k.  The cases (``ROW_CASES``):

- ``skew``: N_k is unique;
- ``intersecting``: a_k = 0, f_k = g_{k+1} the intersection, x_k = ±z_k × z_{k+1} / |z_k × z_{k+1}|, the
  sign that keeps x_k within 90° of x_{k-1} (so |θ_k| ≤ π/2; + when perpendicular);
- ``parallel`` / ``anti-parallel`` (distinct lines): x_k is unique, its foot is not; the normal is taken
  through the origin the URDF gives joint k+1 (so a pedestal's height stays in d_1, as textbooks write it);
- ``coincident`` / ``anti-coincident`` (one line): a_k = 0, α_k ∈ {0, π}; f_k = g_{k+1} is the origin of
  joint k+1 projected on the line, and x_k = x_{k-1} (θ_k = 0).

The DH z axes are the URDF joint axes with their sign (so q is the URDF's joint value; an opposite axis is
α = π, never a negated q), and the DH joint variable is the URDF's: the limits carry over unchanged.
With θ_k = ∠(x_{k-1}, x_k) about z_k and d_k = (f_k − g_k)·z_k, the two conventions share θ and d; standard
DH rows take (a_k, α_k), modified rows (a_{k-1}, α_{k-1}) (Craig 3rd ed. §3.4; Spong 2nd ed. §3.2).
The ends are free: frame {0} lies on L_1 at the point nearest the base link's origin, its x axis the base
link's x (or y) made perpendicular to z_1; frame {n} lies on L_n at the point nearest the tip link's origin,
its x axis the tip's x made perpendicular to z_n.  ``base`` and ``tool`` take the rest, so a chain whose first
axis is the base link's z through its origin gets an identity base.  Fixed joints fold into the geometry.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["dh_geometry", "PARALLEL_TOL", "INTERSECT_TOL", "FAR_FOOT", "ROW_CASES"]

#: Two axes count as parallel when the sine of their angle is below this.
PARALLEL_TOL = 1e-10
#: Two axes count as meeting (and parallel axes as one line) when their distance is below this, relative to
#: the chain's size (at least 1 m).
INTERSECT_TOL = 1e-10
#: Nearly parallel axes whose common normal meets the first axis farther than this (relative to the chain's size)
#: are taken as parallel: the DH model then approximates the URDF, and the self-check reports by how much.
FAR_FOOT = 1e3
#: The geometry of consecutive axes that decides each row (the last row's is ``last``).
ROW_CASES = ("skew", "intersecting", "parallel", "anti-parallel", "coincident", "anti-coincident", "last")


def _unit_perp(v: np.ndarray, z: np.ndarray) -> np.ndarray | None:
    """``v`` made perpendicular to the unit ``z`` and unit, or None when ``v`` is (nearly) along ``z``."""
    w = v - (v @ z) * z
    n = float(np.linalg.norm(w))
    if n < 1e-3 * max(float(np.linalg.norm(v)), 1e-300):
        return None
    w = w / n
    w = w - (w @ z) * z
    return w / np.linalg.norm(w)


def _angle(u: np.ndarray, v: np.ndarray, axis: np.ndarray) -> float:
    """The angle from ``u`` to ``v`` about ``axis`` (all unit; u, v ⟂ axis)."""
    return math.atan2(float(np.cross(u, v) @ axis), float(u @ v))


def _snap(angle: float) -> float:
    """An angle in (−π, π], exact multiples of π/4 made exact (rounding noise of the rotations)."""
    k = round(angle / (math.pi / 4))
    if abs(angle - k * math.pi / 4) < 1e-13:
        angle = k * math.pi / 4
    angle = math.remainder(angle, 2 * math.pi)
    return math.pi if angle == -math.pi else (0.0 if angle == 0 else angle)


def _frame(origin: np.ndarray, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, origin
    return T


def dh_geometry(P: np.ndarray, Z: np.ndarray, T_tip: np.ndarray, scale: float):
    """θ, d, a, α (a, α of the normal from axis k to k+1; last row 0), cases, frame {0}: see the module notes.

    ``P`` (n, 3) and ``Z`` (n, 3): a point and the unit direction of each axis at q = 0; ``T_tip``: the tip
    link's pose; all in the base link's frame.  ``scale`` [m]: the chain's size (at least 1), for tolerances.
    Also returns the rows whose nearly parallel axes were taken as parallel.
    """
    n = len(Z)
    tol = INTERSECT_TOL * scale
    g = P[0] - (P[0] @ Z[0]) * Z[0]  # foot of frame {0}: the point of L_1 nearest the base origin
    x_prev = _unit_perp(np.array([1.0, 0.0, 0.0]), Z[0])
    if x_prev is None:
        x_prev = _unit_perp(np.array([0.0, 1.0, 0.0]), Z[0])
    F0 = _frame(g, x_prev, Z[0])
    theta, d, a, alpha, cases, approximated = [], [], [], [], [], []
    for k in range(n):
        z = Z[k]
        if k == n - 1:
            f = g + ((T_tip[:3, 3] - g) @ z) * z  # the point of L_n nearest the tip origin
            x = _unit_perp(T_tip[:3, 0], z)
            x = x_prev if x is None else x
            ak, alk, g_next, case = 0.0, 0.0, f, "last"
        else:
            zn, w = Z[k + 1], P[k + 1] - P[k]
            c = np.cross(z, zn)
            s = float(np.linalg.norm(c))
            x = c / s if s > 0 else c
            t1 = float(np.cross(w, zn) @ x) / s if s > 0 else math.inf
            if s > PARALLEL_TOL and abs(t1) <= FAR_FOOT * scale:
                # foot on L_k: t = det[w, z_{k+1}, c] / |c|², written so that its error is ~ eps/s, not eps/s²
                # (nearly parallel axes): the foot on L_{k+1} then stays on it to rounding
                f = P[k] + t1 * z
                dist = float(w @ x)  # signed length of the common normal
                if abs(dist) < tol:
                    ak, case = 0.0, "intersecting"
                    if float(x @ x_prev) < -1e-9:  # the sign keeping θ_k within ±π/2 (+ on a tie)
                        x = -x
                else:
                    x, ak, case = (x if dist > 0 else -x), abs(dist), "skew"
                g_next = f + ak * x
            else:  # parallel, or so nearly that the common normal is far away: taken as parallel
                if s > PARALLEL_TOL:
                    approximated.append(k)
                f = P[k] + ((P[k + 1] - P[k]) @ z) * z  # the normal through the next joint's origin
                v = P[k + 1] - f
                v = v - (v @ z) * z  # from L_k to L_{k+1}, perpendicular to both
                ak = float(np.linalg.norm(v))
                same = float(z @ zn) > 0
                if ak <= tol:
                    x, ak, case = x_prev, 0.0, "coincident" if same else "anti-coincident"
                else:
                    x, case = v / ak, "parallel" if same else "anti-parallel"
                g_next = f + ak * x
            alk = math.atan2(float(np.cross(z, zn) @ x), float(z @ zn))
        theta.append(_snap(_angle(x_prev, x, z)))
        dk = float((f - g) @ z)
        d.append(0.0 if abs(dk) < 1e-14 * scale else dk)
        a.append(ak)
        alpha.append(_snap(alk))
        cases.append(case)
        g, x_prev = g_next, x
    return theta, d, a, alpha, cases, F0, approximated
