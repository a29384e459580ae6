"""Reading untrusted YAML, JSON and TOML text into plain data, safely (robot files, claims files).

``yaml.safe_load`` builds no objects, yet an untrusted file can still nest a thousand levels deep (a
RecursionError in the parsers), use aliases to expand a few hundred bytes into billions of entries (the
"billion laughs"), write an integer of 5,000 digits (a ValueError in ``int``), repeat a key (silently keeping
the last value) or smuggle a lone surrogate into a JSON string.  :func:`load_data` refuses each of these
with one :class:`~denavit.errors.ParseError` naming the file (and the line where the parser knows it).
"""

from __future__ import annotations

import functools
import json
import re
from typing import Any

from .errors import ParseError

__all__ = ["load_data", "MAX_NESTING", "MAX_EXPANDED", "MAX_INT_DIGITS", "MAX_TEXT_BYTES"]

#: Largest text read (bytes of a robot file; a 32-joint arm with inertial data is about 10 kB).
MAX_TEXT_BYTES = 256_000
#: Deepest nesting of lists and mappings (a robot file needs 6).
MAX_NESTING = 20
#: Size of the data with every YAML alias expanded: entries plus characters of text, at most this.
MAX_EXPANDED = 2 * MAX_TEXT_BYTES
#: Most digits of an integer written in a file (larger values are refused by the magnitude bounds anyway).
MAX_INT_DIGITS = 100


def load_data(text: str, suffix: str, where: str, *, max_nesting: int = MAX_NESTING,
              max_expanded: int = MAX_EXPANDED, max_int_digits: int = MAX_INT_DIGITS,
              max_entries: int | None = None) -> Any:
    """The plain data of an untrusted YAML, JSON or TOML text, read safely.

    Refused with a :class:`ParseError` naming ``where``: nesting deeper than :data:`MAX_NESTING`; YAML whose
    aliases expand to more than :data:`MAX_EXPANDED` (entries plus characters; the "billion laughs") or that
    refer to themselves; a key given twice in one mapping (YAML and JSON; TOML refuses it itself); integers
    longer than :data:`MAX_INT_DIGITS` digits; strings that are not valid Unicode (a JSON lone surrogate).
    The bounds are the robot file's by default; other untrusted files (claims) pass their own, and may also
    bound the number of entries (lists, mappings, scalars; aliases expanded) with ``max_entries``.

    Parameters
    ----------
    text : str
        The file's text.
    suffix : str
        ``".json"``, ``".toml"``, else YAML.
    where : str
        The file name, for error messages.
    """
    fmt = {".json": "JSON", ".toml": "TOML"}.get(suffix.lower(), "YAML")
    try:
        if fmt == "YAML":
            data = _load_yaml(text, max_nesting, max_expanded, max_int_digits, max_entries or max_expanded)
        else:
            depth = _bracket_depth(text, fmt)
            if depth > max_nesting:
                raise ParseError(f"nested more than {max_nesting} levels deep")
            data = _load_json(text, max_int_digits) if fmt == "JSON" else _load_toml(text, max_int_digits)
        _check_data(data, max_nesting, min(max_expanded, max_entries or max_expanded))
    except ParseError as exc:
        raise ParseError(f"{fmt}: {exc}" if fmt not in str(exc) else str(exc), where=where) from None
    except RecursionError:
        raise ParseError(f"{fmt}: nested too deeply (at most {max_nesting} levels)", where=where) from None
    except (ValueError, OverflowError, TypeError) as exc:  # a scalar the parser's converters cannot read
        raise ParseError(f"unreadable {fmt} ({' '.join(str(exc).split())[:120]})", where=where) from None
    return data


def _load_json(text: str, max_int_digits: int) -> Any:
    def pairs(items: list[tuple[str, Any]]) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for key, value in items:
            if key in out:
                raise ParseError(f"key {key[:40]!r} given twice in one JSON object")
            out[key] = value
        return out

    def integer(digits: str) -> int:
        if len(digits.lstrip("-")) > max_int_digits:
            raise ParseError(f"an integer with more than {max_int_digits} digits")
        return int(digits)

    try:
        return json.loads(text, object_pairs_hook=pairs, parse_int=integer)
    except json.JSONDecodeError as exc:
        raise ParseError(f"malformed JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}") from None


def _load_toml(text: str, max_int_digits: int) -> Any:
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib  # type: ignore[no-redef]
    for m in re.finditer(r"(?<![\w.])[+-]?\d[\d_]*", text):
        if len(m.group().replace("_", "").lstrip("+-")) > max_int_digits:
            raise ParseError(f"a number with more than {max_int_digits} digits")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParseError(f"malformed TOML: {' '.join(str(exc).split())}") from None


_BRACKETS = {
    "JSON": re.compile(r'"(?:[^"\\]|\\.)*"?|[\[\]{}]'),
    "TOML": re.compile(r'"""[\s\S]*?(?:"""|$)|\'\'\'[\s\S]*?(?:\'\'\'|$)|"(?:[^"\\\n]|\\.)*"?|\'[^\'\n]*\'?|#[^\n]*|[\[\]{}]'),
}


def _bracket_depth(text: str, fmt: str) -> int:
    """The deepest nesting of brackets outside strings and comments (one linear scan, before parsing)."""
    depth = deepest = 0
    for m in _BRACKETS[fmt].finditer(text):
        ch = m.group()
        if ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in "]}":
            depth -= 1
    return deepest


@functools.lru_cache(maxsize=4)
def _yaml_loader(max_int_digits: int) -> type:
    import yaml

    base = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml when present: about 20 times faster

    class Loader(base):  # type: ignore[misc, valid-type]
        """A safe loader that checks integers and refuses duplicate keys (depth and size are checked before)."""

        def construct_yaml_int(self, node):  # type: ignore[override]
            if sum(ch.isdigit() for ch in str(node.value)) > max_int_digits:
                raise ParseError(f"YAML: an integer with more than {max_int_digits} digits (line {node.start_mark.line + 1})")
            return super().construct_yaml_int(node)

        def construct_mapping(self, node, deep=False):  # type: ignore[override]
            seen: dict[Any, int] = {}
            for key_node, _ in node.value:
                if isinstance(key_node, yaml.ScalarNode) and key_node.tag != "tag:yaml.org,2002:merge":
                    key = self.construct_object(key_node)
                    try:
                        twice = key in seen
                    except TypeError:  # unhashable: the base class says so
                        continue
                    if twice:
                        raise ParseError(f"YAML: key {str(key)[:40]!r} given twice (lines {seen[key]} and "
                                         f"{key_node.start_mark.line + 1})")
                    seen[key] = key_node.start_mark.line + 1
            return super().construct_mapping(node, deep=deep)

    Loader.add_constructor("tag:yaml.org,2002:int", Loader.construct_yaml_int)
    return Loader


def _load_yaml(text: str, max_nesting: int, max_expanded: int, max_int_digits: int, max_entries: int) -> Any:
    import yaml

    try:
        _check_yaml_events(text, max_nesting, max_expanded, max_entries)
        return yaml.load(text, Loader=_yaml_loader(max_int_digits))  # noqa: S506 - a SafeLoader subclass
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or "syntax error"
        if "nesting depth" in str(problem):  # libyaml's own bound (1,000 levels) met before ours in the events
            raise ParseError(f"YAML nested more than {max_nesting} levels deep{at.replace(' at', ' (') + ')' if at else ''}") from None
        raise ParseError(f"malformed YAML{at}: {' '.join(str(problem).split())[:120]}") from None


def _check_yaml_events(text: str, max_nesting: int, max_expanded: int, max_entries: int) -> None:
    """Depth, size with every alias expanded (entries plus characters) and aliases that contain themselves,
    from the parser's events: one linear pass that builds nothing, so a "billion laughs" costs its own size."""
    import yaml

    depth, expanded, entries = 0, 0, 0
    stack: list[list[Any]] = []  # [anchor, size, entries] of the open lists and mappings
    sizes: dict[str, tuple[int, int]] = {}  # anchor -> (size, entries) of its node, aliases expanded
    parser = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    for ev in yaml.parse(text, Loader=parser):
        if isinstance(ev, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
            depth += 1
            if depth > max_nesting:
                raise ParseError(f"YAML nested more than {max_nesting} levels deep (line {ev.start_mark.line + 1})")
            stack.append([ev.anchor, 1, 1])
            n = e = 1
        elif isinstance(ev, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
            depth -= 1
            anchor, size, count = stack.pop()
            if anchor is not None:
                sizes[anchor] = (size, count)
            if stack:
                stack[-1][1] += size
                stack[-1][2] += count
            continue
        elif isinstance(ev, yaml.ScalarEvent):
            n, e = 1 + len(ev.value), 1
            if ev.anchor is not None:
                sizes[ev.anchor] = (n, e)
        elif isinstance(ev, yaml.AliasEvent):
            if any(item[0] == ev.anchor for item in stack):
                raise ParseError("YAML: an alias refers to a list or mapping that contains it (a recursive structure)")
            n, e = sizes.get(ev.anchor, (1, 1))
        else:
            continue
        expanded += n
        entries += e
        if expanded > max_expanded:
            raise ParseError(f"YAML too large once its aliases are expanded (more than {max_expanded} "
                             "entries and characters)")
        if entries > max_entries:
            raise ParseError(f"more than {max_entries} entries once its aliases are expanded (split the file)")
        if stack and not isinstance(ev, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
            stack[-1][1] += n
            stack[-1][2] += e


def _check_data(data: Any, max_nesting: int, max_expanded: int) -> None:
    """Depth, size and Unicode checks on loaded plain data (iterative, so deep data cannot overflow the stack)."""
    stack: list[tuple[Any, int]] = [(data, 1)]
    count = 0
    while stack:
        value, depth = stack.pop()
        count += 1
        if depth > max_nesting:
            raise ParseError(f"nested more than {max_nesting} levels deep")
        if count > max_expanded:
            raise ParseError(f"more than {max_expanded} entries")
        if isinstance(value, str):
            try:
                value.encode("utf-8")
            except UnicodeEncodeError:
                raise ParseError(f"a string is not valid Unicode (a lone surrogate?): {value[:40]!r}") from None
        elif isinstance(value, dict):
            stack.extend((k, depth + 1) for k in value)
            stack.extend((v, depth + 1) for v in value.values())
        elif isinstance(value, (list, tuple)):
            stack.extend((v, depth + 1) for v in value)
