"""The exported C kernels (`denavit export --lang c`) against Pinocchio's C++, timed in one C++ program.

Run:  python benchmarks/bench_c.py [--rounds 15] [--number 20000] [--native]
Prints a Markdown table per arm: ns per call of each denavit C function and of the Pinocchio function computing the
same quantity, their ratio, and the largest difference between the two results (checked before timing).

Pinocchio's headers and library come from the `pin` wheel (its cmeel prefix under site-packages); Eigen (with its
unsupported/ Tensor module, which Pinocchio includes) from that prefix (`pip install cmeel-eigen`) or /usr/include/eigen3.  Without them, or without gcc/g++, the script prints
one line saying what is missing and exits.  The Pinocchio model is the one `denavit.peers.to_pinocchio` builds,
written out as C++ (joints, placements, inertias, armature, gravity, the end-effector frame); friction is removed from
the arm before export (Pinocchio's algorithms have none).  Both sides are compiled with the same flags (-O3, and
-march=native with --native): Pinocchio's templates are instantiated in this program (PINOCCHIO_ENABLE_TEMPLATE_
INSTANTIATION left undefined), not taken from the wheel's library.  Denavit and Pinocchio take turns within each round; the best round counts.

  FK    arm_fk (4×4 of the tool)              forwardKinematics (joint placements)
  J     arm_jacobian0                          computeFrameJacobian(ee, LOCAL_WORLD_ALIGNED) (includes its FK)
  RNEA  arm_rnea                               rnea
  CRBA  arm_mass_matrix (full)                 crba (upper triangle)
  ABA   arm_forward_dynamics                   aba
  dRNEA arm_rnea_derivatives                   computeRNEADerivatives
  dABA  arm_forward_dynamics_derivatives       computeABADerivatives
  dJ    arm_jacobian_dot0                      computeJointJacobiansTimeVariation + getFrameJacobianTimeVariation
  Y     arm_regressor                          computeJointTorqueRegressor
(the last four when those kernels are registered in this denavit)
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import shutil
import site
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import denavit
from denavit.codegen import KERNEL_NAMES, export_sources, registered_kernels
from _peers import to_pinocchio

ROBOTS = ("puma560", "panda")
#: op -> (denavit kernel, its arguments, Pinocchio call(s), result compared: (ours expression, theirs expression, n))
OPS = {
    "FK": ("fk", "q", "pinocchio::forwardKinematics(model, data, q);", ("fid", 4)),
    "J": ("jacobian0", "q", "pinocchio::computeFrameJacobian(model, data, q, fid, pinocchio::LOCAL_WORLD_ALIGNED, J);",
          ("J", 6)),
    "RNEA": ("rnea", "q, v, a", "pinocchio::rnea(model, data, q, v, a);", ("data.tau", 1)),
    "CRBA": ("mass_matrix", "q", "pinocchio::crba(model, data, q);", ("M_upper", 0)),
    "ABA": ("forward_dynamics", "q, v, tau", "pinocchio::aba(model, data, q, v, tau);", ("data.ddq", 1)),
    "dRNEA": ("rnea_derivatives", "q, v, a", "pinocchio::computeRNEADerivatives(model, data, q, v, a);",
              ("data.dtau_dq", 2)),
    "dABA": ("forward_dynamics_derivatives", "q, v, tau", "pinocchio::computeABADerivatives(model, data, q, v, tau);",
             ("data.ddq_dq", 3)),
    "dJ": ("jacobian_dot0", "q, v", "pinocchio::computeJointJacobiansTimeVariation(model, data, q, v); "
           "pinocchio::getFrameJacobianTimeVariation(model, data, fid, pinocchio::LOCAL_WORLD_ALIGNED, dJ);",
           ("dJ", 6)),
    "Y": ("regressor", "q, v, a", "pinocchio::computeJointTorqueRegressor(model, data, q, v, a);", None),
}
HEADERS = ["kinematics", "frames", "jacobian", "rnea", "crba", "aba", "rnea-derivatives", "aba-derivatives",
           "regressor"]


def _prefix() -> Path | None:
    for root in site.getsitepackages() + [site.getusersitepackages()]:
        p = Path(root) / "cmeel.prefix"
        if (p / "include" / "pinocchio" / "algorithm" / "rnea.hpp").is_file():
            return p
    return None


def _eigen(prefix: Path) -> Path | None:
    candidates = [prefix / "include" / "eigen3", Path("/usr/include/eigen3"), Path("/usr/local/include/eigen3")]
    return next((c for c in candidates if (c / "unsupported" / "Eigen" / "CXX11" / "Tensor").is_file()), None)


def _cpp(x) -> str:
    return repr(float(x))


def model_source(model, fid: int) -> str:
    """C++ statements rebuilding the Pinocchio ``model`` (joints RZ/PZ, placements, inertias, armature, gravity) and
    its frame ``fid``."""
    def se3(M):
        R, p = M.rotation, M.translation
        rot = ", ".join(_cpp(v) for v in R.flatten())
        return f"SE3((Eigen::Matrix3d() << {rot}).finished(), Eigen::Vector3d({', '.join(_cpp(v) for v in p)}))"

    lines = []
    for i in range(1, model.njoints):
        kind = {"JointModelRZ": "JointModelRZ", "JointModelPZ": "JointModelPZ"}[model.joints[i].shortname()]
        lines.append(f"  model.addJoint({model.parents[i]}, pinocchio::{kind}(), {se3(model.jointPlacements[i])}, "
                     f"\"j{i}\");")
        Y = model.inertias[i]
        inertia = ", ".join(_cpp(v) for v in Y.inertia.flatten())
        lines.append(f"  model.inertias[{i}] = pinocchio::Inertia({_cpp(Y.mass)}, Eigen::Vector3d("
                     f"{', '.join(_cpp(v) for v in Y.lever)}), (Eigen::Matrix3d() << {inertia}).finished());")
    f = model.frames[fid]
    lines.append(f"  fid = model.addFrame(pinocchio::Frame(\"ee\", {f.parentJoint}, 0, {se3(f.placement)}, "
                 "pinocchio::OP_FRAME));")
    lines.append(f"  model.gravity.linear(Eigen::Vector3d({', '.join(_cpp(v) for v in model.gravity.linear)}));")
    lines.append(f"  model.armature = (Eigen::VectorXd({model.nv}) << "
                 f"{', '.join(_cpp(v) for v in model.armature)}).finished();")
    return "\n".join(lines)


def robot_function(name: str, n: int, model_code: str, ops: dict, q, v, a) -> str:
    """C++ ``void bench_<name>()``: builds the model, checks each op's result against Pinocchio's, times both."""
    vec = lambda x: ", ".join(_cpp(t) for t in x)  # noqa: E731
    blocks = []
    for op, (kernel, args, pin_call, compare) in ops.items():
        size = _size(kernel, n)
        check = "0.0"
        if compare is not None:
            theirs, kind = compare
            check = (f"maxdiff_4(ours, model, data, fid)" if kind == 4 else f"maxdiff_{kind}(ours, {theirs}, {n})")
        blocks.append(f"""
  {{
    std::vector<double> ours({size});
    {name}_{kernel}({_cptr(args)}, ours.data());
    {pin_call}
    double diff = {check};
    double t_ours = 1e30, t_pin = 1e30, sink = 0.0;
    for (int r = 0; r < ROUNDS; ++r) {{
      auto t0 = clk::now();
      for (int i = 0; i < NUMBER; ++i) {{ {name}_{kernel}({_cptr(args)}, ours.data()); sink += ours[0]; }}
      auto t1 = clk::now();
      for (int i = 0; i < NUMBER; ++i) {{ {pin_call} sink += data.oMi[1].translation()[0]; }}
      auto t2 = clk::now();
      t_ours = std::min(t_ours, std::chrono::duration<double, std::nano>(t1 - t0).count() / NUMBER);
      t_pin = std::min(t_pin, std::chrono::duration<double, std::nano>(t2 - t1).count() / NUMBER);
    }}
    SINK += sink;
    std::printf("{name} {op} %.1f %.1f %.3g\\n", t_ours, t_pin, diff);
  }}""")
    return f"""
void bench_{name}() {{
  pinocchio::Model model;
  pinocchio::FrameIndex fid = 0;
{model_code}
  pinocchio::Data data(model);
  Eigen::VectorXd q({n}), v({n}), a({n}), tau({n});
  q << {vec(q)}; v << {vec(v)}; a << {vec(a)};
  tau = pinocchio::rnea(model, data, q, v, a);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, {n}), dJ = Eigen::MatrixXd::Zero(6, {n});
  const Eigen::MatrixXd& M_upper = data.M;
{''.join(blocks)}
}}
"""


def program(functions: list[str], names: list[str], rounds: int, number: int) -> str:
    """The whole C++ program: the helpers, one function per arm, main calling them in turn."""
    return f"""// generated by benchmarks/bench_c.py
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>
{chr(10).join(f'#include <pinocchio/algorithm/{h}.hpp>' for h in HEADERS)}
extern "C" {{
{''.join(f'#include "{nm}.h"{chr(10)}' for nm in names)}}}
using pinocchio::SE3;
using clk = std::chrono::steady_clock;
static const int ROUNDS = {rounds}, NUMBER = {number};
volatile double SINK = 0.0;

// largest |ours - theirs| over an n-vector (kind 1), a 6 x n matrix (6), the upper triangle of n x n (0),
// dtau/dq then dtau/dv (2), ddq/dq then ddq/dv (3), the end-effector pose after forwardKinematics (4)
static double maxdiff_1(const std::vector<double>& o, const Eigen::VectorXd& t, int n) {{
  double m = 0; for (int i = 0; i < n; ++i) m = std::max(m, std::fabs(o[i] - t[i])); return m; }}
static double maxdiff_6(const std::vector<double>& o, const Eigen::MatrixXd& t, int n) {{
  double m = 0; for (int r = 0; r < 6; ++r) for (int c = 0; c < n; ++c) m = std::max(m, std::fabs(o[r * n + c] - t(r, c)));
  return m; }}
static double maxdiff_0(const std::vector<double>& o, const Eigen::MatrixXd& t, int n) {{
  double m = 0; for (int r = 0; r < n; ++r) for (int c = r; c < n; ++c) m = std::max(m, std::fabs(o[r * n + c] - t(r, c)));
  return m; }}
static double maxdiff_pair(const std::vector<double>& o, const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, int n) {{
  double m = 0; for (int r = 0; r < n; ++r) for (int c = 0; c < n; ++c)
    m = std::max(m, std::max(std::fabs(o[r * n + c] - a(r, c)), std::fabs(o[n * n + r * n + c] - b(r, c))));
  return m; }}

static double maxdiff_4(const std::vector<double>& o, const pinocchio::Model& model, pinocchio::Data& data,
                        pinocchio::FrameIndex fid) {{
  const Eigen::Matrix4d T = pinocchio::updateFramePlacement(model, data, fid).toHomogeneousMatrix();
  double m = 0; for (int r = 0; r < 4; ++r) for (int c = 0; c < 4; ++c) m = std::max(m, std::fabs(o[r * 4 + c] - T(r, c)));
  return m; }}

#define maxdiff_2(o, t, n) maxdiff_pair(o, data.dtau_dq, data.dtau_dv, n)
#define maxdiff_3(o, t, n) maxdiff_pair(o, data.ddq_dq, data.ddq_dv, n)
{''.join(functions)}
int main() {{
{''.join(f"  bench_{nm}();{chr(10)}" for nm in names)}  return SINK == 12345.678;
}}
"""


def _cptr(args: str) -> str:
    return ", ".join(f"{a.strip()}.data()" for a in args.split(","))


def _size(kernel: str, n: int) -> int:
    shapes = {"fk": 16, "jacobian0": 6 * n, "rnea": n, "mass_matrix": n * n, "forward_dynamics": n + 1}
    if kernel in shapes:
        return shapes[kernel]
    return int(np.prod(registered_kernels()[kernel].shape(n)))


#: what Pinocchio's CMake config gives its users (boost::variant of 25 joint types needs the larger MPL limits)
DEFINES = ["-DNDEBUG", "-DBOOST_MPL_LIMIT_LIST_SIZE=30", "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
           "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "-DBOOST_FUSION_INVOKE_MAX_ARITY=12"]


def without_friction(robot):
    """The arm with every joint's viscous and Coulomb friction set to 0 (Pinocchio's algorithms have none)."""
    links = tuple(dataclasses.replace(k, inertia=dataclasses.replace(k.inertia, viscous=0.0, coulomb=0.0))
                  if k.inertia is not None else k for k in robot.links)
    return dataclasses.replace(robot, links=links)


def run(names, prefix: Path, eigen: Path, rounds: int, number: int, native: bool) -> list:
    """Export each arm's kernels (prefix = its name), write and build one C++ program, run it; the rows."""
    reg = registered_kernels()
    ops = {op: spec for op, spec in OPS.items() if spec[0] in KERNEL_NAMES or spec[0] in reg}
    flags = ["-O3"] + (["-march=native"] if native else [])
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        functions = []
        for name in names:
            robot = without_friction(denavit.load_robot(name))
            for fname, text in export_sources(robot, "c", name, kernels=[s[0] for s in ops.values()]).items():
                (work / fname).write_text(text)
            subprocess.run(["gcc", *flags, "-std=c99", "-c", f"{name}.c", "-o", f"{name}.o"], cwd=work, check=True)
            model, _, fid = to_pinocchio(robot)
            rng = np.random.default_rng(0)
            q, v, a = (rng.uniform(-1, 1, robot.dof) for _ in range(3))
            functions.append(robot_function(name, robot.dof, model_source(model, fid), ops, q, v, a))
        (work / "bench.cpp").write_text(program(functions, list(names), rounds, number))
        lib = prefix / "lib"
        subprocess.run(["g++", *flags, "-std=c++17", *DEFINES, "bench.cpp", *[f"{nm}.o" for nm in names], "-o", "bench",
                        f"-I{prefix / 'include'}", f"-I{eigen}", f"-L{lib}", "-lpinocchio_default",
                        f"-Wl,-rpath,{lib}", "-lm"], cwd=work, check=True)
        out = subprocess.run([str(work / "bench")], cwd=work, capture_output=True, text=True, check=True).stdout
    rows = []
    for line in out.split("\n"):
        if line.strip():
            name, op, ours, theirs, diff = line.split()
            rows.append((name, op, float(ours), float(theirs), float(diff)))
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--number", type=int, default=20000)
    ap.add_argument("--native", action="store_true", help="compile both sides with -march=native")
    args = ap.parse_args()
    prefix = _prefix()
    eigen = _eigen(prefix) if prefix else None
    missing = [what for what, ok in (("Pinocchio's C++ headers (pip install pin)", prefix),
                                     ("Eigen headers with unsupported/ (pip install cmeel-eigen)", eigen), ("gcc", shutil.which("gcc")),
                                     ("g++", shutil.which("g++"))) if not ok]
    if missing:
        print(f"bench_c: skipped, missing {', '.join(missing)}")
        return
    import pinocchio as pin

    print(f"gcc/g++ {'-O3 -march=native' if args.native else '-O3'}, Pinocchio {pin.__version__}, "
          f"load average {os.getloadavg()[0]:.1f}\n")
    print("| robot | op | denavit C [ns] | Pinocchio C++ [ns] | ratio | max abs difference |")
    print("|---|---|---:|---:|---:|---:|")
    print("(compiling Pinocchio's headers takes minutes)", file=sys.stderr)
    for r in run(ROBOTS, prefix, eigen, args.rounds, args.number, args.native):
        diff = "—" if r[1] == "Y" else f"{r[4]:.1e}"
        print(f"| {r[0]} | {r[1]} | {r[2]:.0f} | {r[3]:.0f} | {r[2] / r[3]:.2f} | {diff} |")


if __name__ == "__main__":
    main()
