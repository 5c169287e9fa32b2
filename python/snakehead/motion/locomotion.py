"""Locomotion for the closed loop (Section 3.3 (3): "use the rolling gait or turn in place to adjust the location
and orientation of the overall body"): where a body lying on the ground must go, and the next gait that takes it
there.

Poses are :class:`~snakehead.model.robot.BasePlacement` s of the root frame (x, y m, yaw rad), composed as planar
rigid motions (:func:`compose`, :func:`relative`).

* The curl: the plan starts in the bending state (the base on its arc, neck and head curled flat), and a body
  lying straight gets there by a joint motion on the ground that slides and turns it (0.76 m and 179 deg on the
  default robot). :func:`curl_displacement` predicts that motion with the quasi-static friction model of
  :mod:`snakehead.dynamics.sliding`; :func:`straight_pose_for` is where a straight body must lie for the curl to
  leave its base at a given placement.
* The gaits (:mod:`snakehead.motion.gaits`): every run starts and ends with the body straight. Turning in place turns it about
  its middle; sidewinding carries it sideways, square to its axis. Nothing carries it along its axis on an
  isotropic friction ground. :func:`next_step` therefore moves the body's middle (the straight body's virtual
  chassis, :func:`chassis_offset`) to the goal's in the goal's own frame, one leg at a time: along the goal's
  axis (the body turned square to it, sidewinding), then the heading (turning in place), then across the goal's
  axis (sidewinding at the goal's heading), the last leg the most precise since turning in place shifts the middle
  a little. Each step is one gait run; the loop re-estimates the pose after it and asks again, so errors of a leg
  are corrected by the next step.
* :class:`GaitRates` are what one cycle of each gait does, learnt from the runs (estimated, as the robot knows
  them): the first guesses are 0.25 body lengths per cycle sideways and 40 deg per cycle.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from .._validate import finite_array, finite_float, positive
from ..dynamics.sliding import predict_slide
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from .gaits import Gait, make_gait, virtual_chassis


# ------------------------------------------------------------------------------------------------
# planar poses
# ------------------------------------------------------------------------------------------------
def wrap_angle(a: float) -> float:
    """``a`` (rad) in [-pi, pi)."""
    return (float(a) + math.pi) % (2.0 * math.pi) - math.pi


def compose(a: BasePlacement, b: BasePlacement) -> BasePlacement:
    """The pose ``b`` (given in ``a``'s frame) in the world: a * b."""
    c, s = math.cos(a.yaw), math.sin(a.yaw)
    return BasePlacement(a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, a.yaw + b.yaw)


def relative(a: BasePlacement, b: BasePlacement) -> BasePlacement:
    """The pose ``b`` in ``a``'s frame: a^-1 * b (yaw wrapped to [-pi, pi))."""
    c, s = math.cos(a.yaw), math.sin(a.yaw)
    dx, dy = b.x - a.x, b.y - a.y
    return BasePlacement(c * dx + s * dy, -s * dx + c * dy, wrap_angle(b.yaw - a.yaw))


def inverse(a: BasePlacement) -> BasePlacement:
    """a^-1."""
    return relative(a, BasePlacement())


# ------------------------------------------------------------------------------------------------
# the curl on the ground
# ------------------------------------------------------------------------------------------------
#: Steps of the predicted curl (the prediction converges to < 1 mm with 30 on the default robot).
CURL_STEPS = 40


def flat_shape(robot: SnakeRobot, q: npt.ArrayLike, name: str = "q") -> np.ndarray:
    """``q`` (n,) checked to be a shape lying flat on the ground: finite, within the joint limits, every pitch
    joint at 0 (ValueError otherwise)."""
    robot = as_robot(robot)
    q = finite_array(q, name, (robot.n_joints,))
    pitch = np.array([k == "pitch" for k in robot.joint_kinds])
    if np.any(np.abs(q[pitch]) > 1e-9):
        j = int(np.flatnonzero(pitch & (np.abs(q) > 1e-9))[0])
        raise ValueError(f"{name} is not lying flat: pitch joint {robot.joint_names[j]!r} is at {q[j]:.4g} rad "
                         "(a body lying on the ground has its pitch joints at 0)")
    outside = (q < robot.lower - 1e-9) | (q > robot.upper + 1e-9)
    if outside.any():
        j = int(np.flatnonzero(outside)[0])
        raise ValueError(f"{name}[{j}] = {q[j]:.4g} rad is outside the limits of {robot.joint_names[j]!r}")
    return q


def curl_path(q_from: npt.ArrayLike, q_to: npt.ArrayLike, steps: int = CURL_STEPS) -> np.ndarray:
    """The joint path of a curl on the ground: straight in joint space from ``q_from`` to ``q_to``, (steps + 1, n)."""
    a, b = np.asarray(q_from, float), np.asarray(q_to, float)
    s = np.linspace(0.0, 1.0, int(steps) + 1)[:, None]
    return a + s * (b - a)


def curl_displacement(robot: SnakeRobot, q_from: npt.ArrayLike, q_to: npt.ArrayLike, steps: int = CURL_STEPS
                      ) -> BasePlacement:
    """Where the root frame goes, in its own starting frame, when a body lying flat changes its shape from
    ``q_from`` to ``q_to`` along :func:`curl_path` (:func:`snakehead.dynamics.sliding.predict_slide`)."""
    robot = as_robot(robot)
    q_from, q_to = flat_shape(robot, q_from, "q_from"), flat_shape(robot, q_to, "q_to")
    return predict_slide(robot, curl_path(q_from, q_to, steps))[-1]


def straight_pose_for(robot: SnakeRobot, base: BasePlacement, q_curled: npt.ArrayLike, steps: int = CURL_STEPS
                      ) -> BasePlacement:
    """Where a body lying straight must lie for the curl into ``q_curled`` (e.g. the bending state) to leave its
    root frame at ``base``: base * D^-1, D = :func:`curl_displacement` from straight to ``q_curled``."""
    robot = as_robot(robot)
    D = curl_displacement(robot, np.zeros(robot.n_joints), q_curled, steps)
    return compose(as_base(base), inverse(D))


# ------------------------------------------------------------------------------------------------
# gaits towards a goal
# ------------------------------------------------------------------------------------------------
def chassis_offset(robot: SnakeRobot) -> BasePlacement:
    """The virtual chassis of the straight body in its root frame: its middle, x along the body."""
    robot = as_robot(robot)
    F = robot.body.fk_all(np.zeros(robot.n_joints))[None]
    centres = robot.box_poses(F)[0, :, :3, 3]
    T = virtual_chassis(centres, forward=centres[-1] - centres[0])
    return BasePlacement(float(T[0, 3]), float(T[1, 3]), math.atan2(T[1, 0], T[0, 0]))


@dataclass
class GaitRates:
    """What one cycle of a gait does, as the loop has seen it (its estimates).

    sideways_m: how far a sidewinding cycle carries the body (m); sideways_angle_rad: the direction it goes for
    ``direction`` +1, from the body's axis (+pi/2: square to its left; -1 goes the mirror way); turn_rad: how far
    a turning cycle turns it (rad, > 0). :meth:`update` learns them from runs: distance (or angle) over cycles,
    summed over every run so far (so the ramps' share is in them, as it is in the runs to come).
    """

    sideways_m: float
    sideways_angle_rad: float = math.pi / 2
    turn_rad: float = math.radians(40.0)
    _sums: dict = field(default_factory=lambda: {"side_m": 0.0, "side_cycles": 0.0, "side_angle": 0.0,
                                                 "turn_rad": 0.0, "turn_cycles": 0.0}, repr=False)

    @classmethod
    def first_guess(cls, robot: SnakeRobot) -> "GaitRates":
        """0.25 body lengths per sidewinding cycle, square to the body; 40 deg per turning cycle (the default
        robot does 0.28 and 46 at 0.5 Hz: bench/RESULTS.md, "Gaits")."""
        return cls(sideways_m=0.25 * as_robot(robot).body_length)

    def update(self, gait: Gait, cycles: float, start: BasePlacement, end: BasePlacement,
               offset: BasePlacement) -> None:
        """Learn from a run of ``cycles`` cycles of ``gait`` that took the root from ``start`` to ``end``
        (``offset``: :func:`chassis_offset`). Runs under a tenth of a cycle, and turns the wrong way, teach
        nothing."""
        cycles = finite_float(cycles, "cycles")
        if cycles < 0.1:
            return
        a, b = compose(start, offset), compose(end, offset)
        d = relative(a, BasePlacement(b.x, b.y, a.yaw))  # the middle's travel in the start frame
        S = self._sums
        if gait.name == "sidewinding":
            S["side_m"] += math.hypot(d.x, d.y)
            S["side_angle"] += cycles * gait.direction * math.atan2(d.y, d.x)  # mirrored for direction -1
            S["side_cycles"] += cycles
            self.sideways_m = S["side_m"] / S["side_cycles"]
            self.sideways_angle_rad = S["side_angle"] / S["side_cycles"]
        elif gait.name == "turning":
            turned = gait.direction * wrap_angle(b.yaw - a.yaw)
            if turned <= 0:
                return
            S["turn_rad"] += turned
            S["turn_cycles"] += cycles
            self.turn_rad = S["turn_rad"] / S["turn_cycles"]


@dataclass(frozen=True)
class Tolerance:
    """When the body is where it should be: its middle within ``along_m`` along the goal's axis and ``across_m``
    across it, its heading within ``yaw_deg``; ``align_deg``: how square to the goal's axis the body must be
    before sidewinding along it. ``along_m`` is the loosest: the legs after it (turning in place, sidewinding
    across) shift the middle along the axis by a few centimetres, and a tighter bound would send the body back to
    the first leg."""

    along_m: float = 0.08
    across_m: float = 0.03
    yaw_deg: float = 4.0
    align_deg: float = 5.0

    def __post_init__(self) -> None:
        for name in ("along_m", "across_m", "yaw_deg", "align_deg"):
            object.__setattr__(self, name, positive(getattr(self, name), name))


@dataclass(frozen=True)
class LocomotionStep:
    """One gait run: ``gait`` for ``cycles`` cycles, and why (``leg``: "along", "heading" or "across")."""

    gait: Gait
    cycles: float
    leg: str


def next_step(robot: SnakeRobot, current: BasePlacement, goal: BasePlacement, rates: GaitRates, *,
              tolerance: Tolerance = Tolerance(), frequency: float = 0.5, max_cycles: float = 4.0,
              gait_options: dict | None = None) -> LocomotionStep | None:
    """The next gait run that brings a straight body's root frame from ``current`` towards ``goal`` (see the
    module), or None when it is there within ``tolerance``. ``frequency`` Hz of the gaits; a run is at most
    ``max_cycles`` cycles (the loop looks again after each); ``gait_options`` go to every gait
    (:func:`~snakehead.motion.gaits.make_gait`)."""
    robot = as_robot(robot)
    current, goal = as_base(current), as_base(goal)
    frequency = positive(frequency, "frequency")
    max_cycles = positive(max_cycles, "max_cycles")
    options = dict(gait_options or {})
    options.setdefault("frequency", frequency)
    offset = chassis_offset(robot)
    here, there = compose(current, offset), compose(goal, offset)
    error = relative(there, BasePlacement(here.x, here.y, here.yaw))  # the middle in the goal's frame
    along, across = error.x, error.y
    yaw_error = wrap_angle(goal.yaw - current.yaw)  # turn by this to face the goal's way

    def turn_to(heading: float, leg: str) -> LocomotionStep:
        angle = wrap_angle(heading - current.yaw)
        cycles = min(abs(angle) / rates.turn_rad, max_cycles)
        return LocomotionStep(make_gait("turning", 1 if angle > 0 else -1, **options), cycles, leg)

    def sidewind(distance: float, leg: str, direction: int) -> LocomotionStep:
        cycles = min(abs(distance) / rates.sideways_m, max_cycles)
        return LocomotionStep(make_gait("sidewinding", direction, **options), cycles, leg)

    if abs(along) > tolerance.along_m:
        # travel along the goal's axis by -along: face square to it, the side that needs the least turning
        travel = goal.yaw + (math.pi if along > 0 else 0.0)  # direction of travel (world)
        options_side = []
        for direction in (1, -1):
            heading = travel - direction * rates.sideways_angle_rad
            options_side.append((abs(wrap_angle(heading - current.yaw)), direction, heading))
        _, direction, heading = min(options_side)
        if abs(math.degrees(wrap_angle(heading - current.yaw))) > tolerance.align_deg:
            return turn_to(heading, "along")
        return sidewind(along, "along", direction)
    if abs(math.degrees(yaw_error)) > tolerance.yaw_deg:
        return turn_to(goal.yaw, "heading")
    if abs(across) > tolerance.across_m:
        # at the goal's heading, sidewinding +1 goes to the body's left (+y of the goal's frame): across < 0 -> +1
        return sidewind(across, "across", 1 if across < 0 else -1)
    return None
