"""Peer-library models for the benchmarks (see denavit.peers)."""

from denavit.peers import expand_q, to_pinocchio
from denavit.peers import to_roboticstoolbox as to_rtb

__all__ = ["expand_q", "to_pinocchio", "to_rtb"]
