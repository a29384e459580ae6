"""Forward-mode dual numbers, so that the library's own kernels compute derivatives without a second copy.

A :class:`Dual` is a value ``v`` and its tangents ``d`` — the derivatives of ``v`` along m input directions:
x = v + Σ_j d_j ε_j with ε_i ε_j = 0.  Arithmetic follows the rules of differentiation (sum, product,
quotient and chain rules), so running a function on duals seeded with the unit tangents of its inputs yields
its value and its Jacobian in one pass (forward-mode automatic differentiation: Griewank & Walther,
*Evaluating Derivatives*, 2nd ed., SIAM 2008, ch. 3; Wengert, Comm. ACM 7(8), 1964).

The components follow the kernels of :mod:`denavit.numeric._dynamics_fast` and :mod:`denavit.chain`, which
are written on components that are Python floats (one configuration), (B,) arrays (a batch) or traced values
of :mod:`denavit.codegen` (a recording):

- numeric: ``v`` a float and ``d`` an (m,) array, or ``v`` a (B,) array and ``d`` an (m, B) array — one numpy
  operation per dual operation, whatever m;
- traced: ``v`` a traced value (or float) and ``d`` a tuple of m traced values or floats (0.0 where a direction
  does not reach the value, which the recording folds away).

Constants stay plain floats (a plain value is a dual with zero tangents), so the kernels' constant folding and
their ``is ZERO3`` shortcuts keep working.  Numpy's ufuncs (``np.cos(x)``, ``array * x``) dispatch to the dual
(:meth:`Dual.__array_ufunc__`), which the chain walker relies on.

>>> x = Dual(2.0, np.array([1.0, 0.0]))        # x, seeded along direction 0
>>> y = Dual(3.0, np.array([0.0, 1.0]))        # y, along direction 1
>>> f = x * y + np.sin(x)
>>> round(f.v, 6), f.d.round(6).tolist()       # (xy + sin x, [y + cos x, x])
(6.909297, [2.583853, 2.0])
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["Dual", "seed_duals", "tangent_matrix", "dual_sign", "dual_min", "dual_max"]


def _scale(d, s):
    """s · d on a tangent (array or tuple)."""
    if d.__class__ is tuple:
        return tuple(x * s for x in d)
    return d * s


def _lin(d1, s1, d2, s2):
    """s1 · d1 + s2 · d2 on tangents."""
    if d1.__class__ is tuple:
        return tuple(a * s1 + b * s2 for a, b in zip(d1, d2))
    return d1 * s1 + d2 * s2


def _add(d1, d2):
    if d1.__class__ is tuple:
        return tuple(a + b for a, b in zip(d1, d2))
    return d1 + d2


def _sub(d1, d2):
    if d1.__class__ is tuple:
        return tuple(a - b for a, b in zip(d1, d2))
    return d1 - d2


def _neg(d):
    if d.__class__ is tuple:
        return tuple(-x for x in d)
    return -d


def _apply(v, name: str):
    """cos / sin / sign of a value: a float, an array, or a traced value (its method of that name)."""
    if isinstance(v, (int, float)):
        if name == "sign":
            return float((v > 0) - (v < 0))
        return math.cos(v) if name == "cos" else math.sin(v)
    if isinstance(v, np.ndarray):
        return getattr(np, name)(v)
    return getattr(v, name)()


class Dual:
    """A value ``v`` and its tangents ``d`` (see the module notes for the layouts)."""

    __slots__ = ("v", "d")

    def __init__(self, v, d) -> None:
        self.v, self.d = v, d

    def __add__(self, o):
        if o.__class__ is Dual:
            return Dual(self.v + o.v, _add(self.d, o.d))
        return Dual(self.v + o, self.d)

    def __radd__(self, o):
        return Dual(o + self.v, self.d)

    def __sub__(self, o):
        if o.__class__ is Dual:
            return Dual(self.v - o.v, _sub(self.d, o.d))
        return Dual(self.v - o, self.d)

    def __rsub__(self, o):
        return Dual(o - self.v, _neg(self.d))

    def __mul__(self, o):  # (a b)' = a' b + a b'
        if o.__class__ is Dual:
            return Dual(self.v * o.v, _lin(self.d, o.v, o.d, self.v))
        return Dual(self.v * o, _scale(self.d, o))

    def __rmul__(self, o):
        return Dual(o * self.v, _scale(self.d, o))

    def __truediv__(self, o):  # (a / b)' = (a' − (a/b) b') / b
        if o.__class__ is Dual:
            v = self.v / o.v
            return Dual(v, _scale(_lin(self.d, 1.0, o.d, -v), 1.0 / o.v))
        return Dual(self.v / o, _scale(self.d, 1.0 / o))

    def __rtruediv__(self, o):  # (c / b)' = −(c/b) b' / b
        v = o / self.v
        return Dual(v, _scale(self.d, -v / self.v))

    def __neg__(self):
        return Dual(-self.v, _neg(self.d))

    def __pos__(self):
        return self

    def cos(self):
        return Dual(_apply(self.v, "cos"), _scale(self.d, -_apply(self.v, "sin")))

    def sin(self):
        return Dual(_apply(self.v, "sin"), _scale(self.d, _apply(self.v, "cos")))

    def __bool__(self):
        raise TypeError("a dual number has no truth value: the kernels branch on the arm, not on its state")

    def __repr__(self) -> str:
        return f"Dual({self.v!r}, {self.d!r})"

    # numpy: ``array op dual`` and ``np.cos(dual)`` come here (a plain object would become an object array)
    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        names = _UFUNCS.get(ufunc)
        if method != "__call__" or kwargs or names is None:
            return NotImplemented
        if len(inputs) == 1:
            return getattr(inputs[0], names[0])()
        a, b = inputs
        return getattr(a, names[0])(b) if a.__class__ is Dual else getattr(b, names[1])(a)


_UFUNCS = {np.add: ("__add__", "__radd__"), np.subtract: ("__sub__", "__rsub__"),
           np.multiply: ("__mul__", "__rmul__"), np.true_divide: ("__truediv__", "__rtruediv__"),
           np.negative: ("__neg__",), np.positive: ("__pos__",), np.cos: ("cos",), np.sin: ("sin",)}


def dual_sign(x):
    """sign(x), with derivative 0 (taken so at x = 0 too: the one-sided derivatives of Coulomb friction)."""
    return _apply(x.v if x.__class__ is Dual else x, "sign")


def _value_pick(a, b, name: str):
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return float(min(a, b) if name == "min" else max(a, b))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (np.minimum if name == "min" else np.maximum)(a, b)
    return getattr(a, name)(b) if not isinstance(a, (int, float)) else getattr(b, name)(a)


def _pick(a, b, name: str):
    """min / max with the tangent of the selected argument: d = ½(da + db) ∓ ½ sign(a − b)(da − db)."""
    av, bv = (a.v if a.__class__ is Dual else a), (b.v if b.__class__ is Dual else b)
    v = _value_pick(av, bv, name)
    if a.__class__ is not Dual and b.__class__ is not Dual:
        return v
    like = a.d if a.__class__ is Dual else b.d
    zero = tuple(0.0 for _ in like) if like.__class__ is tuple else np.zeros_like(like)
    da, db = (a.d if a.__class__ is Dual else zero), (b.d if b.__class__ is Dual else zero)
    s = _apply(av - bv, "sign") * (-0.5 if name == "min" else 0.5)
    return Dual(v, _lin(_add(da, db), 0.5, _sub(da, db), s))


def dual_min(a, b):
    """min(a, b) on floats, arrays, traced values or duals (the tangent of the smaller; the mean at a tie)."""
    return _pick(a, b, "min")


def dual_max(a, b):
    """max(a, b), as :func:`dual_min`."""
    return _pick(a, b, "max")


def seed_duals(columns, offset: int, m: int, traced: bool = False) -> list:
    """Duals of joint columns (floats, (B,) arrays or traced values), column k seeded along direction offset + k.

    Numeric tangents are arrays ((m,) for floats, (m, B) for (B,) arrays); ``traced=True`` gives tuples.
    """
    out = []
    for k, v in enumerate(columns):
        if traced:
            out.append(Dual(v, tuple(1.0 if j == offset + k else 0.0 for j in range(m))))
            continue
        d = np.zeros((m,) + np.shape(v))
        d[offset + k] = 1.0
        out.append(Dual(v, d))
    return out


def tangent_matrix(values, m: int) -> list[list]:
    """Entries [i][j] = ∂values_i/∂direction_j as nested lists (components; 0.0 where values_i is plain)."""
    rows = []
    for x in values:
        if x.__class__ is not Dual:
            rows.append([0.0] * m)
        else:
            rows.append(list(x.d))
    return rows
