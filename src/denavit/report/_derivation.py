"""A derivation as data: sections of steps (text, equations, numbers, tables, figures).

:func:`derive` builds the whole worked derivation of a robot, in the order a textbook or a course report
writes it (Craig 2005, ch. 3-6; Spong et al. 2006, ch. 3-7): the DH table and convention, each link
transform A_i (general form, then substituted), T_0_n, the end-effector position, the Jacobian with its
route, velocities, statics, singularities, inverse kinematics, dynamics and figures.  Nothing here is
text layout: :mod:`denavit.report._render` turns a :class:`Derivation` into Markdown, LaTeX or HTML.

Sections whose library functions are not available in this installation are kept, with
``status="unavailable"`` and the reason, so a report never pretends to contain what it does not.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from ..model import DHRobot

__all__ = [
    "Text",
    "Heading",
    "Equation",
    "Numbers",
    "Table",
    "Figure",
    "Section",
    "Derivation",
    "Step",
    "derive",
    "TOPICS",
    "MAX_CASES",
]

#: Most numeric cases in one report (each numeric section is written once per case).
MAX_CASES = 8


@dataclass(frozen=True)
class Text:
    """A paragraph; ``$...$`` spans are inline mathematics (LaTeX)."""

    text: str


@dataclass(frozen=True)
class Heading:
    """A sub-heading inside a section (``$...$`` spans are inline mathematics): one numeric case of several."""

    text: str


@dataclass(frozen=True)
class Equation:
    """``lhs = rhs``: ``lhs`` is LaTeX, ``expr`` a sympy expression or matrix (exact or symbolic).

    ``shorthand`` marks that C_12/S_3 style symbols stand for cos(q1 + q2)/sin(q3) (display only).
    """

    lhs: str
    expr: Any
    relation: str = "="
    note: str = ""
    shorthand: bool = False


@dataclass(frozen=True)
class Numbers:
    """``lhs ≈ values``: decimals computed by the numeric engine (``values`` an ndarray, any shape ≤ 2-D)."""

    lhs: str
    values: np.ndarray = field(compare=False)
    digits: int = 4
    note: str = ""


@dataclass(frozen=True)
class Table:
    """A table whose cells are LaTeX snippets (rendered as inline mathematics) or plain text."""

    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    math: bool = True
    caption: str = ""


@dataclass(frozen=True)
class Figure:
    """A PNG picture (bytes) with a caption."""

    png: bytes = field(repr=False)
    caption: str
    name: str


Step = Text | Heading | Equation | Numbers | Table | Figure


@dataclass(frozen=True)
class Section:
    """One part of the derivation.  ``status`` is ``"done"``, ``"skipped"`` (an input was not given)
    or ``"unavailable"`` (the library function is not there); ``reason`` says why for the last two."""

    key: str
    title: str
    steps: tuple[Step, ...] = ()
    status: str = "done"
    reason: str = ""


@dataclass(frozen=True)
class Derivation:
    """The whole report as data."""

    robot: DHRobot
    title: str
    inputs: dict[str, Any]
    sections: tuple[Section, ...]

    def section(self, key: str) -> Section:
        """The section with this key (KeyError naming the keys if absent)."""
        for s in self.sections:
            if s.key == key:
                return s
        raise KeyError(f"no section {key!r}; sections: {', '.join(s.key for s in self.sections)}")

    def _repr_markdown_(self) -> str:
        from ..display import derivation_markdown

        return derivation_markdown(self)


TOPICS = (
    "model", "links", "fk", "case", "jacobian", "velocity", "statics", "singularities", "ik", "dynamics", "figures",
)


def _builders() -> dict[str, Callable[..., Section]]:
    from . import _capabilities, _dynamics, _ik, _motion, _sections

    return {
        "model": _sections.section_model,
        "links": _sections.section_links,
        "fk": _sections.section_fk,
        "case": _sections.section_case,
        "jacobian": _motion.section_jacobian,
        "velocity": _motion.section_velocity,
        "statics": _motion.section_statics,
        "singularities": _capabilities.section_singularities,
        "ik": _ik.section_ik,
        "dynamics": _dynamics.section_dynamics,
        "figures": _capabilities.section_figures,
    }


def derive(
    robot: DHRobot,
    q: Sequence[Any] | None = None,
    qd: Sequence[Any] | None = None,
    wrench: Sequence[Any] | None = None,
    *,
    cases: Sequence[dict[str, Any]] | None = None,
    topics: Sequence[str] | None = None,
    simplify: str = "trig",
    deg: bool = False,
    progress: Callable[[str], None] | None = None,
) -> Derivation:
    """Build the derivation of ``robot`` (data only; render it with :func:`render`).

    Parameters
    ----------
    robot : DHRobot
    q : sequence of float or str, shape (n,), optional
        Joint values of the numeric case.  Strings (``"pi/4"``) are read exactly by the restricted
        expression parser, so cos(π/4) appears as √2/2; floats are used as given.  ``None`` picks a
        default configuration (π/6 for revolute joints, the middle of the stroke for prismatic ones).
        A pose name of the robot (``"qr"``, see ``robot.poses``) picks that named configuration.
    qd : sequence, shape (n,), optional
        Joint rates for the velocity section [rad/s or m/s].
    wrench : sequence, shape (6,), optional
        End-effector wrench (f, n) in base axes [N, N·m] for the statics section.
    cases : sequence of dict, optional
        Several numeric cases instead of ``q``/``qd``/``wrench``: mappings with ``"q"`` and optionally
        ``"qd"``, ``"wrench"`` (read as above), at most :data:`MAX_CASES`.  The derivation (symbolic
        steps) is written once; every numeric section shows each case under its label ("Case 1", …),
        each checked as a single case is.  The figures show the first case.
    topics : sequence of str, optional
        Sections to build, from :data:`TOPICS` (all by default).
    simplify : {"none", "trig", "full"}
        Simplification policy of the symbolic results.
    deg : bool
        Read revolute joint values in ``q`` (and rates in ``qd``) as degrees.
    progress : callable, optional
        Called with a short message before each section is built (the command line prints these on
        stderr; symbolic sections of a 6- or 7-joint arm take seconds each).

    Returns
    -------
    Derivation
    """
    from ._context import Context

    topics = tuple(TOPICS if topics is None else topics)
    bad = [t for t in topics if t not in TOPICS]
    if bad:
        from ..errors import ParseError

        raise ParseError(f"unknown report topic {bad[0]!r}; choose from {', '.join(TOPICS)}")
    from ._cases import CASE_TOPICS, case_list, merge_cases

    ctxs = [Context.build(robot, c["q"], c["qd"], c["wrench"], simplify=simplify, deg=deg)
            for c in case_list(q, qd, wrench, cases)]
    builders = _builders()
    chosen = [t for t in TOPICS if t in topics]
    sections = []
    for k, t in enumerate(chosen, start=1):
        if progress is not None:
            progress(f"section {k}/{len(chosen)}: {t}")
        if len(ctxs) == 1 or t not in CASE_TOPICS:
            sections.append(builders[t](ctxs[0]))
            continue
        built = []
        for c in ctxs:
            c.share_symbolic(ctxs[0])  # the symbolic results are the same for every case: computed once
            built.append(builders[t](c))
        sections.append(merge_cases(built, ctxs))
    sections = tuple(sections)
    title = f"Kinematics and dynamics of {robot.name}"
    inputs = ctxs[0].inputs()
    if len(ctxs) > 1:
        inputs["cases"] = [c.inputs() for c in ctxs]
    return Derivation(robot=robot, title=title, inputs=inputs, sections=sections)
