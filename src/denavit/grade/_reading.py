"""Reading names and values in a report's equations: what a derivation defines, renames, multiplies or renumbers.

Moved from ``_claims.py`` (code unchanged, names made public for the walker).
"""

from __future__ import annotations

import re
from typing import Any

from .._constants import TWIST_ROWS
from ._context import Context, vector_entries
from ._lhs import read_symbol
from ._masses import moves_in_xy
from ._names import Reading, read_name

__all__ = ["vector_reading", "define_chain", "define_term", "det_rows", "only_names", "trailing_name", "names_product", "formula_leftover", "used_where", "plain_name",
           "joint_offset", "renumber"]


def vector_reading(lhs: str, robot: Any) -> Reading | None:
    """``[\\dot x; \\dot y; \\dot z]`` on the left: the twist rows those rates are (each read as a name)."""
    entries = vector_entries(lhs) if lhs.strip().startswith("\\begin") else None
    if not entries or len(entries) > 6:
        return None
    rows = []
    for e in entries:
        sym = read_symbol(e)
        r = read_name(sym, robot) if sym is not None else None
        k = r.spec.get("entry") if r is not None and r.spec.get("quantity") == "twist" else None
        if not isinstance(k, int):
            return None
        rows.append(TWIST_ROWS[k - 1])
    if len(set(rows)) != len(rows):
        return None
    return Reading({"quantity": "twist", "rows": ",".join(rows)}, f"the end-effector velocity rows {', '.join(rows)}",
                   needs=("q", "qd"))


def define_chain(ctx: Context, parts: tuple[str, ...], robot: Any) -> bool:
    """``d_4 = a_2 = k`` or ``k \\cos q_3 \\to \\{AA\\}``: a new name for a known one (remembered for later claims)."""
    params = {k for k, _ in robot.parameters}
    last = plain_name(parts[-1]).strip("{}")
    bare = re.fullmatch(r"\\?\{?([A-Za-z]{1,3}(?:_\{?\w{1,3}\}?)?)\\?\}?", last)
    if bare is None or len(parts) < 3 and not parts[-1].strip().startswith("\\{"):
        return False
    name = bare.group(1)
    if name.replace("_", "").replace("{", "").replace("}", "") in params or read_symbol(last) is None:
        return False
    sym = read_symbol(last)  # "\\ell" as written (read_symbol("ell") is no symbol)
    if sym is None or sym.base in ("theta", "q", "Q", "x", "y", "z", "p", "P", "J", "T", "R", "A"):
        return False
    ctx.define(last if last.startswith("\\") else name, parts[-2])
    return True


_NAMED = re.compile(r"(?:\{\}\s*)?(?:\^\s*\{?[\w\-+]{1,4}\}?\s*)?(?:_\s*\{?[\w\-+]{1,4}\}?\s*)?[A-Z]\s*"
                    r"(?:_\s*\{?[\w\-+]{1,4}\}?\s*)?(?:\^\s*\{?[\w\-+]{1,4}\}?\s*)?")
_FILLER = re.compile(r"\\(?:cdot|cdots|dots|ldots|times|left|right)|\.|[\s{}()]|\^\{?T\}?")


#: A propagated vector named by its frame: ``{}^2 f_2``, ``n_3``, ``\\mathbf{f}_1``, ``{}^1\\omega_1``, ``{}^1 P_2`` is
#: caught by :data:`_NAMED`.  Lower-case only with a numeric subscript (``f_x`` is an entry, ``c_1`` a cosine).
_VECTOR_NAMED = re.compile(r"(?:\{\}\s*\^\s*\{?\s*\d\s*\}?\s*)?(?:\\mathbf\{|\\boldsymbol\{)?(?:[fnvwp]|\\omega)\}?\s*"
                           r"_\s*\{?\s*\d{1,2}\s*\}?")


def formula_leftover(value: str) -> str | None:
    """What is left of ``value`` once its named results (two or more, a propagated vector among them), operators
    and brackets are taken out: ``""`` for a formula in other results (``{}^1R_2 n_2 + {}^1P_2 \\times {}^1f_1``,
    Craig's propagation: a definition, not a value), ``"\\alpha"`` for ``{}^2P_3 \\alpha {}^2f_2`` (a symbol where
    an operator belongs); None when ``value`` is no such formula."""
    if len(value) > 400 or "\\begin" in value or not _VECTOR_NAMED.search(value):
        return None
    value = re.sub(r"\^\s*\{?\s*(?:T|\\top|-1)\s*\}?", " ", value)
    vectors = _VECTOR_NAMED.findall(value)
    rest = _VECTOR_NAMED.sub(" ", value)
    names = _NAMED.findall(rest)
    if len(vectors) + len(names) < 2:
        return None
    return _FILLER.sub("", re.sub(r"[+\-]", "", _NAMED.sub("", rest)))


def names_product(value: str) -> bool:
    """``T_0^1 T_1^2 ⋯``, ``{}^0T_1{}^1T_2``: a product of named transforms (a definition, not a value)."""
    if len(value) > 400 or "\\begin" in value:
        return False
    value = re.sub(r"\^\s*\{?\s*(?:T|\\top|-1)\s*\}?", " ", value)
    names = _NAMED.findall(value)
    rest = _FILLER.sub("", _NAMED.sub("", value))
    return len(names) >= 2 and not rest


def used_where(where: dict[str, str], value: str) -> dict[str, str]:
    """The definitions a value uses (and those they use), in the order they were made."""
    def uses(text: str, name: str) -> bool:
        return re.search(r"(?<![A-Za-z\\])" + re.escape(name) + r"(?![A-Za-z_0-9])", re.sub(r"\s+", " ", text)) is not None

    need = {k for k in where if uses(value, k)}
    for _ in range(len(where)):
        more = {k for k in where for n in need if k not in need and uses(where[n], k)}
        if not more:
            break
        need |= more
    return {k: v for k, v in where.items() if k in need}


def plain_name(lhs: str) -> str:
    return re.sub(r"\s+", "", lhs)


_JOINT_INDEX = re.compile(r"(?:\\(?:var)?theta|\bq|\bQ|(?<![A-Za-z\\])[cCsS])\s*_\s*\{?\s*(\d{1,4})")
_SUBSCRIPT = re.compile(r"(_\s*\{?\s*)(\d{1,4})(?!\.)")
_LEFT_SUP = re.compile(r"(\{\}\s*\^\s*\{?\s*)(\d)")


def joint_offset(texts: list[str], dof: int) -> int:
    """The shift of a section's joint numbers: every index it writes lies in o+1 … o+dof, with o ≥ 1."""
    idx = {int(d) for t in texts for m in _JOINT_INDEX.finditer(t) for d in m.group(1)}
    if not idx or max(idx) <= dof:
        return 0
    lo = min(idx)
    return lo - 1 if lo > 1 and max(idx) - lo < dof else 0


def renumber(latex: str, offset: int, n_rows: int) -> str:
    """Subscripts and left superscripts of a section written with shifted joint and frame numbers, shifted back."""
    def shift(m: re.Match) -> str:
        digits = "".join(str(int(d) - offset) if offset <= int(d) <= offset + n_rows else d for d in m.group(2))
        return m.group(1) + digits

    return _LEFT_SUP.sub(shift, _SUBSCRIPT.sub(shift, latex))


_ONLY_NAMES = re.compile(r"(?:[A-Za-z{}\s]|\\(?:dot|mathbf|boldsymbol|vec)\b){1,40}")
_SCRIPT = re.compile(r"[_^](?:\{[^{}]{0,8}\}|\w)")


_ONE_NAME = re.compile(r"\s*(?:\{\})?[A-Za-z]{1,3}\s*")
_MATRIX = re.compile(r"\s*\\begin\{([pbvBV]?matrix)\}(.{0,400})\\end\{\1\}\s*", re.S)


def only_names(text: str) -> bool:
    """``S v_s``, ``{}^0v_s``, ``\\mathbf{p}``: names (with sub- and superscripts), no number, no operator; or a
    matrix of single names (``[P_x; P_y; P_z]``)."""
    m = _MATRIX.fullmatch(text)
    if m:
        cells = re.split(r"\\\\|&", m.group(2))
        return all(_ONE_NAME.fullmatch(_SCRIPT.sub("", c)) for c in cells)  # P_x, not L_1 c_1 (a formula)
    return bool(_ONLY_NAMES.fullmatch(_SCRIPT.sub("", text.strip()))) and bool(re.search("[A-Za-z]", text))


def det_rows(sym: Any, robot: Any) -> str | None:
    """The rows of J a determinant is taken of: those its name says (``J_v``, ``J_\\omega``), else for an arm of up
    to 3 joints (vx, vy) or (vx, vy, ωz) when it moves in a plane, (vx, vy, vz) when it does not; None (all)
    beyond."""
    sub = (sym.sub if sym is not None else "").strip("{} \\")
    if sub == "v":
        return "vx,vy,vz"
    if sub in ("omega", "w"):
        return "wx,wy,wz"
    if robot.dof > 3:
        return None
    if moves_in_xy(robot):
        return "vx,vy" if robot.dof == 2 else "planar"  # (vx, vy, ωz) for three joints
    return "vx,vy,vz"


def trailing_name(parts: tuple[str, ...], robot: Any) -> Reading | None:
    """The reading of a chain's last part when it only names another result (``… = [⋯] = {}^1f_1``) after a
    value: the value before it is claimed for that name too.  None otherwise."""
    if len(parts) < 3 or "\\begin" in parts[-1] or "\\begin" not in parts[-2]:
        return None
    sym = read_symbol(parts[-1])
    return read_name(sym, robot, parts[-2]) if sym is not None else None


#: Results whose names a derivation goes on to use (d_{11}, φ_1, K, P in τ = … and L = K − P); never the pose's
#: entries (p_x, p_z in an inverse-kinematics formula are the target's).
_TERMS = ("mass_matrix", "gravity", "coriolis", "coriolis_matrix", "kinetic_energy", "potential_energy")
_SCALAR_NAME = re.compile(r"\\?[A-Za-z]{1,5}(?:_\{?\w{1,3}\}?)?")


def define_term(ctx: Context, lhs: str, value: str, quantity: str) -> None:
    """``d_{11} = …`` judged: a later ``τ₁ = d_{11} q̈₁ + …`` uses the report's value (so a wrong d₁₁ carries into
    τ₁, as it does on paper); M is symmetric, so ``d_{21}`` is defined by ``d_{12}`` too."""
    name = lhs.strip()
    if "\\begin" in value or not _SCALAR_NAME.fullmatch(name) or quantity not in _TERMS:
        return
    ctx.define(name, value)
    pair = re.fullmatch(r"(.+_\{?)(\d)(,?)(\d)(\}?)", name)
    if pair and quantity == "mass_matrix":
        ctx.define(pair.expand(r"\g<1>\g<4>\g<3>\g<2>\g<5>"), value)
