"""The symbolic engine (sympy).  Importing this module is what imports sympy.

Results are ``sympy.ImmutableMatrix`` in the joint symbols ``q1…qn`` and the robot's named parameters.
"""

from ._ik import ik_derivation
from ._ik_types import IKDerivation, IKStep
from ._dynamics import christoffel_matrix, christoffel_symbols, lagrangian_dynamics
from ._dynamics_data import inertial_pieces
from ._dynamics_format import format_dynamics
from ._dynamics_trig import fourier_form
from ._dynamics_types import DynamicsTerms
from ._regressor import PARAMETER_NAMES, regressor_sym
from ._derivatives_sym import (
    DERIVATIVES_MAX_DOF,
    acceleration_bias_sym,
    gravity_derivatives_sym,
    hessian_slice_sym,
    jacobian_dot_sym,
    kinematic_hessian_sym,
    rnea_derivative_entry_sym,
    rnea_derivatives_sym,
)
from ._base_params import SymbolicBaseParameters, base_parameters_sym, compare_base_parameters
from ._recursive import HAND_FORM_MAX_DOF, RecursiveDynamics, dynamics_form, format_recursive, recursive_dynamics
from ._lagrange import LagrangeSteps, lagrange_steps, time_derivative
from ._newton_euler import NewtonEulerSteps, newton_euler_dynamics
from ._kinematics import dh_matrix_sym, forward_kinematics_sym, link_matrices_sym, link_transforms_sym
from ._jacobians import (
    analytic_jacobian_sym,
    angle_rate_matrix_sym,
    angle_symbols,
    differentiation_jacobian_sym,
    geometric_jacobian_sym,
    jacobian_base_from_tool_sym,
    jacobian_sym,
    jacobian_tool_from_base_sym,
    propagation_jacobian_sym,
    reduce_trig,
)
from ._propagation import (
    ForcePropagationSym,
    VelocityPropagationSym,
    force_propagation_sym,
    velocity_propagation_sym,
    wrench_symbols,
)
from ._singularities import singularity_analysis
from ._singular_types import SingularCondition, SingularityAnalysis, SingularSolution
from ._simplify import POLICIES, shorthand, shorthand_matrix, simplify_expr, simplify_matrix
from ._symbols import JointSymbols, exact_or_float, joint_symbols, matrix_from_floats, parameter_symbols, row_expressions

__all__ = [
    "analytic_jacobian_sym",
    "angle_rate_matrix_sym",
    "angle_symbols",
    "IKDerivation",
    "IKStep",
    "ik_derivation",
    "DynamicsTerms",
    "christoffel_matrix",
    "christoffel_symbols",
    "format_dynamics",
    "inertial_pieces",
    "lagrangian_dynamics",
    "fourier_form",
    "PARAMETER_NAMES",
    "regressor_sym",
    "DERIVATIVES_MAX_DOF",
    "acceleration_bias_sym",
    "gravity_derivatives_sym",
    "hessian_slice_sym",
    "jacobian_dot_sym",
    "kinematic_hessian_sym",
    "rnea_derivative_entry_sym",
    "rnea_derivatives_sym",
    "SymbolicBaseParameters",
    "base_parameters_sym",
    "compare_base_parameters",
    "RecursiveDynamics",
    "format_recursive",
    "HAND_FORM_MAX_DOF",
    "dynamics_form",
    "recursive_dynamics",
    "LagrangeSteps",
    "lagrange_steps",
    "time_derivative",
    "NewtonEulerSteps",
    "newton_euler_dynamics",
    "dh_matrix_sym",
    "differentiation_jacobian_sym",
    "geometric_jacobian_sym",
    "jacobian_base_from_tool_sym",
    "jacobian_sym",
    "jacobian_tool_from_base_sym",
    "propagation_jacobian_sym",
    "reduce_trig",
    "ForcePropagationSym",
    "VelocityPropagationSym",
    "force_propagation_sym",
    "velocity_propagation_sym",
    "wrench_symbols",
    "SingularCondition",
    "SingularityAnalysis",
    "SingularSolution",
    "singularity_analysis",
    "forward_kinematics_sym",
    "link_matrices_sym",
    "link_transforms_sym",
    "POLICIES",
    "shorthand",
    "shorthand_matrix",
    "simplify_expr",
    "simplify_matrix",
    "JointSymbols",
    "joint_symbols",
    "matrix_from_floats",
    "exact_or_float",
    "parameter_symbols",
    "row_expressions",
]
