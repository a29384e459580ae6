"""Text for a terminal: what a robot file says is shown, never obeyed by the terminal.

A name read from a file may hold ESC (``\\x1b[2J`` clears the screen, ``\\x1b]8;;…`` makes a link, some terminals
answer queries into their input), a carriage return that overwrites the line, C1 controls (``\\x9b`` is CSI on
some terminals) or a bidirectional override (U+202E) that makes the line read differently from what it holds
(CVE-2021-42574).  Everything the command line prints passes :func:`terminal_text`; names in titles, where a
newline would forge a line, pass :func:`one_line_text`.
"""

from __future__ import annotations

from .. import _text

__all__ = ["terminal_text", "one_line_text"]


def terminal_text(text: str) -> str:
    """``text`` with control characters, line separators and bidirectional marks shown as escapes (``\\x1b``,
    ``\\u202e``); newlines and tabs, which lay the output out, are kept.

    >>> terminal_text("arm\\x1b[2J\\n\\u202eq1")
    'arm\\\\x1b[2J\\n\\\\u202eq1'
    """
    return _text.visible(text, keep="\n\t")


def one_line_text(text: str) -> str:
    """``text`` on one line: newlines and carriage returns escaped too (``arm\\nbase`` → ``arm\\\\nbase``)."""
    return _text.visible(text)
