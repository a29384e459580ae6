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


def load_data(text: str, suffix: str, where: str) -> Any:
    """The plain data of an untrusted YAML, JSON or TOML text, read safely.

    Refused with a :class:`ParseError` naming ``where``: nesting deeper than :data:`MAX_NESTING`; YAML whose
    aliases expand to more than :data:`MAX_EXPANDED` (entries plus characters; the "billion laughs") or that
    refer to themselves; a key given twice in one mapping (YAML and JSON; TOML refuses it itself); integers
    longer than :data:`MAX_INT_DIGITS` digits; strings that are not valid Unicode (a JSON lone surrogate).

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
            data = _load_yaml(text)
        else:
            depth = _bracket_depth(text, fmt)
            if depth > MAX_NESTING:
                raise ParseError(f"nested more than {MAX_NESTING} levels deep")
            data = _load_json(text) if fmt == "JSON" else _load_toml(text)
        _check_data(data)
    except ParseError as exc:
        raise ParseError(f"{fmt}: {exc}" if fmt not in str(exc) else str(exc), where=where) from None
    except RecursionError:
        raise ParseError(f"{fmt}: nested too deeply (at most {MAX_NESTING} levels)", where=where) from None
    except (ValueError, OverflowError, TypeError) as exc:  # a scalar the parser's converters cannot read
        raise ParseError(f"unreadable {fmt} ({' '.join(str(exc).split())[:120]})", where=where) from None
    return data


def _load_json(text: str) -> Any:
    def pairs(items: list[tuple[str, Any]]) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for key, value in items:
            if key in out:
                raise ParseError(f"key {key[:40]!r} given twice in one JSON object")
            out[key] = value
        return out

    def integer(digits: str) -> int:
        if len(digits.lstrip("-")) > MAX_INT_DIGITS:
            raise ParseError(f"an integer with more than {MAX_INT_DIGITS} digits")
        return int(digits)

    try:
        return json.loads(text, object_pairs_hook=pairs, parse_int=integer)
    except json.JSONDecodeError as exc:
        raise ParseError(f"malformed JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}") from None


def _load_toml(text: str) -> Any:
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib  # type: ignore[no-redef]
    for m in re.finditer(r"(?<![\w.])[+-]?\d[\d_]*", text):
        if len(m.group().replace("_", "").lstrip("+-")) > MAX_INT_DIGITS:
            raise ParseError(f"a number with more than {MAX_INT_DIGITS} digits")
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


@functools.lru_cache(maxsize=1)
def _yaml_loader() -> type:
    import yaml

    class Loader(yaml.SafeLoader):
        """SafeLoader with a depth limit while composing, checked integers and refused duplicate keys."""

        def __init__(self, stream: str) -> None:
            super().__init__(stream)
            self._depth = 0

        def compose_node(self, parent, index):  # type: ignore[override]
            self._depth += 1
            try:
                if self._depth > MAX_NESTING:
                    mark = self.peek_event().start_mark
                    raise ParseError(f"YAML nested more than {MAX_NESTING} levels deep (line {mark.line + 1})")
                return super().compose_node(parent, index)
            finally:
                self._depth -= 1

        def construct_yaml_int(self, node):  # type: ignore[override]
            if sum(ch.isdigit() for ch in str(node.value)) > MAX_INT_DIGITS:
                raise ParseError(f"YAML: an integer with more than {MAX_INT_DIGITS} digits (line {node.start_mark.line + 1})")
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


def _load_yaml(text: str) -> Any:
    import yaml

    try:
        loader = _yaml_loader()(text)  # the reader refuses control characters here already
    except yaml.YAMLError as exc:
        raise ParseError(f"malformed YAML: {' '.join(str(exc).split())[:120]}") from None
    try:
        root = loader.get_single_node()
        if root is None:
            return None
        _check_expanded_size(root)
        return loader.construct_document(root)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or "syntax error"
        raise ParseError(f"malformed YAML{at}: {problem}") from None
    finally:
        loader.dispose()


def _check_expanded_size(root: Any) -> None:
    """Refuse a YAML node graph whose aliases expand beyond :data:`MAX_EXPANDED`, or that contains itself.

    Each distinct node is measured once (memoised, no recursion), so the check itself stays cheap.
    """
    import yaml

    size: dict[int, int] = {}
    active: set[int] = set()
    stack: list[tuple[Any, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        if isinstance(node, yaml.ScalarNode):
            size[key] = 1 + len(node.value)
            continue
        children = [c for pair in node.value for c in pair] if isinstance(node, yaml.MappingNode) else node.value
        if done:
            active.discard(key)
            size[key] = 1 + sum(size[id(c)] for c in children)
            if size[key] > MAX_EXPANDED:
                raise ParseError(f"YAML too large once its aliases are expanded (more than {MAX_EXPANDED} "
                                 "entries and characters)")
            continue
        if key in size:
            continue
        if key in active:
            raise ParseError("YAML: an alias refers to a list or mapping that contains it")
        active.add(key)
        stack.append((node, True))
        stack.extend((c, False) for c in children if id(c) not in size)


def _check_data(data: Any) -> None:
    """Depth, size and Unicode checks on loaded plain data (iterative, so deep data cannot overflow the stack)."""
    stack: list[tuple[Any, int]] = [(data, 1)]
    count = 0
    while stack:
        value, depth = stack.pop()
        count += 1
        if depth > MAX_NESTING:
            raise ParseError(f"nested more than {MAX_NESTING} levels deep")
        if count > MAX_EXPANDED:
            raise ParseError(f"more than {MAX_EXPANDED} entries")
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
