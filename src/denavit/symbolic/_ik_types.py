"""A closed-form IK derivation as data (:class:`IKDerivation`, its :class:`IKStep` s) and its text, LaTeX and
Markdown forms; built by :func:`~denavit.symbolic.ik_derivation`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import sympy as sp

from ..model import DHRobot

__all__ = ["IKStep", "IKDerivation"]


@dataclass(frozen=True)
class IKStep:
    """One step of a derivation: ``lhs relation rhs`` with an explanation.

    ``assign`` marks a formula that computes ``lhs`` (a symbol or a column of symbols) from quantities known
    at that point; other steps are displayed facts (the equations being solved).
    """

    title: str
    lhs: Any
    rhs: Any
    text: str = ""
    relation: str = "="
    assign: bool = False


@dataclass(frozen=True)
class IKDerivation:
    """A closed-form IK derivation as data; render with :meth:`to_text`, :meth:`to_latex`, :meth:`to_markdown`.

    Attributes
    ----------
    robot : DHRobot
    kind : str
        ``"decoupled"`` (6 joints, spherical wrist) or ``"planar"``.
    steps : tuple of IKStep
    target : sympy.ImmutableMatrix, shape (4, 4)
        The symbols of the solved pose ``T_0_N = B⁻¹ T_w_e E⁻¹`` (DH frame {N} in {0}; B, E base and tool):
        ``r11 … r33, p_x, p_y, p_z``.
    branches : tuple of sympy.Symbol
        Sign symbols σ, each +1 or −1; every sign combination is one candidate solution.
    joints : tuple of sympy.Symbol
        q1 … qn.
    parameters : tuple of (sympy.Symbol, float)
        The robot's named parameters and their values.
    """

    robot: DHRobot
    kind: str
    steps: tuple[IKStep, ...]
    target: sp.ImmutableMatrix
    branches: tuple[sp.Symbol, ...]
    joints: tuple[sp.Symbol, ...]
    parameters: tuple[tuple[sp.Symbol, float], ...] = field(default=())

    @property
    def formulas(self) -> tuple[tuple[Any, Any], ...]:
        """The assignments ``(lhs, rhs)`` in evaluation order."""
        return tuple((s.lhs, s.rhs) for s in self.steps if s.assign)

    def to_text(self) -> str:
        """Plain text (sympy's one-line printer)."""
        out = [f"Inverse kinematics of {self.robot.name} ({self.kind}), derived from its DH table", ""]
        for k, s in enumerate(self.steps, start=1):
            out.append(f"{k}. {s.title}")
            if s.text:
                out.append(f"   {s.text}")
            if s.lhs is not None:
                out.append(f"   {_text(s.lhs)} {s.relation} {_text(s.rhs)}")
            out.append("")
        return "\n".join(out).rstrip() + "\n"

    def to_latex(self) -> str:
        """A LaTeX fragment (``\\subsection*`` per step, ``align*`` for the formulas)."""
        out = [f"\\section*{{Inverse kinematics of {_tex_text(self.robot.name)}}}"]
        for s in self.steps:
            out.append(f"\\subsection*{{{_tex_text(s.title)}}}")
            if s.text:
                out.append(_tex_text(s.text))
            if s.lhs is not None:
                out.append(f"\\begin{{align*}}\n{_latex(s.lhs)} &{_rel(s.relation)} {_latex(s.rhs)}\n\\end{{align*}}")
        return "\n".join(out) + "\n"

    def to_markdown(self) -> str:
        """Markdown with ``$$ … $$`` display math."""
        out = [f"## Inverse kinematics of {self.robot.name}", ""]
        for s in self.steps:
            out += [f"### {s.title}", ""]
            if s.text:
                out += [s.text, ""]
            if s.lhs is not None:
                out += [f"$$ {_latex(s.lhs)} {_rel(s.relation)} {_latex(s.rhs)} $$", ""]
        return "\n".join(out)

    def _repr_markdown_(self) -> str:
        return self.to_markdown()


def _text(e: Any) -> str:
    if isinstance(e, sp.MatrixBase):
        return "[" + "; ".join(", ".join(str(x) for x in e.row(i)) for i in range(e.rows)) + "]"
    return str(e)


def _latex(e: Any) -> str:
    """sympy's LaTeX, with frame names written as Craig does: T_0_6 → {}^{0}T_{6}."""
    names = {}
    for sym in getattr(e, "free_symbols", ()):
        parts = str(sym).split("_")
        if len(parts) == 3 and parts[0] in ("T", "R") and parts[1].isdigit() and parts[2].isdigit():
            names[sym] = f"{{}}^{{{parts[1]}}}{parts[0]}_{{{parts[2]}}}"
    return sp.latex(e, symbol_names=names) if names else sp.latex(e)


def _rel(r: str) -> str:
    return {"=": "=", "≡": "\\equiv", ":=": ":="}.get(r, r)


def _tex_text(s: str) -> str:
    for a, b in (("\\", "\\textbackslash{}"), ("_", "\\_"), ("%", "\\%"), ("&", "\\&"), ("#", "\\#")):
        s = s.replace(a, b)
    return s
