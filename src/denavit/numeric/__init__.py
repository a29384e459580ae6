"""The numeric engine (numpy): every function is batched over leading axes ``(..., n)``."""

from ._jacobians import geometric_jacobian, joint_axes
from ._dynamics import (
    coriolis_matrix,
    coriolis_vector,
    forward_dynamics,
    friction_torques,
    gravity_torques,
    kinetic_energy,
    mass_matrix,
    mass_matrix_derivatives,
    potential_energy,
    rnea,
)
from ._kinematics import forward_kinematics, link_transforms
from ._transforms import (
    adjoint,
    dh_transform,
    inverse_transform,
    rotation_from_rpy,
    rotation_from_zyz,
    rotx,
    roty,
    rotz,
    rpy_from_rotation,
    skew,
    transform_from_xyz_rpy,
    zyz_from_rotation,
)

__all__ = [
    "geometric_jacobian",
    "joint_axes",
    "rnea",
    "mass_matrix",
    "mass_matrix_derivatives",
    "coriolis_matrix",
    "coriolis_vector",
    "gravity_torques",
    "friction_torques",
    "forward_dynamics",
    "kinetic_energy",
    "potential_energy",
    "forward_kinematics",
    "link_transforms",
    "adjoint",
    "dh_transform",
    "inverse_transform",
    "rotation_from_rpy",
    "rotation_from_zyz",
    "rotx",
    "roty",
    "rotz",
    "rpy_from_rotation",
    "skew",
    "transform_from_xyz_rpy",
    "zyz_from_rotation",
]
