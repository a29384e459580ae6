"""The independent derivations behind ``_truth.py`` (DH matrices, Jacobians, propagation, checks), in SymPy.

Every value is derived here with SymPy from first principles — the DH link matrices written out below
(Spong: A_i = Rot_z(θ) Trans_z(d) Trans_x(a) Rot_x(α); Craig: T = Rot_x(α) Trans_x(a) Rot_z(θ) Trans_z(d)), the
geometric Jacobian J_i = [z × (p − p_i); z] (revolute) / [z; 0] (prismatic), velocity and force propagation as
rotations of those base-axes quantities, Lagrange's equations for the dynamics — never with denavit's code.

Each fixture has a list of records, one per expected verdict, in the order of its ``expect`` comments. A record
holds the result as written in the report (transcribed by hand into SymPy) and the truth; the script checks

- the fixture's ``expect`` comments, read in order, equal the records' verdicts;
- a result expected ``correct`` equals its truth (at random points of every free symbol), and a result expected
  ``incorrect`` differs from it (the slip is real);
- singular sets and inverse-kinematics formulas by their own tests (below).
"""

from __future__ import annotations

import random
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp

HERE = Path(__file__).resolve().parent
EXPECT = re.compile(r"^\s*(?:<!--|%)\s*expect:\s*(.*?)\s*(?:-->)?\s*$")

t1, t2, t3, t4, t5, t6 = sp.symbols("theta1:7", real=True)
T = (t1, t2, t3, t4, t5, t6)
pi = sp.pi
c, s = sp.cos, sp.sin


# --- DH link matrices, chains, Jacobians (our own, written from the textbooks) -------------------------------

def rot_z(th):
    return sp.Matrix([[c(th), -s(th), 0, 0], [s(th), c(th), 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


def rot_x(al):
    return sp.Matrix([[1, 0, 0, 0], [0, c(al), -s(al), 0], [0, s(al), c(al), 0], [0, 0, 0, 1]])


def trans(x, y, z):
    return sp.Matrix([[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]])


def link(conv: str, a, alpha, d, theta):
    """Spong (standard): Rz(θ) Tz(d) Tx(a) Rx(α); Craig (modified): Rx(α) Tx(a) Rz(θ) Tz(d)."""
    if conv == "std":
        return rot_z(theta) * trans(0, 0, d) * trans(a, 0, 0) * rot_x(alpha)
    return rot_x(alpha) * trans(a, 0, 0) * rot_z(theta) * trans(0, 0, d)


@dataclass
class Arm:
    conv: str              # "std" | "mdh"
    rows: list             # (a, alpha, d, theta) per DH row, joint variables inside
    joints: list           # per DH row: ("R", var) | ("P", var) | None for a fixed row

    def A(self, i: int) -> sp.Matrix:
        return link(self.conv, *self.rows[i - 1])

    def T(self, i: int, j: int | None = None) -> sp.Matrix:
        """Pose of frame j in frame i (j defaults to the last row)."""
        j = len(self.rows) if j is None else j
        M = sp.eye(4)
        for k in range(i + 1, j + 1):
            M = M * self.A(k)
        return M

    @property
    def q(self) -> list:
        return [jt[1] for jt in self.joints if jt is not None]

    def jacobian(self) -> sp.Matrix:
        """Geometric Jacobian in base axes, rows (v, ω), reference point the last frame's origin."""
        n = len(self.rows)
        p = self.T(0, n)[:3, 3]
        cols = []
        for i, jt in enumerate(self.joints, start=1):
            if jt is None:
                continue
            # the frame holding joint i's axis: i-1 in Spong's convention, i in Craig's
            F = self.T(0, i - 1) if self.conv == "std" else self.T(0, i)
            z, o = F[:3, 2], F[:3, 3]
            if jt[0] == "R":
                cols.append(sp.Matrix.vstack(z.cross(p - o), z))
            else:
                cols.append(sp.Matrix.vstack(z, sp.zeros(3, 1)))
        return sp.Matrix.hstack(*cols)

    def jacobian_in(self, k: int) -> sp.Matrix:
        R = self.T(0, k)[:3, :3]
        Z = sp.zeros(3, 3)
        B = sp.Matrix(sp.BlockMatrix([[R.T, Z], [Z, R.T]]))
        return (B * self.jacobian())


def qd_symbols(arm: Arm) -> list:
    return [sp.Symbol(f"qd{k}", real=True) for k in range(1, len(arm.q) + 1)]


def frame_velocity(arm: Arm, k: int) -> tuple[sp.Matrix, sp.Matrix]:
    """(ᵏωₖ, ᵏvₖ): angular velocity and origin velocity of frame k, in frame k's own axes (by time derivative)."""
    qd = qd_symbols(arm)
    Tk = arm.T(0, k)
    R, p = Tk[:3, :3], Tk[:3, 3]
    Rdot = sum((R.diff(q) * w for q, w in zip(arm.q, qd)), sp.zeros(3, 3))
    W = (R.T * Rdot)       # skew(ᵏω)
    omega = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])
    pdot = sum((p.diff(q) * w for q, w in zip(arm.q, qd)), sp.zeros(3, 1))
    return omega, (R.T * pdot)


def force_moment(arm: Arm, k: int, f_tip, n_tip) -> tuple[sp.Matrix, sp.Matrix]:
    """(ᵏfₖ, ᵏnₖ): the tip wrench (force f_tip, moment n_tip in the last frame's axes, at its origin) carried to
    frame k: the same force, the moment about frame k's origin, both in frame k's axes (statics of a free body)."""
    n = len(arm.rows)
    Tkn = arm.T(k, n)
    R, p = Tkn[:3, :3], Tkn[:3, 3]
    f = R * sp.Matrix(f_tip)
    return f, (R * sp.Matrix(n_tip) + p.cross(f))


# --- comparison --------------------------------------------------------------------------------------------

def _points(exprs, n=6, seed=7):
    syms = set()
    for e in exprs:
        syms |= getattr(e, "free_symbols", set())
    rnd = random.Random(seed)
    syms = sorted(syms, key=str)
    return [{x: rnd.uniform(0.3, 1.4) * rnd.choice((-1, 1)) if str(x).startswith(("theta", "qd", "f", "n"))
             else rnd.uniform(0.3, 1.4) for x in syms} for _ in range(n)]


def _matrix(x) -> sp.Matrix:
    return sp.Matrix([x]) if isinstance(x, (sp.Expr, int, float)) else sp.Matrix(x)


def same(claimed, truth, tol=1e-9) -> bool:
    """Equal as formulas: numerically at random points of every free symbol (entries within ``tol``)."""
    C, Tm = _matrix(claimed), _matrix(truth)
    if C.shape != Tm.shape:
        return False
    syms = sorted(C.free_symbols | Tm.free_symbols, key=str)
    fc, ft = sp.lambdify(syms, C, "numpy"), sp.lambdify(syms, Tm, "numpy")
    for pt in _points([C, Tm]):
        args = [pt[x] for x in syms]
        a, b = np.asarray(fc(*args), dtype=float), np.asarray(ft(*args), dtype=float)
        if np.any(np.abs(a - b) > tol * np.maximum(1.0, np.abs(b))):
            return False
    return True


@dataclass
class R:
    """One expected verdict: the result as written (SymPy), the truth, or a test of its own (``test``)."""
    verdict: str
    label: str
    claimed: Any = None
    truth: Any = None
    tol: float = 1e-9
    test: Callable[[], bool] | None = None

    def holds(self) -> bool | None:
        """True when the written result is right, False when wrong, None when the record has nothing to test."""
        if self.test is not None:
            return bool(self.test())
        if self.claimed is None:
            return None
        return same(self.claimed, self.truth, self.tol)


def expects(path: Path) -> list[str]:
    out: list[str] = []
    for line in path.read_text(encoding="utf-8").splitlines():
        m = EXPECT.match(line)
        if m:
            out += [v.strip() for v in m.group(1).split(",")]
    return out


# --- singular sets and inverse kinematics -------------------------------------------------------------------

def singular_set_ok(det_expr, conditions: list, joints=T) -> bool:
    """The claimed conditions (expressions that vanish on each claimed set) are the zero set of ``det_expr``:
    det_expr factors into exactly those factors (up to constants and the non-zero link lengths): the ratio is
    free of the joint variables ``joints``."""
    prod = sp.Integer(1)
    for cond in conditions:
        prod *= cond
    ratio = det_expr / prod
    others = sorted(ratio.free_symbols - set(joints), key=str)
    rnd = random.Random(11)
    fixed = {x: rnd.uniform(0.3, 1.4) for x in others}
    values = []
    for _ in range(6):
        pt = {**fixed, **{x: rnd.uniform(-3, 3) for x in joints}}
        values.append(complex(ratio.subs(pt).evalf()))
    return abs(values[0]) > 1e-9 and all(abs(v - values[0]) < 1e-9 * abs(values[0]) for v in values)


def ik_ok(arm: Arm, joint: int, formula: Callable[[dict, dict], float], n: int = 6, seed: int = 3,
          params: dict | None = None, point=None, signs: dict | None = None) -> bool:
    """``formula(target, q)`` gives joint ``joint``'s value from the target (px, py, pz, r11 … r33) and the
    other joints of the same solution ``q``; checked at random configurations (angles mod 2π). ``signs`` fixes
    the sign of some joints (the branch a one-branch formula gives); ``point`` replaces (px, py, pz) by another
    point of the arm (e.g. the wrist centre)."""
    rnd = random.Random(seed)
    T0n = arm.T(0)
    if params:
        T0n = T0n.subs(params)
    pose = sp.lambdify(arm.q, T0n, "numpy")
    where = sp.lambdify(arm.q, point.subs(params or {}), "numpy") if point is not None else None
    for _ in range(n):
        qv = {q: rnd.uniform(0.2, 1.3) * (signs or {}).get(q, rnd.choice((-1, 1))) for q in arm.q}
        args = [qv[q] for q in arm.q]
        Mn = np.asarray(pose(*args), dtype=float)
        tgt = {"px": Mn[0, 3], "py": Mn[1, 3], "pz": Mn[2, 3]}
        if where is not None:
            tgt.update(zip(("px", "py", "pz"), np.asarray(where(*args), dtype=float).ravel()))
        for i in range(3):
            for j in range(3):
                tgt[f"r{i + 1}{j + 1}"] = Mn[i, j]
        got = formula(tgt, {str(k): float(v) for k, v in qv.items()})
        want = float(qv[arm.q[joint - 1]])
        d = (got - want + 3.141592653589793) % 6.283185307179586 - 3.141592653589793
        if abs(d) > 1e-7:
            return False
    return True




def planar_lagrange(n: int, L, Lc, m, I, g):
    """Planar nR arm in a vertical plane (gravity −y): centre of mass of link i at Lc_i along it, inertia I_i
    about it. Returns (p_c list, ṗ_c list, K, V, M, gravity vector) from K = Σ ½ mᵢ|ṗ_ci|² + ½ Iᵢ ωᵢ²."""
    q = T[:n]
    qd = [sp.Symbol(f"qd{k}", real=True) for k in range(1, n + 1)]
    pcs, vcs = [], []
    K = 0
    for i in range(n):
        ang = [sum(q[:k + 1]) for k in range(i + 1)]
        x = sum(L[k] * c(ang[k]) for k in range(i)) + Lc[i] * c(ang[i])
        y = sum(L[k] * s(ang[k]) for k in range(i)) + Lc[i] * s(ang[i])
        p = sp.Matrix([x, y, 0])
        v = sum((p.diff(qq) * w for qq, w in zip(q, qd)), sp.zeros(3, 1))
        pcs.append(p)
        vcs.append(v)
        K += m[i] * (v.T * v)[0] / 2 + I[i] * sum(qd[:i + 1]) ** 2 / 2
    V = sum(m[i] * g * pcs[i][1] for i in range(n))
    Mq = sp.Matrix(n, n, lambda i, j: sp.diff(K, qd[i], qd[j]))
    G = sp.Matrix([sp.diff(V, qq) for qq in q])
    return pcs, vcs, sp.expand(K), V, Mq, G
