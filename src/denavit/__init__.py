"""denavit: serial robot arms from their Denavit–Hartenberg table.

The core import is light (numpy only): the symbolic engine lives in :mod:`denavit.symbolic` (sympy),
pictures in :mod:`denavit.viz` (matplotlib).  The public names below are imported on first use (PEP 562), so
``import denavit`` — and every ``denavit`` command — loads only the parts it calls: the model and the errors at
once, IK, dynamics, the compiler, interchange formats and calibration when first named.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .errors import (
    DenavitError, DenavitWarning, MissingDependencyError, ModelError, ParseError, ShapeError, UnsupportedRobotError,
)
from .model import Convention, DHLink, DHRobot, Frame, JointType, LinkInertia

#: Where each lazily imported public name lives (module of this package → its names).
_LAZY: dict[str, tuple[str, ...]] = {
    "io": (
        "catalogue_names", "dump_robot", "load_robot", "resolve_pose", "robot_from_dict", "save_robot",
        "with_parameters",
    ),
    "_convert": ("convert_convention",),
    "build": ("fixed", "prismatic", "revolute", "robot",),
    "display": ("dh_table",),
    "interop": ("from_urdf", "to_mjcf", "to_urdf",),
    "numeric": (
        "forward_kinematics", "geometric_jacobian", "link_transforms", "end_effector_twist",
        "force_propagation", "joint_torques", "manipulability", "velocity_propagation", "coriolis_matrix",
        "forward_dynamics", "gravity_torques", "mass_matrix", "rnea", "simulate",
        "forward_dynamics_derivatives", "gravity_derivatives", "rnea_derivatives", "BaseParameters",
        "base_parameters", "base_regressor", "inertial_parameters", "regressor", "acceleration_bias",
        "jacobian_dot", "kinematic_hessian", "coriolis_vector", "friction_torques", "kinetic_energy",
        "mass_matrix_derivatives", "potential_energy",
    ),
    "ik": (
        "AnalyticIKResult", "IKResult", "analytic_ik", "solve_ik", "PathResult", "PathTrajectory",
        "cartesian_line", "ik_path", "FreeJointSweep", "free_joint_sweep",
    ),
    "codegen": ("CompiledRobot", "compile",),
    "calibration": (
        "Measurements", "read_measurements", "write_measurements", "CalibrationResult", "calibrate",
        "excitation_trajectory", "Identification", "identify",
    ),
}
_MODULE_OF = {name: module for module, names in _LAZY.items() for name in names}

if TYPE_CHECKING:  # what a type checker and an editor see: the same names, imported eagerly
    from .io import catalogue_names, dump_robot, load_robot, resolve_pose, robot_from_dict, save_robot, with_parameters
    from ._convert import convert_convention
    from .build import fixed, prismatic, revolute, robot
    from .display import dh_table
    from .interop import from_urdf, to_mjcf, to_urdf
    from .numeric import (
        forward_kinematics, geometric_jacobian, link_transforms, end_effector_twist, force_propagation,
        joint_torques, manipulability, velocity_propagation, coriolis_matrix, forward_dynamics, gravity_torques,
        mass_matrix, rnea, simulate, forward_dynamics_derivatives, gravity_derivatives, rnea_derivatives,
        BaseParameters, base_parameters, base_regressor, inertial_parameters, regressor, acceleration_bias,
        jacobian_dot, kinematic_hessian, coriolis_vector, friction_torques, kinetic_energy,
        mass_matrix_derivatives, potential_energy,
    )
    from .ik import (
        AnalyticIKResult, IKResult, analytic_ik, solve_ik, PathResult, PathTrajectory, cartesian_line, ik_path,
        FreeJointSweep, free_joint_sweep,
    )
    from .codegen import CompiledRobot, compile
    from .calibration import (
        Measurements, read_measurements, write_measurements, CalibrationResult, calibrate,
        excitation_trajectory, Identification, identify,
    )

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



def __getattr__(name: str) -> Any:
    """A public name on first use (PEP 562): import its module, keep the name here, return it.  The package's
    submodules (``denavit.numeric`` ...) resolve as attributes too, as after an eager import."""
    module = _MODULE_OF.get(name)
    if module is not None:
        value = getattr(importlib.import_module(f".{module}", __name__), name)
    elif not name.startswith("__"):
        try:
            value = importlib.import_module(f".{name}", __name__)
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":
                raise
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_MODULE_OF))
