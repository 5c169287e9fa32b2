"""The control process of Section 3.3 from any lying state, closed in MuJoCo: gaits that move the body where the
targets need its base, the curl into the bending state, the lift, the targets.

Why a controller that steps with the simulation and not ``plan(..., start=...)``: gaits and a curl on the ground
do not go exactly where they are commanded (their contacts slip), so what comes after each of them depends on
where the body really went. A plan made once from the start would be open-loop; here each phase is decided from
the pose estimated after the last one, as the robot would do it.

:class:`ClosedLoop` ``.run(start)``, from the body lying at ``start`` (straight, or curled with ``q_start``):

1. **Where the base must go.** ``plan(..., allow_relocation=True)`` from where the curl into the bending state would
   leave the base (:func:`snakehead.motion.locomotion.curl_displacement`, the quasi-static friction model): that
   placement when the plan succeeds from it, else the relocation's (the plan then starts there), checked in
   dynamics as in 6; when that fails, the same from the scene's own placement, then placements near a plan that
   passed its own checks but tipped in dynamics. The placement of a
   successful plan is the loop's goal.
2. **Locomotion** (when the curl from here would not leave the base at the goal, within
   :class:`~snakehead.motion.locomotion.Tolerance`): the body uncurls if it is curled, then gait runs
   (:func:`snakehead.motion.locomotion.next_step`: turning in place and sidewinding) take the straight body to
   where the curl will leave its base at the goal (:func:`~snakehead.motion.locomotion.straight_pose_for`). After
   each run the next is decided from the pose the robot estimates (:mod:`snakehead.sim.estimate`: joint angles, one
   IMU, contact odometry), never from MuJoCo's.
3. **The curl** into the bending state: a joint motion on the ground (it slides the body by most of a metre on the
   default robot: predicted by the friction model, followed by the estimate).
4. **Re-plan** from the estimated pose with the base kept (``allow_relocation=False``, from the joints as measured):
   when the plan fails, back to 2 (a correction: uncurl, gaits, curl) with a tighter tolerance, or, when the body
   is already as close to the goal as the gaits bring it, towards another goal nearby whose plan succeeds. (The
   planner times its paths under the ZMP constraint, so a slower plan would not pass where the timed one fails.)
5. **The fix.** Dead reckoning drifts: by 2-5 % of the distance travelled with the friction odometry, tens of
   millimetres after a metre, far from the 2 mm the head must reach. The loop closes it the way the paper's
   simulation does ("the pose of the base frame of the neck part is obtained in time"): once the body rests in
   the bending state, an outside measurement of the pose of the neck's base frame (``base_end``, the paper's P0;
   a motion-capture system, or the head's camera fixing known landmarks) with the joint angles gives the root
   frame's placement (:class:`PoseFix`, with Gaussian noise: 0.5 mm and 0.05 deg by default). This is an
   assumption of the loop, stated in every report. The head phases are planned again from the fixed pose (base
   kept); when that plan fails, back to 2, the locomotion starting from the fixed pose.
6. **The head phases**, checked as every plan (ZMP, clearance, obstacles) and in dynamics the way the pipeline
   checks a plan (simulated from the plan's own start, the base where the loop believes it lies: a plan whose
   body tips in it, CHECK_ZMP_OUTSIDE and CHECK_BASE_LIFT, is a failed plan, back to 2; the planner keeps its ZMP
   5 mm inside, which is not always enough in MuJoCo), then run in MuJoCo from the simulation's state
   (:func:`snakehead.sim.simulate_trajectory` with ``state=``) and compared with the plan
   (:func:`snakehead.sim.compare`).

The result, :class:`LoopRun`, has the phases (``name``, ``kind`` one of gait/curl/lift/move/hold, ``t0_s``,
``t1_s``), the estimate's error after every ground phase, how far the tail travelled, and the head's errors.
Obstacles are in the simulation all along, but the locomotion does not steer around them (it goes straight).
"""
from __future__ import annotations

import math
import re
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import numpy.typing as npt

from .._validate import finite_float, positive
from ..control.controller import HeadController
from ..geometry import collision as coll
from ..margins import EXACT_DISTANCE_WITHIN
from ..model.robot import BasePlacement, SnakeRobot, as_base
from ..motion import locomotion as lc
from ..motion.plan_result import Plan
from ..motion.planner import as_scene, plan
from ..motion.start_state import bending_state
from ..scenes.scene import Scene
from .compare import check_plan_span, compare
from .estimate import BodyPose, pose_error
from .gaits import GaitRun, GaitSimulator
from .tracking import SimResult, simulate_trajectory
from .._errors import InputError, InputTypeError, InternalError, entry_point, inputs_checked

#: The kinds of phases in a loop's report.
PHASE_KINDS = ("gait", "curl", "lift", "move", "hold")
#: The dynamics check of the head phases fails when the simulated ZMP leaves the planned support polygon by more
#: than this (m) or a base frame rises more than CHECK_BASE_LIFT (m): the body tips (a plan that tips goes out by
#: tens of millimetres and lifts its base by centimetres; the ZMP grazing the edge at the first tick does not).
CHECK_ZMP_OUTSIDE = 0.002
CHECK_BASE_LIFT = 0.005
#: When the body is as close to its goal as the gaits bring it and the head phases still fail, the loop looks for
#: another goal this far from it (m along and across, deg turned).
NEARBY_STEP_M = 0.08
NEARBY_STEP_DEG = 8.0


@dataclass(frozen=True)
class PoseFix:
    """The outside measurement that closes the loop (see the module): the world pose of one frame of the body,
    ``frame`` (default the neck's base frame, ``robot.parts.base_end``), in the ground plane (x, y and heading), with
    Gaussian noise of ``position_noise_m`` (m, per axis) and ``yaw_noise_deg`` (deg); ``seed`` for the noise."""

    frame: str | None = None
    position_noise_m: float = 0.0005
    yaw_noise_deg: float = 0.05
    seed: int | None = 0

    def __post_init__(self) -> None:
        for name in ("position_noise_m", "yaw_noise_deg"):
            v = finite_float(getattr(self, name), name)
            if v < 0:
                raise InputError(f"{name} must be >= 0, got {v!r}")
            object.__setattr__(self, name, v)

    def measure(self, simulator: GaitSimulator, rng: np.random.Generator) -> BodyPose:
        """The body's pose from the measured frame, the joint angles (encoders) and the IMU, as the estimator
        represents it."""
        robot = simulator.robot
        k = robot.link_index(self.frame or robot.parts.base_end)
        data = simulator.data
        body = simulator.sim.body_ids[k]
        R = data.xmat[body].reshape(3, 3)
        p = data.xpos[body].copy()
        p[:2] += rng.normal(0.0, self.position_noise_m, 2)
        a = math.radians(rng.normal(0.0, self.yaw_noise_deg)) if self.yaw_noise_deg > 0 else 0.0
        Rz = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = Rz @ R, p
        q = simulator.joint_angles()
        body = T @ np.linalg.inv(robot.body.fk_all(q)[k]) @ robot.body_in_root  # the body frame's world pose
        yaw = math.atan2(body[1, 0], body[0, 0])
        return simulator.estimator.reset(q, simulator.imu_orientation(), body[:2, 3], yaw)


@dataclass
class Phase:
    """One phase of a loop: ``name``, ``kind`` (one of :data:`PHASE_KINDS`), from ``t0_s`` to ``t1_s`` (s, the
    simulation's clock); for ground phases, the estimate's error against MuJoCo's pose at its end
    (:func:`snakehead.sim.estimate.pose_error`) and the run itself."""

    name: str
    kind: str
    t0_s: float
    t1_s: float
    estimate_error: dict | None = None
    run: GaitRun | None = field(default=None, repr=False)

    def as_dict(self) -> dict:
        d = {"name": self.name, "kind": self.kind, "t0_s": self.t0_s, "t1_s": self.t1_s}
        if self.estimate_error is not None:
            d["estimate_error"] = dict(self.estimate_error)
        return d


@dataclass
class LoopRun:
    """What a closed loop did (see the module).

    start / believed_start: where the body truly lay and where the loop believed it did; phases; fixes: each
    fix's record (the estimate before it and its error, the fix's error); plan: the plan of the head phases (None
    if the loop never got there); head: their simulation (:class:`~snakehead.sim.SimResult`); metrics: the head
    phases against their plan (:func:`snakehead.sim.compare`); head_t0_s: when the head phases began;
    corrections: how many times the loop went back to step 1 after a curl; planning_time_s: wall time spent
    planning; notes; failure: None when the head phases were planned and simulated, else why not.
    """

    robot: SnakeRobot
    scene: Scene
    start: BasePlacement
    believed_start: BasePlacement
    q_start: np.ndarray
    phases: list
    fixes: list
    plan: Plan | None
    head: SimResult | None
    metrics: dict | None
    head_t0_s: float
    corrections: int
    planning_time_s: float
    notes: list
    failure: str | None
    fix: PoseFix | None = None

    @property
    def success(self) -> bool:
        """The head phases were planned successfully and simulated (how close the head came: ``metrics``)."""
        return self.failure is None

    @property
    def ground_runs(self) -> list[GaitRun]:
        return [p.run for p in self.phases if p.run is not None]

    @property
    def total_time_s(self) -> float:
        """Simulated time from the start to the end of the last phase (s)."""
        return float(self.phases[-1].t1_s) if self.phases else 0.0

    def timeline(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The whole sequence as MuJoCo ran it: t (T,) s, the root frame's world pose (T, 4, 4), the joints (T, n)."""
        ts: list[np.ndarray] = []
        roots: list[np.ndarray] = []
        qs: list[np.ndarray] = []
        for run in self.ground_runs:
            if run.root_truth is None:  # every ground run of a loop records where the body truly was
                raise InternalError(f"the loop's ground run {run.name!r} has no recorded root pose")
            ts.append(run.t)
            roots.append(run.root_truth)
            qs.append(run.q)
        if self.head is not None and self.head.root_pose is not None:
            ts.append(self.head_t0_s + self.head.t - self.head.t[0])
            roots.append(self.head.root_pose)
            qs.append(self.head.q)
        if not ts:
            return np.zeros(0), np.zeros((0, 4, 4)), np.zeros((0, self.robot.n_joints))
        return np.concatenate(ts), np.concatenate(roots), np.concatenate(qs)

    @property
    def base_travel_m(self) -> float:
        """How far the tail (the root frame's origin) moved over the ground in the simulation: the length of its
        path (m)."""
        _, roots, _ = self.timeline()
        if len(roots) < 2:
            return 0.0
        return float(np.linalg.norm(np.diff(roots[:, :2, 3], axis=0), axis=1).sum())

    @property
    def base_displacement_m(self) -> float:
        """The tail's straight-line distance from the start to the end (m)."""
        _, roots, _ = self.timeline()
        if len(roots) < 1:
            return 0.0
        return float(np.linalg.norm(roots[-1, :2, 3] - roots[0, :2, 3]))

    def estimate_summary(self) -> dict:
        """The estimate's error: after every ground phase (dead reckoning, chained from the start or the last
        fix), the largest, and at each fix."""
        errors = [p.estimate_error for p in self.phases if p.estimate_error is not None]
        out = {"after_ground_phases": [dict(name=p.name, **p.estimate_error) for p in self.phases
                                       if p.estimate_error is not None],
               "max_position_error_m": max((e["position_error_m"] for e in errors), default=None),
               "max_yaw_error_deg": max((e["yaw_error_deg"] for e in errors), default=None),
               "fixes": [dict(f) for f in self.fixes]}
        if self.fix is not None:
            out["fix"] = {"frame": self.fix.frame or self.robot.parts.base_end,
                          "position_noise_m": self.fix.position_noise_m, "yaw_noise_deg": self.fix.yaw_noise_deg}
        return out

    def report(self) -> dict:
        """The loop's part of a report entry: ``phases``, ``sim`` (``base_travel_m`` and the head's metrics),
        ``estimate``, ``start``, ``total_time_s``, ``corrections``."""
        sim = dict(self.metrics) if self.metrics is not None else {}
        sim.update(base_travel_m=self.base_travel_m, base_displacement_m=self.base_displacement_m,
                   total_time_s=self.total_time_s)
        return {"phases": [p.as_dict() for p in self.phases],
                "sim": sim,
                "estimate": self.estimate_summary(),
                "start": {"x_m": self.start.x, "y_m": self.start.y, "yaw_rad": self.start.yaw,
                          "q_rad": self.q_start.tolist()},
                "believed_start": {"x_m": self.believed_start.x, "y_m": self.believed_start.y,
                                   "yaw_rad": self.believed_start.yaw},
                "total_time_s": self.total_time_s, "corrections": self.corrections,
                "loop_planning_time_s": self.planning_time_s, "loop_notes": list(self.notes),
                "loop_failure": self.failure}


_STEP = re.compile(r" \(\d+/\d+\)$")


def head_phases(p: Plan, t0: float) -> list[Phase]:
    """The phases of a plan's states: the lift to the initial state, each move to a target (its intermediate
    waypoints, labelled "name (k/n)", in it) and each hold, on the clock that starts at ``t0`` s."""
    phases: list[Phase] = []
    prev_t = p.states[0][1]
    for k, (label, t, _) in enumerate(p.states[1:], start=1):
        name = _STEP.sub("", label)
        last = k == len(p.states) - 1 or _STEP.sub("", p.states[k + 1][0]) != name
        if not last:
            continue
        kind = ("lift" if name.startswith("initial state") else "hold" if name.endswith("(hold)") else "move")
        phases.append(Phase(name, kind, float(t0 + prev_t - p.t[0]), float(t0 + t - p.t[0])))
        prev_t = t
    if phases:  # the plan's samples run to its last state's time; the simulation ticks to the same end
        phases[-1].t1_s = t0 + float(p.t[-1] - p.t[0])
    return phases


class ClosedLoop:
    """The control process from any lying state, run in MuJoCo (see the module).

    scene: a :class:`~snakehead.scenes.Scene`, a scene file, or (position, direction) pairs. controller: the
    :class:`~snakehead.control.HeadController` (default: one for ``robot``, whose default is the scene's robot or
    the shipped one). timing: the planner's retiming options (:func:`snakehead.plan`'s ``timing``). fix: the :class:`PoseFix` (None: no fix, the
    head phases planned from dead reckoning alone). frequency: the gaits' (Hz). curl_speed: the curl's largest
    joint rate (rad/s). tolerance: the locomotion's (:class:`snakehead.motion.locomotion.Tolerance`).
    max_gait_runs: per correction; max_corrections: returns to step 2 after a curl before giving up.
    dynamics_check: simulate the head phases from the plan's own start before running them (step 6).
    imu_yaw_drift_deg_per_s, odometry and the other keywords (friction, ...) go to the
    :class:`~snakehead.sim.GaitSimulator`; the head phases' simulation uses the same ground.
    """

    def __init__(self, scene: Any, *, controller: HeadController | None = None, robot: SnakeRobot | None = None,
                 timing: dict[str, Any] | None = None, fix: PoseFix | None = PoseFix(),
                 frequency: float = 0.5, curl_speed: float = 0.4, tolerance: lc.Tolerance = lc.Tolerance(),
                 max_gait_runs: int = 16, max_corrections: int = 3, method: str = "rotated", seed: int | None = 1,
                 dynamics_check: bool = True, **sim_options: Any) -> None:
        self.scene = as_scene(scene)
        if controller is None:
            if robot is None:
                robot = (SnakeRobot.from_file(self.scene.robot_file) if self.scene.robot_file is not None
                         else SnakeRobot.default())
            controller = HeadController(robot, method=method, seed=seed)
        elif not isinstance(controller, HeadController):
            raise InputTypeError(f"controller must be a HeadController, got {type(controller).__name__}")
        elif robot is not None and robot is not controller.robot:
            raise InputError("give a robot or a controller (whose robot is used), not both")
        self.controller = controller
        self.robot = controller.robot
        if timing is not None and not isinstance(timing, dict):
            raise InputTypeError(f"timing must be a dict of the retiming's options, got {type(timing).__name__}")
        self.timing = None if timing is None else dict(timing)
        if fix is not None and not isinstance(fix, PoseFix):
            raise InputTypeError(f"fix must be a PoseFix or None, got {type(fix).__name__}")
        if fix is not None and fix.frame is not None:
            self.robot.link_index(fix.frame)  # ValueError for a frame not on the body
        self.fix = fix
        self.frequency = positive(frequency, "frequency")
        self.curl_speed = positive(curl_speed, "curl_speed")
        if not isinstance(tolerance, lc.Tolerance):
            raise InputTypeError(f"tolerance must be a snakehead.motion.locomotion.Tolerance, got "
                            f"{type(tolerance).__name__}")
        self.tolerance = tolerance
        for name, value in (("max_gait_runs", max_gait_runs), ("max_corrections", max_corrections)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
                raise InputError(f"{name} must be a non-negative integer, got {value!r}")
        self.max_gait_runs, self.max_corrections = int(max_gait_runs), int(max_corrections)
        self.dynamics_check = bool(dynamics_check)
        self.obstacles = list(self.scene.obstacles)
        self.sim_options = dict(sim_options)
        self.simulator = GaitSimulator(self.robot, obstacles=self.obstacles, **self.sim_options)
        self._ground_options = {k: v for k, v in self.sim_options.items()
                                if k in ("friction", "joint_damping", "armature", "timestep", "control_dt",
                                         "hole_slices", "torque_limit")}
        self._offset = lc.chassis_offset(self.robot)

    def straight_start(self, base: BasePlacement | None = None) -> BasePlacement:
        """Where the body lies straight when the curl into the bending state alone brings its base to ``base``
        (default: the scene's placement, else the default one): the paper's "current state" (Fig. 17a) before
        its bending state (Fig. 17b)."""
        base = as_base(base if base is not None else self.scene.base)
        return lc.straight_pose_for(self.robot, base, bending_state(self.controller))

    # --- checks --------------------------------------------------------------------------------------
    def _dynamics_check(self, p: Plan) -> str | None:
        """The dynamics check of a plan, as the pipeline checks every plan: simulated from its own start (the base
        where the loop believes it lies, the joints as planned), not from the truth. None when the body does not
        tip in it (CHECK_ZMP_OUTSIDE, CHECK_BASE_LIFT), else why."""
        robot = self.robot
        checked = simulate_trajectory(robot, p.t, p.q, p.base, obstacles=self.obstacles, **self._ground_options)
        check_plan_span(p.t, [tg.time_s for tg in p.targets], checked)
        check = compare(robot, p.t, p.q, checked, base=p.base,
                        targets=[(tg.time_s, tg.position, tg.direction) for tg in p.targets] or None)
        if check["zmp_min_margin_m"] < -CHECK_ZMP_OUTSIDE or check["base_lift_m"] > CHECK_BASE_LIFT:
            return (f"in its dynamics check the simulated ZMP leaves the support polygon by "
                    f"{1000 * -check['zmp_min_margin_m']:.1f} mm and the base lifts {1000 * check['base_lift_m']:.1f} mm")
        return None

    def _goal_failure(self, p: Plan) -> str | None:
        """Why the head phases planned at a candidate goal would fail: the plan's own failure, else its dynamics
        check (when the loop checks); None when they pass."""
        if p.failure is not None:
            return p.failure
        return self._dynamics_check(p) if self.dynamics_check else None

    def _nearby_goal(self, goal: BasePlacement, q_bend: np.ndarray) -> BasePlacement | None:
        """A placement near ``goal`` (NEARBY_STEP_M along and across, NEARBY_STEP_DEG turned) from which the head
        phases are planned successfully and pass the dynamics check, the nearest first; None if there is none."""
        d, a = NEARBY_STEP_M, math.radians(NEARBY_STEP_DEG)
        for offset in ((d, 0, 0), (-d, 0, 0), (0, d, 0), (0, -d, 0), (0, 0, a), (0, 0, -a)):
            candidate = lc.compose(goal, BasePlacement(*offset))
            p = plan(self.scene, controller=self.controller, base=candidate, allow_relocation=False,
                     base_shape=q_bend, timing=self.timing)
            if self._goal_failure(p) is None:
                return candidate
        return None

    # --- running ---------------------------------------------------------------------------------------
    @entry_point
    def run(self, start: BasePlacement, q_start: npt.ArrayLike | None = None, *, believed_start: BasePlacement | None = None,
            progress: Callable[[str], None] | None = None) -> LoopRun:
        """Run the loop from the body lying at ``start`` (the body frame's placement) with joints ``q_start``
        (default straight; a flat shape: pitch joints 0). The loop knows where the body starts
        (``believed_start``, default ``start``; give another to start from a wrong belief). ``progress``: called
        with a line of text at every step."""
        robot = self.robot
        start = as_base(start)
        believed = start if believed_start is None else as_base(believed_start)
        q_now = lc.flat_shape(robot, np.zeros(robot.n_joints) if q_start is None else q_start, "q_start")
        q_first = q_now.copy()
        if coll.self_clearance(robot, q_now[None])[0] <= 0.0:
            raise InputError("q_start folds the body onto itself (two links overlap)")
        if self.obstacles and coll.collision_check(robot, q_now[None], self.obstacles, start,
                                                   exact_within=EXACT_DISTANCE_WITHIN).distance[0] <= 0.0:
            raise InputError(f"the body lying at {_fmt(start)} is inside an obstacle of the scene")
        inputs_checked()  # the loop plans and simulates from here: an InputError inside would be a bug
        say = progress or (lambda text: None)
        sim = self.simulator
        rng = np.random.default_rng(None if self.fix is None else self.fix.seed)
        state = sim.lying(start, q_now)
        sim.restore(state)
        est = sim.estimator.reset(sim.joint_angles(), sim.imu_orientation(), (believed.x, believed.y), believed.yaw)
        phases: list[Phase] = []
        fixes: list[dict] = []
        notes: list[str] = []
        rates = lc.GaitRates.first_guess(robot)
        planning = 0.0
        head_plan: Plan | None = None
        head: SimResult | None = None
        metrics, head_t0 = None, 0.0
        failure = None
        corrections = -1

        def ground(run: GaitRun, name: str, kind: str) -> None:
            nonlocal state, est
            phases.append(Phase(name, kind, float(state.time), float(run.state.time), run.estimate_error, run))
            state, est = run.state, run.estimate
            e = run.estimate_error
            say(f"{name}: estimated at {_fmt(est.base)}; estimate off by {1000 * e['position_error_m']:.1f} mm, "
                f"{e['yaw_error_deg']:.2f} deg")

        def curl(q_to: np.ndarray, name: str) -> None:
            nonlocal q_now
            duration = max(1.0, float(np.abs(q_to - q_now).max()) / self.curl_speed)
            ground(sim.run_path(state, lc.curl_path(q_now, q_to), duration, start_estimate=est, name=name), name,
                   "curl")
            q_now = q_to.copy()

        goal: BasePlacement | None = None  # where the base must lie: a placement whose plan succeeds
        q_bend = bending_state(self.controller, self.controller.q_initial)
        tolerance = self.tolerance

        def head_plan_here(label: str, dynamics_check: bool) -> Plan | None:
            """The head phases from the current estimate, the base kept, starting from the joints as they are
            (measured: they rest a few tenths of a degree from their commands, friction holding the links against
            the servos, which moves P0 by millimetres), checked in dynamics when asked. None when it fails.
            A joint commanded to its limit rests a fraction of a milliradian past it (the servo's error): the
            measured joints are clipped to the limits, which the retiming requires of every waypoint."""
            nonlocal planning
            t0 = time.perf_counter()
            q_measured = np.clip(sim.joint_angles(), robot.lower, robot.upper)
            p = plan(self.scene, controller=self.controller, base=est.base, allow_relocation=False,
                     start_q=q_measured, timing=self.timing)
            planning += time.perf_counter() - t0
            why = p.failure if p.failure is not None else self._dynamics_check(p) if dynamics_check else None
            if why is None:
                return p
            notes.append(f"{label}: the head phases from {_fmt(est.base)} fail ({why})")
            say(notes[-1])
            return None

        while failure is None:
            corrections += 1
            if corrections > self.max_corrections:
                failure = (f"the body was not brought where the head phases succeed after {self.max_corrections} "
                           "corrections")
                break
            if goal is None:
                # 1. where must the base go? The plan from where the curl would leave it, relocated if need be,
                # checked in dynamics at its own start (a relocated base's plan can pass its static checks and still
                # tip the body in MuJoCo: then every attempt to reach that goal fails); when it fails, the scene's
                # own placement (the default one for a scene without); then placements near a plan that tipped
                after_curl = lc.compose(est.base, lc.curl_displacement(robot, q_now, q_bend))
                tried, tipped = [], None
                t0 = time.perf_counter()
                for candidate in (after_curl, as_base(self.scene.base)):
                    first = plan(self.scene, controller=self.controller, base=candidate, allow_relocation=True,
                                 timing=self.timing)
                    why = self._goal_failure(first)
                    if why is None:
                        goal, q_bend = first.base, first.states[0][2].copy()
                        break
                    if first.failure is None and tipped is None:
                        tipped = first
                    tried.append(f"from {_fmt(candidate)}: {why}")
                    notes.append(f"the plan from {_fmt(candidate)} fails ({why})")
                    say(notes[-1])
                if goal is None and tipped is not None:
                    goal = self._nearby_goal(tipped.base, tipped.states[0][2])
                    if goal is not None:
                        q_bend = tipped.states[0][2].copy()
                planning += time.perf_counter() - t0
                if goal is None:
                    failure = "no plan reaches the targets " + "; nor ".join(tried)
                    break
                if goal != after_curl:
                    say(f"the base must go to {_fmt(goal)}")
            else:  # a correction: closer to the goal than last time, or to another goal nearby
                tolerance = tolerance.tighter()
                straight_here = lc.compose(lc.compose(est.base, lc.curl_displacement(robot, q_now, q_bend)),
                                           lc.inverse(lc.curl_displacement(robot, np.zeros(robot.n_joints), q_bend)))
                straight_goal = lc.compose(goal, lc.inverse(lc.curl_displacement(robot, np.zeros(robot.n_joints),
                                                                                q_bend)))
                if lc.next_step(robot, straight_here, straight_goal, rates, tolerance=tolerance) is None:
                    # as close to the goal as the gaits get, and the head phases still fail: another goal nearby
                    t0 = time.perf_counter()
                    nearby = self._nearby_goal(goal, q_bend)
                    planning += time.perf_counter() - t0
                    if nearby is None:
                        failure = f"no placement near {_fmt(goal)} gives head phases that succeed"
                        break
                    goal = nearby
                    say(f"the base must go to {_fmt(goal)} instead")
            # 2. locomotion, when the curl from here would not leave the base at the goal
            D = lc.curl_displacement(robot, np.zeros(robot.n_joints), q_bend)
            straight_goal = lc.compose(goal, lc.inverse(D))
            landing = lc.compose(est.base, lc.curl_displacement(robot, q_now, q_bend))
            if lc.next_step(robot, lc.compose(landing, lc.inverse(D)), straight_goal, rates,
                            tolerance=tolerance) is not None:
                if np.abs(q_now).max() > 0.0:
                    curl(np.zeros(robot.n_joints), "uncurl")
                for _ in range(self.max_gait_runs):
                    step = lc.next_step(robot, est.base, straight_goal, rates, tolerance=tolerance,
                                        frequency=self.frequency)
                    if step is None:
                        break
                    before = est.base
                    run = sim.run(state, step.gait, step.cycles, start_estimate=est)
                    direction = {1: "+", -1: "-"}[step.gait.direction]
                    ground(run, f"{step.gait.name} {direction} ({step.leg}, {step.cycles:.0f} x {step.scale:.2f})",
                           "gait")
                    rates.update(step, before, est.base, self._offset)
            # 3. the curl into the bending state
            if np.abs(q_bend - q_now).max() > 1e-9:
                curl(q_bend, "curl into the bending state")
            # 4. re-plan from the estimate (dead reckoning)
            head_plan = head_plan_here("after the curl", self.dynamics_check and self.fix is None)
            if head_plan is None:
                continue
            # 5. the fix, and the plan from it
            if self.fix is not None:
                dead_reckoned, truth = est, sim.true_pose()
                est = self.fix.measure(sim, rng)
                fixes.append({"t_s": float(state.time), "dead_reckoning": pose_error(dead_reckoned, truth),
                              "fix": pose_error(est, truth)})
                say(f"the fix puts the base at {_fmt(est.base)} (dead reckoning said {_fmt(dead_reckoned.base)})")
                head_plan = head_plan_here("after the fix", self.dynamics_check)
                if head_plan is None:
                    continue
            # 6. the head phases, in MuJoCo from where the body is
            say(f"head phases planned from {_fmt(est.base)}: {head_plan.duration_s:.1f} s; simulating")
            head_t0 = float(state.time)
            head = simulate_trajectory(robot, head_plan.t, head_plan.q, head_plan.base, state=state, settle=0.0,
                                       obstacles=self.obstacles, **self._ground_options)
            check_plan_span(head_plan.t, [tg.time_s for tg in head_plan.targets], head)
            targets = [(tg.time_s, tg.position, tg.direction) for tg in head_plan.targets] or None
            metrics = compare(robot, head_plan.t, head_plan.q, head, targets=targets, base=head_plan.base)
            phases += head_phases(head_plan, head_t0)
            break
        return LoopRun(robot=robot, scene=self.scene, start=start, believed_start=believed, q_start=q_first,
                       phases=phases, fixes=fixes, plan=head_plan, head=head, metrics=metrics, head_t0_s=head_t0,
                       corrections=max(corrections, 0), planning_time_s=planning, notes=notes, failure=failure,
                       fix=self.fix)


def _fmt(b: BasePlacement) -> str:
    return f"({b.x:.3f}, {b.y:.3f}) m, {math.degrees(b.yaw):.1f} deg"

