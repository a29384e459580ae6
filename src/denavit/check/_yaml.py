"""Reading a claims file's YAML safely: bounded nesting, bounded size after aliases, no duplicate keys.

PyYAML's ``safe_load`` builds no objects but plain data, yet an untrusted file can still nest a thousand levels
deep (a RecursionError in the composer) or use aliases to expand a few hundred bytes into millions of entries (the
"billion laughs"), and a key written twice silently keeps its last value.  This loader composes the node graph
with a depth limit, measures its size with every alias expanded (without expanding it) and refuses duplicate
keys, each as a :class:`~denavit.errors.ParseError` naming the file and line.

``denavit.io`` is hardening its own loader at the same time; this one is local to the checker until the project
has one public safe loader (then this module should use it).
"""

from __future__ import annotations

from typing import Any

from ..errors import ParseError

__all__ = ["load_claims_yaml", "MAX_YAML_DEPTH", "MAX_YAML_NODES", "MAX_INT_DIGITS"]

#: Deepest nesting of lists and mappings in a claims file.
MAX_YAML_DEPTH = 40
#: Most YAML nodes (scalars, lists, mappings) in a claims file, counting every use of an alias in full.
MAX_YAML_NODES = 200_000
#: Most digits of an integer written in a claims file.
MAX_INT_DIGITS = 40


def _loader_class():
    import yaml

    class Loader(yaml.SafeLoader):
        def __init__(self, stream: str) -> None:
            super().__init__(stream)
            self._depth = 0

        def compose_node(self, parent, index):  # type: ignore[override]
            self._depth += 1
            try:
                if self._depth > MAX_YAML_DEPTH:
                    mark = self.peek_event().start_mark
                    raise ParseError(f"nested more than {MAX_YAML_DEPTH} levels deep at line {mark.line + 1}")
                return super().compose_node(parent, index)
            finally:
                self._depth -= 1

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


def _expanded_size(root) -> int:
    """The number of nodes with every alias expanded, computed once per distinct node (no recursion)."""
    import yaml

    size: dict[int, int] = {}
    visiting: set[int] = set()  # nodes whose subtree is being measured (the path from the root)
    stack = [(root, False)]
    while stack:
        node, done = stack.pop()
        if id(node) in size:
            continue
        if not done and id(node) in visiting:
            raise ParseError("an alias refers to the list or mapping that contains it (a recursive structure)")
        if isinstance(node, yaml.ScalarNode):
            size[id(node)] = 1
            continue
        children = [c for pair in node.value for c in pair] if isinstance(node, yaml.MappingNode) else list(node.value)
        if done:
            visiting.discard(id(node))
            total = 1 + sum(size.get(id(c), 0) for c in children)
            size[id(node)] = total
            if total > MAX_YAML_NODES:
                return total
        else:
            visiting.add(id(node))
            stack.append((node, True))
            stack += [(c, False) for c in children if id(c) not in size]
    return size.get(id(root), 0)


def load_claims_yaml(text: str, where: str) -> Any:
    """The data of a claims file's text (see the module notes); ParseError naming ``where`` if refused."""
    import yaml

    loader = None
    try:
        loader = _loader_class()(text)  # the reader already refuses control characters here
        root = loader.get_single_node()
        if root is None:
            return None
        if _expanded_size(root) > MAX_YAML_NODES:
            raise ParseError(f"too large once its aliases are expanded (more than {MAX_YAML_NODES} entries)")
        return loader.construct_document(root)
    except ParseError as exc:
        raise ParseError(str(exc), where=where) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        raise ParseError(f"malformed YAML{at}: {getattr(exc, 'problem', None) or 'syntax error'}", where=where) from None
    except (RecursionError, ValueError, OverflowError) as exc:  # a scalar the constructors cannot read
        raise ParseError(f"unreadable YAML ({type(exc).__name__})", where=where) from None
    finally:
        if loader is not None:
            loader.dispose()
