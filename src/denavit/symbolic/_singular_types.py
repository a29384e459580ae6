"""The results of the singularity analysis (data only; built by :func:`~denavit.symbolic.singularity_analysis`,
presented by the CLI and the reports)."""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

__all__ = ["SingularSolution", "SingularCondition", "SingularityAnalysis"]


@dataclass(frozen=True)
class SingularSolution:
    """Closed form ``variable = expression`` (None when only numeric roots were found) and its values
    at the robot's parameter values [rad in (−π, π] or m]; ``in_limits`` flags each value."""

    variable: str
    expression: sp.Expr | None
    values: tuple[float, ...]
    in_limits: tuple[bool, ...]


@dataclass(frozen=True)
class SingularCondition:
    """One factor of the determinant set to zero, its solutions (empty: kept as an equation) and its kind."""

    factor: sp.Expr
    variables: tuple[str, ...]
    solutions: tuple[SingularSolution, ...]
    kind: str
    explanation: str

    @property
    def equation(self) -> sp.Eq:
        return sp.Eq(self.factor, 0, evaluate=False)


@dataclass(frozen=True)
class SingularityAnalysis:
    """Result of :func:`singularity_analysis` (data only; presenters live in the CLI and reports)."""

    robot: str
    rows: tuple[str, ...]
    matrix: sp.ImmutableMatrix
    matrix_note: str
    measure: str
    determinant: sp.Expr
    constant_factors: tuple[sp.Expr, ...]
    conditions: tuple[SingularCondition, ...]
    everywhere: bool
    generic_rank: int
    full_rank: int
    reason: str

    def _repr_markdown_(self) -> str:
        from ..display import singularities_markdown

        return singularities_markdown(self)
