"""The head part (paper, Section 3 and Fig. 9): joint angles that put the head link at a position, pointing
along a direction, with the roll about that direction left to the solver.

Two methods:
- ``rotated_frames``: the paper's. Frames sharing the desired origin and x-axis, rolled evenly about it
  (Fig. 9), are each solved with a full-pose TRAC-IK; the solution kept is the one closest to the desired
  frame (smallest roll) or to the previous joints.
- ``free_roll``: one TRAC-IK call whose tolerance on the roll about the target's x-axis is open.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import numpy.typing as npt

from .._errors import InputTypeError
from .._validate import finite_array, finite_float, integer, pose, unit_vector3, vector3
from ..kinematics.ik import FREE_ROLL, TracIK

__all__ = ["FREE_ROLL_BOUNDS", "HeadIKResult", "angle_between_deg", "frame_along", "frame_from_direction", "free_roll",
           "position_and_direction_error", "roll_about_x", "rotated_frames", "select"]

#: Tolerances (vx vy vz wx wy wz, target frame) that leave the roll about the head's x-axis free (TRAC-IK's).
FREE_ROLL_BOUNDS = np.array(FREE_ROLL)


def frame_from_direction(position: npt.ArrayLike, direction: npt.ArrayLike, up: npt.ArrayLike = (0.0, 0.0, 1.0)
                         ) -> np.ndarray:
    """A 4x4 frame at ``position`` (3,) whose x-axis is ``direction`` (3,), z as close to ``up`` as possible.

    When the direction is parallel to ``up``, world x (or y) is used instead, so every direction has a frame.
    """
    return frame_along(vector3(position, "position"), unit_vector3(direction, "direction"), unit_vector3(up, "up"))


def frame_along(p: np.ndarray, x: np.ndarray, up: np.ndarray = np.array([0.0, 0.0, 1.0])) -> np.ndarray:
    """:func:`frame_from_direction` of values already checked: ``p`` (3,) finite, ``x`` and ``up`` (3,) unit
    vectors (a target's, checked where it entered)."""
    for candidate in (up, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
        z = candidate - (candidate @ x) * x
        if np.linalg.norm(z) > 1e-6:
            break
    z /= np.linalg.norm(z)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = p
    return T


def roll_about_x(T: npt.ArrayLike, angle: float) -> np.ndarray:
    """``T`` rotated by ``angle`` (rad) about its own x-axis (Fig. 9)."""
    angle = finite_float(angle, "angle")
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    out = np.array(pose(T, "T"), dtype=float, copy=True)
    out[:3, :3] = out[:3, :3] @ R
    return out


def angle_between_deg(a: Any, b: Any) -> float:
    """Angle (deg) between two directions (3,), e.g. an achieved and a desired head x-axis."""
    a, b = unit_vector3(a, "direction a"), unit_vector3(b, "direction b")
    cosang = float(np.clip(a @ b, -1.0, 1.0))
    return float(np.degrees(np.arccos(cosang)))


def position_and_direction_error(achieved: npt.ArrayLike, desired: npt.ArrayLike) -> tuple[float, float]:
    """|p_a - p_d| (m) and the angle between the x-axes (deg) of two frames (4, 4)."""
    achieved, desired = np.asarray(achieved), np.asarray(desired)
    return float(np.linalg.norm(achieved[:3, 3] - desired[:3, 3])), angle_between_deg(achieved[:3, 0], desired[:3, 0])


@dataclass
class HeadIKResult:
    """A head solution in the head's base frame."""

    q: np.ndarray | None  # (n_head,) joint angles (rad), None when no frame was solved
    frame: np.ndarray | None  # (4, 4) achieved head frame in the head's base frame
    position_error_m: float  # against the desired position
    direction_error_deg: float  # deg, between achieved and desired x-axes
    roll_deg: float  # the achieved frame's roll about x relative to the desired frame (deg)
    tried: int  # IK problems posed
    solved: int  # of which solved
    seconds: float
    candidates: list = field(default_factory=list)  # (roll angle, q) of every solved frame

    @property
    def success(self) -> bool:
        """Whether a frame was solved (and accepted)."""
        return self.q is not None


def _roll_between(achieved: np.ndarray, desired: np.ndarray) -> float:
    R = desired[:3, :3].T @ achieved[:3, :3]
    return float(np.degrees(np.arctan2(R[2, 1], R[1, 1])))


def _finish(ik: TracIK, q: np.ndarray | None, target: Any, tried: int, solved: int, t0: float, candidates: list[Any]
            ) -> HeadIKResult:
    if q is None:
        return HeadIKResult(None, None, np.inf, np.inf, np.nan, tried, solved, time.perf_counter() - t0, candidates)
    T = ik.fk(q)
    pe, de = position_and_direction_error(T, target)
    return HeadIKResult(q, T, pe, de, _roll_between(T, target), tried, solved, time.perf_counter() - t0, candidates)


def _check_solver(ik: Any) -> None:
    if not isinstance(ik, TracIK):
        raise InputTypeError(f"ik must be a snakehead TracIK, got {type(ik).__name__}")


def rotated_frames(ik: TracIK, target: Any, n_frames: int = 10, q_init: np.ndarray | None = None,
                   q_prev: npt.ArrayLike | None = None, accept: Callable[..., bool] | None = None
                   ) -> HeadIKResult:
    """The paper's method: solve ``n_frames`` frames rolled evenly about the target's x-axis, keep one.

    ``target`` (4, 4) is the desired head frame in the head chain's base frame (its roll is the preferred
    one). Each rolled frame is solved from ``q_init`` (or ``q_prev``, or zeros). The kept solution is the
    one closest to ``q_prev`` in joint space when ``q_prev`` is given (Section 4.2: the smallest change from
    the previous state), else the one whose frame is closest to ``target`` (smallest roll). ``accept``: an
    optional test ``accept(q) -> bool`` of a head solution; only accepted solutions are candidates (``solved``
    still counts every solution found).
    """
    _check_solver(ik)
    target = pose(target, "target")
    n_frames = integer(n_frames, "n_frames", least=1, most=360)
    if accept is not None and not callable(accept):
        raise InputTypeError(f"accept must be a callable accept(q) -> bool or None, got {type(accept).__name__}")
    n = ik.n_joints
    if q_prev is not None:
        q_prev = finite_array(q_prev, "q_prev", (n,))
    seed_q = q_init if q_init is not None else (q_prev if q_prev is not None else np.zeros(n))
    seed_q = np.clip(finite_array(seed_q, "q_init", (n,)), ik.lower, ik.upper)
    t0 = time.perf_counter()
    angles = 2 * np.pi * np.arange(int(n_frames)) / n_frames
    # All rolled frames at once: the batch call spreads them over every core.
    qs, ok = ik.ik_many(np.stack([roll_about_x(target, a) for a in angles]), np.tile(seed_q, (len(angles), 1)))
    found = [(float(a), q) for a, q, good in zip(angles, qs, ok) if good]
    candidates = found if accept is None else [c for c in found if accept(c[1])]
    return _finish(ik, select(candidates, q_prev), target, int(n_frames), len(found), t0, candidates)


def select(candidates: list[Any], q_prev: np.ndarray | None = None) -> Any:
    """The kept solution among (roll angle, q) candidates: closest to ``q_prev`` in joint space when given,
    else the least rolled from the desired frame. None when there is no candidate."""
    if not candidates:
        return None
    if q_prev is not None:
        return min(candidates, key=lambda c: float(np.linalg.norm(c[1] - q_prev)))[1]
    return min(candidates, key=lambda c: abs(np.arctan2(np.sin(c[0]), np.cos(c[0]))))[1]


def free_roll(ik: TracIK, target: Any, q_init: npt.ArrayLike | None = None, attempts: int = 1) -> HeadIKResult:
    """One TRAC-IK call (or ``attempts`` calls from random seeds) with the roll about x left free."""
    _check_solver(ik)
    target = pose(target, "target")
    attempts = integer(attempts, "attempts", least=1, most=1000)
    n = ik.n_joints
    q0 = np.zeros(n) if q_init is None else np.clip(finite_array(q_init, "q_init", (n,)), ik.lower, ik.upper)
    t0 = time.perf_counter()
    q = None
    tried = 0
    for attempt in range(attempts):
        tried += 1
        # Later attempts restart from fixed pseudo-random joints (a seeded solver given no start would
        # start every attempt from the same point, and an unseeded one would not be reproducible).
        start = q0 if attempt == 0 else np.random.default_rng(attempt).uniform(ik.lower, ik.upper)
        q = ik.ik(target, q_init=start, bounds=FREE_ROLL_BOUNDS)
        if q is not None:
            break
    candidates = [] if q is None else [(np.nan, q)]
    return _finish(ik, q, target, tried, 0 if q is None else 1, t0, candidates)
