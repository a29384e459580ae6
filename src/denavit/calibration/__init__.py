"""Calibration and identification: the arm's DH parameters and inertial parameters fitted to measurements.

- :func:`read_measurements` / :func:`write_measurements`: the measurement CSV files (joint readings, poses,
  positions, torques) shared by every command of this package.
"""

from ._measurements import Measurements, read_measurements, write_measurements

__all__ = ["Measurements", "read_measurements", "write_measurements"]
