"""denavit's torch and JAX backends against pytorch_kinematics, and jax.jit against the numba batch kernel, in one run.

Run:  python benchmarks/bench_tensor.py [--robots puma560 panda] [--batches 10000 1000000] [--repeat 3]
                                        [--only torch|jax]
Prints a Markdown table of ratios (peer time / denavit time: > 1 means denavit is faster), one process pinned to
one CPU core (os.sched_setaffinity, before any library starts its threads: XLA then plans no parallel loops),
torch.set_num_threads(1), numba threads=1, so the figures compare the code and not how many of the machine's
cores each one grabs.  Times are the process's CPU time (time.process_time), not wall time: on a loaded machine a
call longer than the scheduler's slice is preempted, and best-of wall times then favour the shorter calls.

Both sides get the same arm: pytorch_kinematics builds its serial chain from denavit's URDF export of the robot
(``denavit.to_urdf``), and its results are first checked to equal denavit's (FK and J0 to 1e-6 in float64: the URDF
holds the numbers as printed, 1e-8 apart) on the
configurations timed.  Rows, each batch size × dtype:
  FK        fast.fk(q) → (B, 4, 4)                  chain.forward_kinematics(q).get_matrix()
  J         fast.jacobian(q) → (B, 6, n), J0         chain.jacobian(q) (base axes, end-effector origin: J0)
  FK f+b    T = fk(q) with q.requires_grad; T.sum().backward(): forward and backward pass, both libraries
  jax.jit   jax.jit(fast.fk) on a jax array (float64, and float32 at the same rounded q) against the numba
            backend's batch fk(q, threads=1) on the float64 NumPy array (numba's kernels are float64 only);
            ratio = numba time / jax time: ≥ 0.5 is "within 2×"; "(out=)": numba writing into a preallocated
            array, its kernel's work alone (XLA allocates its output and temporaries on every call: at 10⁶ rows
            most of both sides' allocating time is the kernel's page faults, which vary from process to process)
  (donated) jax.jit(lambda q, T: fast.fk(q), donate_argnums=1, keep_unused=True) called as T = fk(q, T), XLA
            writing into the previous result's buffer (JAX's counterpart of out=), against numba's out= call
  XLA floor jax.jit of a function that only fills a fresh (B, 4, 4) array (one pass, no arithmetic) against the
            same numba call: what returning a fresh array costs plain XLA code (at 10⁶ rows, a page fault per 4 KB
            on Linux), which denavit's blocks avoid by advising their result buffer huge pages
Each time is the best of ``repeat`` calls (after one warm-up call each, which also compiles), the libraries taking
turns.
"""

from __future__ import annotations

import argparse
import os
import re
import time

if hasattr(os, "sched_setaffinity"):  # one core for the whole process (Linux), before jax, torch, numba start
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
os.environ.setdefault("XLA_FLAGS", "--xla_cpu_multi_thread_eigen=false")

import numpy as np  # noqa: E402

import denavit  # noqa: E402


def once(fn) -> float:
    """CPU seconds of one call (all the process's threads: on one core, the work the call did)."""
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def best_pair(ours, theirs, repeat: int) -> tuple[float, float]:
    """Best of ``repeat`` timed calls of each, after one warm-up call each (which also compiles), taking turns so
    that a change of the machine's load hits both."""
    ours(), theirs()
    t_ours = t_theirs = np.inf
    for _ in range(repeat):
        t_ours, t_theirs = min(t_ours, once(ours)), min(t_theirs, once(theirs))
    return t_ours, t_theirs


def pk_chain(robot, dtype):
    """pytorch_kinematics' serial chain of the robot, from denavit's URDF (its last link is the tool)."""
    import pytorch_kinematics as pk

    text = denavit.to_urdf(robot)
    end = re.findall(r'<link name="([^"]+)"', text)[-1]
    return pk.build_serial_chain_from_urdf(text.encode(), end).to(dtype=dtype)


def check_agreement(fast, chain, q) -> None:
    T = fast.fk(q)
    T_pk = chain.forward_kinematics(q).get_matrix()
    J, J_pk = fast.jacobian(q), chain.jacobian(q)
    for what, a, b in (("FK", T, T_pk), ("J0", J, J_pk)):
        err = float((a - b).abs().max())
        if err > 1e-6:  # the URDF holds the numbers as printed (about 9 digits): 1e-8 differences
            raise SystemExit(f"pytorch_kinematics and denavit disagree on {what}: max difference {err:.3g}")


def fwd_bwd(fk, q):
    def run():
        x = q.detach().requires_grad_()
        fk(x).sum().backward()
        return x.grad

    return run


def torch_rows(robot, batch: int, repeat: int, rng):
    import torch

    fast = denavit.compile(robot, backend="torch")
    rows = []
    for dtype in (torch.float32, torch.float64):
        chain = pk_chain(robot, dtype)
        q = torch.tensor(rng.uniform(-np.pi, np.pi, (batch, robot.dof)), dtype=dtype)
        if dtype == torch.float64:
            check_agreement(fast, chain, q[:1000])
        pairs = {"FK": (lambda: fast.fk(q), lambda: chain.forward_kinematics(q).get_matrix()),
                 "J": (lambda: fast.jacobian(q), lambda: chain.jacobian(q)),
                 "FK f+b": (fwd_bwd(fast.fk, q), fwd_bwd(lambda x: chain.forward_kinematics(x).get_matrix(), q))}
        for op, (ours, theirs) in pairs.items():
            t_ours, t_pk = best_pair(ours, theirs, repeat)
            rows.append((robot.name, op, batch, str(dtype).split(".")[-1], t_pk / t_ours))
    return rows


def jax_rows(robot, batch: int, repeat: int, rng):
    import jax

    rows = []
    with jax.enable_x64(True):
        fast = denavit.compile(robot, backend="jax", kernels=["fk"])
        nb = denavit.compile(robot, backend="numba", kernels=["fk"])
        q = rng.uniform(-np.pi, np.pi, (batch, robot.dof))
        fk = jax.jit(fast.fk)
        for dtype, tol in ((np.float64, 1e-12), (np.float32, 1e-5)):
            qj = jax.numpy.asarray(q.astype(dtype))
            np.testing.assert_allclose(np.asarray(fk(qj)), nb.fk(q.astype(dtype).astype(np.float64)), atol=tol)
            out = np.empty((batch, 4, 4))
            for _ in range(3):  # XLA's first calls after compiling ran slower (the process's first jax row: 2x)
                fk(qj).block_until_ready()
            t_jax, t_nb = best_pair(lambda: fk(qj).block_until_ready(), lambda: nb.fk(q, threads=1), repeat)
            rows.append((robot.name, "jax.jit FK vs numba", batch, dtype.__name__, t_nb / t_jax))
            t_jax, t_nb = best_pair(lambda: fk(qj).block_until_ready(), lambda: nb.fk(q, threads=1, out=out), repeat)
            rows.append((robot.name, "jax.jit FK vs numba (out=)", batch, dtype.__name__, t_nb / t_jax))
            into = jax.jit(lambda q, T: fast.fk(q), donate_argnums=1, keep_unused=True)
            T = [into(qj, fk(qj))]
            for _ in range(3):
                T[0] = into(qj, T[0]).block_until_ready()

            def donated():
                T[0] = into(qj, T[0]).block_until_ready()

            t_jax, t_nb = best_pair(donated, lambda: nb.fk(q, threads=1, out=out), repeat)
            rows.append((robot.name, "jax.jit FK, result donated, vs numba (out=)", batch, dtype.__name__,
                         t_nb / t_jax))
            fill = jax.jit(lambda x: jax.numpy.broadcast_to(x[..., :1, None], x.shape[:-1] + (4, 4)) + 0.0)
            for _ in range(4):
                fill(qj).block_until_ready()
            t_fill, t_nb = best_pair(lambda: fill(qj).block_until_ready(), lambda: nb.fk(q, threads=1), repeat)
            rows.append((robot.name, "XLA floor: fresh (B, 4, 4) output alone vs numba", batch, dtype.__name__,
                         t_nb / t_fill))
    return rows


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robots", nargs="+", default=["puma560", "panda"])
    p.add_argument("--batches", nargs="+", type=float, default=[1e4, 1e6])
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--only", choices=("torch", "jax"), help="only the rows of one framework")
    args = p.parse_args(argv)
    import torch

    torch.set_num_threads(1)
    rng = np.random.default_rng(0)
    rows = []
    for name in args.robots:
        robot = denavit.load_robot(name)
        for batch in (int(b) for b in args.batches):
            if args.only != "jax":
                rows += torch_rows(robot, batch, args.repeat, rng)
            if args.only != "torch":
                rows += jax_rows(robot, batch, args.repeat, rng)
            print(f"... {name} batch {batch} done", flush=True)
    from importlib.metadata import version

    print(f"\ntorch {torch.__version__}, pytorch_kinematics {version('pytorch_kinematics')}, jax {version('jax')}, "
          f"numba {version('numba')}; one core, CPU time\n")
    print("| robot | operation | batch | dtype | ratio (peer time / denavit time) |")
    print("|---|---|---|---|---|")
    for name, op, batch, dtype, ratio in rows:
        print(f"| {name} | {op} | {batch:.0e} | {dtype} | {ratio:.3g} |")


if __name__ == "__main__":
    main()
