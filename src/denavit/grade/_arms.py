"""The arm(s) of a report: its own DH tables (read as ``import-table`` reads them), or arms given by the user.

Each table governs the report from its own section on, until the next table.  A section whose heading names a
different number of joints ("Equation of Motion for 3DOF Manipulator" after a 6-joint table) gets no arm here
(judging it against the wrong arm would call right results wrong): one is given for it (``--arm
6=planar3r-lagrange``) or recognised from its own results (:func:`._infer.infer_sections`).  Lengths a table names without a value (``a_2``, ``d_4``) stay symbols for formulas; for numeric work they
get distinct generic values (never 1, so that no two lengths coincide by accident).
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass
from typing import Any

from ..errors import DenavitError, ParseError
from ..io import catalogue_names, load_robot, robot_from_dict
from ..model import DHRobot
from ..tables import find_tables, import_table
from ._document import Document, Heading, Math
from ._masses import check_buildable, massed_arm_data, moves_in_xy, names_written
from ._types import ArmInfo, GradedClaim

__all__ = ["Arm", "Section", "arms_of", "compare_tables", "with_equal_lengths", "with_given_lengths", "length_value",
           "stated_lengths", "GENERIC_LENGTHS"]

#: Values given to lengths a table names without a value (distinct, not round, so no two coincide).
GENERIC_LENGTHS = (0.537, 0.419, 0.3271, 0.6143, 0.2789, 0.4657, 0.3917, 0.7129, 0.2473, 0.5861)
_DOF = re.compile(r"(\d)\s*-?\s*(?:dof|d\.o\.f|axis|axes|joints?\b|link\b)|\b(\d)\s*-?\s*[rRpP]{0,1}\s*(?:arm|robot|"
                  r"manipulator)|\b([RP]{2,7})\b", re.IGNORECASE)


@dataclass(frozen=True)
class Section:
    heading: Heading | None
    line: int
    end_line: int


@dataclass
class Arm:
    robot: DHRobot | None
    info: ArmInfo
    problem: str = ""
    advice: str = ""
    data: dict | None = None  # the table as read (a robot file's dict), to rebuild the arm with lengths equated
    free: tuple[str, ...] = ()  # its lengths without a value (generic numbers stand in for them)
    gravity_assumed: bool = False  # masses read from the report's symbols: gravity along −y is our assumption
    wants_dof: int = 0  # no arm: the section's heading names an arm of this many joints (one may be recognised)


def _dof_named(title: str) -> int | None:
    m = _DOF.search(title)
    if not m:
        return None
    if m.group(3):
        return len(m.group(3))
    return int(m.group(1) or m.group(2))


_NO_VALUE = re.compile(r"parameter (\w{1,40}) has no value")


def _generic_values(names) -> dict[str, float]:
    """Distinct generic lengths for ``names``, in order."""
    n = len(GENERIC_LENGTHS)
    return {name: GENERIC_LENGTHS[k % n] * (1 + k // n) for k, name in enumerate(names)}


def _generic(robot: DHRobot, data: dict, notes: tuple[str, ...], where: str) -> tuple[DHRobot, list[str]]:
    """The table's robot with every parameter that had no value set to a distinct generic length."""
    missing = [m.group(1) for n in notes for m in [_NO_VALUE.search(n)] if m]
    if not missing:
        return robot, []
    params = {**data["parameters"], **_generic_values(missing)}
    return robot_from_dict({**data, "parameters": params}, where=where), missing


def _table_arm(doc: Document, first: int, last: int, source: str, title: str, end_line: int) -> Arm:
    text = "\n".join(doc.lines[first - 1:last])
    where = f"{source}: table at line {first}"
    try:
        imp = import_table(text, name=f"table-line-{first}", where=where)
        robot, free = _generic(imp.robot, imp.data, imp.notes, where)
    except DenavitError as exc:
        info = ArmInfo(f"table-line-{first}", title, first, end_line, f"table at lines {first}-{last}", "", 0)
        return Arm(None, info, f"the DH table at line {first} cannot be read: {exc}")
    notes = tuple(n for n in imp.notes if "set to 1" not in n)
    if free:
        notes += (f"{', '.join(free)} kept as symbols (no value in the table; numbers need them)",)
    info = ArmInfo(robot.name, title, first, end_line, f"table at lines {first}-{last}", robot.convention.value,
                   robot.dof, notes)
    return Arm(robot, info, data=imp.data, free=tuple(free))


def _with_masses(arm: Arm, maths: list[str]) -> Arm:
    """The table's arm with the lumped masses its part of the report writes (see :mod:`._masses`), or as it is."""
    if arm.robot is None or arm.data is None or arm.robot.has_dynamics:
        return arm
    names = names_written(maths)
    if not any(re.fullmatch(r"m\d", k) for k in names):
        return arm
    found = massed_arm_data(arm.data, arm.robot, names, moves_in_xy(arm.robot))
    robot = check_buildable(found[0], arm.info.source) if found else None
    if robot is None:
        return arm
    info = dataclasses.replace(arm.info, notes=arm.info.notes + (found[1],))
    added = tuple(k for k in found[0]["parameters"] if k not in arm.data["parameters"] and k not in arm.free)
    # the masses' names have stand-in values too: a report that gives them numbers (m_1 = 2) has them so after
    return Arm(robot, info, arm.problem, arm.advice, found[0], arm.free + added, gravity_assumed=True)


def _renamed(value: Any, word: re.Pattern, keep: str) -> Any:
    if isinstance(value, str):
        return word.sub(keep, value)
    if isinstance(value, dict):
        return {k: _renamed(v, word, keep) for k, v in value.items()}
    if isinstance(value, list):
        return [_renamed(v, word, keep) for v in value]
    return value


def with_equal_lengths(arm: Arm, names: list[str], where: str) -> Arm | None:
    """The arm with the table's value-less lengths ``names`` made one (``d_4 = a_2 = k``: the report's arm has
    d₄ = a₂): every entry naming one of them names the last instead, and the others are no parameters any more.
    None when fewer than two of ``names`` are such lengths (a length the table gives a value keeps it)."""
    same = [n for n in dict.fromkeys(names) if n in arm.free]
    if len(same) < 2 or arm.data is None:
        return None
    keep, gone = same[-1], same[:-1]
    word = re.compile(r"\b(" + "|".join(map(re.escape, gone)) + r")\b")
    joints = _renamed(arm.data["joints"], word, keep)
    params = {k: v for k, v in arm.data["parameters"].items() if k not in gone}
    data = {**arm.data, "joints": joints, "parameters": params}
    free = tuple(n for n in arm.free if n not in gone)
    values = _generic_values(free)
    robot = robot_from_dict({**data, "parameters": {**params, **values}}, where=where)
    return Arm(robot, arm.info, arm.problem, arm.advice, data, free, arm.gravity_assumed)


_LENGTH = re.compile(r"^\s*(-?\d{1,6}(?:\.\d{1,9})?)\s*(?:\\[,;:! ]\s*)*(?:\\(?:text|mathrm|rm)\s*\{\s*(m|cm|mm)\s*\}"
                     r"|(m|cm|mm)\b)?\s*[.,;]?\s*$")


def length_value(text: str) -> float | None:
    """``1``, ``0.8 m``, ``250\\,\\text{mm}`` → the number as written (1, 0.8, 250: the report's results are in
    its own unit, so no conversion); None for anything else (a formula, a name)."""
    m = _LENGTH.match(text)
    return float(m.group(1)) if m else None


def with_given_lengths(arm: Arm, names: list[str], value: float, where: str) -> Arm | None:
    """The arm with the table's value-less lengths ``names`` given ``value`` (``L_1 = L_2 = 1`` m: the report's
    numbers at a case use them); None when none of ``names`` is such a length."""
    given = [n for n in dict.fromkeys(names) if n in arm.free]
    if not given or arm.data is None:
        return None
    free = tuple(n for n in arm.free if n not in given)
    params = {**arm.data["parameters"], **{n: value for n in given}}
    data = {**arm.data, "parameters": params}
    robot = robot_from_dict({**data, "parameters": {**params, **_generic_values(free)}}, where=where)
    return Arm(robot, arm.info, arm.problem, arm.advice, data, free, arm.gravity_assumed)


def stated_lengths(arm: Arm, parts: tuple[str, ...], line: int) -> tuple[Arm, str, list[tuple[str, str]]] | None:
    """``d_4 = a_2 = k`` (the table's value-less lengths stated equal) or ``L_1 = L_2 = 1`` m (given a value): (the
    arm so, a note, the names now written as another) — judging with distinct generic values would call a right
    formula, or a right number at a case, wrong; None when the equation states nothing of the kind."""
    written = {re.sub(r"[^A-Za-z0-9]", "", re.sub(r"\s+", "", p)): p.strip() for p in parts[:-1]}
    value, where = length_value(parts[-1]), f"the equation at line {line}"
    new = with_given_lengths(arm, list(written), value, where) if value is not None else \
        with_equal_lengths(arm, list(written), where)
    if new is None:
        return None
    gone = [n for n in arm.free if n in written and n not in new.free]
    if value is not None:
        return new, (f"line {line}: {' = '.join(gone)} = {value:g} as the report states: the table's arm is read "
                     "with that value from there on (in the report's unit)"), []
    keep = next(n for n in reversed(list(written)) if n in new.free)
    return new, (f"line {line}: {', '.join(gone)} = {keep} as the report states: the table's arm is read with them "
                 "equal from there on"), [(written[n], written[keep]) for n in gone]


def _extent(h: Heading, heads: list[Heading], n: int) -> int:
    """The last line of the section heading ``h`` opens (until the next heading of its level or higher)."""
    later = [g.line for g in heads if g.line > h.line and g.level <= h.level]
    return (later[0] - 1) if later else n


def _check_given(heads: list[Heading], given: dict[str, DHRobot]) -> None:
    """Refuse an arm given for a section the report does not have (a typo was silently ignored, and the report
    judged against its own table as if ``--arm`` had not been given)."""
    keys = sorted(dict.fromkeys(h.key for h in heads if h.key), key=lambda k: (not k.isdigit(), len(k), k))
    for key in given:
        if key not in keys:
            have = f"its sections: {', '.join(keys[:20])}" if keys else "it has no section headings"
            raise ParseError(f"--arm {key[:40]}=...: the report has no section {key[:40]!r} ({have}; SECTION is a "
                             "heading's number)")


def arms_of(doc: Document, source: str, robot: DHRobot | None, given: dict[str, DHRobot],
            recognised: frozenset[str] = frozenset()) -> list[tuple[Section, Arm | None]]:
    """Spans of the report and the arm that governs each (None: no arm); the first span holding a line decides.

    Each table governs from the heading just before it (the first table from the top of the report) to the span of
    the next table; a section given with ``--arm`` takes that arm (``recognised``: the keys whose arm was not
    given but recognised from the section's results); a section whose heading names another number of joints
    and holds no table of its own gets none.
    """
    n = len(doc.lines)
    heads = [h for h in doc.items if isinstance(h, Heading)]
    _check_given(heads, given)
    tables = [t for t in find_tables(list(doc.lines)) if t[2] is None]
    base: list[tuple[int, Arm]] = []
    if robot is not None:
        base.append((1, Arm(robot, ArmInfo(robot.name, "", 1, n, f"ROBOT {robot.name}", robot.convention.value,
                                           robot.dof))))
    else:
        for i, (first, last, _) in enumerate(tables):
            before = [h for h in heads if h.line < first]
            start = before[-1].line if before and i > 0 else 1
            if i > 0:
                start = max(start, tables[i - 1][1] + 1)
            title = before[-1].title if before else ""
            base.append((start, _table_arm(doc, first, last, source, title, n)))
    spans: list[tuple[Section, Arm | None]] = []
    for h in heads:
        end = _extent(h, heads, n)
        if h.key in given:
            g = given[h.key]
            how = (f"catalogue arm its results fit (--arm {h.key}=ROBOT overrides)" if h.key in recognised
                   else f"--arm {h.key}={g.name}")
            spans.append((Section(h, h.line, end), Arm(g, ArmInfo(g.name, h.title, h.line, end, how,
                                                                    g.convention.value, g.dof))))
            continue
        current = next((arm for start, arm in reversed(base) if start <= h.line), None)
        named = _dof_named(h.title)
        has_table = any(h.line <= t[0] <= end for t in tables)
        if current is not None and current.robot is not None and named is not None and named != current.robot.dof \
                and not has_table:
            spans.append((Section(h, h.line, end), Arm(None, ArmInfo("", h.title, h.line, end, "none", "", 0),
                          f"the section at line {h.line} is about a {named}-joint arm and has no DH table of its own "
                          f"(give one: --arm {h.key or 'SECTION'}=ROBOT)",
                          _catalogue_advice(doc.lines[h.line - 1:end], named, h.key or "SECTION", h.line),
                          wants_dof=named)))
    spans.sort(key=lambda s: s[0].end_line - s[0].line)  # the most specific section decides
    for k, (start, arm) in enumerate(base):
        stop = base[k + 1][0] - 1 if k + 1 < len(base) else n
        maths = [it.latex for it in doc.items if isinstance(it, Math) and start <= it.line <= stop]
        spans.append((Section(None, start, stop), _with_masses(arm, maths)))
    return spans


_SYMBOL = re.compile(r"\b([A-Za-z]{1,3})\s?_?\{?(\d)\}?")


def _catalogue_advice(lines, dof: int, key: str, line: int) -> str:
    """The catalogue arms with ``dof`` joints whose parameters are the symbols a section writes (L_1, Lc_2, m_3,
    I_1 …), best first: a suggestion for ``--arm``, never applied (the user says which arm the section is about).
    """
    written = {a + b for a, b in _SYMBOL.findall("\n".join(lines))}
    scored = []
    for name in catalogue_names():
        robot = load_robot(name)
        shared = sorted({k for k, _ in robot.parameters} & written)
        if robot.dof == dof and len(shared) >= 2:
            scored.append((-len(shared), name, shared))
    if not scored:
        return ""
    best = sorted(scored)[:2]
    said = "; ".join(f"--arm {key}={name} (its parameters {', '.join(shared)} are symbols the section writes)"
                     for _, name, shared in best)
    return f"arms of the catalogue with {dof} joints that may fit the section at line {line}: {said}"


def compare_tables(doc: Document, robot: DHRobot, source: str) -> list[GradedClaim]:
    """The report's own DH tables against the arm given on the command line: the first finding.

    Two tables describe the same arm when they have the same joints (revolute/prismatic, in order) and the
    same end-effector pose T_0_N at random configurations (lengths the report leaves as symbols are compared
    structurally only: they have no value to compare).
    """
    import numpy as np

    from .. import numeric as N

    out = []
    for first, last, why in find_tables(list(doc.lines)):
        if why is not None:
            continue
        arm = _table_arm(doc, first, last, source, "", last)
        if arm.robot is None:
            out.append(GradedClaim(first, last, "dh_table", robot.name, "unreadable", arm.problem))
            continue
        mine, theirs = arm.robot, robot
        if mine.joint_types != theirs.joint_types:
            msg = (f"the report's table has joints {''.join(t.value[0].upper() for t in mine.joint_types)}, "
                   f"{robot.name} has {''.join(t.value[0].upper() for t in theirs.joint_types)}")
            out.append(GradedClaim(first, last, "dh_table", robot.name, "incorrect", msg, understood="the DH table"))
            continue
        if any("kept as symbols" in n for n in arm.info.notes):
            out.append(GradedClaim(first, last, "dh_table", robot.name, "ambiguous", "same joints as "
                                   f"{robot.name}; the table's lengths are symbols, so only its structure was "
                                   "compared", understood="the DH table"))
            continue
        rng = np.random.default_rng(0)
        q = rng.uniform(-np.pi, np.pi, (4, theirs.dof))
        same = np.allclose(N.forward_kinematics(mine, q), N.forward_kinematics(theirs, q), atol=1e-9)
        out.append(GradedClaim(first, last, "dh_table", robot.name, "correct" if same else "incorrect",
                               f"the same arm as {robot.name}" if same else
                               f"not the arm {robot.name}: its end-effector pose differs at the same joint values "
                               "(the verdicts below use ROBOT)", understood="the DH table"))
    return out
