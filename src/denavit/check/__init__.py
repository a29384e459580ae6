"""Checking a person's derivation: a claims file in, a verdict per claim out.

A claim names a quantity (a link transform, T_0_n, the end-effector position, a Jacobian or one of its
columns, a twist, joint torques, M or g), where it holds (``q``, ``qd``, ``wrench``, or everywhere when it is
a formula in the joint variables) and its value in LaTeX or plain mathematics.  See ``docs/claims.md``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DenavitError, ParseError
from ..model import DHRobot
from ._engine import Verdict, check_claim
from ._ik_claims import wrist_offset
from ._text import bracket_depths
from ._tokens import normalize
from ._latex import parse_math
from ._matrices import parse_matrix, split_matrix
from ._quantities import QUANTITIES
from ._resolve import robot_resolver

__all__ = ["CheckResult", "Verdict", "check_claims", "check_file", "verdicts_text", "parse_math", "parse_matrix",
           "split_matrix", "robot_resolver", "QUANTITIES", "MAX_CLAIMS", "MAX_SIGN_CHOICES", "MAX_SINGULAR_SETS", "MAX_DETAILED",
           "MAX_FILE_BYTES", "read_input_text", "wrist_offset",
           "bracket_depths", "normalize"]

#: Most claims in one file (a whole course report is a few hundred; 500 are judged in well under a minute).
MAX_CLAIMS = 500
#: Most ± sign choices in one file, over its ik_formula and singularities claims (a claim without ± is one choice;
#: each claim has at most 64).  Each choice is one evaluation of the claim (~7 ms on a 6-joint arm).
MAX_SIGN_CHOICES = 1024
#: Most different (rows, frame) of the singularities claims of one file: each is one symbolic singularity analysis
#: (up to check._singular.MAX_ANALYSIS_CPU_SECONDS of CPU each).
MAX_SINGULAR_SETS = 3
#: Incorrect claims that get the full explanation (tested hints, the correct formula); later ones get the verdict,
#: the differing entries and a counterexample only, so the work per file stays bounded.
MAX_DETAILED = 8
MAX_FILE_BYTES = 1_000_000
_SINGULAR = ("singularities", "singular_configurations", "singular")
_COSTLY = _SINGULAR + ("ik_formula", "ik_solutions")
_SIGNS = ("\\pm", "\\mp", "±", "∓")


def _sign_choices(claim: dict[str, Any]) -> int:
    """The ± choices of one claim as written (2 per sign, at most 64: a claim with more is refused by itself)."""
    text = str(claim.get("value", ""))[:100_000] + str(claim.get("where", ""))[:100_000]
    n = sum(text.count(s) for s in _SIGNS)
    return 2 ** n if n <= 6 else 1


@dataclass(frozen=True)
class CheckResult:
    """Verdicts on every claim of a file."""

    robot: str
    source: str
    verdicts: tuple[Verdict, ...]
    notes: tuple[str, ...] = ()

    def count(self, verdict: str) -> int:
        return sum(v.verdict == verdict for v in self.verdicts)

    def to_json(self) -> dict[str, Any]:
        return {"robot": self.robot, "claims_file": self.source, "notes": list(self.notes),
                "summary": {k: self.count(k) for k in ("correct", "incorrect", "ambiguous", "unreadable")
                            if k != "ambiguous" or self.count(k)},  # "ambiguous" only when some are
                "claims": [v.to_json() for v in self.verdicts]}


def check_claims(robot: DHRobot, claims: list[Any], *, seed: int = 0, deg: bool = False,
                 source: str = "<claims>") -> CheckResult:
    """Judge a list of claims (mappings as in a claims file) for ``robot``."""
    if not isinstance(claims, list):
        raise ParseError("'claims' must be a list of claims", where=source)
    if len(claims) > MAX_CLAIMS:
        raise ParseError(f"too many claims ({len(claims)}; at most {MAX_CLAIMS}: split the file)", where=source)
    choices = sum(_sign_choices(c) for c in claims if isinstance(c, dict) and str(c.get("quantity")) in _COSTLY)
    if choices > MAX_SIGN_CHOICES:
        raise ParseError(f"the ik_formula/singularities claims have {choices} ± sign choices together (at most "
                         f"{MAX_SIGN_CHOICES} in one file: split the file)", where=source)
    sets = {(str(c.get("rows", "all")), str(c.get("frame", "base"))) for c in claims
            if isinstance(c, dict) and str(c.get("quantity")) in _SINGULAR}
    if len(sets) > MAX_SINGULAR_SETS:
        raise ParseError(f"the singularities claims use {len(sets)} different rows/frame (at most {MAX_SINGULAR_SETS} "
                         "in one file, each is one symbolic analysis: split the file)", where=source)
    rng = np.random.default_rng(seed)
    verdicts, detailed, notes = [], 0, []
    for k, c in enumerate(claims, start=1):
        v = _judge(robot, c, f"claim {k}", rng, deg, detail=detailed < MAX_DETAILED)
        detailed += v.verdict == "incorrect"
        verdicts.append(v)
    if detailed > MAX_DETAILED:
        notes.append(f"hints and correct formulas are given for the first {MAX_DETAILED} incorrect claims only")
    return CheckResult(robot.name, source, tuple(verdicts), tuple(notes))


def _judge(robot: DHRobot, raw: Any, label: str, rng: np.random.Generator, deg: bool, detail: bool) -> Verdict:
    """One claim's verdict; a failure inside the checker is that claim's "unreadable" verdict, never the file's."""
    try:
        return check_claim(robot, raw, label, rng, deg, detail=detail)
    except Exception as exc:  # noqa: BLE001 - a bug of ours on one claim must not abort the file
        cid = str(raw.get("id", label))[:80] if isinstance(raw, dict) else label
        qname = str(raw.get("quantity", "?"))[:80] if isinstance(raw, dict) else "?"
        if isinstance(exc, DenavitError):
            return Verdict(cid, qname, "unreadable", f"could not be judged: {str(exc)[:300]}")
        return Verdict(cid, qname, "unreadable", f"could not be judged: the checker failed on it "
                       f"({type(exc).__name__}: {str(exc)[:200]}); please report this claim")


def read_input_text(path: Path, what: str, encoding: str = "utf-8") -> str:
    """The text of an input file (a claims file, a report), refused in one line when missing, not a regular file,
    over :data:`MAX_FILE_BYTES` or not UTF-8."""
    where = str(path)
    if not path.exists():
        raise ParseError(f"no such {what}: {where!r}")
    if not path.is_file():
        raise ParseError(f"the {what} {where!r} is not a regular file")
    if path.stat().st_size > MAX_FILE_BYTES:
        raise ParseError(f"{what} too large (at most {MAX_FILE_BYTES} bytes)", where=where)
    try:
        return path.read_bytes().decode(encoding)
    except UnicodeDecodeError as exc:
        raise ParseError(f"not UTF-8 text (byte {exc.start + 1})", where=where) from None


def check_file(robot: DHRobot, path: str | Path, *, seed: int = 0) -> CheckResult:
    """Read a YAML claims file (see ``docs/claims.md``) and judge its claims."""
    from ._yaml import load_claims_yaml

    path = Path(path)
    where = str(path)
    text = read_input_text(path, "claims file")
    data = load_claims_yaml(text, where)
    if isinstance(data, list):
        data = {"claims": data}
    if not isinstance(data, dict) or "claims" not in data:
        raise ParseError("a claims file is a mapping with a 'claims' list (see docs/claims.md)", where=where)
    unit = data.get("angle_unit", "rad")
    if unit not in ("rad", "deg"):
        raise ParseError(f"'angle_unit' must be rad or deg, got {str(unit)[:40]!r}", where=where)
    claims = data["claims"]
    if not isinstance(claims, list):
        raise ParseError("'claims' must be a list of claims", where=where)
    for k, c in enumerate(claims, start=1):
        if not isinstance(c, dict):
            raise ParseError(f"claim {k} is not a mapping (write '- quantity: …' then 'value: …' under it)",
                             where=where)
    result = check_claims(robot, claims, seed=seed, deg=unit == "deg", source=where)
    notes = list(result.notes)
    named = data.get("robot")
    if named is not None and str(named) != robot.name:
        notes.append(f"the claims file names robot {str(named)[:80]!r}; checked against {robot.name!r}")
    return CheckResult(result.robot, result.source, result.verdicts, tuple(notes))


def verdicts_text(result: CheckResult) -> str:
    """A readable summary, one block per claim."""
    lines = [f"{result.robot}: {result.count('correct')} correct, {result.count('incorrect')} incorrect, "
             f"{result.count('unreadable')} unreadable"
             + (f", {result.count('ambiguous')} ambiguous" if result.count("ambiguous") else "") + f" ({result.source})"]
    lines += [f"note: {n}" for n in result.notes]
    for v in result.verdicts:
        lines.append(f"\n[{v.verdict.upper()}] {v.id} ({v.quantity}): {v.message}")
        for e in v.entries[:12]:
            lines.append(f"  entry {tuple(e['entry'])}: claimed {e['claimed']:.6g}, expected {e['expected']:.6g}")
        if v.counterexample:
            cx = v.counterexample
            head = ("q = [" + ", ".join(f"{x:.6g}" for x in cx["q"]) + "]" if "q" in cx else
                    ", ".join(f"{k} = {x:.6g}" for k, x in cx.items() if isinstance(x, float)))
            lines.append("  counterexample: " + head
                         + (f", parameters {cx['parameters']}" if "parameters" in cx else "")
                         + "".join(f", {k} = {x:.6g}" for k, x in cx.get("symbols", {}).items()))
        lines += [f"  hint: {h}" for h in v.hints]
        if v.extra.get("expected_latex"):
            lines.append(f"  correct formula (LaTeX): {v.extra['expected_latex']}")
    return "\n".join(lines)
