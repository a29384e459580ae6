"""The IK half of :class:`denavit.codegen.CompiledRobot`: numeric (LM) and analytic IK on the compiled kernels."""

from __future__ import annotations

import random as _random
from dataclasses import fields

import numpy as np

from .._threads import resolve_threads, split_rows
from ..chain import chain_of
from ..errors import ShapeError
from ..ik import MAX_ITERATIONS as IK_MAX_ITERATIONS, RESTARTS as IK_RESTARTS, TOL as IK_TOL
from ..ik import AnalyticIKResult, IKResult, JointLimits, analytic_ik, characteristic_length, ik_plan, row_mask, solve_ik
from ..ik import forms as ik_forms
from ._cache import guard_cache
from ._emit import NUMBA
from ._ik_elbow import ELBOW_LAYOUT
from ._ik_finish import pack_constants
from ._ik_parallel import parallel_constants
from ._ik_stanford import stanford_constants

__all__ = ["IKMethods"]

_ndarray, _F64, _POSE = np.ndarray, np.dtype(np.float64), (4, 4)
_new = object.__new__
#: Fewest targets a thread is given by a batch solve_ik (a target takes tens of microseconds: far more than an FK).
IK_MIN_ROWS = 64
_NO_FREE = ("",) * 8
#: ``valid`` of a one-pose result with k solutions (all True), shared read-only arrays
_ALL_VALID = tuple(np.ones(k, dtype=bool) for k in range(9))
for _a in _ALL_VALID:
    _a.flags.writeable = False


class IKMethods:
    """``solve_ik`` and ``analytic_ik`` of a compiled arm (mixed into CompiledRobot, whose kernels they call)."""

    # --- inverse kinematics ------------------------------------------------------------------------------------
    def solve_ik(self, T, q0=None, *, mask="pose", tol: float | None = None, max_iterations: int | None = None,
                 restarts: int | None = None, respect_limits: bool = True, rng: np.random.Generator | None = None,
                 threads=None):
        """Numeric IK by Levenberg–Marquardt on the compiled FK and Jacobian: as :func:`denavit.solve_ik`
        (same arguments, same :class:`~denavit.IKResult`), each iteration in machine code.

        Targets the compiled search does not solve are handed to :func:`denavit.solve_ik` with the same
        arguments (its closed-form and bank rescues, and its diagnosis of *why* a target fails), so the
        answers are never worse than the plain function's.  The numpy backend always uses the plain function.

        ``threads`` (default every core): a batch of targets is split over that many threads
        (:mod:`denavit._threads`, blocks of at least ``IK_MIN_ROWS`` targets); each target's random restarts
        come from its own stream, so the answers do not depend on ``threads``.  The plain function's rescues
        run in the calling thread.
        """
        if threads is not None:
            resolve_threads(threads)  # refused before any work, for one target too
        tol = IK_TOL if tol is None else float(tol)
        max_iterations = IK_MAX_ITERATIONS if max_iterations is None else int(max_iterations)
        restarts = IK_RESTARTS if restarts is None else int(restarts)
        plain = dict(mask=mask, tol=tol, max_iterations=max_iterations, restarts=restarts,
                     respect_limits=respect_limits, rng=rng)
        if self.backend != NUMBA or not {"fk", "fk_jacobian0"} <= set(self.kernels):
            return solve_ik(self.robot, T, q0, **plain)
        c = self._ik_constants
        if c is None or c[0] != (mask if isinstance(mask, str) else tuple(mask), respect_limits):
            L = characteristic_length(self.robot)
            w = np.where(row_mask(mask), 1.0, 0.0) * np.array([1.0, 1.0, 1.0, L, L, L])
            lim = JointLimits(self.robot, not respect_limits)
            slo, shi = lim.sample_bounds(L)
            mid = 0.5 * (slo + shi)  # the middle of the limits, 0 without
            c = self._ik_constants = ((mask if isinstance(mask, str) else tuple(mask), respect_limits), w, L, lim,
                                      slo, shi, lim.revolute.astype(np.bool_), mid)
        _, w, L, lim, slo, shi, revolute, mid = c
        n = self.dof
        Ta = np.asarray(T, dtype=np.float64)
        if Ta.ndim < 2 or Ta.shape[-2:] != (4, 4):
            raise ShapeError(f"T: expected shape (..., 4, 4), got {Ta.shape}")
        batch = Ta.shape[:-2]
        Tf = np.ascontiguousarray(Ta.reshape(-1, 4, 4))
        B = Tf.shape[0]
        if q0 is None:
            Q0 = np.ascontiguousarray(np.broadcast_to(mid, (B, n)))
        elif B == 1 and q0.__class__ is _ndarray and q0.dtype is _F64 and q0.shape == self._vec:
            Q0 = np.ascontiguousarray(q0).reshape(1, n)
        else:
            try:
                Q0 = np.broadcast_to(np.asarray(q0, dtype=np.float64), batch + (n,)).reshape(B, n)
            except (ValueError, TypeError):
                raise ShapeError(f"q0: expected shape (..., {n}) matching the targets {batch}, got "
                                 f"{np.shape(q0)}") from None
            Q0 = np.ascontiguousarray(Q0)
        err = self._m.ik_check(Tf, Q0)  # NaN, inf and orthonormality in one pass
        if err < 0.0:
            raise ShapeError("q0 has non-finite values (NaN or inf)")
        if err > 1e-6:
            raise ShapeError("T has non-finite values" if err == np.inf else
                             f"T: rotation part is not orthonormal (error {err:.2g})")
        seed = _random.getrandbits(31) if rng is None else int(rng.bit_generator.random_raw() & 0x7FFFFFFF)
        q_out = np.empty((B, n))
        info = np.empty((B, 5))
        lm = self._m.ik_lm

        def block(s: int, e: int) -> None:  # targets s..e-1 (the kernel releases the GIL)
            lm(Tf[s:e], Q0[s:e], lim.lo, lim.hi, slo, shi, revolute, w, L, tol, max_iterations, restarts, seed, s,
               q_out[s:e], info[s:e])

        split_rows(B, block, threads, IK_MIN_ROWS)
        if batch == () and info[0, 0] > 0.0:  # one target, solved: the lean path
            return IKResult(q_out[0], True, float(info[0, 1]), float(info[0, 2]), int(info[0, 3]), int(info[0, 4]),
                            "")
        success = info[:, 0] > 0.0
        reason = np.full(B, "", dtype=object)
        iters, used = info[:, 3].astype(int), info[:, 4].astype(int)
        pe, re = info[:, 1].copy(), info[:, 2].copy()
        if not success.all():  # the plain solver: rescues, and the reason of each failure
            fail = np.flatnonzero(~success)
            again = solve_ik(self.robot, Tf[fail], Q0[fail], **plain)
            q_out[fail] = again.q
            success[fail] = again.success
            pe[fail], re[fail] = again.position_error, again.orientation_error
            iters[fail] += again.iterations
            used[fail] += again.restarts
            reason[fail] = again.reason
        if batch == ():
            return IKResult(q_out[0], bool(success[0]), float(pe[0]), float(re[0]), int(iters[0]), int(used[0]),
                            str(reason[0]))
        return IKResult(q_out.reshape(batch + (n,)), success.reshape(batch), pe.reshape(batch), re.reshape(batch),
                        iters.reshape(batch), used.reshape(batch), reason.reshape(batch))

    def analytic_ik(self, T) -> AnalyticIKResult:
        """Every closed-form solution of one pose: as :func:`denavit.analytic_ik` (same result), in machine code
        for arms of the elbow + spherical-wrist class (Puma 560 and most industrial 6R arms), of the UR class
        (6R, axes 2, 3, 4 parallel and axes 5, 6 meeting: UR3/5/10 and their e-series) and of the Stanford class
        (R R P with axes 1, 2 meeting, spherical wrist).

        Poses the plain solver treats specially (a joint left free, a double root, a candidate that needs
        polishing, solutions about to merge) are answered by :func:`denavit.analytic_ik`, and so are arms of other
        classes.  One pose is one machine-code call (the check of T and the kernel, :mod:`._ik_nb_entry`); the
        result's arrays are views of its output vector, made when first read.  From the first call on, a float64
        4x4 ndarray is taken by a built-in function in this method's place (:mod:`._ik_fastcall`: the check, the
        kernel and the result in machine code); it hands everything else, and every pose the kernel does not
        answer, to this method.  A batch (..., 4, 4) goes through
        the kernel's own loop and comes back in the plain solver's batched layout (:func:`_batch`).
        """
        c = self._elbow
        if c is None:
            c = self._elbow = self._analytic_solver()
        if c is False:
            return analytic_ik(self.robot, T)
        if T.__class__ is not _ndarray or T.dtype is not _F64 or T.shape != _POSE or not T.flags.c_contiguous:
            Ta = np.asarray(T, dtype=np.float64)
            if Ta.shape != _POSE:
                if Ta.ndim > 2 and Ta.shape[-2:] == _POSE and Ta.size:
                    return _batch(self.robot, c, Ta)
                return analytic_ik(self.robot, T)
            T = np.ascontiguousarray(Ta)
        o = np.empty(c[4])
        status = c[2](T, c[0], o)
        if c[5]:  # numba compiled (or loaded) it on this first call: call its machine code from now on
            one, c[5] = c[2], False
            c[2] = next(iter(one.overloads.values())).entry_point
            self._ik_builtin(one, c)
        if status == 0.0:
            res = _new(_PackedResult)
            _set_o(res, o)  # the slots' own setters: the frozen dataclass refuses setattr, and no __dict__ is made
            _set_m(res, c[1])
            _set_s(res, o[:112].reshape(8, 14)[: int(o[120]), :6].copy())  # as the built-in's: (k, 6), C order
            return res
        if status == 2.0:
            err = o[132]
            raise ShapeError("T has non-finite values" if err == np.inf else
                             f"T: rotation part is not orthonormal (error {err:.2g})")
        return analytic_ik(self.robot, T)

    def _ik_builtin(self, one, c) -> None:
        """Put the one-pose built-in of :mod:`._ik_fastcall` on this object in place of ``analytic_ik``: a call with
        one float64 4x4 ndarray then runs in machine code, result included; every other call, and every pose the
        kernel does not answer itself, goes to the method, unchanged.  Nothing changes when it cannot be made."""
        try:
            from ._ik_fastcall import install

            made = install(one, type(self).analytic_ik.__get__(self), c[0], c[1], _PackedResult, guard_cache)
        except Exception:  # noqa: BLE001 — a numba or platform difference: the method stays, correct, slower
            made = None
        if made is not None:
            self.analytic_ik = made[0]
            self._keep.append(made[1])

    def _analytic_solver(self):
        """``[K, (labels, plan kind), one, many, OUT_SIZE, first call]`` for the compiled closed form of this arm's
        IK plan (``one(T, K, o)``: the one-pose entry of :mod:`._ik_nb_entry`, ``many``: the batch entry of
        :mod:`._ik_nb_batch`, of its elbow, UR-class or Stanford-class kernel, by plan kind and route), or False
        where there is none (the plain solver answers)."""
        plan = ik_plan(self.robot)  # UnsupportedRobotError for arms with no closed form, as the plain function
        if self.backend != NUMBA or plan.closed is None or not {"fk", "fk_jacobian0"} <= set(self.kernels):
            return False
        from ._ik_jit import fresh_cache
        from ._ik_nb_batch import BATCH
        from ._ik_nb_entry import ENTRIES, OUT_SIZE  # module-level kernels: compiled once per machine

        if plan.kind == "parallel":
            K, kind = parallel_constants(self.robot, plan), "parallel"
        elif plan.route == "closed form (stanford)":
            K, kind = stanford_constants(self.robot, plan), "stanford"
        else:
            k = dict(plan.closed)
            lim = self.robot.q_limits
            sc = np.asarray(k["scalars"], dtype=float)  # h, na, nb, base3, L, rho_w, base_w, br, bu
            k.update(lo=lim[:, 0], hi=lim[:, 1],
                     revolute=[float(t.value == "revolute") for t in self.robot.joint_types],
                     chain=np.array(chain_of(self.robot).constants, dtype=float),
                     trig=[*ik_forms.wrist_constants(*sc[5:9]), np.cos(sc[3]), np.sin(sc[3])])
            if not np.array_equal(np.reshape(k["consts"], (4, 4, 4))[:3], k["chain"][:3]):
                return False  # the kernel's labels read the frames after joints 1, 2 off its verifying FK
            K, kind = pack_constants(k, ELBOW_LAYOUT, "elbow"), "elbow"
        one, many = ENTRIES[kind], BATCH[kind]
        fresh_cache(one, many)  # none stale (see there)
        return [K, (tuple(plan.closed["labels"]), plan.kind), one, many, OUT_SIZE, True]


class _PackedResult(AnalyticIKResult):
    """The :class:`~denavit.AnalyticIKResult` of one pose answered by the compiled kernel: its solutions a (k, 6)
    array in a slot, made with it (the field most read; a slot is read as fast as Python reads anything), its other
    fields read from the kernel's output vector ``o`` (layout: :mod:`._ik_nb_entry`; kept in a slot with the labels
    and plan kind) when first asked for (views of ``o``, each made once).  Copied or pickled, it is a plain
    AnalyticIKResult."""

    __slots__ = ("_o", "_m", "solutions")  # the output vector; (labels, plan kind); the solutions, made at once

    def __reduce__(self):
        return AnalyticIKResult, tuple(getattr(self, f) for f in _FIELDS)


class _Lazy:
    """A non-data descriptor: the field ``name`` computed by ``get(o, labels, kind)`` on first access and kept in
    the instance's __dict__ (where the frozen dataclass keeps its fields), which is read from then on."""

    __slots__ = ("name", "get")

    def __init__(self, name, get):
        self.name, self.get = name, get

    def __get__(self, obj, cls=None):
        if obj is None:
            return self
        value = obj.__dict__[self.name] = self.get(obj._o, *obj._m)
        return value


_FIELDS = tuple(f.name for f in fields(AnalyticIKResult))
for _lazy in (_Lazy("position_error", lambda o, labels, kind: o[6:112:14][: int(o[120])]),
              _Lazy("orientation_error", lambda o, labels, kind: o[7:112:14][: int(o[120])]),
              _Lazy("outside_limits", lambda o, labels, kind: o[:112].reshape(8, 14)[: int(o[121]), 8:]),
              _Lazy("branches", lambda o, labels, kind: tuple([labels[int(x)] for x in o[112:112 + int(o[120])]])),
              _Lazy("free", lambda o, labels, kind: _NO_FREE[: int(o[120])]),
              _Lazy("method", lambda o, labels, kind: kind), _Lazy("controlled", lambda o, labels, kind: "pose"),
              _Lazy("valid", lambda o, labels, kind: _ALL_VALID[int(o[120])])):
    setattr(_PackedResult, _lazy.name, _lazy)
_PackedResult.__name__ = _PackedResult.__qualname__ = "AnalyticIKResult"  # its repr is a plain result's
_set_o, _set_m, _set_s = _PackedResult._o.__set__, _PackedResult._m.__set__, _PackedResult.solutions.__set__


def _batch(robot, c, Ta: np.ndarray) -> AnalyticIKResult:
    """The solutions of a batch of poses Ta (..., 4, 4) by the compiled kernel's own loop, in the plain solver's
    batched layout: slot k of a pose is its k-th verified candidate in candidate order (NaN rows, ``valid``
    False, where that candidate was a duplicate or outside the limits), K slots = the most verified candidates
    of any pose; ``outside_limits`` counts per pose.  The kernel writes that layout itself (:mod:`._ik_nb_entry`);
    poses it hands over are solved by :func:`denavit.analytic_ik` as one sub-batch and put in their rows.  The
    kernel runs over blocks of poses (:mod:`._ik_nb_batch`: its scratch made once per block, not per pose)."""
    batch, n = Ta.shape[:-2], robot.dof
    Tf = np.ascontiguousarray(Ta.reshape(-1, 4, 4))  # (B, 4, 4)
    B = len(Tf)
    sol, pe, re = np.empty((B, 8, n)), np.empty((B, 8)), np.empty((B, 8))
    valid, codes = np.empty((B, 8), dtype=bool), np.empty((B, 8), dtype=np.int8)
    outside, status = np.empty(B, dtype=np.int64), np.empty(B, dtype=np.int8)
    most, bad, err = c[3](Tf, c[0], sol, pe, re, valid, codes, outside, status)
    if bad >= 0:
        raise ShapeError("T has non-finite values" if err == np.inf else
                         f"T: rotation part is not orthonormal (error {err:.2g})")
    hand = np.flatnonzero(status == 1)
    sub = analytic_ik(robot, Tf[hand]) if len(hand) else None
    K = max(1, most, 0 if sub is None else sub.solutions.shape[1])
    if K > 8:  # the plain solver found more slots (partners of a double root): room for them
        sol, pe, re = _widen(sol, K, np.nan), _widen(pe, K, np.nan), _widen(re, K, np.nan)
        valid, codes = _widen(valid, K, False), _widen(codes, K, -1)
    elif K < 8:
        sol, pe, re = (np.ascontiguousarray(a[:, :K]) for a in (sol, pe, re))
        valid, codes = np.ascontiguousarray(valid[:, :K]), codes[:, :K]
    labels, kind = c[1]
    branches = np.array(list(labels) + [""], dtype=object)[codes]  # code -1: ""
    free = np.full((B, K), "", dtype=object)
    if sub is not None:
        k = sub.solutions.shape[1]
        sol[hand, :k], pe[hand, :k], re[hand, :k] = sub.solutions, sub.position_error, sub.orientation_error
        valid[hand, :k], branches[hand, :k], free[hand, :k] = sub.valid, sub.branches, sub.free
        outside[hand] = sub.outside_limits
    return AnalyticIKResult(sol.reshape(batch + (K, n)), branches.reshape(batch + (K,)), free.reshape(batch + (K,)),
                            pe.reshape(batch + (K,)), re.reshape(batch + (K,)), outside.reshape(batch), kind, "pose",
                            valid.reshape(batch + (K,)))


def _widen(a: np.ndarray, K: int, fill) -> np.ndarray:
    """a (B, k, ...) with slots k..K-1 added, filled with ``fill``."""
    return np.concatenate([a, np.full(a.shape[:1] + (K - a.shape[1],) + a.shape[2:], fill, a.dtype)], axis=1)
