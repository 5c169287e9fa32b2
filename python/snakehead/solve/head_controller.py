"""`HeadController`: the control process of Section 3.3 for one target (steps 1, 3, 4 and the static check of 5).

Given where the head must be and where it must point, find all the joint angles:
1. the base lies on the optimised plane arc (``backbone.initial_configuration``; on the body's actual ground
   contacts when the paper's arc does not stand on them: ``initial_state``);
3. P0, the accepted-range test, and, if the target is out of range, the planar move of the base that brings
   it in (reported, as the rolling gait or turning in place would have to carry it out);
   then the neck end frame by Eqs. 18-22 with the dexterous centre G0 of the head's reachability map;
4. the head joints by TRAC-IK towards the position and the direction (``head.rotated_frames`` or
   ``head.free_roll``);
5. (static part) the centre of mass inside the support polygon.
The motions to the solution (steps 2, 5 dynamic, 6) are the planner's (:mod:`snakehead.planning.planner`).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError, entry_point, inputs_checked
from .._validate import duration, integer, joint_vector, positive, unit_vector3, vector3, within_limits
from ..dynamics import stability
from ..kinematics import ik
from ..kinematics import reachability as workspace
from ..kinematics.ik import TracIK
from ..kinematics.reachability.reachability_map import ReachabilityMap
from ..model.robot import BasePlacement, SnakeRobot, as_robot
from . import head as head_ik
from . import neck as nk
from .body_problem import BodyProblem
from .initial_state import stable_initial_configuration

__all__ = ["FREE_ROLL_ATTEMPTS", "HeadController", "HeadSolution"]

#: TRAC-IK calls of the head's free-roll solve from different starts (an unseeded solver's calls search anew).
FREE_ROLL_ATTEMPTS = 3


@dataclass
class HeadSolution:
    """The result of ``HeadController.solve``. Positions in m (world), angles in rad unless named _deg."""

    q: np.ndarray  # (n,) all joint angles; the best attempt even when success is False
    base: BasePlacement  # the base placement used (moved when the target was out of range)
    base_moved: bool
    head_frame: np.ndarray  # (4, 4) achieved head_tip pose in the world (by whole-body FK)
    desired_frame: np.ndarray  # (4, 4) the desired head frame (x-axis = desired direction)
    position_error_m: float  # |achieved - desired| head position
    direction_error_deg: float  # between achieved and desired head x-axes
    success: bool
    message: str
    static_stable: bool  # centre of mass inside the support polygon (Eqs. 23-24)
    static_margin_m: float  # signed distance of the CoM projection to the polygon edge (> 0 inside)
    timings: dict = field(default_factory=dict)  # seconds spent in each stage
    neck_goal: nk.NeckGoal | None = None
    neck: nk.NeckSolution | None = None
    head: head_ik.HeadIKResult | None = None

    @property
    def head_position(self) -> np.ndarray:
        """The achieved head position (3,) m, world."""
        return self.head_frame[:3, 3]


class HeadController:
    """Segmented head control on a snake robot.

    robot: the robot (default: the shipped 16-joint snake). workspace_map: the head's reachability map, whose
    dexterous centre G0 places the head's base (default: ``kinematics.reachability.map_for(robot)``: the robot
    file's map, else a cached one, else one computed now with a progress bar). The dexterous workspace is the
    map's voxels of index 100 or, for a head that reaches 100 nowhere enough, its best band
    (``dexterous_threshold``, said in ``dexterous_note``).
    base_pose: where the base lies (default ``BasePlacement()``). method: "rotated" (the paper's Fig. 9,
    ``n_frames`` rolled frames) or "free_roll". ``slack`` is the paper's L_0 of the accepted range (m;
    default: one neck link). ``timeout`` (s) and ``epsilon`` are the head TRAC-IK's; ``seed`` makes the
    solutions reproducible.
    """

    def __init__(self, robot: SnakeRobot | None = None, workspace_map: ReachabilityMap | None = None,
                 base_pose: BasePlacement | None = None, *, method: str = "rotated", n_frames: int = 10,
                 timeout: float = ik.DEFAULT_TIMEOUT_S, epsilon: float = ik.DEFAULT_EPSILON, seed: int | None = None, slack: float | None = None,
                 base_configuration: npt.ArrayLike | None = None, allow_base_move: bool = True) -> None:
        self.robot = as_robot(robot) if robot is not None else SnakeRobot.default()
        if method not in ("rotated", "free_roll"):
            raise InputError(f"method must be 'rotated' or 'free_roll', got {method!r}")
        self.method, self.n_frames = method, integer(n_frames, "n_frames", least=1, most=360)
        timeout = duration(timeout, "timeout")
        if workspace_map is None:
            workspace_map = workspace.map_for(self.robot)
        # a whole map of this robot's head, with enough voxels for G0 (a shard's G0 is elsewhere)
        self.map = workspace.require_map(workspace_map, self.robot, needs=("G0",), what="workspace_map")
        #: The dexterous workspace's lower index (100 unless the head reaches 100 in too few voxels).
        self.dexterous_threshold = float(self.map.dexterous_threshold())
        self.dexterous_note = ("G0 is the centre of the voxels of index 100 (the paper's dexterous workspace)"
                               if self.dexterous_threshold >= 100.0 else
                               f"the head reaches index 100 in too few voxels; G0 is the centre of its best band, "
                               f"index >= {self.dexterous_threshold:.1f}")
        if self.map.quality_problem():
            self.dexterous_note += f" ({self.map.quality_problem()})"
        self.G0_local = vector3(self.map.center(threshold=self.dexterous_threshold), "dexterous centre G0")
        self.Lc = nk.dexterous_distance(self.G0_local)
        self.base = base_pose if base_pose is not None else BasePlacement()
        if not isinstance(self.base, BasePlacement):
            raise InputTypeError("base_pose must be a BasePlacement")
        self.neck_length = self.robot.lift_length  # the part of the neck that can lift (all of it, usually)
        self.slack = positive(slack, "slack") if slack is not None else self.neck_length / 2
        self.allow_base_move = bool(allow_base_move)
        if base_configuration is None:  # the paper's, unless it does not stand on the body's actual contacts
            base_configuration = stable_initial_configuration(self.robot)
        self.q_initial = within_limits(joint_vector(base_configuration, self.robot.n_joints, "base_configuration"),
                                       self.robot.lower, self.robot.upper, "base_configuration")
        self._polygons: dict = {}  # (base placement, base joints) -> support polygon
        self.ik = TracIK.from_chain(self.robot.head_chain, timeout=timeout,
                                    epsilon=positive(epsilon, "epsilon"), seed=seed)

    @property
    def _free_roll_attempts(self) -> int:
        """TRAC-IK calls of the head's free-roll solve: FREE_ROLL_ATTEMPTS, or one for a seeded solver, whose
        later calls would run the same seeded restarts to the same budget after one other first descent, and a
        failing call costs the whole budget)."""
        return 1 if self.ik.seed is not None else FREE_ROLL_ATTEMPTS

    # --- the process ---------------------------------------------------------------------------
    @entry_point
    def solve(self, position: npt.ArrayLike, direction: npt.ArrayLike, q_prev: npt.ArrayLike | None = None,
              base: BasePlacement | None = None, accept: Callable[..., bool] | None = None,
              allow_base_move: bool | None = None) -> HeadSolution:
        """All joint angles that put the head at ``position`` (3,) m pointing along ``direction`` (3,).

        ``q_prev`` (n_joints,): the current joints, within the joint limits (ValueError otherwise: the base would keep
        them); the base keeps its shape from it and the neck and head start from it (and, with the rotated-frames
        method, the solution closest to it is kept). ``base``: the base placement to start from (default: the
        controller's).

        Step 3's accepted range decides where the base must be. Out of range, the base is moved (when
        ``allow_base_move``) by the planar move that brings the target in range; the accepted range is a
        sufficient test, not a necessary one, so a target out of range is first tried from where the base is,
        and the move is made only when that fails or leaves the body statically unstable.

        ``allow_base_move``: whether a target out of range may move the base (default: the controller's
        ``allow_base_move``).

        ``accept``: an optional test ``accept(q (n,), base) -> bool`` of a whole-body solution (e.g. no
        collision with an obstacle). Only accepted solutions are kept: with free roll, when its solution is
        rejected, the ``n_frames`` rolled frames of the paper's method are solved and filtered.
        """
        position = vector3(position, "position")
        direction = unit_vector3(direction, "direction")
        if q_prev is not None:  # joints outside their limits would be returned as they are, with success=True
            q_prev = within_limits(joint_vector(q_prev, self.robot.n_joints, "q_prev"), self.robot.lower,
                                   self.robot.upper, "q_prev")
        if base is not None and not isinstance(base, BasePlacement):
            raise InputTypeError(f"base must be a BasePlacement, got {type(base).__name__}")
        if accept is not None and not callable(accept):
            raise InputTypeError("accept must be a callable accept(q, base) -> bool or None, got "
                                 f"{type(accept).__name__}")
        inputs_checked()
        return self.solve_checked(position, direction, q_prev, base, accept, allow_base_move)

    def solve_checked(self, position: np.ndarray, direction: np.ndarray, q_prev: np.ndarray | None = None,
                      base: BasePlacement | None = None, accept: Callable[..., bool] | None = None,
                      allow_base_move: bool | None = None) -> HeadSolution:
        """:meth:`solve` of values already checked (a target's, checked where it entered the library; joints the
        planner computed): ``position`` (3,) finite, ``direction`` (3,) a unit vector, ``q_prev`` within the
        limits. A value that is not is a bug of the caller's, not bad input."""
        t_start = time.perf_counter()
        q = self.q_initial.copy() if q_prev is None else np.array(q_prev, float)
        base = self.base if base is None else base
        desired = head_ik.frame_along(position, direction)
        P0_frame = self.robot.frame(q, self.robot.lift_frame, base)
        check = self._accepted_range(position, P0_frame)
        solution = self._solve_from(base, q, desired, q_prev is not None, accept)
        if not check.accepted:
            note = f"the target is outside the accepted range from the given base ({check.reason})"
            move = self.allow_base_move if allow_base_move is None else bool(allow_base_move)
            if not (solution.success and solution.static_stable) and move and self.neck_length > 0:
                P0_local = np.linalg.inv(self.robot.body_pose(base)) @ P0_frame
                moved = nk.base_move_into_range(position, P0_local, base, self.Lc, self.neck_length, self.slack,
                                                     self.robot.body_axis_height)
                if moved is not None:
                    retry = self._solve_from(moved, q, desired, q_prev is not None, accept)
                    retry.base_moved = True
                    note += "; moved the base into range"
                    if retry.success or not solution.success:
                        solution = retry
                else:
                    note += "; no planar base move brings it in range (too high above the ground)"
            solution.message += f" ({note})"
        solution.timings["total"] = time.perf_counter() - t_start
        return solution

    def _accepted_range(self, position: np.ndarray, P0_frame: np.ndarray) -> nk.RangeCheck:
        """Step 3's accepted range from the lift frame P0_frame; a neck without a pitch joint lifts nothing, so no
        target is in its range (the whole-body solve may still reach it)."""
        if self.neck_length > 0:
            return nk.accepted_range(position, P0_frame[:3, 3], self.Lc, self.neck_length, self.slack)
        return nk.RangeCheck(False, float("nan"), 0.0, 0.0, "the neck has no pitch joint: it cannot lift the head's "
                             "base (name a base_end before a pitch joint to give the neck one)")

    def _solve_lift(self, P0_frame: np.ndarray, goal: nk.NeckGoal, q_init: np.ndarray) -> nk.NeckSolution:
        """Eqs. 18-22 over the neck's lifting joints from the lift frame P0_frame. A neck without a pitch joint
        (a one-joint yaw neck before a pitch-first head) has none: its lift frame is the neck's end, the chain
        between them would have no link, and B0 is P0_frame itself."""
        if self.robot.lift_joints.start < self.robot.lift_joints.stop:
            return nk.solve_neck(self.robot.lift_chain, P0_frame, goal, q_init=q_init)
        ra = P0_frame[:3, 0]
        error = P0_frame[:3, 3] - goal.P_d
        cost = float(error @ error + nk.DEFAULT_H * np.sum(np.cross(goal.r_d, ra) ** 2))
        return nk.NeckSolution(q=np.zeros(0), frame=P0_frame.copy(), cost=cost,
                               position_error_m=float(np.linalg.norm(error)),
                               direction_error_deg=head_ik.angle_between_deg(ra, goal.r_d))

    def _solve_from(self, base: BasePlacement, q: np.ndarray, desired: np.ndarray, keep_close: bool,
                    accept: Callable[..., bool] | None = None) -> HeadSolution:
        """Steps 3-5 with the base where it is: the neck by Eqs. 18-22, the head by TRAC-IK, the static check."""
        timings: dict[str, float] = {}
        q = q.copy()
        parts = self.robot.parts

        t0 = time.perf_counter()
        goal, neck = self._place_neck(base, q, desired[:3, 3])
        timings["neck"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        head = self._solve_head(base, q, neck, desired, keep_close, accept)
        timings["head"] = time.perf_counter() - t0
        if head.success:
            q[parts.head] = head.q

        # Check by whole-body FK, and the static part of step 5.
        t0 = time.perf_counter()
        achieved = self.robot.head_pose(q, base)
        pe, de = head_ik.position_and_direction_error(achieved, desired)
        margin = self._static_margin(q, base)
        timings["check"] = time.perf_counter() - t0
        return HeadSolution(q=q, base=base, base_moved=False, head_frame=achieved, desired_frame=desired,
                            position_error_m=pe, direction_error_deg=de, success=head.success,
                            message=_head_message(head, margin), static_stable=margin > 0, static_margin_m=margin,
                            timings=timings, neck_goal=goal, neck=neck, head=head)

    def _place_neck(self, base: BasePlacement, q: np.ndarray, position: np.ndarray
                    ) -> tuple[nk.NeckGoal, nk.NeckSolution]:
        """Step 3: the neck end frame by Eqs. 18-22 towards ``position``; sets the neck's joints in ``q``.

        Eqs. 18-22 pivot on P0; on a neck that begins with yaw joints, on the frame where its lifting begins (the
        joints before it keep the initial state's angles: see ``SnakeRobot.lift_joints``)."""
        lift = self.robot.lift_joints
        neck_start = self.robot.parts.neck.start
        q[neck_start:lift.start] = self.q_initial[neck_start:lift.start]
        P0_frame = self.robot.frame(q, self.robot.lift_frame, base)
        goal = nk.neck_goal(P0_frame[:3, 3], position, self.Lc)
        neck = self._solve_lift(P0_frame, goal, q[lift])
        q[lift] = neck.q
        return goal, neck

    def _solve_head(self, base: BasePlacement, q: np.ndarray, neck: nk.NeckSolution, desired: np.ndarray,
                    keep_close: bool, accept: Callable[..., bool] | None) -> head_ik.HeadIKResult:
        """Step 4: the head joints by TRAC-IK from the neck end frame B0 towards the desired frame (4, 4), the
        other joints those of ``q``; with ``keep_close``, the rolled frames' solution nearest ``q``'s head."""
        head_part = self.robot.parts.head
        target = np.linalg.inv(neck.frame) @ desired
        q_close = q[head_part].copy() if keep_close else None

        def accepted(q_head: Any) -> bool:
            if accept is None:
                return True
            q_full = q.copy()
            q_full[head_part] = q_head
            return bool(accept(q_full, base))

        if self.method == "free_roll":
            head = head_ik.free_roll(self.ik, target, q_init=q[head_part], attempts=self._free_roll_attempts)
        if self.method == "rotated" or (accept is not None and head.success and not accepted(head.q)):
            # The paper's rolled frames give a set of candidates to choose from (also when the free-roll
            # solution fails the caller's test).
            head = head_ik.rotated_frames(self.ik, target, self.n_frames, q_init=q[head_part], q_prev=q_close,
                                          accept=None if accept is None else accepted)
        return head

    @property
    def body_problem(self) -> BodyProblem:
        """The geometry the whole-body solve needs for this robot (:class:`~.body_problem.BodyProblem`), made
        once."""
        if getattr(self, "_body_problem", None) is None:
            self._body_problem = BodyProblem(self.robot)
        return self._body_problem

    def _static_margin(self, q: np.ndarray, base: BasePlacement) -> float:
        """``stability.static_margin`` with the support polygon cached: it depends only on the base joints
        and placement, which a controller keeps (the polygon is the costly part: a convex hull)."""
        key = (base, q[self.robot.parts.base].tobytes())
        poly = self._polygons.get(key)
        if poly is None:
            if len(self._polygons) > 64:
                self._polygons.clear()
            poly = self._polygons[key] = stability.support_polygon(self.robot, q, base)
        c = stability.center_of_mass(self.robot, q, base)
        return float(stability.polygon_margin_many(poly[None], np.ones((1, len(poly)), bool), c[None, :2])[0])


def _head_message(head: head_ik.HeadIKResult, margin: float) -> str:
    """What a segmented solution says: solved (and whether it stands), or why the head's IK found nothing."""
    if head.success:
        return "solved" if margin > 0 else "solved, but the centre of mass is outside the support polygon"
    if head.solved:
        return f"none of the {head.solved} head solutions found passed the caller's acceptance test"
    return (f"the head IK found no solution from the neck end frame ({head.tried} frames tried): "
            "the target lies outside the head's workspace from there")
