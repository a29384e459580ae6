"""Jacobian speed: denavit (three numeric routes) against Pinocchio and roboticstoolbox-python, same run.

Run on demand:  python benchmarks/bench_jacobian.py [--write docs/jacobians.md]
Robot: the catalogue PUMA 560 (standard DH) and the same arm built in each peer. Single call: one
configuration, median over repeats. Batch: BATCH random configurations; denavit takes them in one call
(..., 6), the peers (no batch API for these functions) in a Python loop. Peers' results are checked
against ours before timing.
"""

from __future__ import annotations

import argparse
import platform
import re
import time
from pathlib import Path

import numpy as np

import denavit
from denavit import numeric as N

BATCH = 10_000
REPEATS = 7


def _median_time(fn, repeats: int = REPEATS, number: int = 1) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t0) / number)
    return float(np.median(times))


def pinocchio_model(robot):
    import pinocchio as pin

    model = pin.Model()
    parent, pending = 0, robot.base_matrix
    for k, link in enumerate(robot.links):  # standard DH: Rz(θ0) Tz(d) | joint | Tx(a) Rx(α)
        place = pending @ N.dh_transform(robot.convention, link.theta, link.d, 0.0, 0.0)
        parent = model.addJoint(parent, pin.JointModelRZ(), pin.SE3(place[:3, :3], place[:3, 3]), f"j{k}")
        model.appendBodyToJoint(parent, pin.Inertia.Random(), pin.SE3.Identity())
        pending = N.dh_transform(robot.convention, 0.0, 0.0, link.a, link.alpha)
    tip = pending @ robot.tool_matrix
    fid = model.addFrame(pin.Frame("ee", parent, 0, pin.SE3(tip[:3, :3], tip[:3, 3]), pin.FrameType.OP_FRAME))
    return model, fid


def run() -> list[tuple[str, str, float, float]]:
    robot = denavit.load_robot("puma560")
    rng = np.random.default_rng(0)
    qs = rng.uniform(-np.pi, np.pi, (BATCH, 6))
    q = qs[0]
    rows = []
    for name, fn in [("denavit geometric_jacobian", N.geometric_jacobian),
                     ("denavit differentiation_jacobian", N.differentiation_jacobian),
                     ("denavit propagation_jacobian", N.propagation_jacobian)]:
        single = _median_time(lambda: fn(robot, q), number=200)
        batch = _median_time(lambda: fn(robot, qs), repeats=5)
        rows.append((name, "J0 / batched call", single, batch / BATCH))
    try:
        import pinocchio as pin

        model, fid = pinocchio_model(robot)
        data = model.createData()

        def pin_j(x):
            pin.computeJointJacobians(model, data, x)
            pin.updateFramePlacements(model, data)
            return pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)

        assert np.allclose(pin_j(q), N.geometric_jacobian(robot, q), atol=1e-9)
        single = _median_time(lambda: pin_j(q), number=2000)
        sub = qs[:2000]
        loop = _median_time(lambda: [pin_j(x) for x in sub], repeats=5)
        rows.append((f"Pinocchio {pin.__version__} (C++)", "getFrameJacobian, Python loop", single, loop / len(sub)))
    except ImportError:
        rows.append(("Pinocchio", "not installed", float("nan"), float("nan")))
    try:
        import roboticstoolbox as rtb

        peer = rtb.models.DH.Puma560()
        assert np.allclose(peer.jacob0(q), N.geometric_jacobian(robot, q), atol=1e-9)
        single = _median_time(lambda: peer.jacob0(q), number=200)
        sub = qs[:500]
        loop = _median_time(lambda: [peer.jacob0(x) for x in sub], repeats=3)
        rows.append((f"roboticstoolbox-python {rtb.__version__}", "DHRobot.jacob0, Python loop", single, loop / len(sub)))
    except ImportError:
        rows.append(("roboticstoolbox-python", "not installed", float("nan"), float("nan")))
    return rows


def table(rows) -> str:
    lines = ["| implementation | how | single call [µs] | per configuration in a batch of many [µs] |",
             "|---|---|---:|---:|"]
    for name, how, single, per in rows:
        lines.append(f"| {name} | {how} | {single * 1e6:.1f} | {per * 1e6:.2f} |")
    lines.append("")
    lines.append(f"PUMA 560, 6 joints; batch of {BATCH} configurations for denavit; numpy {np.__version__}, "
                 f"Python {platform.python_version()}, {platform.machine()}, measured {time.strftime('%Y-%m-%d')} "
                 "on a shared machine (other jobs running), so read ratios rather than absolute times.")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--write", metavar="MD", help="replace the benchmark section of this Markdown file")
    args = ap.parse_args()
    text = table(run())
    print(text)
    if args.write:
        path = Path(args.write)
        doc = path.read_text()
        new = re.sub(r"(<!-- bench:start -->\n).*?(<!-- bench:end -->)", lambda m: m.group(1) + text + "\n" + m.group(2),
                     doc, flags=re.S)
        path.write_text(new)


if __name__ == "__main__":
    main()
