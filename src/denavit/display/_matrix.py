"""A symbolic matrix as terminal text that fits the terminal: sympy's 2-D picture when it fits, otherwise the
entries one after another, each labelled with its (row, column) and wrapped to the width (issue 31: the Puma
560's T_0_6 in shorthand was 226 columns wide)."""

from __future__ import annotations

import shutil
import textwrap

__all__ = ["terminal_width", "matrix_text", "equations_text", "prose_text"]

#: Narrowest width written to: below it, a labelled entry would have no room left.
MIN_WIDTH = 40


def terminal_width() -> int:
    """Columns of the terminal: ``COLUMNS`` when set, else the terminal's size, else 80 (output to a file or a
    pipe), never below ``MIN_WIDTH`` (``shutil.get_terminal_size`` reads ``COLUMNS`` first)."""
    return max(MIN_WIDTH, shutil.get_terminal_size((80, 24)).columns)


def _pretty(expr, width: int | None) -> str:
    import sympy as sp

    if width is None:
        return sp.pretty(expr, use_unicode=True, wrap_line=False)
    return sp.pretty(expr, use_unicode=True, wrap_line=True, num_columns=width)


def _break_sum(line: str, width: int) -> list[str]:
    """A one-line sum broken before its top-level `` + `` / `` - `` (outside brackets) into lines of at most
    ``width`` columns where the terms allow; continuation lines are indented by two."""
    cuts, depth = [0], 0
    for k, ch in enumerate(line):
        depth += (ch in "([{") - (ch in ")]}")
        if depth == 0 and line.startswith((" + ", " - "), k) and k > 0:
            cuts.append(k + 1)  # the next line starts with the sign
    pieces = [line[a:b].rstrip() for a, b in zip(cuts, cuts[1:] + [len(line)])]
    out = [pieces[0]]
    for piece in pieces[1:]:
        if len(out[-1]) + 1 + len(piece) <= width:
            out[-1] += " " + piece
        else:
            out.append("  " + piece)
    return out


def _entry_lines(expr, width: int) -> list[str]:
    """One entry in at most ``width`` columns where it can be: a one-line entry broken at its top-level + and -,
    a 2-D one (fractions, powers) wrapped by sympy's printer."""
    one = _pretty(expr, None).splitlines()
    if len(one) == 1:
        return _break_sum(one[0], width) if len(one[0]) > width else one
    return _pretty(expr, width).splitlines()


def matrix_text(M, width: int | None = None) -> str:
    """``M`` (a sympy matrix or expression) as text no wider than ``width`` columns (default: the terminal's).

    A matrix whose 2-D picture is wider is written entry by entry, ``(i, j) = entry`` with 1-based indices as
    in the textbooks' T_ij; an entry that is itself wider goes under its label, broken before its top-level
    ``+`` and ``-`` (a 2-D entry, with fractions or powers, is wrapped by sympy's printer).  (A single entry can still not be narrower than its widest unbreakable piece, e.g. a long name.)
    """
    width = terminal_width() if width is None else max(MIN_WIDTH, int(width))
    if not hasattr(M, "shape"):  # one expression
        return "\n".join(_entry_lines(M, width))
    whole = _pretty(M, None)
    if max(map(len, whole.splitlines()), default=0) <= width:
        return whole
    rows, cols = M.shape
    out = [f"({rows}×{cols}, entry by entry: wider than {width} columns as a matrix)"]
    for i in range(rows):
        for j in range(cols):
            label = f"({i + 1}, {j + 1}) = "
            text = _entry_lines(M[i, j], width - len(label))
            if len(text) == 1:
                out.append(label + text[0])
            else:  # a 2-D entry (fractions, powers) or a long one: under its label
                out.append(label.rstrip())
                out += ["    " + line for line in _entry_lines(M[i, j], width - 4)]
    return "\n".join(out)


def equations_text(text: str, width: int | None = None) -> str:
    """Lines of ``name = expression`` text fitted to ``width`` columns (default: the terminal's): a longer line is
    broken before the top-level ``+`` and ``-`` of its right-hand side, the continuation lines aligned under the
    expression's start, as a textbook aligns a long sum.  Lines without `` = ``, and lines that fit, are kept.

    >>> print(equations_text("c[1] = a*b + c*(d + e) - f*g", width=40))
    c[1] = a*b + c*(d + e) - f*g
    >>> print(equations_text("c[1] = aaaa*bbbb + cccc*(d + e) - ffff*gggg + hhhh*iiii", width=40))
    c[1] = aaaa*bbbb + cccc*(d + e)
           - ffff*gggg + hhhh*iiii
    """
    width = terminal_width() if width is None else max(MIN_WIDTH, int(width))
    out = []
    for line in text.split("\n"):
        head, sep, rhs = line.partition(" = ")
        if len(line) <= width or not sep:
            out.append(line)
            continue
        pad = len(head) + len(sep)
        if pad > width // 2:  # a long left-hand side: continue under a fixed indent instead
            pad = 4
        pieces = _break_sum(rhs, max(MIN_WIDTH // 2, width - pad))
        pieces = [pieces[0]] + [p[2:] if p.startswith("  ") else p for p in pieces[1:]]
        out.append(head + sep + pieces[0])
        out += [" " * pad + p for p in pieces[1:]]
    return "\n".join(out)


def prose_text(line: str, width: int | None = None) -> str:
    """A line of prose fitted to ``width`` columns (default: the terminal's) at spaces, continuation lines indented
    two more than the line; words are never cut (a single longer word keeps its line).

    >>> print(prose_text("    kind: elbow — joint 3 stretches the arm out or folds it back", width=40))
        kind: elbow — joint 3 stretches the
          arm out or folds it back
    """
    width = terminal_width() if width is None else max(MIN_WIDTH, int(width))
    if len(line) <= width:
        return line
    lead = line[:len(line) - len(line.lstrip())]
    return "\n".join(textwrap.wrap(line.strip(), width, initial_indent=lead, subsequent_indent=lead + "  ",
                                    break_long_words=False, break_on_hyphens=False))
