"""How a report's left-hand side was read (the data type the readers build, apart from the functions that build
it: :mod:`._names` and :mod:`._names_dyn`).  Moved from ``_names.py`` (code unchanged)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

__all__ = ["Reading", "digit"]


@dataclass(frozen=True)
class Reading:
    """How a left-hand side was read: the claim keys, in words, other readings, and whether it is only a guess."""

    spec: dict[str, Any]
    understood: str
    alternatives: tuple[tuple[dict[str, Any], str], ...] = ()
    sure: bool = True
    needs: tuple[str, ...] = field(default=())  # "q" "qd" "wrench": context the claim takes when the value is numeric


def digit(t: str) -> int | None:
    t = re.sub(r"[{}\s]", "", t)
    return int(t) if t.isdigit() and len(t) <= 3 else None
