"""Reading untrusted XML (URDF) safely: no DTD, no entities, bounded size, depth and element count.

Python's expat is used directly, with handlers that refuse a document type declaration, any entity
declaration and any external entity reference before they take effect: the "billion laughs" (nested
entity expansion) and external entities (XXE: a file or URL read into the document) cannot happen because
no ``<!DOCTYPE`` is accepted at all.  URDF never needs one.  Every error is one
:class:`~denavit.errors.ParseError` naming the file and the line.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Iterator

from ..errors import ParseError

__all__ = ["Element", "parse_xml", "read_xml_source", "MAX_XML_BYTES", "MAX_XML_DEPTH", "MAX_XML_ELEMENTS"]

#: Largest XML document read [bytes].  The largest arm URDFs of example-robot-data are about 40 kB.
MAX_XML_BYTES = 4_000_000
#: Deepest element nesting accepted (a URDF needs 5: robot/link/inertial/origin).
MAX_XML_DEPTH = 32
#: Most elements in one document (a 32-joint arm with visuals and collisions needs a few hundred).
MAX_XML_ELEMENTS = 100_000


class Element:
    """One XML element: ``tag``, ``attrib`` (dict of str), ``children`` (list of Element), ``line`` (1-based),
    ``parent`` (Element or None)."""

    __slots__ = ("tag", "attrib", "children", "line", "parent")

    def __init__(self, tag: str, attrib: dict[str, str], line: int, parent: "Element | None" = None) -> None:
        self.tag, self.attrib, self.children, self.line, self.parent = tag, attrib, [], line, parent

    def iter(self, tag: str) -> Iterator["Element"]:
        """Direct children named ``tag``."""
        return (c for c in self.children if c.tag == tag)

    def find(self, tag: str) -> "Element | None":
        """The first direct child named ``tag``, or None."""
        return next(self.iter(tag), None)

    def describe(self) -> str:
        """``<joint name='shoulder'> <origin> (line 12)``: how errors name the element (with its nearest named
        ancestor)."""
        def tag(el: Element) -> str:
            name = el.attrib.get("name")
            return f"<{el.tag[:40]}" + (f" name={name[:40]!r}>" if name is not None else ">")

        owner = self.parent
        while owner is not None and "name" not in owner.attrib:
            owner = owner.parent
        prefix = f"{tag(owner)} " if owner is not None and owner.parent is not None and "name" not in self.attrib else ""
        return f"{prefix}{tag(self)} (line {self.line})"


def read_xml_source(source: str | os.PathLike[str], what: str = "URDF") -> tuple[str, bytes]:
    """``(where, data)`` for a path or an XML text (a string starting with ``<``), size-checked.

    A path is read after its size is checked (at most :data:`MAX_XML_BYTES`), so a 100 MB file is refused
    without being read.
    """
    if isinstance(source, str) and source.lstrip().startswith("<"):
        data = source.encode("utf-8", "surrogatepass")
        where = f"<{what} text>"
    else:
        path = Path(source)
        where = str(path)
        try:
            if not path.is_file():
                raise ParseError("no such file" if not path.exists() else "not a regular file", where=where)
            size = path.stat().st_size
            if size > MAX_XML_BYTES:
                raise ParseError(f"{what} file of {size} bytes is larger than the limit of {MAX_XML_BYTES} bytes",
                                 where=where)
            with path.open("rb") as fh:
                data = fh.read(MAX_XML_BYTES + 1)
        except OSError as exc:
            raise ParseError(f"cannot read it ({exc.strerror or exc})", where=where) from None
    if len(data) > MAX_XML_BYTES:
        raise ParseError(f"{what} text of more than {MAX_XML_BYTES} bytes is larger than the limit", where=where)
    return where, data


class _Refused(Exception):
    pass


def parse_xml(data: bytes, where: str) -> Element:
    """The element tree of an untrusted XML document (see the module notes for what is refused).

    Raises
    ------
    ParseError
        ``"<where>: line N: <reason>"`` for a malformed document, a DOCTYPE/ENTITY declaration, nesting deeper
        than :data:`MAX_XML_DEPTH` or more than :data:`MAX_XML_ELEMENTS` elements.
    """
    from xml.parsers import expat  # loaded on use: `import denavit` reads no XML

    parser = expat.ParserCreate()
    stack: list[Element] = []
    root: list[Element] = []
    count = [0]

    def line() -> int:
        return parser.CurrentLineNumber

    def refuse(what: str):
        def handler(*_args):
            raise _Refused(f"line {line()}: {what} refused (untrusted XML: no DTD or entities are read)")
        return handler

    def start(tag: str, attrib: dict[str, str]) -> None:
        count[0] += 1
        if count[0] > MAX_XML_ELEMENTS:
            raise _Refused(f"line {line()}: more than {MAX_XML_ELEMENTS} elements")
        if len(stack) >= MAX_XML_DEPTH:
            raise _Refused(f"line {line()}: <{tag[:40]}> nested more than {MAX_XML_DEPTH} levels deep")
        el = Element(tag, dict(attrib), line(), stack[-1] if stack else None)
        if stack:
            stack[-1].children.append(el)
        else:
            root.append(el)
        stack.append(el)

    def end(_tag: str) -> None:
        stack.pop()

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.StartDoctypeDeclHandler = refuse("a DOCTYPE declaration")
    parser.EntityDeclHandler = refuse("an ENTITY declaration")
    parser.UnparsedEntityDeclHandler = refuse("an ENTITY declaration")
    parser.ExternalEntityRefHandler = refuse("an external entity")
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    try:
        parser.Parse(data, True)
    except _Refused as exc:
        raise ParseError(str(exc), where=where) from None
    except expat.ExpatError as exc:
        reason = expat.ErrorString(exc.code)
        raise ParseError(f"line {exc.lineno}: malformed XML ({reason})", where=where) from None
    except (LookupError, ValueError) as exc:  # encoding="x-nonexistent" (LookupError), "utf-7" (ValueError)
        declared = re.match(rb"""\s*<\?xml[^>]{0,200}?encoding\s*=\s*["']([^"']{0,40})""", data)
        name = declared.group(1).decode("ascii", "replace") if declared else "?"
        raise ParseError(f"line 1: the XML declaration names the encoding {name!r}, which cannot be read here "
                         f"({' '.join(str(exc).split())[:80]}); save the file as UTF-8", where=where) from None
    except RecursionError:
        raise ParseError(f"nested more than {MAX_XML_DEPTH} levels deep", where=where) from None
    if not root:
        raise ParseError("no XML element in the document", where=where)
    return root[0]
