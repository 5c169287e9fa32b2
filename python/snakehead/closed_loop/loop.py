"""The control process of Section 3.3 from any lying state, closed in MuJoCo: gaits that move the body where the
targets need its base, the curl into the bending state, the lift, the targets.

Why a controller that steps with the simulation and not ``plan(..., start=...)``: gaits and a curl on the ground
do not go exactly where they are commanded (their contacts slip), so what comes after each of them depends on
where the body really went. A plan made once from the start would be open-loop; here each phase is decided from
the pose estimated after the last one, as the robot would do it.

:class:`ClosedLoop` ``.run(start)``, from the body lying at ``start`` (straight, or curled with ``q_start``):

1. **Where the base must go.** ``plan(..., allow_relocation=True)`` from where the curl into the bending state would
   leave the base (:func:`snakehead.locomotion.goals.curl_displacement`, the quasi-static friction model): that
   placement when the plan succeeds from it, else the relocation's (the plan then starts there), checked in
   dynamics as in 6; when that fails, the same from the scene's own placement, then placements near a plan that
   passed its own checks but tipped in dynamics. The placement of a
   successful plan is the loop's goal.
2. **Locomotion** (when the curl from here would not leave the base at the goal, within
   :class:`~snakehead.locomotion.goals.Tolerance`): the body uncurls if it is curled, then gait runs
   (:func:`snakehead.locomotion.goals.next_step`: turning in place and sidewinding) take the straight body to
   where the curl will leave its base at the goal (:func:`~snakehead.locomotion.goals.straight_pose_for`). After
   each run the next is decided from the pose the robot estimates (:mod:`snakehead.closed_loop.estimate`: joint
   angles, one IMU, contact odometry), never from MuJoCo's. With ``sensing="onboard"`` (the default) the estimate
   reads only the robot's own sensor models (:mod:`snakehead.sim.sensors`: 12-bit encoders, a MEMS IMU's gyro and
   accelerometer through an attitude filter); every ground run keeps the stream it read
   (:class:`~snakehead.closed_loop.gait_runner.SensorLog`), from which
   :func:`~snakehead.closed_loop.gait_runner.replay_estimate` gives the same estimate without the simulator.
3. **The curl** into the bending state: a joint motion on the ground (it slides the body by most of a metre on the
   default robot: predicted by the friction model, followed by the estimate).
4. **Re-plan** from the estimated pose with the base kept (``allow_relocation=False``, from the joints as measured):
   when the plan fails, back to 2 (a correction: uncurl, gaits, curl) with a tighter tolerance, or, when the body
   is already as close to the goal as the gaits bring it, towards another goal nearby whose plan succeeds. (The
   planner times its paths under the ZMP constraint, so a slower plan would not pass where the timed one fails.)
5. **The fix.** Dead reckoning drifts: by 2-5 % of the distance travelled with the friction odometry, tens of
   millimetres after a metre, far from the 2 mm the head must reach.

   *Onboard* (``sensing="onboard"``, the default): the head camera (:class:`~snakehead.sim.sensors.HeadSensor`)
   sees a fiducial marker ahead of each target. The head phases run up to the first waypoint from which the plan
   expects a marker well inside the camera's view (:func:`~snakehead.closed_loop.episode.look_waypoint`), and the
   head holds still there; the marker's pose relative to the head (averaged frames) with the encoders gives the
   root frame's world pose (:func:`snakehead.closed_loop.servo.root_from_head_reading`), and the head phases are
   planned again from there and the fixed pose (base kept). When that plan fails, the head goes back down along
   the plan and the loop returns to 2 from the fixed pose. When no marker is in view, the head phases go on from
   dead reckoning (a note says so).

   *Outside fix* (``sensing="outside fix"``): perfect encoders and IMU, and once the body rests in the bending
   state an outside measurement of the pose of the neck's base frame (``base_end``, the paper's P0: "the pose of
   the base frame of the neck part is obtained in time"; a motion-capture system) with the joint angles gives the
   root frame's placement (:class:`~snakehead.closed_loop.pose_fix.PoseFix`, with Gaussian noise: 0.5 mm and
   0.05 deg by default). The head phases are planned again from the fixed pose (base kept); when that plan fails, back
   to 2, the locomotion starting from the fixed pose.

   Each report states which (``sim.sensing`` and a note).
6. **The head phases**, checked as every plan (ZMP, clearance, obstacles) and in dynamics the way the pipeline
   checks a plan (simulated from the plan's own start, the base where the loop believes it lies: a plan whose
   body tips in it, CHECK_ZMP_OUTSIDE and CHECK_BASE_LIFT, is a failed plan, back to 2; the planner keeps its ZMP
   5 mm inside, which is not always enough in MuJoCo), then run in MuJoCo from the simulation's state
   (:func:`snakehead.sim.simulate_trajectory` with ``state=``) and compared with the plan
   (:func:`snakehead.sim.compare`), the plan placed where the body truly lies (its support polygon is where the
   simulated ZMP must stay, not where the loop believes it).
7. **The final approach** (onboard): the camera measures the last target relative to the head, and the head chain
   (the neck's lifting joints and the head's; the base's stay, so the support does not change) is corrected by a
   differential-IK step on that measurement (:func:`snakehead.closed_loop.servo.servo_step`), run in MuJoCo, up to
   SERVO_ITERATIONS times until the measured error is within SERVO_POSITION_TOL_M and SERVO_DIRECTION_TOL_DEG;
   a correction that lifts the base is the last. The head's accuracy then depends on the camera and the head
   chain, not on where the body believes it lies. ``metrics`` gain ``final_position_error_m`` and
   ``final_direction_error_deg`` (MuJoCo's truth after the last correction); ``LoopRun.servo`` has each look.

The result, :class:`~snakehead.closed_loop.loop_run.LoopRun`, has the phases (``name``, ``kind`` one of
gait/curl/lift/move/hold/servo, ``t0_s``, ``t1_s``), the estimate's error after every ground phase, how far the tail
travelled, and the head's errors.
Obstacles are in the simulation all along. The locomotion goes around them: when the gaits' straight legs would
come within the body's turning disc of one, step 2 follows a route of the body's middle planned around their
footprints (:func:`snakehead.locomotion.ground_path.plan_route`), planned again from the estimate whenever the body
drifts off it, every gait run's predicted sweep checked before it runs
(:func:`snakehead.locomotion.ground_path.sweep_clear`); a goal whose straight pose before the curl, or the curl
itself as the friction model predicts it, would come within GOAL_CLEARANCE_M of one is refused in step 1.
``sim.min_obstacle_distance_m`` is the body's smallest distance to any obstacle over the run.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError, entry_point, inputs_checked
from .._validate import positive
from ..collision import body_collisions as coll
from ..locomotion import goals as lc
from ..margins import EXACT_DISTANCE_WITHIN
from ..model.placement import WORLD_FRAME
from ..model.robot import BasePlacement, SnakeRobot, as_base
from ..planning.planner import as_scene
from ..planning.start_state import bending_state
from ..scenes.ground_scene import base_on_slope
from ..scenes.scene import Scene
from ..sim.sensors import OnboardSensors
from ..solve.head_controller import HeadController
from .episode import LOOK_HOLD_S, Episode, look_waypoint
from .gait_runner import GaitSimulator
from .goal_checks import CHECK_BASE_LIFT, CHECK_ZMP_OUTSIDE, CURL_CHECKS, NEARBY_STEP_DEG, NEARBY_STEP_M, GoalChecks
from .loop_run import ESTIMATE_SAMPLES, PHASE_KINDS, LoopRun, Phase, head_phases, placement_text
from .pose_fix import PoseFix
from .route_follower import MAX_LEGS, WAYPOINT_TOLERANCE, RouteFollower

# the supervisor's own names, then those of its parts, importable from here as they always were
__all__ = ["SENSING", "ClosedLoop",
           "PoseFix", "Phase", "LoopRun", "head_phases", "PHASE_KINDS", "ESTIMATE_SAMPLES", "LOOK_HOLD_S",
           "look_waypoint", "WAYPOINT_TOLERANCE", "MAX_LEGS", "CURL_CHECKS", "CHECK_ZMP_OUTSIDE", "CHECK_BASE_LIFT",
           "NEARBY_STEP_M", "NEARBY_STEP_DEG"]

#: How the loop knows where it is (:class:`ClosedLoop`'s ``sensing``): "onboard", the robot's own sensors alone
#: (:mod:`snakehead.sim.sensors`), or "outside fix", perfect joint angles and IMU and an outside measurement of the
#: neck's base frame (:class:`~snakehead.closed_loop.pose_fix.PoseFix`) once the body rests in the bending state.
SENSING = ("onboard", "outside fix")


class ClosedLoop:
    """The control process from any lying state, run in MuJoCo (see the module).

    scene: a :class:`~snakehead.scenes.Scene`, a scene file, or (position, direction) pairs. controller: the
    :class:`~snakehead.HeadController` (default: one for ``robot``, whose default is the scene's robot or the
    shipped one). timing: the planner's retiming options (:func:`snakehead.plan`'s ``timing``). fix: the
    :class:`~snakehead.closed_loop.pose_fix.PoseFix` (None: no fix, the head phases planned from dead reckoning
    alone). frequency: the gaits' (Hz). curl_speed: the curl's largest joint rate (rad/s). tolerance: the
    locomotion's (:class:`snakehead.locomotion.goals.Tolerance`). max_gait_runs: per correction; max_corrections:
    returns to step 2 after a curl before giving up. dynamics_check: simulate the head phases from the plan's own
    start before running them (step 6). sensing: one of SENSING (see the module; "outside fix" uses ``fix``,
    default a :class:`~snakehead.closed_loop.pose_fix.PoseFix`); sensor_seed: the onboard sensors' noise
    (:meth:`snakehead.sim.sensors.OnboardSensors.realistic`). imu_yaw_drift_deg_per_s, odometry and the other
    keywords (friction, ...) go to the :class:`~snakehead.closed_loop.gait_runner.GaitSimulator`; the head phases'
    simulation uses the same ground (``ground_options``).

    Its parts: ``goal_checks`` (:class:`~snakehead.closed_loop.goal_checks.GoalChecks`, steps 1 and 4),
    ``route_follower`` (:class:`~snakehead.closed_loop.route_follower.RouteFollower`, step 2); each run is an
    :class:`~snakehead.closed_loop.episode.Episode`.
    """

    def __init__(self, scene: Any, *, controller: HeadController | None = None, robot: SnakeRobot | None = None,
                 timing: dict[str, Any] | None = None, fix: PoseFix | None = None, sensing: str = "onboard",
                 sensor_seed: int | None = 0,
                 frequency: float = 0.5, curl_speed: float = 0.4, tolerance: lc.Tolerance = lc.Tolerance(),
                 max_gait_runs: int = 16, max_corrections: int = 3, method: str = "rotated", seed: int | None = 1,
                 dynamics_check: bool = True, **sim_options: Any) -> None:
        self.scene = as_scene(scene)
        self.controller = _head_controller(self.scene, controller, robot, method, seed)
        self.robot = self.controller.robot
        if timing is not None and not isinstance(timing, dict):
            raise InputTypeError(f"timing must be a dict of the retiming's options, got {type(timing).__name__}")
        self.timing = None if timing is None else dict(timing)
        self.sensing = sensing
        self.fix = _pose_fix(self.robot, sensing, fix)
        self.frequency = positive(frequency, "frequency")
        self.curl_speed = positive(curl_speed, "curl_speed")
        if not isinstance(tolerance, lc.Tolerance):
            raise InputTypeError(f"tolerance must be a snakehead.locomotion.goals.Tolerance, got "
                            f"{type(tolerance).__name__}")
        self.tolerance = tolerance
        for name, value in (("max_gait_runs", max_gait_runs), ("max_corrections", max_corrections)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
                raise InputError(f"{name} must be a non-negative integer, got {value!r}")
        self.max_gait_runs, self.max_corrections = int(max_gait_runs), int(max_corrections)
        self.dynamics_check = bool(dynamics_check)
        self.obstacles = list(self.scene.obstacles)
        self.sim_options = dict(sim_options)
        self.sensors = (OnboardSensors.realistic([(tg.position, tg.direction) for tg in self.scene.targets],
                                                 self.obstacles, sensor_seed) if sensing == "onboard" else None)
        # on a plane terrain the scene is in the slope's ground frame (as_scene) and its base holds that frame
        self.ground = self.scene.base.ground if self.scene.base is not None else WORLD_FRAME
        self.simulator = GaitSimulator(self.robot, obstacles=self.obstacles, sensors=self.sensors, ground=self.ground,
                                       **self.sim_options)
        self.ground_options = {k: v for k, v in self.sim_options.items()
                               if k in ("friction", "joint_damping", "armature", "timestep", "control_dt",
                                        "hole_slices", "torque_limit")}
        self.goal_checks = GoalChecks(self.scene, self.controller, timing=self.timing,
                                      obstacles=self.obstacles, dynamics_check=self.dynamics_check,
                                      ground_options=self.ground_options)
        self.route_follower = RouteFollower(self.robot, self.obstacles, frequency=self.frequency,
                                            max_gait_runs=self.max_gait_runs)

    def straight_start(self, base: BasePlacement | None = None) -> BasePlacement:
        """Where the body lies straight when the curl into the bending state alone brings its base to ``base``
        (default: the scene's placement, else the default one): the paper's "current state" (Fig. 17a) before
        its bending state (Fig. 17b)."""
        base = self._on_ground(base if base is not None else self.scene.base)
        return lc.straight_pose_for(self.robot, base, bending_state(self.controller))

    @entry_point
    def run(self, start: BasePlacement, q_start: npt.ArrayLike | None = None, *,
            believed_start: BasePlacement | None = None, progress: Callable[[str], None] | None = None) -> LoopRun:
        """Run the loop from the body lying at ``start`` (the body frame's placement) with joints ``q_start``
        (default straight; a flat shape: pitch joints 0); on a slope (a scene whose terrain is a plane) ``start`` is
        in the slope's ground frame (:attr:`BasePlacement.ground`), or in the world as a scene's base is written.
        The loop knows where the body starts
        (``believed_start``, default ``start``; give another to start from a wrong belief). ``progress``: called
        with a line of text at every step."""
        robot = self.robot
        start = self._on_ground(start)
        believed = start if believed_start is None else self._on_ground(believed_start)
        q_now = lc.flat_shape(robot, np.zeros(robot.n_joints) if q_start is None else q_start, "q_start")
        if coll.self_clearance(robot, q_now[None])[0] <= 0.0:
            raise InputError("q_start folds the body onto itself (two links overlap)")
        if self.obstacles and coll.collision_check(robot, q_now[None], self.obstacles, start,
                                                   exact_within=EXACT_DISTANCE_WITHIN).distance[0] <= 0.0:
            raise InputError(f"the body lying at {placement_text(start)} is inside an obstacle of the scene")
        inputs_checked()  # the loop plans and simulates from here: an InputError inside would be a bug
        ep = Episode(self, start, believed, q_now, progress or (lambda text: None))
        failure, corrections = self._steps(ep)
        return LoopRun(robot=robot, scene=self.scene, start=start, believed_start=believed, q_start=q_now,
                       phases=ep.phases, fixes=ep.fixes, plan=ep.head_plan, head=ep.head, metrics=ep.metrics,
                       head_t0_s=ep.head_t0, corrections=max(corrections, 0), planning_time_s=ep.planning,
                       notes=ep.notes, failure=failure, fix=self.fix, sensing=self.sensing, head_extra=ep.extra,
                       servo=ep.servo_log, routes=ep.routes)

    def _on_ground(self, base: BasePlacement | None) -> BasePlacement:
        """A placement on the loop's ground (the default one when None): on a slope one given in the world is
        put on it as the planner puts a scene's base (:func:`snakehead.scenes.ground_scene.base_on_slope`), one
        already in the slope's ground frame is kept."""
        base = BasePlacement(ground=self.ground) if base is None else as_base(base)
        return base if self.ground.is_world else base_on_slope(base, self.ground)

    def _steps(self, ep: Episode) -> tuple[str | None, int]:
        """The episode's steps (see the module): 1. the goal (after a failed head plan: a correction, a closer
        goal), 2. the gaits and the curl, 3.-5. the head phases planned, 6. run; back to 1 while the head phases
        fail, at most ``max_corrections`` times. Why the loop failed (None when the head phases ran) and how many
        corrections it made."""
        failure, corrections = None, -1
        while failure is None:
            corrections += 1
            if corrections > self.max_corrections:
                failure = (f"the body was not brought where the head phases succeed after {self.max_corrections} "
                           "corrections")
                break
            failure = ep.choose_goal() if ep.goal is None else ep.closer_goal()
            if failure is None:
                failure = ep.go_to_goal()
            if failure is not None:
                break
            started = ep.plan_head_phases()
            if started is None:
                continue
            ep.run_head_phases(*started)
            break
        return failure, corrections


def _head_controller(scene: Scene, controller: HeadController | None, robot: SnakeRobot | None, method: str,
                     seed: int | None) -> HeadController:
    """:class:`ClosedLoop`'s controller: ``controller``, else one for ``robot`` (default: the scene's robot, else
    the shipped one) with ``method`` and ``seed``."""
    if controller is None:
        if robot is None:
            robot = scene.load_robot() or SnakeRobot.default()  # a scene file's: confined to its folder
        return HeadController(robot, method=method, seed=seed)
    if not isinstance(controller, HeadController):
        raise InputTypeError(f"controller must be a HeadController, got {type(controller).__name__}")
    if robot is not None and robot is not controller.robot:
        raise InputError("give a robot or a controller (whose robot is used), not both")
    return controller


def _pose_fix(robot: SnakeRobot, sensing: str, fix: PoseFix | None) -> PoseFix | None:
    """:class:`ClosedLoop`'s outside fix for ``sensing`` (one of SENSING): none on board; with "outside fix",
    ``fix`` (default a :class:`~snakehead.closed_loop.pose_fix.PoseFix`), its frame on ``robot``'s body."""
    if sensing not in SENSING:
        raise InputError(f"sensing must be one of {SENSING}, got {sensing!r}")
    if fix is not None and not isinstance(fix, PoseFix):
        raise InputTypeError(f"fix must be a PoseFix or None, got {type(fix).__name__}")
    if fix is not None and sensing == "onboard":
        raise InputError('a PoseFix is the "outside fix" sensing: give sensing="outside fix" with it')
    if sensing == "outside fix" and fix is None:
        fix = PoseFix()
    if fix is not None and fix.frame is not None:
        robot.link_index(fix.frame)  # ValueError for a frame not on the body
    return fix
