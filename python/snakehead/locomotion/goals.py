"""Locomotion for the closed loop (Section 3.3 (3): "use the rolling gait or turn in place to adjust the location
and orientation of the overall body"): where a body lying on the ground must go, and the next gait that takes it
there.

Poses are :class:`~snakehead.model.robot.BasePlacement` s of the root frame (x, y m, yaw rad), composed as planar
rigid motions (:func:`compose`, :func:`relative`) in the plane the body lies on: on a slope its ground frame, which
a composed pose keeps (``compose(a, b)`` lies on ``a``'s ground; ``relative`` gives a motion, on no ground).

* The curl: the plan starts in the bending state (the base on its arc, neck and head curled flat), and a body
  lying straight gets there by a joint motion on the ground that slides and turns it. :func:`curl_displacement`
  predicts that motion with the quasi-static friction model of :mod:`snakehead.dynamics.sliding`;
  :func:`straight_pose_for` is where a straight body must lie for the curl to leave its base at a given placement.
* The gaits (:mod:`snakehead.locomotion.gaits`): every run starts and ends with the body straight, and runs whole
  cycles, its amplitudes scaled down for a smaller effect (:func:`gait_run`). Turning in place turns it about
  its middle; sidewinding carries it sideways, square to its axis. Nothing carries it along its axis on an
  isotropic friction ground. :func:`next_step` therefore moves the body's middle (the straight body's virtual
  chassis, :func:`chassis_offset`) to the goal's in the goal's own frame, one leg at a time: along the goal's
  axis (the body turned square to it, sidewinding), then the heading (turning in place), then across the goal's
  axis (sidewinding at the goal's heading), the last leg the most precise since turning in place shifts the middle
  a little. Each step is one gait run; the loop re-estimates the pose after it and asks again, so errors of a leg
  are corrected by the next step.
* :class:`GaitRates` are what one cycle of each gait does at full amplitude, learnt from the runs (estimated, as the
  robot knows them): the first guesses are 0.25 body lengths per cycle sideways and 40 deg per cycle.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from .._errors import InputError
from .._validate import finite_array, positive
from ..dynamics.sliding import predict_slide
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from .gaits import Gait, make_gait, virtual_chassis

__all__ = ["wrap_angle", "compose", "relative", "inverse", "CURL_STEPS", "flat_shape", "curl_path",
           "curl_displacement", "straight_pose_for", "chassis_offset", "AMPLITUDE_EXPONENT", "MIN_AMPLITUDE_SCALE",
           "GaitRates", "Tolerance", "LocomotionStep", "gait_run", "next_step"]


# ------------------------------------------------------------------------------------------------
# planar poses
# ------------------------------------------------------------------------------------------------
def wrap_angle(a: float) -> float:
    """``a`` (rad) in [-pi, pi)."""
    return (float(a) + math.pi) % (2.0 * math.pi) - math.pi


def compose(a: BasePlacement, b: BasePlacement) -> BasePlacement:
    """The pose ``b`` (given in ``a``'s frame) in the world: a * b, on ``a``'s ground (a slope's frame stays)."""
    c, s = math.cos(a.yaw), math.sin(a.yaw)
    return a.moved(a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, a.yaw + b.yaw)


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
#: Steps of the predicted curl (enough for the prediction to converge: bench/RESULTS.md).
CURL_STEPS = 40


def flat_shape(robot: SnakeRobot, q: npt.ArrayLike, name: str = "q") -> np.ndarray:
    """``q`` (n,) checked to be a shape lying flat on the ground: finite, within the joint limits, every pitch
    joint at 0 (ValueError otherwise)."""
    robot = as_robot(robot)
    q = finite_array(q, name, (robot.n_joints,))
    pitch = np.array([k == "pitch" for k in robot.joint_kinds])
    if np.any(np.abs(q[pitch]) > 1e-9):
        j = int(np.flatnonzero(pitch & (np.abs(q) > 1e-9))[0])
        raise InputError(f"{name} is not lying flat: pitch joint {robot.joint_names[j]!r} is at {q[j]:.4g} rad "
                         "(a body lying on the ground has its pitch joints at 0)")
    outside = (q < robot.lower - 1e-9) | (q > robot.upper + 1e-9)
    if outside.any():
        j = int(np.flatnonzero(outside)[0])
        raise InputError(f"{name}[{j}] = {q[j]:.4g} rad is outside the limits of {robot.joint_names[j]!r}")
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
    """The virtual chassis of the straight body in its body frame (the base placement's): its middle, x along the
    body."""
    robot = as_robot(robot)
    F = robot.frames(np.zeros(robot.n_joints), BasePlacement())[None]  # the default placement: the body frame
    centres = robot.link_centres(F)[0]
    T = virtual_chassis(centres, forward=centres[-1] - centres[0])
    return BasePlacement(float(T[0, 3]), float(T[1, 3]), math.atan2(T[1, 0], T[0, 0]))


#: How a gait's effect per cycle grows with the scale k of its amplitudes (both waves scaled alike), as k**exponent:
#: fitted to whole cycles of the default robot at 0.5 Hz (bench/RESULTS.md, "Gaits").
AMPLITUDE_EXPONENT = {"sidewinding": 1.0, "turning": 1.25, "linear_progression": 1.6}
#: The smallest amplitude scale a run uses (smaller waves barely move the body).
MIN_AMPLITUDE_SCALE = 0.1


@dataclass
class GaitRates:
    """What one cycle of a gait at full amplitude does, as the loop has seen it (its estimates).

    sideways_m: how far a sidewinding cycle carries the body (m); sideways_angle_rad: the direction it goes for
    ``direction`` +1, from the body's axis (+pi/2: square to its left; -1 goes the mirror way); turn_rad: how far
    a turning cycle turns it (rad, > 0); forward_m: how far a cycle of linear progression carries it along its axis
    (m; first guess 0.15). :meth:`update` learns them from runs: the effect over the cycles run at the run's
    amplitude scale k, over k**AMPLITUDE_EXPONENT, summed over every run so far.
    """

    sideways_m: float
    sideways_angle_rad: float = math.pi / 2
    turn_rad: float = math.radians(40.0)
    forward_m: float = 0.15
    _sums: dict = field(default_factory=lambda: {"side_m": 0.0, "side_cycles": 0.0, "side_angle": 0.0,
                                                 "turn_rad": 0.0, "turn_cycles": 0.0, "forward_m": 0.0,
                                                 "forward_cycles": 0.0}, repr=False)

    @classmethod
    def first_guess(cls, robot: SnakeRobot) -> "GaitRates":
        """0.25 body lengths per sidewinding cycle, square to the body; 40 deg per turning cycle (a little less
        than the default robot does: bench/RESULTS.md, "Gaits")."""
        return cls(sideways_m=0.25 * as_robot(robot).body_length)

    def update(self, step: "LocomotionStep", start: BasePlacement, end: BasePlacement,
               offset: BasePlacement) -> None:
        """Learn from ``step``, which took the root from ``start`` to ``end`` (``offset``: :func:`chassis_offset`).
        A turn the wrong way teaches nothing."""
        gait = step.gait
        full = step.cycles * step.scale ** AMPLITUDE_EXPONENT.get(gait.name, 1.0)  # in full-amplitude cycles
        if full <= 0:
            return
        a, b = compose(start, offset), compose(end, offset)
        d = relative(a, b.moved(b.x, b.y, a.yaw))  # the middle's travel in the start frame
        S = self._sums
        if gait.name == "sidewinding":
            S["side_m"] += math.hypot(d.x, d.y)
            S["side_angle"] += full * gait.direction * math.atan2(d.y, d.x)  # mirrored for direction -1
            S["side_cycles"] += full
            self.sideways_m = S["side_m"] / S["side_cycles"]
            self.sideways_angle_rad = S["side_angle"] / S["side_cycles"]
        elif gait.name == "turning":
            turned = gait.direction * wrap_angle(b.yaw - a.yaw)
            if turned <= 0:
                return
            S["turn_rad"] += turned
            S["turn_cycles"] += full
            self.turn_rad = S["turn_rad"] / S["turn_cycles"]
        elif gait.name == "linear_progression":
            moved = gait.direction * d.x
            if moved <= 0:
                return
            S["forward_m"] += moved
            S["forward_cycles"] += full
            self.forward_m = S["forward_m"] / S["forward_cycles"]

    def predicted(self, step: "LocomotionStep", start: BasePlacement, offset: BasePlacement) -> BasePlacement:
        """Where ``step`` is expected to take the body's middle from the root placement ``start`` (the middle's
        placement; ``offset``: :func:`chassis_offset`), at these rates."""
        gait = step.gait
        full = step.cycles * step.scale ** AMPLITUDE_EXPONENT.get(gait.name, 1.0)
        m = compose(start, offset)
        if gait.name == "turning":
            return m.moved(m.x, m.y, m.yaw + gait.direction * full * self.turn_rad)
        if gait.name == "linear_progression":
            return compose(m, BasePlacement(gait.direction * full * self.forward_m, 0.0, 0.0))
        angle = gait.direction * self.sideways_angle_rad
        d = full * self.sideways_m
        return compose(m, BasePlacement(d * math.cos(angle), d * math.sin(angle), 0.0))


@dataclass(frozen=True)
class Tolerance:
    """When the body is where it should be: its middle within ``along_m`` along the goal's axis and ``across_m``
    across it, its heading within ``yaw_deg``; ``align_deg``: how square to the goal's axis the body must be
    before sidewinding along it. ``along_m`` is the loosest: the legs after it (turning in place, sidewinding
    across) shift the middle along the axis by a few centimetres, and a tighter bound would send the body back to
    the first leg. A turning run is precise to a degree or two, a sidewinding run to a centimetre or two."""

    along_m: float = 0.08
    across_m: float = 0.03
    yaw_deg: float = 4.0
    align_deg: float = 5.0

    def __post_init__(self) -> None:
        for name in ("along_m", "across_m", "yaw_deg", "align_deg"):
            object.__setattr__(self, name, positive(getattr(self, name), name))

    def tighter(self, floor: "Tolerance | None" = None) -> "Tolerance":
        """Half this tolerance, but not below ``floor`` (default: 3 cm, 2 cm, 2 deg, 3 deg)."""
        floor = floor or Tolerance(0.03, 0.02, 2.0, 3.0)
        return Tolerance(max(0.5 * self.along_m, floor.along_m), max(0.5 * self.across_m, floor.across_m),
                         max(0.5 * self.yaw_deg, floor.yaw_deg), max(0.5 * self.align_deg, floor.align_deg))


@dataclass(frozen=True)
class LocomotionStep:
    """One gait run: ``gait`` (its amplitudes scaled by ``scale``) for ``cycles`` whole cycles, and why (``leg``:
    "along", "heading" or "across")."""

    gait: Gait
    cycles: float
    leg: str
    scale: float = 1.0


def gait_run(name: str, direction: int, amount: float, full_rate: float, *, max_cycles: int = 4,
             frequency: float = 0.5, gait_options: dict | None = None, scale: float | None = None,
             leg: str = "") -> LocomotionStep:
    """A run of gait ``name`` that does ``amount`` (m sideways, rad of turn; > 0) at ``full_rate`` per cycle at full
    amplitude: whole cycles (a run of whole cycles ends in the shape it started from, so the sliding of its ramps
    cancels; fractions of a cycle do not, and turn the body by as much as they were meant to), as few as do it
    (at most ``max_cycles``), the amplitudes scaled down for the rest (AMPLITUDE_EXPONENT); ``scale``: this
    amplitude scale instead (at least MIN_AMPLITUDE_SCALE); ``leg``: the step's."""
    amount, full_rate = positive(amount, "amount"), positive(full_rate, "full_rate")
    cycles = int(min(max(math.ceil(amount / full_rate - 1e-9), 1), max_cycles))
    share = min(amount / (cycles * full_rate), 1.0)
    scale = max(share ** (1.0 / AMPLITUDE_EXPONENT.get(name, 1.0)) if scale is None else scale, MIN_AMPLITUDE_SCALE)
    options = dict(gait_options or {})
    options.setdefault("frequency", frequency)
    full = make_gait(name, direction, **options)
    for key in ("yaw_amplitude", "pitch_amplitude", "amplitude"):
        if key in full.parameters:
            options[key] = scale * full.parameters[key]
    return LocomotionStep(make_gait(name, direction, **options), float(cycles), leg, scale)


def next_step(robot: SnakeRobot, current: BasePlacement, goal: BasePlacement, rates: GaitRates, *,
              tolerance: Tolerance = Tolerance(), frequency: float = 0.5, max_cycles: int = 4,
              gait_options: dict | None = None, creep: bool = False) -> LocomotionStep | None:
    """The next gait run that brings a straight body's root frame from ``current`` towards ``goal`` (see the
    module), or None when it is there within ``tolerance``. ``frequency`` Hz of the gaits; a run is at most
    ``max_cycles`` cycles (the loop looks again after each; :func:`gait_run`); ``gait_options`` go to every gait
    (:func:`~snakehead.locomotion.gaits.make_gait`). ``creep``: travel along the goal's axis by linear progression at
    the body's own heading (no turn square to it: for an escape along the body's axis where it cannot turn)."""
    robot = as_robot(robot)
    current, goal = as_base(current), as_base(goal)
    frequency = positive(frequency, "frequency")
    if isinstance(max_cycles, bool) or not isinstance(max_cycles, (int, np.integer)) or max_cycles < 1:
        raise InputError(f"max_cycles must be a positive integer, got {max_cycles!r}")
    offset = chassis_offset(robot)
    here, there = compose(current, offset), compose(goal, offset)
    error = relative(there, here)  # the middle in the goal's frame
    along, across = error.x, error.y
    yaw_error = wrap_angle(goal.yaw - current.yaw)  # turn by this to face the goal's way

    def turn_to(heading: float, leg: str) -> LocomotionStep:
        angle = wrap_angle(heading - current.yaw)
        step = gait_run("turning", 1 if angle > 0 else -1, abs(angle), rates.turn_rad, max_cycles=max_cycles,
                        frequency=frequency, gait_options=gait_options)
        return LocomotionStep(step.gait, step.cycles, leg, step.scale)

    def sidewind(distance: float, leg: str, direction: int) -> LocomotionStep:
        step = gait_run("sidewinding", direction, abs(distance), rates.sideways_m, max_cycles=max_cycles,
                        frequency=frequency, gait_options=gait_options)
        return LocomotionStep(step.gait, step.cycles, leg, step.scale)

    if creep and abs(along) > tolerance.along_m:  # (the heading is corrected where the body can turn)
        step = gait_run("linear_progression", -1 if along > 0 else 1, abs(along), rates.forward_m,
                        max_cycles=max_cycles, frequency=frequency, gait_options=gait_options)
        return LocomotionStep(step.gait, step.cycles, "along", step.scale)
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
