"""``dh_matrix`` claims: the general DH link matrix with symbolic a, α, d, θ.

The person's 4×4 matrix is read with a resolver that knows only the four DH symbols (any subscript: ``a_{i-1}``,
``\\alpha_{i-1}``, ``d_i``, ``\\theta_i`` or ``q_i``, ``Q_i``; shorthand ``c_i``/``s_i``/``c\\theta_i`` for the
cosine and sine of θ, ``c\\alpha``/``s\\alpha`` for α) and compared, at random values of the four, with the numeric engine's
:func:`denavit.numeric.dh_transform` for the convention named in the claim (default: the robot's).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import _expr
from .. import numeric as N
from ..errors import ParseError
from ..model import Convention, DHRobot
from ._matrices import parse_matrix
from ._tokens import Ident

__all__ = ["check_dh_matrix", "N_DH_POINTS"]

#: Random (a, α, d, θ) at which a claimed general DH matrix is compared.
N_DH_POINTS = 8
_BASES = {"a": "a", "alpha": "alpha", "d": "d", "theta": "theta", "vartheta": "theta", "q": "theta", "Q": "theta", "r": "a"}
_SHORT = {"c": "cos", "C": "cos", "s": "sin", "S": "sin"}


def _resolve(ident: Ident) -> tuple:
    if ident.dots:
        raise ParseError("a DH matrix has no rates; write a, \\alpha, d, \\theta")
    base = ident.base
    if base in _BASES:
        return ("name", _BASES[base])
    if base in _SHORT:  # c_i, s_i: cos θ, sin θ; c\alpha_{i-1}: cos α (\alpha read as the subscript)
        return ("call", _SHORT[base], (("name", "theta"),))
    for short, fn in _SHORT.items():  # c\theta, s\alpha written as one word: "ctheta", "salpha"
        if base.startswith(short) and base[1:] in _BASES:
            return ("call", fn, (("name", _BASES[base[1:]]),))
    raise ParseError(f"unknown symbol {ident.plain!r} in a general DH matrix; known: a, \\alpha, d, \\theta "
                     "(any subscript), c_i/s_i for cos/sin θ")


def _cos_sin_of_alpha(text: str) -> str:
    """``c\\alpha_{i-1}`` / ``s_{\\alpha_{i-1}}`` → ``\\cos\\alpha`` / ``\\sin\\alpha`` (before the generic reader)."""
    import re

    text = re.sub(r"\b([cCsS])_?\{?\\(alpha|theta)(_\{[^{}]*\}|_[A-Za-z0-9])?\}?",
                  lambda m: ("\\cos" if m.group(1) in "cC" else "\\sin") + " \\" + m.group(2) + " ", text)
    return text


def check_dh_matrix(robot: DHRobot, raw: dict[str, Any], cid: str, rng: np.random.Generator, deg: bool):
    """The verdict on a claimed general DH link matrix (see the module notes)."""
    from ._engine import Verdict

    conv = raw.get("convention", robot.convention.value)
    try:
        conv = Convention(str(conv))
    except ValueError:
        raise ParseError(f"'convention' must be standard or modified, got {str(conv)[:40]!r}") from None
    value = raw["value"]
    if isinstance(value, list):
        rows = value if all(isinstance(r, list) for r in value) else [value]
        value = r"\begin{bmatrix}" + r" \\ ".join(" & ".join(str(c) for c in r) for r in rows) + r"\end{bmatrix}"
    cells = parse_matrix(_cos_sin_of_alpha(str(value)), _resolve)
    shape = (len(cells), len(cells[0]))
    if shape not in ((4, 4), (3, 4)):
        return Verdict(cid, "dh_matrix", "incorrect", f"incorrect: shape: expected a 4×4 matrix, got {shape[0]}×{shape[1]}")
    pts = [dict(zip(("a", "alpha", "d", "theta"), rng.uniform(-np.pi, np.pi, 4))) for _ in range(N_DH_POINTS)]

    def truth(c: Convention) -> np.ndarray:
        return np.array([N.dh_transform(c, p["theta"], p["d"], p["a"], p["alpha"])[:shape[0]] for p in pts])

    claimed = np.array([[[_expr.evaluate(x, p) for x in row] for row in cells] for p in pts])
    want = truth(conv)
    ok = np.abs(claimed - want) <= 1e-9 * np.maximum(1.0, np.abs(want))
    method = f"evaluated at {N_DH_POINTS} random (a, α, d, θ), compared with the numeric engine's {conv.value} DH matrix"
    if ok.all():
        return Verdict(cid, "dh_matrix", "correct", f"correct ({conv.value} DH)", method=method)
    bad = [[int(i) + 1, int(j) + 1] for i, j in zip(*np.nonzero(~ok.all(axis=0)))]
    k = int(np.argmax(np.abs(claimed - want).reshape(len(pts), -1).max(axis=1)))
    entries = tuple({"entry": e, "claimed": float(claimed[k][e[0] - 1, e[1] - 1]),
                     "expected": float(want[k][e[0] - 1, e[1] - 1])} for e in bad)
    other = Convention.MODIFIED if conv is Convention.STANDARD else Convention.STANDARD
    hints = ()
    alt = truth(other)
    if np.all(np.abs(claimed - alt) <= 1e-9 * np.maximum(1.0, np.abs(alt))):
        hints = (f"it is the {other.value} DH matrix; the claim (or the robot) uses {conv.value} DH "
                 "(give 'convention' if you meant the other)",)
    where = ", ".join(str(tuple(e)) for e in bad[:12])
    return Verdict(cid, "dh_matrix", "incorrect",
                   f"incorrect: {len(bad)} entr{'y differs' if len(bad) == 1 else 'ies differ'} ({where})", entries,
                   {k2: float(v) for k2, v in pts[k].items()}, hints, want[k].tolist(), method)
