"""Kinematic derivatives, single call: compiled denavit against Pinocchio in the same process.

Run on demand:  python benchmarks/bench_kin_derivatives.py [--repeat 7] [--number 20000]

For the Puma 560 and the Panda (catalogue arms; the Pinocchio model from denavit.peers.to_pinocchio), one
configuration per call, from Python:

- J̇ in base axes: ``fast.jacobian_dot(q, qd)`` against ``computeJointJacobiansTimeVariation`` +
  ``updateFramePlacements`` + ``getFrameJacobianTimeVariation(LOCAL_WORLD_ALIGNED)`` (what a Pinocchio user calls
  for the end-effector frame), and against ``computeJointJacobiansTimeVariation`` alone (Pinocchio's bare pass,
  a lower bound: it stores every joint's J̇ but hands back none);
- the acceleration bias J̇q̇ against ``forwardKinematics(q, qd, 0)`` + ``getFrameClassicalAcceleration``;
- ∂J/∂q against ``computeJointKinematicHessians`` + ``getFrameKinematicHessian(LOCAL_WORLD_ALIGNED)``.

Results are checked against each other before timing.  Times: best over rounds of the mean of ``number``
calls, the contenders taking turns within each round (the machine is shared: read the ratios, and the load
average printed with them).
"""

from __future__ import annotations

import argparse
import os

import numpy as np

import denavit
from _peers import best_times, to_pinocchio


def _pin_calls(pin, model, data, fid, q, qd):
    zero = np.zeros(model.nv)
    LWA = pin.LOCAL_WORLD_ALIGNED

    def jdot():
        pin.computeJointJacobiansTimeVariation(model, data, q, qd)
        pin.updateFramePlacements(model, data)
        return pin.getFrameJacobianTimeVariation(model, data, fid, LWA)

    def jdot_bare():
        pin.computeJointJacobiansTimeVariation(model, data, q, qd)

    def bias():
        pin.forwardKinematics(model, data, q, qd, zero)
        return pin.getFrameClassicalAcceleration(model, data, fid, LWA).vector

    def hessian():
        pin.computeJointKinematicHessians(model, data, q)
        pin.updateFramePlacements(model, data)
        return pin.getFrameKinematicHessian(model, data, fid, LWA)

    return jdot, jdot_bare, bias, hessian


def bench(name: str, repeat: int, number: int) -> list[tuple[str, float, float, float]]:
    import pinocchio as pin

    robot = denavit.load_robot(name)
    fast = denavit.compile(robot)
    rng = np.random.default_rng(0)
    q, qd = rng.uniform(-1.0, 1.0, robot.dof), rng.normal(size=robot.dof)
    model, data, fid = to_pinocchio(robot)
    p_jdot, p_bare, p_bias, p_hess = _pin_calls(pin, model, data, fid, q, qd)
    n = robot.dof
    # agreement first (Pinocchio 4.1's Python binding hands the Hessian tensor back in column-major order)
    assert np.abs(fast.jacobian_dot(q, qd) - p_jdot()).max() < 1e-9
    assert np.abs(fast.acceleration_bias(q, qd) - p_bias()).max() < 1e-9
    H_pin = np.asarray(p_hess()).ravel(order="C").reshape((6, n, n), order="F")
    assert np.abs(fast.kinematic_hessian(q) - H_pin).max() < 1e-9
    rows = []
    for what, ours, theirs in (("J̇ (base)", lambda: fast.jacobian_dot(q, qd), p_jdot),
                               ("J̇ vs Pinocchio's bare pass", lambda: fast.jacobian_dot(q, qd), p_bare),
                               ("J̇q̇ (base)", lambda: fast.acceleration_bias(q, qd), p_bias),
                               ("∂J/∂q (base)", lambda: fast.kinematic_hessian(q), p_hess)):
        t_ours, t_theirs = best_times([ours, theirs], repeat, number)
        rows.append((what, t_ours * 1e6, t_theirs * 1e6, t_ours / t_theirs))
    return rows


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--number", type=int, default=20000)
    args = ap.parse_args(argv)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    print(f"{'arm':10} {'call':30} {'denavit µs':>11} {'Pinocchio µs':>13} {'ratio':>6}")
    for name in ("puma560", "panda"):
        for what, ours, theirs, ratio in bench(name, args.repeat, args.number):
            print(f"{name:10} {what:30} {ours:11.2f} {theirs:13.2f} {ratio:6.2f}")
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
