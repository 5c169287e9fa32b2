"""`TracIK`: inverse kinematics of a chain with TRAC-IK (C++ core, Beeson and Ames 2015).

KDL-RR (Newton-Raphson with joint limits and random restarts) and SQP (NLopt's SLSQP) search at the same
time; with ``solve_type="Speed"`` the first solution wins. ``Distance``, ``Manip1`` and ``Manip2`` search
until the timeout and return the solution closest to ``q_init``, with the largest sqrt(det(J J^T)), or with
the largest smallest-to-largest singular value ratio.

Tolerances: a solution puts the tip at ``pose`` within ``epsilon`` on each of the six axes of the pose
error (position and rotation vector of the tip relative to the target, in the target's frame), plus the
per-axis ``bounds`` (vx vy vz wx wy wz): ``bounds=[0, 0, 0, inf, 0, 0]`` leaves the roll about the target's
x-axis free. The GIL is released while solving, and one solver may be shared by many threads.
"""
from __future__ import annotations

import math
import os
import weakref
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import _core
from .._errors import InputError, InputTypeError
from .._validate import ORTHONORMAL_TOLERANCE, duration, finite_array, integer, joint_vector, positive, within_limits
from .._validate import pose as check_pose
from ..model.chain import Chain

SOLVE_TYPES = ("Speed", "Distance", "Manip1", "Manip2")
#: s: a solve's budget by default (TracIKOptions' in include/snakehead/trac_ik.hpp; tests/package/test_shared_numbers.py).
DEFAULT_TIMEOUT_S = 0.005
#: The allowed residual per axis (m, rad) by default (TracIKOptions' too).
DEFAULT_EPSILON = 1e-5
#: Bounds that leave the roll about the target's x-axis free.
FREE_ROLL = (0.0, 0.0, 0.0, np.inf, 0.0, 0.0)


def _bounds(bounds: Any) -> np.ndarray:
    """``bounds`` as the 6 per-axis tolerances (vx vy vz wx wy wz, each >= 0, inf for a free axis)."""
    try:
        b = np.asarray(bounds, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"bounds must be 6 numbers: {exc}") from None
    if b.shape != (6,):
        raise InputError(f"bounds must have 6 entries (vx vy vz wx wy wz), got shape {b.shape}")
    if np.any(np.isnan(b)) or np.any(b < 0):
        raise InputError(f"bounds must be >= 0 (inf leaves an axis free), got {b.tolist()}")
    return b


def _pose(T: npt.ArrayLike, name: str = "pose") -> np.ndarray:
    """``T`` as a valid 4x4 pose. The common case (a valid float64 array) is checked in plain Python, several
    times faster than the numpy checks of ``_validate.pose`` for one small matrix; anything that fails here
    goes to ``_validate.pose``, whose message says what is wrong (same tolerances)."""
    a = np.asarray(T, dtype=np.float64) if isinstance(T, np.ndarray) else None
    if a is not None and a.shape == (4, 4):
        m = a.tolist()
        r0, r1, r2, last = m
        if (all(math.isfinite(v) for row in m for v in row) and last == [0.0, 0.0, 0.0, 1.0]):
            c = [[r0[i] * r0[j] + r1[i] * r1[j] + r2[i] * r2[j] for j in range(3)] for i in range(3)]
            err = max(abs(c[i][j] - (1.0 if i == j else 0.0)) for i in range(3) for j in range(3))
            det = (r0[0] * (r1[1] * r2[2] - r1[2] * r2[1]) - r0[1] * (r1[0] * r2[2] - r1[2] * r2[0])
                   + r0[2] * (r1[0] * r2[1] - r1[1] * r2[0]))
            if err <= ORTHONORMAL_TOLERANCE and det > 0:
                return a
    return check_pose(T, name)


def _poses(poses: npt.ArrayLike) -> np.ndarray:
    """``poses`` as valid 4x4 poses (T, 4, 4): all at once in numpy where every one is clearly valid (half
    :func:`_pose`'s tolerance); else pose by pose, so that a bad one is named (``poses[k]``) as :func:`_pose` names it."""
    P = finite_array(poses, "poses", (None, 4, 4))
    R = P[:, :3, :3]
    err = np.abs(np.einsum("kji,kjl->kil", R, R) - np.eye(3)).max(initial=0.0)
    if err <= 0.5 * ORTHONORMAL_TOLERANCE and np.all(P[:, 3] == (0.0, 0.0, 0.0, 1.0)) and np.all(np.linalg.det(R) > 0):
        return P
    for k in range(P.shape[0]):
        _pose(P[k], f"poses[{k}]")
    return P


def _seed(seed: int | None) -> int | None:
    """``seed`` as an unsigned 64-bit integer, or None."""
    return None if seed is None else integer(seed, "seed", least=0, most=2**64 - 1)


#: The solvers alive in this process, whose generators a forked child renews (:func:`_renew_generators`).
_LIVE_SOLVERS: "weakref.WeakSet[TracIK]" = weakref.WeakSet()


def _renew_generators() -> None:
    """In a forked child: each solver's generator continues from its state with a lock of its own. (numpy's lock
    was copied as it was at the fork: held, if another thread of the parent was drawing then, and never released
    in the child, whose next draw would wait for ever.)"""
    for solver in list(_LIVE_SOLVERS):
        old = solver._rng.bit_generator  # noqa: SLF001 (TracIK's own generator, renewed by its module)
        new = type(old)()
        new.state = old.state
        solver._rng = np.random.Generator(new)  # noqa: SLF001


os.register_at_fork(after_in_child=_renew_generators)


class TracIK:
    """TRAC-IK for the chain ``base`` -> ``tip`` of a URDF (a path or an XML string).

    ``timeout`` (s) bounds each call; ``epsilon`` is the per-axis tolerance (m, rad); ``solve_type`` is one of
    Speed, Distance, Manip1, Manip2; ``bounds`` the default per-axis tolerances; ``seed`` an integer makes
    every call reproducible (a seeded call is a pure function of its inputs: both solvers run interleaved in
    the calling thread, bounded by an evaluation budget derived from the timeout rather than the clock: such a call
    never reads the clock, so a slow or loaded machine takes longer than ``timeout`` and gives the same answer).
    Without a seed, ``timeout`` is wall-clock time, and what a call finds depends on the machine's load.
    """

    def __init__(self, urdf: str | os.PathLike, base: str, tip: str, timeout: float = DEFAULT_TIMEOUT_S,
                 epsilon: float = DEFAULT_EPSILON, solve_type: str = "Speed", seed: int | None = None, bounds: Any = None) -> None:
        self._init(Chain.from_urdf(urdf, base, tip), timeout, epsilon, solve_type, seed, bounds)

    @classmethod
    def from_chain(cls, chain: Chain, timeout: float = DEFAULT_TIMEOUT_S, epsilon: float = DEFAULT_EPSILON, solve_type: str = "Speed",
                   seed: int | None = None, bounds: Any = None) -> "TracIK":
        """A solver for an existing :class:`Chain` (its model is copied into the solver)."""
        if not isinstance(chain, Chain):
            raise InputTypeError(f"chain must be a snakehead.Chain, got {type(chain).__name__}")
        self = cls.__new__(cls)
        self._init(chain, timeout, epsilon, solve_type, seed, bounds)
        return self

    def _init(self, chain: Chain, timeout: float, epsilon: float, solve_type: str, seed: int | None, bounds: Any
              ) -> None:
        if not isinstance(solve_type, str) or solve_type not in SOLVE_TYPES:
            raise InputError(f"unknown solve_type {solve_type!r}; expected one of {', '.join(SOLVE_TYPES)}")
        self._chain = chain
        self._solver = _core.TracIK(chain.model, duration(timeout, "timeout"), positive(epsilon, "epsilon"),
                                    solve_type, _bounds(np.zeros(6) if bounds is None else bounds), _seed(seed))
        self._rng = np.random.default_rng(seed)
        _LIVE_SOLVERS.add(self)
        self._lo, self._hi = self._solver.lower.tolist(), self._solver.upper.tolist()

    # --- description -------------------------------------------------------------------------
    @property
    def chain(self) -> Chain:
        return self._chain

    @property
    def n_joints(self) -> int:
        return self._solver.n_joints

    @property
    def lower(self) -> np.ndarray:
        return self._solver.lower

    @property
    def upper(self) -> np.ndarray:
        return self._solver.upper

    @property
    def timeout(self) -> float:
        return self._solver.timeout

    @property
    def epsilon(self) -> float:
        return self._solver.epsilon

    @property
    def solve_type(self) -> str:
        return self._solver.solve_type

    @property
    def bounds(self) -> np.ndarray:
        return self._solver.bounds

    @property
    def seed(self) -> int | None:
        return self._solver.seed

    # --- solving -----------------------------------------------------------------------------
    def fk(self, q: npt.ArrayLike) -> np.ndarray:
        """Pose of the tip in the base frame, (4, 4)."""
        return self._solver.fk(joint_vector(q, self.n_joints))

    def _q_init(self, q_init: npt.ArrayLike, name: str = "q_init") -> np.ndarray:
        if isinstance(q_init, np.ndarray) and q_init.shape == (self.n_joints,) and q_init.dtype == np.float64:
            # The common case in plain Python (faster than numpy's reductions for a few values).
            if all(lo - 1e-9 <= v <= hi + 1e-9 for v, lo, hi in zip(q_init.tolist(), self._lo, self._hi)):
                return q_init  # NaN fails the comparisons and goes to the checks below
        return within_limits(joint_vector(q_init, self.n_joints, name), self.lower, self.upper, name)

    def random_configuration(self) -> np.ndarray:
        """Uniform within the limits ([-pi, pi] for continuous joints), from the solver's own generator."""
        return self._chain.random_configuration(self._rng)

    def _start_generator(self) -> np.random.Generator:
        # Starts drawn when q_init is omitted: with a seed, a fresh generator from the seed alone, so that
        # identical calls get identical starts (and results); without one, the solver's running generator.
        return self._rng if self.seed is None else np.random.default_rng(self.seed)

    def ik(self, pose: np.ndarray, q_init: np.ndarray | None = None, bounds: Any = None) -> np.ndarray | None:
        """Joint angles putting the tip at ``pose`` (4x4, base frame), or None if none was found in time.

        ``q_init``: the start (and the reference of ``Distance``); random within the limits when omitted (with a
        seed, the same start on every call, so identical calls return identical results).
        ``bounds``: per-axis tolerances (vx vy vz wx wy wz, target frame) for this call.
        """
        found, q, _ = self.ik_ex(pose, q_init, bounds)
        return q if found else None

    def ik_ex(self, pose: npt.ArrayLike, q_init: npt.ArrayLike | None = None, bounds: Any = None,
              algorithm: str = "TRAC-IK", timeout: float | None = None) -> Any:
        """(found, q, seconds): like :meth:`ik`, with the wall-clock time of the C++ call, a per-call timeout,
        and a choice of ``algorithm`` ("TRAC-IK", or for comparisons "KDL-RR" or "SQP" alone)."""
        T = _pose(pose)
        q = self._chain.random_configuration(self._start_generator()) if q_init is None else self._q_init(q_init)
        b = None if bounds is None else _bounds(bounds)
        t = None if timeout is None else duration(timeout, "timeout")
        if not isinstance(algorithm, str) or algorithm not in ("TRAC-IK", "KDL-RR", "SQP"):
            raise InputError(f"unknown algorithm {algorithm!r}; expected TRAC-IK, KDL-RR or SQP")
        return self._solver.ik(T, q, b, t, algorithm)

    def ik_many(self, poses: npt.ArrayLike, q_inits: npt.ArrayLike | None = None,
                streams: npt.ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Solve many targets across ``snakehead.core_threads()`` threads (all cores by default): poses (T, 4, 4) -> (q (T, n), ok (T,) bool).

        Rows of ``q`` where ``ok`` is False hold the start configuration. With a seed, target k's search
        depends only on (seed, k), so results do not depend on which thread solved it. ``streams`` (T,) non-negative
        integers stand for the k's: the targets of a batch solved in parts, each with its index in the batch, give
        what the whole batch gives.
        """
        P = _poses(poses)
        if q_inits is None:
            rng = self._start_generator()
            Q = np.array([self._chain.random_configuration(rng) for _ in range(P.shape[0])]).reshape(
                P.shape[0], self.n_joints)
        else:
            Q = finite_array(q_inits, "q_inits", (P.shape[0], self.n_joints))
            if not (np.all(Q >= self.lower - 1e-9) and np.all(Q <= self.upper + 1e-9)):
                for k in range(Q.shape[0]):  # (the first out of its limits is named)
                    self._q_init(Q[k], f"q_inits[{k}]")
        return self._solver.ik_many(np.ascontiguousarray(P), np.ascontiguousarray(Q), _streams(streams, P.shape[0]))

    def __repr__(self) -> str:
        return (f"TracIK({self._chain.base!r} -> {self._chain.tip!r}, {self.n_joints} joints, "
                f"{self.solve_type}, timeout={self.timeout:g} s, epsilon={self.epsilon:g})")


def _streams(streams: npt.ArrayLike | None, count: int) -> list[int] | None:
    """:meth:`TracIK.ik_many`'s ``streams``, checked: ``count`` integers in [0, 2**63)."""
    if streams is None:
        return None
    values = np.asarray(streams)
    if values.shape != (count,) or (count and values.dtype.kind not in "iu"):
        raise InputError(f"streams must be {count} integers (one per pose), got {values.dtype} of shape {values.shape}")
    if count and (values.min() < 0 or values.max() >= 2 ** 63):
        raise InputError(f"streams must be in [0, 2**63), got values from {values.min()} to {values.max()}")
    return [int(v) for v in values]


def pose_error(target: Any, current: Any) -> np.ndarray:
    """The IK pose error (vx vy vz wx wy wz) of ``current`` relative to ``target``, in the target's frame."""
    return _core.pose_error(check_pose(target, "target"), check_pose(current, "current"))


__all__ = ["TracIK", "SOLVE_TYPES", "FREE_ROLL", "DEFAULT_TIMEOUT_S", "DEFAULT_EPSILON", "pose_error"]
