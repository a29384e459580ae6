"""Results and shared pieces of the symbolic dynamics (data only): the equations of motion
:class:`DynamicsTerms`, one row's inertial data :class:`InertialPiece`, and the progress callback."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import sympy as sp

__all__ = ["DynamicsTerms", "InertialPiece", "Progress", "report_progress"]

Progress = Callable[[str, int, int], None]


def report_progress(progress: Progress | None, stage: str, done: int, total: int) -> None:
    if progress is not None:
        progress(stage, done, total)


@dataclass(frozen=True)
class DynamicsTerms:
    """M(q), C(q, q̇), c = C q̇, g(q) and friction τ_f(q̇) as sympy matrices (column vectors for c, g, τ_f)."""

    M: sp.ImmutableMatrix
    C: sp.ImmutableMatrix | None
    c: sp.ImmutableMatrix
    g: sp.ImmutableMatrix
    friction: sp.ImmutableMatrix
    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    qdd: tuple[sp.Symbol, ...]
    form: str = "expanded"
    """"hand": each entry a sum of parameter groups times sines and cosines (``simplify="trig"``)."""
    gravity: sp.Expr | None = None
    """|g₀| [m/s²] when ``g_unit`` is given."""
    g_unit: sp.ImmutableMatrix | None = None
    """g(q) per unit of gravitational acceleration (g = |g₀| · g_unit): presenters write g as a symbol."""

    def _repr_latex_(self) -> str:
        from ..display import dynamics_latex

        return dynamics_latex(self)

    @property
    def tau(self) -> sp.ImmutableMatrix:
        """τ = M q̈ + c + g + τ_f."""
        return sp.ImmutableMatrix(self.M * sp.Matrix(self.qdd) + self.c + self.g + self.friction)


@dataclass(frozen=True)
class InertialPiece:
    """One row's inertial data as sympy: ``row`` (DH row), ``body`` (joint index), mass, COM, inertia in {row}."""

    row: int
    body: int
    mass: sp.Expr
    com: sp.ImmutableMatrix
    inertia: sp.ImmutableMatrix
