"""Reading a claims file's YAML safely: bounded nesting, bounded size after aliases, no duplicate keys.

PyYAML's ``safe_load`` builds no objects but plain data, yet an untrusted file can still nest a thousand levels
deep (a RecursionError in the composer) or use aliases to expand a few hundred bytes into millions of entries (the
"billion laughs"), and a key written twice silently keeps its last value.  This loader first walks the parser's
events (libyaml's when installed) to bound the nesting and the size with every alias expanded, without building
anything, then loads with a safe loader that refuses duplicate keys and huge integers; each refusal is a
:class:`~denavit.errors.ParseError` naming the file and line.

``denavit.io`` is hardening its own loader at the same time; this one is local to the checker until the project
has one public safe loader (then this module should use it).
"""

from __future__ import annotations

from typing import Any

from ..errors import ParseError

__all__ = ["load_claims_yaml", "MAX_YAML_DEPTH", "MAX_YAML_NODES", "MAX_INT_DIGITS"]

#: Deepest nesting of lists and mappings in a claims file.
MAX_YAML_DEPTH = 40
#: Most YAML nodes (scalars, lists, mappings) in a claims file, counting every use of an alias in full (100 claims
#: of 6×64 entries are about 40 000; the pure-Python reader needs about a second per 20 000).
MAX_YAML_NODES = 50_000
#: Most digits of an integer written in a claims file.
MAX_INT_DIGITS = 40


def _base():
    import yaml

    return getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml when present: about 20 times faster


def _loader_class():
    import yaml

    class Loader(_base()):  # type: ignore[misc, valid-type]
        def construct_yaml_int(self, node):  # type: ignore[override]
            digits = sum(ch.isdigit() for ch in str(node.value))
            if digits > MAX_INT_DIGITS:
                raise ParseError(f"an integer with more than {MAX_INT_DIGITS} digits at line {node.start_mark.line + 1}")
            return super().construct_yaml_int(node)

        def construct_mapping(self, node, deep=False):  # type: ignore[override]
            seen: dict[Any, int] = {}
            for key_node, _ in node.value:
                if isinstance(key_node, yaml.ScalarNode):
                    key = (key_node.tag, key_node.value)
                    if key in seen:
                        raise ParseError(f"key {str(key_node.value)[:40]!r} given twice (lines {seen[key]} and "
                                         f"{key_node.start_mark.line + 1})")
                    seen[key] = key_node.start_mark.line + 1
            return super().construct_mapping(node, deep=deep)

    Loader.add_constructor("tag:yaml.org,2002:int", Loader.construct_yaml_int)
    return Loader


def _check_events(text: str) -> None:
    """Depth, size with aliases expanded and recursive aliases, from the parser's events (no tree is built)."""
    import yaml

    depth, expanded = 0, 0
    stack: list[list[Any]] = []  # [anchor, size] of the open lists and mappings
    sizes: dict[str, int] = {}  # anchor -> size of its node, aliases expanded
    for ev in yaml.parse(text, Loader=_base()):
        if isinstance(ev, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
            depth += 1
            if depth > MAX_YAML_DEPTH:
                raise ParseError(f"nested more than {MAX_YAML_DEPTH} levels deep at line {ev.start_mark.line + 1}")
            stack.append([ev.anchor, 1])
            n = 1
        elif isinstance(ev, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
            depth -= 1
            anchor, size = stack.pop()
            if anchor is not None:
                sizes[anchor] = size
            if stack:
                stack[-1][1] += size
            continue
        elif isinstance(ev, yaml.ScalarEvent):
            n = 1
            if ev.anchor is not None:
                sizes[ev.anchor] = 1
        elif isinstance(ev, yaml.AliasEvent):
            if any(a == ev.anchor for a, _ in stack):
                raise ParseError("an alias refers to the list or mapping that contains it (a recursive structure)")
            n = sizes.get(ev.anchor, 1)
        else:
            continue
        expanded += n
        if expanded > MAX_YAML_NODES:
            raise ParseError(f"more than {MAX_YAML_NODES} entries once its aliases are expanded (split the file)")
        if stack and not isinstance(ev, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
            stack[-1][1] += n


def load_claims_yaml(text: str, where: str) -> Any:
    """The data of a claims file's text (see the module notes); ParseError naming ``where`` if refused."""
    import yaml

    try:
        _check_events(text)
        return yaml.load(text, Loader=_loader_class())  # noqa: S506 - a SafeLoader subclass
    except ParseError as exc:
        raise ParseError(str(exc), where=where) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        raise ParseError(f"malformed YAML{at}: {getattr(exc, 'problem', None) or 'syntax error'}", where=where) from None
    except (RecursionError, ValueError, OverflowError) as exc:  # a scalar the constructors cannot read
        raise ParseError(f"unreadable YAML ({type(exc).__name__})", where=where) from None
