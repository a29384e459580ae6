"""What a report states before a result and the result depends on: the case's q, the rates q̇, the wrench, names
the derivation introduced, and whether the text is about singular configurations.

Givens are recognised by their shape, never evaluated here: ``(\\theta_1, …)[rad] = (0, \\frac{\\pi}{4}, …)``,
``q = (…)``, ``\\theta_1 = 0^\\circ, \\theta_2 = 90^\\circ …`` (every joint once), ``\\dot q = [2, 3.2, …]``, ``F =
[30, 20, …]``, and a numeric vector right after a Jacobian (``J \\begin{bmatrix} 2 \\\\ 3.2 … \\end{bmatrix}``).  The
checker reads the values themselves (its q reader accepts all of these forms).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace

from ..model import DHRobot
from ._lhs import Symbol
from ._names import JOINT_LETTERS
from ._split import top_level_split

__all__ = ["Context", "case_of", "rate_value", "vector_entries", "is_numeric", "has_joint_names", "rates_or_wrench",
           "MAX_WHERE", "is_wrench_name", "is_rate_name"]

#: Most names a derivation introduces that are passed to one claim (the checker's own bound).
MAX_WHERE = 20
_NUMERIC = re.compile(r"^[\s\d.+\-*/(){}\[\],^°]*$")
_NUM_WORDS = re.compile(r"\\(?:frac|dfrac|tfrac|sqrt|pi|cdot|times|left|right|circ|mathrm|rm|text|deg|,|;|!|quad)"
                        r"|\bpi\b|\bdeg\b|\brad\b|π|√")
_JOINTS = re.compile(r"\\(?:var)?theta|\\dot|\\ddot|\bq_?\{?\d|\bQ_?\{?\d|\b[cCsS]_?\{?\d|\\cos|\\sin|\bcos\b|\bsin\b|"
                     r"\bheta|θ")
_MATRIX = re.compile(r"\\begin\{([bBpv]?matrix)\}(.{0,4000}?)\\end\{\1\}", re.S)


@dataclass
class Context:
    """Givens in force at the current point of the report."""

    q: str | None = None
    qd: str | None = None
    wrench: str | None = None
    partial: dict[int, str] = field(default_factory=dict)
    partial_rates: dict[int, str] = field(default_factory=dict)  # joint rates given one by one
    where: dict[str, str] = field(default_factory=dict)
    singular: bool = False
    propagation: bool = False
    jacobian_frame: int | None = None
    wrench_frame: str | None = None
    cases: dict[str, str] = field(default_factory=dict)
    case_number: str = ""
    wrench_texts: list[str] = field(default_factory=list)
    target: str | None = None  # an IK target stated in words (a 4×4 as text), and the line that stated it
    target_line: int = 0
    target_words_line: int = 0  # the last line with words of a target ("the desired pose"): a T after it is one
    renames: dict[str, str] = field(default_factory=dict)
    trig_steps: dict[tuple[str, int], str] = field(default_factory=dict)  # ("cos", 2) → what "cos θ2 = …" gave  # shorthand digits → signed form ("124" → "12-4")
    p_wrist: bool = False
    ik_section: bool = False  # under a heading about inverse kinematics: coordinates stated are a target  # the report named the wrist centre's coordinates P_x, P_y, P_z (see ._points)

    def define(self, name: str, value: str) -> None:
        self.where.pop(name, None)
        self.where[name] = value
        while len(self.where) > MAX_WHERE:
            self.where.pop(next(iter(self.where)))


def is_numeric(text: str) -> bool:
    """Only numbers, π, √, fractions and operators (a value at a case, not a formula)."""
    return bool(_NUMERIC.match(_NUM_WORDS.sub(" ", text)))


def has_joint_names(text: str) -> bool:
    return bool(_JOINTS.search(text))


def vector_entries(text: str) -> list[str] | None:
    """The entries of a column/row vector written as a matrix, ``(a, b, c)`` or ``[a, b, c]``."""
    t = re.sub(r"\^\s*\{?\s*(?:T|\\top|\\intercal)\s*\}?\s*$", "", text.strip()).strip()
    m = _MATRIX.fullmatch(t)
    if m:
        body = m.group(2)
        rows = [r.strip() for r in top_level_split(body, ("\\\\",)) if r.strip()]
        if len(rows) == 1:
            rows = [c.strip() for c in rows[0].split("&")]
        elif any("&" in r for r in rows):
            return None
        return rows
    t = re.sub(r"^\\left\s*|\\right\s*(?=[)\]]$)", "", t)
    if len(t) >= 2 and t[0] in "([" and t[-1] in ")]":
        inner = t[1:-1]
        items = [x.strip() for x in top_level_split(inner, (",", ";"))]
        return items if len(items) >= 2 else None
    return None


def _joint_tuple(lhs: str, dof: int) -> bool:
    """``(\\theta_1, …, \\theta_n)`` possibly with a unit ``[rad]``; or ``q``, ``\\mathbf q``, ``\\theta``."""
    t = re.sub(r"^.{0,20}?(?:case|Case|CASE)\s*\d{1,2}\s*:?", "", lhs.strip())
    t = re.sub(r"\[(?:rad|deg|°|\\circ)\]|\((?:rad|deg)\)|\\(?:mathbf|boldsymbol|bm)\s*|\s+|[{}]", "", t)
    if t in ("q", "\\theta", "\\vartheta", "Q", "\\Theta"):
        return True
    m = re.fullmatch(r"(?:\\left)?\((.*)(?:\\right)?\)", t)
    if not m:
        return False
    items = [x for x in m.group(1).replace("\\right", "").split(",") if x]
    return len(items) == dof and all(re.fullmatch(r"\\?(?:var)?(?:theta|q|Q|heta|d)_?\d", x) for x in items)


def case_of(parts: tuple[str, ...], text: str, robot: DHRobot) -> str | None:
    """The q of a case stated by this equation (its text, as the checker reads it), or None."""
    if len(parts) != 2 or not _joint_tuple(parts[0], robot.dof):
        return None
    entries = vector_entries(parts[1])
    if entries is None or len(entries) != robot.dof or not all(is_numeric(e) for e in entries):
        return None
    lhs = re.sub(r"^.{0,20}?(?:case|Case|CASE)\s*\d{1,2}\s*:?", "", parts[0].strip())
    return f"{lhs} = {parts[1]}"


def joint_value(sym: Symbol, rhs: str, robot: DHRobot) -> tuple[int, str] | None:
    """``\\theta_2 = 90^\\circ``: (joint, value text) when the right side is one number."""
    if sym.base not in JOINT_LETTERS + ("d",) or sym.dots or sym.pre_sup or sym.sup:
        return None
    k = sym.sub.strip("{} ")
    if not (k.isdigit() and 1 <= int(k) <= robot.dof) or not is_numeric(rhs) or "," in rhs:
        return None
    if sym.base == "d" and (robot.joint_types[int(k) - 1].value != "prismatic"
                            or f"d{k}" in {n for n, _ in robot.parameters}):
        return None
    return int(k), rhs


def rate_value(sym: Symbol, rhs: str, robot: DHRobot) -> tuple[int, str] | None:
    """``\\dot\\theta_2 = 0.2``: (joint, value text) of a joint rate given as one number."""
    if sym.dots != 1 or sym.pre_sup or sym.sup:
        return None
    return joint_value(replace(sym, dots=0), rhs, robot)


def is_rate_name(lhs: str) -> bool:
    t = re.sub(r"\s+|[{}]|\\(?:mathbf|boldsymbol|bm)", "", lhs)
    return t in ("\\dot\\theta", "\\dotq", "\\dot\\vartheta", "\\dotQ", "qd", "\\dot\\Theta")


def is_wrench_name(lhs: str) -> bool:
    t = re.sub(r"\s+|[{}]|\\(?:mathbf|boldsymbol|bm|mathcal)", "", lhs)
    return t in ("F", "F_E", "F_e", "w", "W", "h", "F_{ext}", "Fext", "\\mathcalF", "\\xi_F") or \
        t.startswith("\\begin{bmatrix}f_") or t.startswith("\\begin{bmatrix}f_E")


def rates_or_wrench(part: str) -> tuple[str, str] | None:
    """``J_\\vartheta \\begin{bmatrix} 2 \\\\ 3.2 … \\end{bmatrix}`` → ("J", the vector text), ``J^T [...]`` → ("JT", …)."""
    m = re.match(r"^\s*(?:\\mathbf\{J\}|J)(?:_\{?[^\s\\{}]{0,3}\}?|_\{?\\(?:vartheta|theta)\}?)?(\^\{?T\}?)?"
                 r"(?:_\{?\\(?:vartheta|theta)\}?)?(\^\{?T\}?)?\s*(\\begin\{[bp]matrix\}.*\\end\{[bp]matrix\})\s*$",
                 part, re.S)
    if not m:
        return None
    entries = vector_entries(m.group(3))
    if entries is None or not all(is_numeric(e) for e in entries):
        return None
    return ("JT" if (m.group(1) or m.group(2)) else "J"), "[" + ", ".join(entries) + "]"
