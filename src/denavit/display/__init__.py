"""Presenters for people: the DH table of a robot as text, Markdown, LaTeX or HTML, and the rich displays
Jupyter shows for robots and results (``_repr_html_``, ``_repr_latex_``, ``_repr_markdown_`` delegate here).

Results stay data; this package only turns them into text.  It needs numpy only, except where a result is
symbolic (sympy is then already loaded) and for the optional picture of the arm (matplotlib, when installed).
"""

from ._matrix import equations_text, matrix_text, prose_text, terminal_width
from ._results import (
    MAX_HTML_ROWS,
    derivation_markdown,
    dynamics_latex,
    ik_html,
    singularities_markdown,
)
from ._terminal import one_line_text, terminal_text
from ._table import PICTURE_DPI, PICTURE_SIZE, TABLE_FORMATS, dh_table, robot_html, robot_summary

__all__ = [
    "TABLE_FORMATS",
    "MAX_HTML_ROWS",
    "PICTURE_SIZE",
    "PICTURE_DPI",
    "dh_table",
    "robot_summary",
    "robot_html",
    "ik_html",
    "dynamics_latex",
    "derivation_markdown",
    "singularities_markdown",
    "terminal_text",
    "one_line_text",
    "matrix_text",
    "terminal_width",
    "equations_text",
    "prose_text",
]
