"""User text (robot names, descriptions, pose names, file names) written as data, never as syntax.

A name is free text: it may hold a newline, a carriage return, NEL (U+0085), a line or paragraph separator
(U+2028/U+2029), an escape character starting a terminal control sequence, or a bidirectional override
(U+202E) that makes a line read differently from what it holds.  Every writer puts such text through one of
these functions:

* :func:`visible` — one line of text with those characters shown as Python escapes (``\\n``, ``\\x1b``,
  ``\\u202e``): for comments (YAML/TOML ``#``, XML, C, Python), titles and terminal output;
* :func:`yaml_string` — a double-quoted YAML scalar (also a JSON string) that reads back to exactly the text;
* :func:`xml_comment`, :func:`c_comment`, :func:`docstring` — :func:`visible` plus what each comment syntax
  forbids (``--`` in XML, ``*/`` in C, ``\"\"\"`` and backslashes in a Python docstring).

The characters escaped (:data:`UNSAFE`) are the C0 and C1 control characters and DEL (terminal controls; YAML and
XML refuse most of them raw), the line breaks YAML and Unicode know (``\\n``, ``\\r``, U+0085, U+2028, U+2029),
the bidirectional marks, embeddings, overrides and isolates (U+061C, U+200E/F, U+202A-E, U+2066-9; the
"Trojan Source" characters, CVE-2021-42574), lone surrogates and the non-characters U+FFFE/U+FFFF.
"""

from __future__ import annotations

import json
import re

__all__ = ["UNSAFE", "visible", "yaml_string", "xml_comment", "c_comment", "docstring", "has_unsafe"]

#: Characters never written raw into a file or onto a terminal (see the module notes).
UNSAFE = re.compile("[\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028\u2029\u202a-\u202e\u2066-\u2069"
                    "\ud800-\udfff\ufffe\uffff]")
_SHORT = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}


def _escape(ch: str) -> str:
    code = ord(ch)
    return _SHORT.get(ch) or (f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}")


def has_unsafe(text: str, keep: str = "") -> bool:
    """Whether ``text`` holds a character of :data:`UNSAFE` (other than those in ``keep``)."""
    return any(ch not in keep for ch in UNSAFE.findall(text))


def visible(text: str, keep: str = "") -> str:
    """``text`` with every :data:`UNSAFE` character (except those in ``keep``) written as a Python escape.

    >>> visible("arm\\nbase: [1] #\\u202e"), visible("a\\tb\\nc", keep="\\n\\t") == "a\\tb\\nc"
    ('arm\\\\nbase: [1] #\\\\u202e', True)
    """
    return UNSAFE.sub(lambda m: m.group() if m.group() in keep else _escape(m.group()), str(text))


def yaml_string(text: str) -> str:
    """``text`` as a double-quoted scalar that YAML (1.1 and 1.2) and JSON read back to exactly ``text``.

    JSON's escapes are YAML's: ``\\"``, ``\\\\``, ``\\n``, ``\\uXXXX``.  Every :data:`UNSAFE` character is
    escaped (a raw U+2028 or U+0085 is a line break to YAML, folded into a space inside quotes).

    >>> yaml_string('a"b\\u2028c')
    '"a\\\\"b\\\\u2028c"'
    """
    quoted = json.dumps(str(text), ensure_ascii=False)
    return UNSAFE.sub(lambda m: f"\\u{ord(m.group()):04x}", quoted)


def xml_comment(text: str) -> str:
    """Text for inside ``<!-- ... -->``: :func:`visible`, with no ``--`` (illegal in an XML comment) and no
    trailing ``-`` (a comment cannot end in ``--->``).

    >>> xml_comment("a---b-")
    'a- - -b- '
    """
    out = re.sub(r"-(?=-)", "- ", visible(text))
    return out + " " if out.endswith("-") else out


def c_comment(text: str) -> str:
    """Text for inside ``/* ... */``: :func:`visible`, with ``*/`` (which would end the comment) split.

    >>> c_comment("a*/b/*c")
    'a* /b/ *c'
    """
    return visible(text).replace("*/", "* /").replace("/*", "/ *")


def docstring(text: str) -> str:
    """Text for inside a Python ``\"\"\"`` docstring: :func:`visible`, backslashes doubled, quotes escaped.

    >>> docstring('a\"\"\"b\\\\N')
    'a\\\\"\\\\"\\\\"b\\\\\\\\N'
    """
    return visible(text).replace("\\", "\\\\").replace('"', '\\"')
