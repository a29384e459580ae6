"""Calibration and identification: the arm's DH parameters and inertial parameters fitted to measurements.

- :func:`calibrate`: kinematic calibration, the DH table, base and tool fitted to measured poses or positions.
- :func:`error_model`: the arm as elementary motions with an unknown correction each, its pose and
  identification Jacobian (what :func:`calibrate` fits).
- :func:`read_measurements` / :func:`write_measurements`: the measurement CSV files (joint readings, poses,
  positions, torques) shared by every command of this package.
- :func:`excitation_trajectory`: a finite-Fourier-series trajectory within the joint limits that makes the base
  regressor well conditioned (what to run on the arm before :func:`identify`).
- :func:`identify`: dynamic identification, the base inertial parameters (OLS/WLS, σ, observability) from
  torques measured along a motion; :func:`physical_parameters` the realisable full set nearest to it, and
  :func:`robot_with_parameters` the arm that carries a full set.
"""

from ._measurements import Measurements, read_measurements, write_measurements
from ._kinematic_model import ErrorModel, error_model
from ._kinematic import CalibrationResult, ParameterEstimate, ResidualStats, WorstPose, calibrate
from ._excite import ExcitationTrajectory, excitation_trajectory, fourier_series
from ._identify import Identification, identify
from ._physical import PhysicalEstimate, physical_parameters, robot_with_parameters

__all__ = ["Measurements", "read_measurements", "write_measurements", "calibrate", "CalibrationResult",
           "ParameterEstimate", "ResidualStats", "WorstPose", "ErrorModel", "error_model",
           "ExcitationTrajectory", "excitation_trajectory", "fourier_series", "Identification", "identify",
           "PhysicalEstimate", "physical_parameters", "robot_with_parameters"]
