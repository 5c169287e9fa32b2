"""What a plan returns: the :class:`Plan` (the 2 ms motion, its states, targets and checks), each target's
:class:`TargetResult`, and the :class:`PlanProgress` records :func:`~snakehead.planning.planner.plan` reports while it
works."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ..collision import body_collisions as coll
from ..dynamics import stability
from ..margins import EXACT_DISTANCE_WITHIN, ZMP_MARGIN
from ..model.robot import BasePlacement, SnakeRobot
from ..scenes.scene import Scene
from .fallbacks import tried_message

if TYPE_CHECKING:
    from .base_choice import Relocation


@dataclass(frozen=True)
class PlanProgress:
    """What :func:`~snakehead.planning.planner.plan` tells its ``progress`` callback, one record per call.

    kind: "target" once a target of the scene has been solved and the move to it planned (in the scene's order,
    via poses included): ``index`` 1..``count`` (the scene's targets), ``name``, ``solved``, ``seconds`` (its solve
    and move), ``message`` (why it was not solved; "" when it was). "stage" when a stage over the whole plan begins:
    ``name`` "base" (every target solved from the start, to choose the base), "timing" (the time-optimal retiming of
    the whole path, often the longest stage), "checks" (the ZMP, the ground and the obstacles at every 2 ms sample);
    ``message`` says what it does. ``elapsed_s``: seconds since :func:`~snakehead.planning.planner.plan` was called.
    """

    kind: str
    name: str
    index: int = 0
    count: int = 0
    solved: bool = True
    seconds: float = 0.0
    elapsed_s: float = 0.0
    message: str = ""


#: The signature of ``plan(progress=...)``: called with a :class:`PlanProgress`; its return value is ignored and an
#: exception it raises stops the plan (it propagates to the caller of :func:`~snakehead.planning.planner.plan`).
ProgressCallback = Callable[[PlanProgress], None]


@dataclass
class TargetResult:
    """One head target of a plan and how well the plan reaches it (planned, by forward kinematics)."""

    name: str
    position: np.ndarray  # (3,) m
    direction: np.ndarray  # (3,) unit
    time_s: float  # when the plan arrives
    solution: Any  # solve.whole_body.WholeBodySolution (the segmented HeadSolution in its ``segmented``)

    @property
    def position_error_m(self) -> float:
        return self.solution.position_error_m

    @property
    def direction_error_deg(self) -> float:
        return self.solution.direction_error_deg

    @property
    def solved(self) -> bool:
        return bool(self.solution.success)


@dataclass
class Plan:
    """A planned motion: the 2 ms joint trajectory, its states and targets, and its checks.

    name: the scene's. robot, base: the robot and where its base lies. t (T,) s, q (T, n) rad, qd (T, n) rad/s:
    the planner's joint angles, zero with the body straight (the description's are ``robot.description_angles(q)``,
    the same when the robot file has no ``[home]``; the files written for the plan hold the description's).
    states: (label, time s, q (n,)) of every waypoint. targets: :class:`TargetResult` per reported target.
    stability: ``dynamics.DynamicStability`` (ZMP and its margin at every sample). ground_clearance (T,) m: the
    lowest neck or head box corner above the ground. obstacles and obstacle_distance (T,) m (None without
    obstacles): a lower bound of the smallest distance to them from each sample to the next (exact at the samples
    the proof evaluated). motion_proof: ``collision.path_proof.MotionReport``, the proof that the motion is clear of
    the ground, itself and the obstacles between its samples too (None when not checked). segments: (segment,
    interpolation used). notes: what the planner had to do or could not.
    """

    name: str
    robot: SnakeRobot
    base: BasePlacement
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    states: list
    targets: list
    stability: stability.DynamicStability
    ground_clearance: np.ndarray
    obstacles: list = field(default_factory=list)
    obstacle_distance: np.ndarray | None = None
    planning_time_s: float = 0.0
    notes: list = field(default_factory=list)
    segments: list = field(default_factory=list)
    scene: Scene | None = None
    relocation: Relocation | None = None  # the change of base the targets need, before the plan (locomotion)
    timing_failure: str | None = None  # why the path could not be timed within the limits, when it could not
    out_of_range: str | None = None  # why no relocation was tried: a target beyond MAX_RELOCATION_M of the start
    motion_proof: Any = None  # collision.path_proof.MotionReport of the motion (None: not checked)
    attempts: list = field(default_factory=list)  # what was tried before the plan failed (planning.fallbacks)

    @property
    def min_zmp_margin_m(self) -> float:
        return float(self.stability.min_margin)

    @property
    def min_ground_clearance_m(self) -> float:
        return float(self.ground_clearance.min())

    @property
    def duration_s(self) -> float:
        return float(self.t[-1] - self.t[0])

    @property
    def min_obstacle_distance_m(self) -> float | None:
        """The smallest distance (m) of the robot to the obstacles at the motion's samples (None without obstacles):
        exact when it is below EXACT_DISTANCE_WITHIN, else a lower bound of it that is at least that. The proof's
        lower bounds in ``obstacle_distance`` stop tightening once positive (micrometres where the head passes a
        hole), so the samples whose bound is below EXACT_DISTANCE_WITHIN get their exact distance here."""
        if self.obstacle_distance is None:
            return None
        near = np.flatnonzero(self.obstacle_distance < EXACT_DISTANCE_WITHIN)
        if len(near) == 0:
            return float(self.obstacle_distance.min())
        exact = coll.collision_check(self.robot, self.q[near], self.obstacles, self.base,
                                     exact_within=EXACT_DISTANCE_WITHIN).distance
        far = np.delete(self.obstacle_distance, near)
        return float(min(exact.min(), far.min(initial=np.inf)))

    @property
    def touches_obstacle(self) -> bool:
        return self.obstacle_distance is not None and bool((self.obstacle_distance <= 0).any())

    @property
    def failure(self) -> str | None:
        """None when the plan succeeds, else the first reason it does not (a target not solved, the ZMP leaving the
        support polygon, a link in the ground, a link touching an obstacle), and what the planner tried before it
        gave up (``attempts``: ``planning.fallbacks``)."""
        reason = self._first_failure()
        return None if reason is None else tried_message(reason, self.attempts)

    def _first_failure(self) -> str | None:
        for tg in self.targets:
            if not tg.solved:
                why = self.out_of_range if self.out_of_range is not None else tg.solution.message
                return f"target {tg.name!r} not solved: {why}"
        if self.timing_failure is not None:
            return self.timing_failure
        if self.min_zmp_margin_m < ZMP_MARGIN:
            k = self.stability.argmin
            where = "leaves the support polygon by" if self.min_zmp_margin_m < 0 else "comes within"
            return (f"the ZMP {where} {abs(1000 * self.min_zmp_margin_m):.1f} mm of its edge at t = {self.t[k]:.2f} s "
                    f"(a plan keeps it {1000 * ZMP_MARGIN:.0f} mm inside)")
        if self.min_ground_clearance_m <= -coll.GROUND_TOLERANCE:
            k = int(np.argmin(self.ground_clearance))
            return (f"a neck or head link goes {-1000 * self.min_ground_clearance_m:.1f} mm into the ground at "
                    f"t = {self.t[k]:.2f} s")
        if self.touches_obstacle and self.obstacle_distance is not None:
            k = int(np.argmax(self.obstacle_distance <= 0))
            return f"a link touches an obstacle at t = {self.t[k]:.2f} s"
        if self.motion_proof is not None and not self.motion_proof.clear:
            return f"the motion is not proven clear between its samples: {self.motion_proof.describe()}"
        return None

    @property
    def success(self) -> bool:
        return self.failure is None


__all__ = ["PlanProgress", "ProgressCallback", "TargetResult", "Plan"]
