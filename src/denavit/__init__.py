"""denavit: serial robot arms from their Denavit–Hartenberg table.

The core import is light (numpy only): the symbolic engine lives in :mod:`denavit.symbolic` (sympy),
pictures in :mod:`denavit.viz` (matplotlib).
"""

from .errors import (
    DenavitError,
    DenavitWarning,
    MissingDependencyError,
    ModelError,
    ParseError,
    ShapeError,
    UnsupportedRobotError,
)
from .io import catalogue_names, dump_robot, load_robot, resolve_pose, robot_from_dict, save_robot, with_parameters
from .model import Convention, DHLink, DHRobot, Frame, JointType, LinkInertia
from ._convert import convert_convention
from .build import fixed, prismatic, revolute, robot
from .display import dh_table
from .interop import from_urdf, to_mjcf, to_urdf
from .numeric import forward_kinematics, geometric_jacobian, link_transforms
from .numeric import end_effector_twist, force_propagation, joint_torques, manipulability, velocity_propagation
from .ik import AnalyticIKResult, IKResult, analytic_ik, solve_ik
from .ik import PathResult, PathTrajectory, cartesian_line, ik_path
from .ik import FreeJointSweep, free_joint_sweep
from .numeric import coriolis_matrix, forward_dynamics, gravity_torques, mass_matrix, rnea, simulate
from .numeric import forward_dynamics_derivatives, gravity_derivatives, rnea_derivatives
from .numeric import BaseParameters, base_parameters, base_regressor, inertial_parameters, regressor
from .codegen import CompiledRobot, compile
from .calibration import Measurements, read_measurements, write_measurements
from .calibration import CalibrationResult, calibrate
from .numeric import acceleration_bias, jacobian_dot, kinematic_hessian
from .numeric import coriolis_vector, friction_torques, kinetic_energy, mass_matrix_derivatives, potential_energy
from .calibration import excitation_trajectory
from .calibration import Identification, identify

__version__ = "0.1.0"

__all__ = [
    "DenavitError",
    "DenavitWarning",
    "MissingDependencyError",
    "ModelError",
    "ParseError",
    "ShapeError",
    "UnsupportedRobotError",
    "catalogue_names",
    "dump_robot",
    "load_robot",
    "resolve_pose",
    "robot_from_dict",
    "save_robot",
    "with_parameters",
    "convert_convention",
    "revolute",
    "prismatic",
    "fixed",
    "robot",
    "dh_table",
    "from_urdf",
    "to_urdf",
    "to_mjcf",
    "Convention",
    "Frame",
    "DHLink",
    "DHRobot",
    "JointType",
    "LinkInertia",
    "forward_kinematics",
    "link_transforms",
    "geometric_jacobian",
    "jacobian_dot",
    "acceleration_bias",
    "kinematic_hessian",
    "rnea",
    "mass_matrix",
    "coriolis_matrix",
    "gravity_torques",
    "forward_dynamics",
    "rnea_derivatives",
    "regressor",
    "base_parameters",
    "base_regressor",
    "inertial_parameters",
    "BaseParameters",
    "forward_dynamics_derivatives",
    "gravity_derivatives",
    "simulate",
    "coriolis_vector",
    "friction_torques",
    "kinetic_energy",
    "potential_energy",
    "mass_matrix_derivatives",
    "end_effector_twist",
    "force_propagation",
    "joint_torques",
    "manipulability",
    "velocity_propagation",
    "AnalyticIKResult",
    "IKResult",
    "analytic_ik",
    "solve_ik",
    "ik_path",
    "cartesian_line",
    "PathResult",
    "PathTrajectory",
    "free_joint_sweep",
    "FreeJointSweep",
    "compile",
    "CompiledRobot",
    "Measurements",
    "read_measurements",
    "write_measurements",
    "calibrate",
    "CalibrationResult",
    "excitation_trajectory",
    "identify",
    "Identification",
    "__version__",
]
