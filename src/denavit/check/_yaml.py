"""Reading a claims file's YAML safely: the project's one safe loader (``denavit.io.load_data``), with the
claims file's own bounds.

An untrusted file can nest a thousand levels deep, use aliases to expand a few hundred bytes into millions of
entries (the "billion laughs"), repeat a key or write an integer of thousands of digits; ``load_data`` refuses
each with one :class:`~denavit.errors.ParseError` naming the file and line, before anything is built.
"""

from __future__ import annotations

from typing import Any

__all__ = ["load_claims_yaml", "MAX_YAML_DEPTH", "MAX_YAML_NODES", "MAX_YAML_EXPANDED", "MAX_INT_DIGITS"]

#: Deepest nesting of lists and mappings in a claims file.
MAX_YAML_DEPTH = 40
#: Most YAML nodes (scalars, lists, mappings) in a claims file, counting every use of an alias in full (100 claims
#: of 6x64 entries are about 40 000).
MAX_YAML_NODES = 50_000
#: Size of a claims file with every alias expanded: entries plus characters (the file itself is at most 1 MB;
#: 100 claims of 6x64 entries are well inside).
MAX_YAML_EXPANDED = 2_000_000
#: Most digits of an integer written in a claims file.
MAX_INT_DIGITS = 40


def load_claims_yaml(text: str, where: str) -> Any:
    """The data of a claims file's text; ParseError naming ``where`` if refused."""
    from ..io import load_data

    return load_data(text, ".yaml", where, max_nesting=MAX_YAML_DEPTH, max_expanded=MAX_YAML_EXPANDED,
                     max_int_digits=MAX_INT_DIGITS, max_entries=MAX_YAML_NODES)
