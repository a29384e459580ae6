"""From a report's equations to claims of the YAML claims format: one walk in reading order, carrying givens.

Every equation becomes a :class:`Pending`: a claim for :mod:`denavit.check` (with the context it needs: the case's
q, q̇, the wrench, names defined earlier) and the other readings of its left-hand side — or a verdict decided here
("not a claim" for a given or a definition, "unreadable" when no arm governs its section).  Singular
configurations stated over several lines ("θ₃ = 0° … θ₃ = 180° … and when L₂C₂ + L₃C₂₃ = 0") are one claim.
"""

from __future__ import annotations

import re
from typing import Any

from ._arms import Arm, length_value, stated_lengths
from ._prose import plain_prose, prose_case, prose_conditions, prose_definitions, prose_wrench
from ._context import (Context, case_of, has_joint_names, is_numeric, is_rate_name, is_wrench_name, joint_value,
                       rate_value, rates_or_wrench, vector_entries)
from ._document import Document, Heading, Math, Prose, joined_display, plain_names
from ._lhs import read_symbol
from ._masses import moves_in_xy
from ._names import joint_of, read_name
from ._reading import (define_chain, define_term, formula_leftover, joint_offset, names_product, only_names,
                       renumber, trailing_name, vector_reading)
from ._pending import (MANIPULABILITY, Pending, build_claim, det_pending, ik_formula_pending,
                       manipulability_pending, singular_pending)
from ._points import names_wrist_centre
from ._shorthand import define_name, rename_recent
from ._split import Equation, split_block
from ._target import (IK_HEADING, case_solution, is_target_part, matrix_target, prose_target, slide_formula,
                      solution_claim, target_words)
from ._values import wrench_symbols

__all__ = ["Pending", "walk"]

_IK_FUNCS = re.compile(r"atan|arctan|arccos|arcsin|sqrt|\\cos\^\{?-1|\\sin\^\{?-1|\\tan\^\{?-1|acos|asin|\\sqrt|[pP]_\{?[xyz]"
                       r"|r_\{?\d\d|[xyz]_[cw]|\\operatorname")
_TRIG_LHS = re.compile(r"^\\?(cos|sin|tan)\s*\(?\s*\\?(?:var)?(?:theta|q|Q)_\{?\d\}?\s*\)?$")
_SINGULAR = re.compile(r"singular|vanish|loses? rank|rank[- ]deficien|degenerat", re.I)
_MATRIX_QUANTITIES = ("dh_matrix", "link_transform", "transform", "end_effector")
_RELATION = re.compile(r"(?:J(?:_\{?\\?\w+\}?)?(?:\^\{?T\}?)?|\\mathbf\{J\}\^T)(?:F|\\mathbf\{F\}|\\dot\{?q\}?|"
                       r"\\dot\{?\\theta\}?|\\begin\{bmatrix\}f_E\\\\n_E\\end\{bmatrix\})")
_NAMED_RESULT = re.compile(r"(?:\{\}\s*\^\s*\{?\w{1,3}\}?\s*)?(?:\\mathbf\{)?J\}?(?:_|\^|\s|\\dot|$)")
_MORE_VALUES = re.compile(r"\$\s*([^$=]{1,60}?)\s*=\s*[^$=]{1,60}\$\s*(?:,|or|and)\s*\$\s*([^$=]{1,60}?)\s*\$")
_DET_OF_MATRIX = re.compile(r"\s*\\det\s*(?:\\left\s*)?[(\[|]?\s*\\begin\{[bpv]?matrix\}")
_CASE = re.compile(r"\bcase\s*\d", re.I)
_WRENCH_NAMES = re.compile(r"\b[fFnN]_\{?[xyz123456]")
_PROPAGATION = re.compile(r"\{\}\s*\^\s*\{?\s*\d\s*\}?\s*\\?(?:mathbf\{)?[fn]\}?\s*_")


class _Walker:
    def __init__(self, doc: Document, arms: list) -> None:
        self.doc, self.arms = doc, arms
        self.out: list[Pending] = []
        self.ctx = Context()
        self.sing: list[tuple[Equation, str]] = []
        self.sing_arm: Arm | None = None
        self.offsets: dict = {}
        self.equated: dict[int, Arm] = {}  # id of a section's arm → the arm with the lengths the report equates
        self.ctx_arm: Arm | None = None  # the arm of the last equation read
        self.notes: list[str] = []
        from ..tables import find_tables
        self.tables = [(a, b) for a, b, why in find_tables(list(doc.lines)) if why is None]

    def offset_of(self, line: int, arm: Arm | None) -> int:
        """How far the section's joint numbers are shifted (a wrist written θ4…θ6 for a 3-joint arm: 3)."""
        if arm is None or arm.robot is None:
            return 0
        for sec, a in self.arms:
            if sec.line <= line <= sec.end_line:
                key = (sec.line, id(a))
                if key not in self.offsets:
                    texts = [it.latex for it in self.doc.items if isinstance(it, Math)
                             and sec.line <= it.line <= sec.end_line]
                    self.offsets[key] = joint_offset(texts, arm.robot.dof)
                    if self.offsets[key]:
                        k = self.offsets[key]
                        self.notes.append(f"lines {sec.line}-{sec.end_line}: joints {k + 1}…{k + arm.robot.dof} "
                                          f"and frames {k}…{k + arm.robot.n_rows} of the report read as 1…"
                                          f"{arm.robot.dof} and 0…{arm.robot.n_rows} of {arm.info.name}")
                return self.offsets[key]
        return 0

    def in_table(self, line: int) -> bool:
        return any(a <= line <= b for a, b in self.tables)

    def arm_at(self, line: int) -> Arm | None:
        for sec, arm in self.arms:
            if sec.line <= line <= sec.end_line:
                return self.equated.get(id(arm), arm)
        return None

    def equate(self, eq: Equation, arm: Arm) -> None:
        """Lengths stated equal (``d_4 = a_2 = k``) or given a value (``L_1 = L_2 = 1`` m): the section's arm so
        from here on (:func:`._arms.stated_lengths`)."""
        found = stated_lengths(arm, eq.parts, eq.line)
        if found is not None:
            self.equated[id(next(a for sec, a in self.arms if sec.line <= eq.line <= sec.end_line))] = found[0]
            for name, value in found[2]:
                self.ctx.define(name, value)
            self.notes.append(found[1])

    def run(self) -> list[Pending]:
        items = list(self.doc.items)
        k = 0
        levels = [h.level for h in items if isinstance(h, Heading)]
        top = min(levels, default=1)
        if levels.count(top) == 1 and len(set(levels)) > 1:  # a title above the sections
            top = min(v for v in levels if v != top)
        while k < len(items):
            it = items[k]
            if isinstance(it, Heading):
                self.flush()
                self.ctx.singular, self.ctx.target = bool(_SINGULAR.search(it.title)), None
                if it.level <= top:  # a new part: its givens are its own; names defined stay while the arm does
                    same = self.ctx_arm is not None and self.arm_at(it.line) is self.ctx_arm
                    self.ctx = Context(singular=self.ctx.singular, where=dict(self.ctx.where) if same else {},
                                       p_wrist=self.ctx.p_wrist and same, cases=dict(self.ctx.cases) if same else {})
                elif _CASE.search(it.title):
                    self.ctx.q = None
                self.ctx.ik_section = bool(IK_HEADING.search(it.title))
            elif isinstance(it, Prose):
                self.prose(it)
            elif isinstance(it, Math) and not self.in_table(it.line):
                it, k = joined_display(items, k)
                self.math(it)
            k += 1
        self.flush()
        return self.out

    def prose(self, it: Prose) -> None:
        """Words that set the scene (a case, singular configurations) or state singular values in plain text."""
        plain = plain_prose(it.text)
        if _SINGULAR.search(it.text):
            self.ctx.singular = True
        arm = self.arm_at(it.line)
        robot = arm.robot if arm is not None else None
        case = _CASE.search(it.text)
        if case:
            number = re.sub(r"\D", "", case.group(0))
            self.ctx.q, self.ctx.partial, self.ctx.target = self.ctx.cases.get(number), {}, None
            self.ctx.case_number = number
            if robot is not None:
                q = prose_case(plain, robot)
                if q is not None:
                    self.ctx.q = self.ctx.cases[number] = q
        if robot is not None and (target := prose_target(it.text, robot.dof, self.ctx.ik_section)) is not None:
            self.ctx.target, self.ctx.target_line = target, it.line
        self.ctx.target_words_line = it.line if target_words(it.text) else self.ctx.target_words_line
        for name, value in prose_definitions(plain_names(plain)):
            self.ctx.define(name, value)
        w = prose_wrench(plain)
        if w is not None:
            self.ctx.wrench = w
        frame = re.search(r"\b(base|tool|gripper|end[- ]effector|world)\b[ -](?:frame|axes)", plain, re.I)
        if frame and re.search(r"\b(?:force|wrench|F)\b", plain):
            self.ctx.wrench_frame = "base" if frame.group(1).lower() in ("base", "world") else "tool"
        det = re.search(r"determinant (?:is |of |equal to )?\$([^$=]{1,400})\$", it.text)
        if det and robot is not None:
            eq = Equation(it.line, it.line, det.group(1), ("\\det J", det.group(1)), "=")
            self._det(eq, arm, det.group(1), None)
        if self.ctx.singular and robot is not None:
            for m in _MORE_VALUES.finditer(it.text):  # "$\theta_2 = 0$ or $\pi$": π is θ2's too
                cond = f"{m.group(1)} = {m.group(2)}"
                self.sing.append((Equation(it.line, it.line, cond, (cond,), "="), cond))
                self.sing_arm = arm
            for cond in prose_conditions(plain, robot):
                eq = Equation(it.line, it.line, cond, (cond,), "=")
                self.sing.append((eq, cond))
                self.sing_arm = arm

    def math(self, m: Math) -> None:
        arm = self.ctx_arm = self.arm_at(m.line)
        offset = self.offset_of(m.line, arm)
        latex = renumber(m.latex, offset, arm.robot.n_rows) if offset else m.latex
        eqs = split_block(latex, m.line, m.end_line)
        if len(eqs) == 1 and self._det_at_case(eqs[0], arm):
            return
        for eq in eqs:
            if len(eq.parts) < 2 or not eq.parts[0]:
                continue
            if _PROPAGATION.search(eq.parts[0]):
                self.ctx.propagation = True
            self.equation(eq, arm)

    def _det_at_case(self, eq: Equation, arm: Arm | None) -> bool:
        """``\\det J = 0`` alone, with a case in force: the claim that J is singular at that case."""
        if arm is None or arm.robot is None or not self.ctx.q or len(eq.parts) != 2 or eq.parts[1].strip() != "0":
            return False
        sym = read_symbol(eq.parts[0])
        if sym is None or not sym.det:
            return False
        self._det(eq, arm, "0", sym)
        self.out[-1].claim["q"] = self.ctx.q
        for alt, _ in self.out[-1].equivalent:
            alt["q"] = self.ctx.q
        return True

    def note(self, eq: Equation, arm: Arm | None, verdict: str, message: str, quantity: str = "") -> None:
        self.out.append(Pending(eq.line, eq.end_line, eq.text, arm, verdict=verdict, message=message,
                                quantity=quantity))

    def equation(self, eq: Equation, arm: Arm | None) -> None:
        if arm is None or arm.robot is None:
            why = arm.problem if arm is not None else "no DH table governs this part of the report (give ROBOT, or " \
                "--arm SECTION=ROBOT)"
            if self.givens(eq, None):
                return
            self.note(eq, arm, "unreadable", f"not judged: {why}")
            return
        if wrench_symbols(eq.text):
            self.ctx.wrench_texts.append(eq.text[:2000])
        head = read_symbol(eq.parts[0])
        if head is not None and head.det and eq.parts[-1].strip() == "0":
            self.ctx.singular = True  # "det J = … = 0 ⇒ θ2 = 0, π": what follows are singular values
        if self.givens(eq, arm):
            return
        if self.ctx.singular and self.condition(eq, arm):
            return
        self.flush()
        self.result(eq, arm)

    def givens(self, eq: Equation, arm: Arm | None) -> bool:
        """A case's q, rates, a wrench: remembered, and the equation is "not a claim"."""
        robot = arm.robot if arm is not None else None
        lhs, last = eq.parts[0], eq.parts[-1]
        if is_target_part(self.ctx, eq.line, lhs):
            self.note(eq, arm, "not a claim", "the target of the inverse kinematics", "given: target")
            return True
        if robot is not None and (target := matrix_target(self.ctx, eq.parts, eq.line)) is not None:
            self.ctx.target, self.ctx.target_line = target, eq.line
            self.note(eq, arm, "not a claim", "the target of the inverse kinematics (a pose)", "given: target")
            return True
        q = case_of(eq.parts, eq.text, robot) if robot is not None else None
        if q is not None:
            self.ctx.q, self.ctx.partial = q, {}
            if (claim := case_solution(self.ctx, eq.parts[1])) is not None:  # a whole q after a target
                self.out.append(Pending(eq.line, eq.end_line, eq.text, arm, claim, "joint values that reach the "
                                        "target", quantity="ik_solutions"))
            if self.ctx.case_number:
                self.ctx.cases[self.ctx.case_number] = q
            self.note(eq, arm, "not a claim", "the configuration of this case (used for the numeric results "
                      "below)", "given: q")
            return True
        vec = vector_entries(last)
        if vec and all(is_numeric(v) for v in vec) and is_rate_name(lhs):
            self.ctx.qd = "[" + ", ".join(vec) + "]"
            self.note(eq, arm, "not a claim", "the joint rates of this case", "given: q̇")
            return True
        if vec and is_wrench_name(lhs) and len(vec) in (2, 3, 6):
            self.ctx.wrench = "[" + ", ".join(vec + ["0"] * (len(vec) == 2)) + "]"  # (f_x, f_y): in the plane
            planar = " (f_x, f_y; f_z = 0)" * (len(vec) == 2)
            self.note(eq, arm, "not a claim", "the wrench at the end effector" + planar, "given: wrench")
            return True
        for part in eq.parts[1:]:
            rw = rates_or_wrench(part)
            if rw is not None:
                if rw[0] == "JT" or "tau" in lhs:
                    self.ctx.wrench = rw[1]
                else:
                    self.ctx.qd = rw[1]
        if robot is not None and not self.ctx.singular:
            sym = read_symbol(lhs)
            jv = joint_value(sym, last, robot) if sym is not None and len(eq.parts) == 2 else None
            if jv is not None:
                self.ctx.partial[jv[0]] = f"q_{jv[0]} = {jv[1]}"
                if len(self.ctx.partial) == robot.dof:
                    self.ctx.q = ", ".join(self.ctx.partial[k] for k in sorted(self.ctx.partial))
                    if self.ctx.target is not None:  # joint values after a target: a solution claimed
                        self.out.append(Pending(eq.line, eq.end_line, eq.text, arm, solution_claim(
                            self.ctx, self.ctx.partial), "joint values that reach the target", quantity="ik_solutions"))
                self.note(eq, arm, "not a claim", f"a given joint value (θ{jv[0]})", "given: q")
                return True
            rv = rate_value(sym, last, robot) if sym is not None and len(eq.parts) == 2 else None
            if rv is not None:  # θ̇1 = 0.1, θ̇2 = 0.2: the rates, once all are given
                self.ctx.partial_rates[rv[0]] = rv[1]
                if len(self.ctx.partial_rates) == robot.dof:
                    self.ctx.qd = "[" + ", ".join(v for _, v in sorted(self.ctx.partial_rates.items())) + "]"
                self.note(eq, arm, "not a claim", f"a given joint rate (θ̇{rv[0]})", "given: q̇")
                return True
        return False

    def condition(self, eq: Equation, arm: Arm) -> bool:
        """A singular condition (``θ₂ = 0°, 180°``, ``s₂ = 0``, ``L₂C₂ + L₃C₂₃ = 0``) joins the current group."""
        lhs, last = eq.parts[0], eq.parts[-1]
        sym = read_symbol(lhs)
        if sym is not None and sym.det:
            if len(eq.parts) > 2 and last.strip() == "0":
                self._det(eq, arm, eq.parts[-2], sym)
            elif last.strip() != "0":
                self._det(eq, arm, last, sym)
            return True
        if lhs.strip().startswith("\\begin{vmatrix}") or lhs.strip().startswith("|"):
            if len(eq.parts) > 2:
                self._det(eq, arm, eq.parts[-2] if last.strip() == "0" else last, None)
                if "\\begin" not in eq.parts[-2]:
                    self.sing.append((eq, f"{eq.parts[-2]} = 0"))
            else:
                self._det(eq, arm, last, None)
            self.sing_arm = arm
            return True
        joint = joint_of(sym, arm.robot) if sym is not None else None
        if joint is not None and not _IK_FUNCS.search(last):
            self.sing.append((eq, f"{lhs} = {', '.join(eq.parts[1:])}"))
            self.sing_arm = arm
            return True
        if last.strip() == "0" and has_joint_names(lhs) and (sym is None or read_name(sym, arm.robot) is None):
            self.sing.append((eq, f"{lhs} = 0"))
            self.sing_arm = arm
            return True
        return False

    def _det(self, eq: Equation, arm: Arm, value: str, sym: Any) -> None:
        self.out.append(det_pending(eq, arm, value, sym))

    def flush(self) -> None:
        """The singular conditions collected so far, as one claim."""
        if self.sing:
            self.out.append(singular_pending(self.sing, self.sing_arm))
        self.sing, self.sing_arm = [], None

    def result(self, eq: Equation, arm: Arm) -> None:
        robot = arm.robot
        lhs, value = eq.parts[0], eq.parts[-1]
        if len(eq.parts) > 2 and _NAMED_RESULT.search(value) and "\\begin" not in value:
            value = eq.parts[-2]  # "ν = [M][q̇] = {}^0J q̇": the value is the step before the restated relation
        also = trailing_name(eq.parts, robot)
        if also is not None:
            value = eq.parts[-2]  # "²f₂ = ²R₃ ³f₃ = [⋯] = ¹f₁": the value is claimed for both names
        elif len(eq.parts) > 2 and "\\begin" in eq.parts[-2] and only_names(value):
            value = eq.parts[-2]  # "⁴v₄ = [⋯] = S v_s": names after the matrix, not a value: the matrix is judged
        sym = read_symbol(lhs)
        last = read_symbol(value)
        if len(eq.parts) == 2 and last is not None and joint_of(last, robot) is not None and _IK_FUNCS.search(lhs):
            lhs, value, sym = value, lhs, last  # "\arctan(P_y, P_x) = q_1"
        if len(eq.parts) >= 3 or (len(eq.parts) == 2 and length_value(eq.parts[1]) is not None):
            self.equate(eq, arm)
        if len(eq.parts) >= 2 and define_chain(self.ctx, eq.parts, robot):
            self.note(eq, arm, "not a claim", "a name the derivation introduces")
            return
        if (sym is not None and joint_of(sym, robot) is not None) or _TRIG_LHS.match(lhs.replace(" ", "")):
            heading = re.search(r"\\(?:var)?phi\b", value) and moves_in_xy(robot)  # θ₃ = φ − θ₁ − θ₂ (planar)
            if (_IK_FUNCS.search(value) or heading or slide_formula(sym, robot, value)) and len(eq.parts) == 2:
                self.out.append(ik_formula_pending(self.ctx, eq, arm, lhs, value))
            else:
                self.note(eq, arm, "not a claim", f"not judged: {lhs} = … is an intermediate step, not a formula for "
                          "the joint in terms of the target")
            return
        manip = next((m for part in eq.parts[:-1] if (m := MANIPULABILITY.search(part))), None)
        if manip is not None and len(eq.parts) > 2:
            self.out.append(manipulability_pending(eq, arm, value, manip.group(1)))
            return
        if _DET_OF_MATRIX.match(lhs) and "\\begin" not in value:  # det [the rows of J written out] = −d_2
            return self._det(eq, arm, value, None)
        reading = read_name(sym, robot, value) if sym is not None else vector_reading(lhs, robot)
        if reading is not None and reading.spec.get("quantity") == "det_jacobian":
            self._det(eq, arm, value, sym)
            return
        if reading is not None and reading.spec.get("quantity") in _MATRIX_QUANTITIES and "\\begin" not in value \
                and "[" not in value:
            self.note(eq, arm, "not a claim", "a definition (a transform written as named motions, not as a "
                      "matrix)", reading.spec["quantity"])
            return
        product = reading is not None and names_product(value)
        left = formula_leftover(value) if reading is not None else None  # "" for a formula in other results
        if reading is not None and (product or left == "" or _RELATION.fullmatch(value.replace(" ", ""))):
            if reading.spec["quantity"] in ("torques", "twist", "jacobian"):
                claim = {"quantity": "relation", "value": eq.text}
                p = Pending(eq.line, eq.end_line, eq.text, arm, claim, "a relation between the arm's quantities",
                            quantity="relation")
                p.not_a_claim_if_unreadable = True
                self.out.append(p)
                return
            what = "the product of other results" if product else "a formula in other results"
            self.note(eq, arm, "not a claim", f"a definition: {what}", reading.spec["quantity"])
            return
        if left and re.fullmatch(r"\\[A-Za-z]{1,12}", left):
            self.note(eq, arm, "unreadable", f"a formula in other results with '{left}' where an operator (×, ·, +) "
                      "belongs: not judged", reading.spec["quantity"])
            return
        if reading is None:
            if define_name(self.ctx, sym, lhs, value, eq.parts, {k for k, _ in robot.parameters}):
                rename_recent(self.out, self.ctx, eq.line)  # "… where c_{124} = \cos(θ1 + θ2 − θ4)"
            self.note(eq, arm, "not a claim", f"not judged: {lhs[:60]} names no result denavit checks (a definition "
                      "or an intermediate step)")
            return
        self.out.append(build_claim(self.ctx, eq, arm, reading, value))
        define_term(self.ctx, lhs, value, reading.spec["quantity"])
        self.ctx.p_wrist = self.ctx.p_wrist or names_wrist_centre(eq.parts, reading.spec, robot)
        if value is not eq.parts[-1] and also is None and "\\begin" in value and "\\begin" not in eq.parts[-1]:
            self.out[-1].understood += f" (the matrix before '= {eq.parts[-1].strip()[:40]}')"
        if also is not None:
            self.out.append(build_claim(self.ctx, eq, arm, also, value))


def walk(doc: Document, arms: list) -> tuple[list[Pending], list[str]]:
    """Every equation of ``doc`` as a :class:`Pending`, in reading order, and notes on how it was read."""
    w = _Walker(doc, arms)
    return w.run(), w.notes
