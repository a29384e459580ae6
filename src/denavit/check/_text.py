"""Small text helpers for claims written as relations: top-level splitting and ± expansion.

Only slicing and joining of the person's text happens here; the pieces are then read by the restricted
reader (:mod:`denavit.check._latex`).
"""

from __future__ import annotations

import itertools
import re

from ..errors import ParseError

__all__ = ["bracket_depths", "split_top", "split_relation", "expand_pm", "after_last_equals", "strip_equation_number", "MAX_SIGN_COMBOS"]

MAX_SIGN_COMBOS = 64
_OPENERS, _CLOSERS = "({[", ")}]"


def bracket_depths(text: str, env: re.Pattern | None = None, clamp: bool = False, start: int = 0):
    """Yield ``(index, depth)`` for every character of ``text`` from ``start``: the depth after it in brackets,
    braces and (``env``: a pattern of ``\\begin{…}``/``\\end{…}`` with the word in group 1) environments, whose
    own characters count at least 1 deep.  ``clamp``: a closer too many leaves the depth at 0 (else it goes below).
    The one bracket walker of the checker and the report reader."""
    depth, k = 0, start
    while k < len(text):
        m = env.match(text, k) if env is not None and text[k] == "\\" else None
        if m:
            depth += 1 if m.group(1) == "begin" else -1
            for j in range(k, m.end()):
                yield j, max(depth, 1)
            k = m.end()
            continue
        ch = text[k]
        if ch in _OPENERS:
            depth += 1
        elif ch in _CLOSERS:
            depth = max(depth - 1, 0) if clamp else depth - 1
        yield k, depth
        k += 1


def split_top(text: str, seps: tuple[str, ...]) -> list[str]:
    """Split ``text`` at any of ``seps`` that stand outside brackets and braces."""
    out, start, skip_to = [], 0, 0
    for k, depth in bracket_depths(text):
        if k < skip_to or depth:
            continue
        sep = next((s for s in seps if text.startswith(s, k)), None)
        if sep is not None:
            out.append(text[start:k])
            start = skip_to = k + len(sep)
    out.append(text[start:])
    return out


def split_relation(text: str) -> tuple[str, str]:
    """``lhs = rhs`` → (lhs, rhs); exactly one top-level ``=`` is required."""
    parts = split_top(text, ("=",))
    if len(parts) != 2 or not parts[0].strip() or not parts[1].strip():
        raise ParseError(f"expected one relation 'left = right', got {text.strip()[:60]!r}")
    return parts[0].strip(), parts[1].strip()


_PM = re.compile(r"\\pm(?![A-Za-z])|±|\\mp(?![A-Za-z])|∓")


def expand_pm(texts: list[str]) -> list[list[str]]:
    """Every choice of the ± signs in ``texts`` (jointly): a list of versions of ``texts``.

    Each ``\\pm``/``±`` is an independent sign; each ``\\mp``/``∓`` takes the opposite of the first ±.
    """
    marks = [(i, m) for i, t in enumerate(texts) for m in _PM.finditer(t)]
    n_pm = sum(1 for _, m in marks if m.group(0) in ("\\pm", "±"))
    n_free = n_pm if n_pm else sum(1 for _ in marks)
    if 2 ** n_free > MAX_SIGN_COMBOS:
        raise ParseError(f"too many ± signs ({n_free}; at most {MAX_SIGN_COMBOS.bit_length() - 1})")
    versions = []
    for signs in itertools.product("+-", repeat=n_free):
        out = list(texts)
        per_text: dict[int, list] = {}
        order = 0
        for i, m in marks:
            is_pm = m.group(0) in ("\\pm", "±") or not n_pm
            if is_pm:
                sign = signs[order] if order < n_free else "+"
                order += 1
            else:
                sign = "-" if signs[0] == "+" else "+"
            per_text.setdefault(i, []).append((m.start(), m.end(), sign))
        for i, reps in per_text.items():
            t = out[i]
            for a, b, sign in sorted(reps, reverse=True):
                t = t[:a] + f" {sign} " + t[b:]
            out[i] = t  # replaced from the right, so earlier positions stay valid
        versions.append(out)
    return versions


_ENV = re.compile(r"\\(begin|end)\{(?:[bBpvV]?matrix|array|smallmatrix)\*?\}")  # not split/aligned: an = there counts


def after_last_equals(text: str) -> str:
    """What follows the last ``=`` outside brackets and matrix environments (``J = [\\begin…] = \\begin…``)."""
    cut = max((k for k, depth in bracket_depths(text, _ENV) if depth == 0 and text[k] == "="), default=-1)
    return text[cut + 1:] if cut >= 0 else text


_EQ_NUMBER = re.compile(r"(?:\\q?quad\s*\(\s*\d{1,6}[a-z]?\s*\)|\\tag\*?\{[^{}]{0,40}\})\s*$")


def strip_equation_number(text: str) -> str:
    """``… \\quad (11)`` or ``… \\tag{11}`` at the end: the report's equation number, not a factor 11."""
    return _EQ_NUMBER.sub("", text.strip().strip("$").strip())
