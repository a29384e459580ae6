"""The closed forms of the analytic IK written once, for numpy batches and for numba alike.

Each function here is elementwise: its arguments are floats or numpy arrays of one broadcast shape (constant
vectors and matrices are indexed, ``R[0, 1]``, and give floats), and it uses only arithmetic, comparisons, ``&``,
``|``, ``abs`` and the numpy ufuncs numba compiles on floats (``np.sqrt``, ``np.sin``, ``np.cos``, ``np.minimum``,
``np.maximum``, ``np.copysign``, ``np.floor``), plus :func:`select` for a choice per element.  A square root of a
quantity ≥ 0 by construction is taken of its ``abs`` (the same value): LLVM then knows it needs no libm call.
Their angles come from :func:`atan2`, a branch-free rational approximation (no libm call: a compiled loop over
poses or candidates can be vectorised; arcsin and arccos are atan2 of a sine and a cosine).  So the plain solver
calls them on whole batches (numpy, the branch slots stacked on trailing axes) and :mod:`denavit.codegen` jits the
very same functions (``register_jitable``, with ``select`` as ``a if c else b``) for its one-pose loops: one copy
of every formula, no source strings.

Formulas (joint-screw form of :mod:`._chain`; derivations in :mod:`._closed` and docs/ik.md):

- :func:`atan2` — the angle of (x, y) within 2 ulp of libm's (Cody & Waite's reduction to |t| ≤ 0.66 and the
  Cephes rational approximation of atan on it, Moshier 1989).
- :func:`trig_roots` — ``a cos θ + b sin θ = c`` (Paden–Kahan subproblem 1 in scalar form); :func:`trig_pairs` —
  the cosines and sines of its roots, algebraically (only the angles themselves need atan2 and arccos).
- :func:`half_angle` — x from ``(1 − cos x)/2`` and ``(1 + cos x)/2`` given as products (Kahan's digit-keeping
  triangle angles), the smaller of the two.
- :func:`shoulder_roots`, :func:`elbow_plane`, :func:`elbow_roots`, :func:`elbow_q2` — the elbow arm's joints
  1–3 (Craig 3rd ed. Sec. 4.7, eqs. 4.65–4.76).
- :func:`stanford_q3`, :func:`stanford_q2`, :func:`stanford_q1` — the Stanford arm's joints 1–3 (R R P, axes 1, 2
  meeting; Spong, Hutchinson & Vidyasagar 2006, Sec. 5.3.3).
- :func:`wrist_constants`, :func:`wrist_qb`, :func:`wrist_rest` — the three-axis wrist
  ``Rz(qa) Ra Rz(qb) Rb Rz(qc) = M`` (Paden–Kahan subproblems 2 and 1; Murray, Li & Sastry 1994, Sec. 3.3).
"""

from __future__ import annotations

import numpy as np

__all__ = ["JITTABLE", "WRIST_TOL", "select", "atan2", "trig_roots", "trig_pairs", "half_angle", "shoulder_roots",
           "elbow_plane", "elbow_roots", "elbow_q2", "wrist_constants", "wrist_qb", "wrist_rest", "stanford_q3",
           "stanford_q2", "stanford_q1"]

ALIGNED_EXACT = 1e-11  # below this angle [rad] the representative of the continuum is taken with qa = 0
AXES_ALIGNED_TOL = 1e-7  # angle [rad] between the outer axes of a three-axis wrist under which it is singular
WRIST_TOL = 1e-9  # how far (1 ∓ cos x)/2 of the wrist's z-row may fall below 0 and still count as the double root


def select(c, a, b):
    """a where c, else b (``np.where``; numba compiles it as ``a if c else b``)."""
    return np.where(c, a, b)


def _clip(x, lo, hi):
    return np.minimum(np.maximum(x, lo), hi)


# atan t = t + t z P(z)/Q(z), z = t², |t| ≤ 0.66 (Cephes atan.c, Moshier 1989); PI_LO: π/4 − fl(π/4)
_AP = (-8.750608600031904122785e-1, -1.615753718733365076637e1, -7.500855792314704667340e1,
       -1.228866684490136173410e2, -6.485021904942025371773e1)
_AQ = (2.485846490142306297962e1, 1.650270098316988542046e2, 4.328810604912902668951e2, 4.853903996359136964868e2,
       1.945506571482613964425e2)
_PI_LO = 3.061616997868382943065e-17


def atan2(y, x):
    """θ ∈ [−π, π] with (cos θ, sin θ) ∥ (x, y), as ``np.arctan2`` (signed zeros and NaN alike) within 2 ulp for
    finite (x, y) outside the subnormals (an infinite pair gives NaN), with no branch and no libm call:
    t = min(|x|, |y|)/max(|x|, |y|) ∈ [0, 1], above 0.66 replaced by (t − 1)/(t + 1) (then atan t + π/4; Cody &
    Waite 1980, Ch. 17), atan by the Cephes rational t + t z P(z)/Q(z), z = t² (Moshier 1989, atan.c), then the
    octant: π/2 − θ where |y| > |x|, π − θ where x < 0 (or −0), the sign of y."""
    ax, ay = abs(x), abs(y)
    hi, lo = np.maximum(ax, ay), np.minimum(ax, ay)
    big = lo > 0.66 * hi
    den = select(big, lo + hi, hi)
    t = select(big, lo - hi, lo) / select(den == 0.0, 1.0, den)
    z = t * t
    p = (((_AP[0] * z + _AP[1]) * z + _AP[2]) * z + _AP[3]) * z + _AP[4]
    q = ((((z + _AQ[0]) * z + _AQ[1]) * z + _AQ[2]) * z + _AQ[3]) * z + _AQ[4]
    r = t + t * (z * p / q)
    r = select(big, 0.7853981633974483 + (r + _PI_LO), r)
    r = select(ay > ax, 1.5707963267948966 + (2.0 * _PI_LO - r), r)
    r = select(np.copysign(1.0, x) < 0.0, 3.141592653589793 + (4.0 * _PI_LO - r), r)
    return np.copysign(r, y)


def trig_roots(a, b, c, tol):
    """(θ₊, θ₋) with ``a cos θ + b sin θ = c``: ``atan2(b, a) ± arccos(c/ρ)``, ρ = √(a² + b²); NaN where |c| > ρ
    beyond ``tol`` (a ratio within it is the tangent, double root) or where ρ ≤ 1e-12 (no dependence on θ).
    Also returns ρ and the ratio c/ρ (0 where ρ ≤ 1e-12)."""
    rho = np.sqrt(a * a + b * b)  # lengths of an arm: no overflow to guard against (hypot is a libm call)
    some = rho > 1e-12
    ratio = select(some, c / select(some, rho, 1.0), 0.0)
    ok = some & (abs(ratio) <= 1.0 + tol)
    base = atan2(b, a)
    r = _clip(select(ok, ratio, 0.0), -1.0, 1.0)
    delta = atan2(np.sqrt(abs((1.0 - r) * (1.0 + r))), r)  # arccos r
    return select(ok, base + delta, np.nan), select(ok, base - delta, np.nan), rho, ratio


def trig_pairs(a, b, rho, ratio, tol):
    """(cos θ₊, sin θ₊, cos θ₋, sin θ₋) of the roots θ± = β ± δ of :func:`trig_roots` (given its ρ and ratio) with
    no cos or sin: the sum formulas with cos β = a/ρ, sin β = b/ρ, cos δ = ratio, sin δ = √((1 − ratio)(1 + ratio))
    (the ratio clipped to [−1, 1] as there); NaN where trig_roots gives NaN."""
    ok = (rho > 1e-12) & (abs(ratio) <= 1.0 + tol)
    r = _clip(select(ok, ratio, 0.0), -1.0, 1.0)
    sd = np.sqrt(abs((1.0 - r) * (1.0 + r)))
    n = select(ok, rho, np.nan)
    cb, sb = a / n, b / n
    return cb * r - sb * sd, sb * r + cb * sd, cb * r + sb * sd, sb * r - cb * sd


def half_angle(lo, hi, tol):
    """(x, cos x, sin x), x in [0, π] with (1 − cos x)/2 = lo and (1 + cos x)/2 = hi, from the smaller one, y (its
    digits survive next to x = 0 or π, where arccos loses half of them): x = 2 arcsin √y (or π minus it), cos x =
    ±(1 − 2y), sin x = 2 √y √(1 − y) (no cos or sin); NaN when either is below −tol/2 (out of range)."""
    ok = (lo >= -0.5 * tol) & (hi >= -0.5 * tol)
    small = lo <= hi
    y = _clip(select(small, lo, hi), 0.0, 1.0)
    r = np.sqrt(abs(y))
    rc = np.sqrt(abs(1.0 - y))
    x = 2.0 * atan2(r, rc)  # 2 arcsin √y, once: select evaluates both sides
    c = 1.0 - 2.0 * y
    return (select(ok, select(small, x, np.pi - x), np.nan), select(ok, select(small, c, -c), np.nan),
            select(ok, 2.0 * r * rc, np.nan))


def shoulder_roots(Wx, Wy, Wz, a, h, tiny, tol):
    """The elbow arm's q1: ``(Rz(q1) a)·W = h`` (Craig eq. 4.65 in joint-screw form), a the axis of joints 2, 3
    in the frame after joint 1, W the wrist centre in the frame before joint 1.

    Returns (q1₊, q1₋, free, ratio, cos q1₊, sin q1₊, cos q1₋, sin q1₋) (the cosines and sines by
    :func:`trig_pairs`): where W lies on axis 1 (within ``tiny``) q1 is free: (0, NaN) and free True; ratio = c/ρ of
    the equation (|ratio| near 1: the double root)."""
    c = h - a[2] * Wz
    ea, eb = a[0] * Wx + a[1] * Wy, a[0] * Wy - a[1] * Wx
    q1a, q1b, rho, ratio = trig_roots(ea, eb, c, tol)
    ca, sa, cb, sb = trig_pairs(ea, eb, rho, ratio, tol)
    free = (np.sqrt(Wx * Wx + Wy * Wy) < tiny) & (abs(c) < tiny)
    return (select(free, 0.0, q1a), select(free, np.nan, q1b), free, ratio, select(free, 1.0, ca),
            select(free, 0.0, sa), select(free, np.nan, cb), select(free, np.nan, sb))


def elbow_plane(c1, s1, Wx, Wy, Wz, R1, p1):
    """(g0, g1): the xy of g = R1ᵀ (Rz(−q1) W − p1), the wrist centre in the frame of joint 2 (c1, s1: cos q1,
    sin q1)."""
    d0 = c1 * Wx + s1 * Wy - p1[0]
    d1 = -s1 * Wx + c1 * Wy - p1[1]
    d2 = Wz - p1[2]
    return d0 * R1[0, 0] + d1 * R1[1, 0] + d2 * R1[2, 0], d0 * R1[0, 1] + d1 * R1[1, 1] + d2 * R1[2, 1]


def elbow_roots(G, na, nb, base, cb, sb, tol):
    """(q3₊, q3₋, x, cos q3₊, sin q3₊, cos q3₋, sin q3₋): q3 = base ± x with G² = na² + nb² + 2 na nb cos x (the
    elbow's law of cosines, Craig eq. 4.69), (1 ∓ cos x)/2 written as products so that a folded or stretched elbow
    keeps its digits; NaN beyond the reach (``tol``).  cb, sb: cos and sin of base; the cosines and sines of the
    roots by the sum formulas from :func:`half_angle`'s."""
    den = 4.0 * na * nb
    s, d = na + nb, abs(na - nb)
    x, cx, sx = half_angle((s - G) * (s + G) / den, (G - d) * (G + d) / den, tol)
    return base + x, base - x, x, cb * cx - sb * sx, sb * cx + cb * sx, cb * cx + sb * sx, sb * cx - cb * sx


def elbow_q2(g0, g1, c3, s3, R2, p2, P, tiny):
    """(q2, free, |v_xy|, cos q2, sin q2): q2 turns v = p2 + R2 Rz(q3) P (the point of the elbow triangle: the
    wrist centre, or the UR arm's planar-pair point; c3, s3: cos q3, sin q3) onto g about axis 2, by one atan2 of
    v_xy × g and v_xy · g (their normalised values are cos q2 and sin q2, returned for the compiled kernels'
    verifying FK); where v lies on axis 2 (within ``tiny``) q2 is free: 0 and free True (a planar pair passes
    tiny = 0 and reads |v_xy| instead)."""
    u0, u1 = c3 * P[0] - s3 * P[1], s3 * P[0] + c3 * P[1]  # Rz(q3) P, xy (z is P_z)
    vx = p2[0] + R2[0, 0] * u0 + R2[0, 1] * u1 + R2[0, 2] * P[2]
    vy = p2[1] + R2[1, 0] * u0 + R2[1, 1] * u1 + R2[1, 2] * P[2]
    vxy = np.sqrt(vx * vx + vy * vy)  # lengths of an arm: no overflow to guard against (hypot is a libm call)
    free = vxy < tiny
    dot, crs = vx * g0 + vy * g1, vx * g1 - vy * g0  # |v_xy| |g| (cos q2, sin q2)
    h = np.sqrt(dot * dot + crs * crs)
    zero = free | (h == 0.0)  # q2 = 0 there; NaN stays NaN
    h = select(zero, 1.0, h)
    return (select(zero, 0.0, atan2(crs, dot)), free, vxy, select(zero, 1.0, dot / h),
            select(zero, 0.0, crs / h))


def wrist_constants(rho, base, br, bu):
    """The constants of :func:`wrist_qb` for one wrist, as one tuple: (ρ, β, cos β, sin β, cos Δ/2, sin Δ/2,
    cos Σ/2, sin Σ/2) with ρ, β the hypot and atan2 of the z-row's cos/sin coefficients, Δ = br − bu, Σ = br + bu
    (br, bu: the angles of r and u to the z axis)."""
    return (rho, base, np.cos(base), np.sin(base), np.cos(0.5 * (br - bu)), np.sin(0.5 * (br - bu)),
            np.cos(0.5 * (br + bu)), np.sin(0.5 * (br + bu)))


def wrist_qb(m0, m1, m2, wc, tol):
    """(qb₊, qb₋, lo, hi, cos qb₊, sin qb₊, cos qb₋, sin qb₋): the roots of the wrist's z-row ``rᵀ Rz(qb) u = m_z``
    (m = M e_z, r = Raᵀ e_z, u = Rb e_z; wc: :func:`wrist_constants`), qb = β ± x.

    x from φ = ∠(m, e_z), whose half-angle cosine and sine are taken from all of m (cos φ = m_z, sin φ = |m_xy|,
    each from the side where it is well conditioned): ``(1 − cos x)/2 = sin((φ + Δ)/2) sin((φ − Δ)/2)/ρ`` and
    ``(1 + cos x)/2 = sin((Σ + φ)/2) sin((Σ − φ)/2)/ρ`` (see ``axis_angle_roots``), each sine by the sum formula;
    NaN where ρ < 1e-12.  lo and hi (the two products) tell how near the roots are to a double root; the cosines
    and sines of the roots by the sum formulas from :func:`half_angle`'s (no cos or sin of qb)."""
    rho, base, cb, sb, cd, sd, cs, ss = wc
    t = np.sqrt(m0 * m0 + m1 * m1)  # sin φ
    up = m2 >= 0.0
    hc, hs = np.sqrt(np.maximum(0.5 * (1.0 + m2), 0.0)), np.sqrt(np.maximum(0.5 * (1.0 - m2), 0.0))
    ch = select(up, hc, t / (2.0 * select(up, 1.0, hs)))  # cos φ/2
    sh = select(up, t / (2.0 * select(up, hc, 1.0)), hs)  # sin φ/2
    r = select(rho < 1e-12, np.nan, rho)
    lo = (sh * cd + ch * sd) * (sh * cd - ch * sd) / r  # (1 − cos x)/2
    hi = (ss * ch + cs * sh) * (ss * ch - cs * sh) / r  # (1 + cos x)/2
    x, cx, sx = half_angle(lo, hi, tol)
    return base + x, base - x, lo, hi, cb * cx - sb * sx, sb * cx + cb * sx, cb * cx + sb * sx, sb * cx - cb * sx


def _ra_rz(Ra, cb, sb, x0, x1, x2, i):
    """Row i of Ra Rz(qb) x for a constant vector x."""
    return Ra[i, 0] * (cb * x0 - sb * x1) + Ra[i, 1] * (sb * x0 + cb * x1) + Ra[i, 2] * x2


def wrist_rest(qb, cb, sb, m00, m10, m20, m02, m12, Ra, Rb):
    """(qa, qc, singular, sign, vxy, cb, sb, ca, sa, cc, sc) of the wrist ``Rz(qa) Ra Rz(qb) Rb Rz(qc) = M`` once qb
    is known, with its cos and sin cb, sb (of M only the five entries m_ij it reads, each a float or an array; ca,
    sa, cc, sc: cos and sin of qa and qc as computed, before the exact-alignment choice):
    qa turns v = Ra Rz(qb) Rb e_z onto M e_z, qc from the x-row of ``(Rz(qa) Ra Rz(qb) Rb)ᵀ M`` (Paden–Kahan
    subproblems 2 and 1).

    Each angle is one atan2 of a (sine, cosine) pair whose normalised values are its cosine and sine, so no cos or
    sin of qa or qc is computed: qa = atan2(v_xy × m_xy, v_xy · m_xy), qc = atan2(N10, N00).

    singular: axes a and c aligned within AXES_ALIGNED_TOL (only qa ± qc is determined, sign +1 for qa + qc);
    aligned within ALIGNED_EXACT the representative is the middle of the family: qa = ±w/2, qc = w/2.  vxy: sine
    of the angle between axes a and c (how near the wrist is to its singularity)."""
    v0 = _ra_rz(Ra, cb, sb, Rb[0, 2], Rb[1, 2], Rb[2, 2], 0)
    v1 = _ra_rz(Ra, cb, sb, Rb[0, 2], Rb[1, 2], Rb[2, 2], 1)
    v2 = _ra_rz(Ra, cb, sb, Rb[0, 2], Rb[1, 2], Rb[2, 2], 2)
    vxy = np.sqrt(v0 * v0 + v1 * v1)  # unit vectors: no overflow to guard against (hypot is a libm call)
    exact = vxy < ALIGNED_EXACT
    dot, crs = v0 * m02 + v1 * m12, v0 * m12 - v1 * m02  # |v_xy| |m_xy| (cos qa, sin qa)
    h = np.sqrt(dot * dot + crs * crs)
    zero = exact | (h == 0.0)  # qa = 0 there (atan2(0, 0)); NaN stays NaN
    h = select(zero, 1.0, h)
    qa = select(zero, 0.0, atan2(crs, dot))
    ca, sa = select(zero, 1.0, dot / h), select(zero, 0.0, crs / h)
    y0, y1, n2 = ca * m00 + sa * m10, -sa * m00 + ca * m10, m20  # Rz(qa)ᵀ M e_x
    N00 = (_ra_rz(Ra, cb, sb, Rb[0, 0], Rb[1, 0], Rb[2, 0], 0) * y0
           + _ra_rz(Ra, cb, sb, Rb[0, 0], Rb[1, 0], Rb[2, 0], 1) * y1
           + _ra_rz(Ra, cb, sb, Rb[0, 0], Rb[1, 0], Rb[2, 0], 2) * n2)
    N10 = (_ra_rz(Ra, cb, sb, Rb[0, 1], Rb[1, 1], Rb[2, 1], 0) * y0
           + _ra_rz(Ra, cb, sb, Rb[0, 1], Rb[1, 1], Rb[2, 1], 1) * y1
           + _ra_rz(Ra, cb, sb, Rb[0, 1], Rb[1, 1], Rb[2, 1], 2) * n2)
    qc = atan2(N10, N00)
    r = np.sqrt(N00 * N00 + N10 * N10)  # 1 up to rounding (a row of a rotation with N20 = 0 there)
    rn = select(r == 0.0, 1.0, r)
    sign = select(v2 >= 0.0, 1.0, -1.0)
    y = np.pi - qc  # the determined qa ± qc (computed with qa = 0) wrapped into (−π, π], the mod by floor
    w = np.pi - (y - 2.0 * np.pi * np.floor(y / (2.0 * np.pi)))
    singular = (vxy < AXES_ALIGNED_TOL) & np.isfinite(qb)
    return (select(exact, sign * w / 2, qa), select(exact, w / 2, qc), singular, sign, vxy, cb, sb, ca, sa,
            select(r == 0.0, 1.0, N00 / rn), N10 / rn)


def stanford_q3(Dx, Dy, Dz, uz, uperp, L):
    """(q3₊, q3₋, disc, root) of the Stanford arm's prismatic joint: turning about axes 1 and 2 keeps |D| (D the
    wrist centre from the point O where they meet), so |D|² = |u + q3 z|², q3 = −u·z ± √disc (Spong, Hutchinson &
    Vidyasagar 2006, Sec. 5.3.3); the discriminant |D|² − |u⊥|² written as (|D| − |u⊥|)(|D| + |u⊥|) keeps its
    digits next to the double root; NaN where disc < −1e-12 L²."""
    nD = np.sqrt(Dx * Dx + Dy * Dy + Dz * Dz)
    disc = (nD - uperp) * (nD + uperp)
    root = np.sqrt(select(disc >= -1e-12 * L * L, np.maximum(disc, 0.0), np.nan))
    return -uz + root, -uz - root, disc, root


def stanford_q2(w0, w1, w2, Dz, r, tol):
    """(q2₊, q2₋, ρ, ratio): the height along axis 1, ``D_z = rᵀ Rz(q2) w`` (w = u + q3 z, the wrist centre in the
    frame of joint 2; r = axis 1 there), by :func:`trig_roots`."""
    return trig_roots(r[0] * w0 + r[1] * w1, r[1] * w0 - r[0] * w1, Dz - r[2] * w2, tol)


def stanford_q1(q2, w0, w1, w2, Dx, Dy, R1):
    """(q1, ex, ey): q1 turns e = R1 Rz(q2) w (its xy: ex, ey) onto D about axis 1."""
    c2, s2 = np.cos(q2), np.sin(q2)
    x, y = c2 * w0 - s2 * w1, s2 * w0 + c2 * w1  # Rz(q2) w
    ex = R1[0, 0] * x + R1[0, 1] * y + R1[0, 2] * w2
    ey = R1[1, 0] * x + R1[1, 1] * y + R1[1, 2] * w2
    return atan2(Dy, Dx) - atan2(ey, ex), ex, ey


#: The functions numba compiles (``select`` gets its scalar twin there), callers after callees.
JITTABLE = (_clip, atan2, trig_roots, trig_pairs, half_angle, shoulder_roots, elbow_plane, elbow_roots, elbow_q2,
            wrist_constants, wrist_qb, _ra_rz, wrist_rest, stanford_q3, stanford_q2, stanford_q1)
