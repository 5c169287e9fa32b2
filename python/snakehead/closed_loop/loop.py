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
   each run the next is decided from the pose the robot estimates (:mod:`snakehead.closed_loop.estimate`: joint angles, one
   IMU, contact odometry), never from MuJoCo's. With ``sensing="onboard"`` (the default) the estimate reads only
   the robot's own sensor models (:mod:`snakehead.sim.sensors`: 12-bit encoders, a MEMS IMU's gyro and
   accelerometer through an attitude filter); every ground run keeps the stream it read
   (:class:`~snakehead.closed_loop.gait_runner.SensorLog`), from which :func:`~snakehead.closed_loop.gait_runner.replay_estimate` gives the
   same estimate without the simulator.
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
   expects a marker well inside the camera's view (:func:`look_waypoint`), and the head holds still there; the
   marker's pose relative to the head (averaged frames) with the encoders gives the root frame's world pose
   (:func:`snakehead.closed_loop.servo.root_from_head_reading`), and the head phases are planned again from there and the
   fixed pose (base kept). When that plan fails, the head goes back down along the plan and the loop returns to 2
   from the fixed pose. When no marker is in view, the head phases go on from dead reckoning (a note says so).

   *Outside fix* (``sensing="outside fix"``, the earlier behaviour): perfect encoders and IMU, and once the body
   rests in the bending state an outside measurement of the pose of the neck's base frame (``base_end``, the
   paper's P0: "the pose of the base frame of the neck part is obtained in time"; a motion-capture system) with
   the joint angles gives the root frame's placement (:class:`PoseFix`, with Gaussian noise: 0.5 mm and 0.05 deg
   by default). The head phases are planned again from the fixed pose (base kept); when that plan fails, back
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

The result, :class:`LoopRun`, has the phases (``name``, ``kind`` one of gait/curl/lift/move/hold, ``t0_s``,
``t1_s``), the estimate's error after every ground phase, how far the tail travelled, and the head's errors.
Obstacles are in the simulation all along. The locomotion goes around them: when the gaits' straight legs would
come within the body's turning disc of one, step 2 follows a route of the body's middle planned around their
footprints (:func:`snakehead.locomotion.ground_path.plan_route`), planned again from the estimate whenever the body
drifts off it, every gait run's predicted sweep checked before it runs
(:func:`snakehead.locomotion.ground_path.sweep_clear`); a goal whose straight pose before the curl, or the curl
itself as the friction model predicts it, would come within GOAL_CLEARANCE_M of one is refused in step 1.
``sim.min_obstacle_distance_m`` is the body's smallest distance to any obstacle over the run.
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
from ..solve.head_controller import HeadController
from ..collision import body_collisions as coll
from ..margins import EXACT_DISTANCE_WITHIN
from ..model.robot import BasePlacement, SnakeRobot, as_base
from ..locomotion import ground_path as gp
from ..locomotion import goals as lc
from ..planning.plan_result import Plan
from ..planning.planner import as_scene, plan
from ..planning.start_state import bending_state
from ..scenes.scene import Scene
from ..sim.compare import check_plan_span, compare
from ..locomotion.gaits import virtual_chassis
from .estimate import BodyPose, pose_error
from .gait_runner import GaitRun, GaitSimulator
from ..sim import sensors as sn
from . import servo as sv
from ..sim.sensors import OnboardSensors
from ..sim.tracking import SimState
from ..sim.tracking import SimResult, simulate_trajectory
from .._errors import Infeasible, InputError, InputTypeError, InternalError, entry_point, inputs_checked

#: How the loop knows where it is (:class:`ClosedLoop`'s ``sensing``): "onboard", the robot's own sensors alone
#: (:mod:`snakehead.sim.sensors`), or "outside fix", perfect joint angles and IMU and an outside measurement of the
#: neck's base frame (:class:`PoseFix`) once the body rests in the bending state.
SENSING = ("onboard", "outside fix")
#: How near the gaits bring the body to a waypoint of a route around obstacles (its middle off the leg's line, m,
#: and along it, m; its heading, deg): looser than the goal's, the next leg corrects what is left. Off the line it
#: is loosest: a turn square to the line and back to correct it shifts the middle by as much again (turning in
#: place moves the middle by up to 0.05 body lengths a cycle), and where being off the line matters the route is
#: planned again (ClosedLoop._route_holds: the leg from where the body is must keep the clearance less
#: ground_path.EXECUTION_M).
WAYPOINT_TOLERANCE = lc.Tolerance(along_m=0.25, across_m=0.08, yaw_deg=8.0, align_deg=8.0)
#: Every this many steps of the curl's path (of locomotion.CURL_STEPS) the goal's check puts the curling body
#: against the obstacles.
CURL_CHECKS = 4
#: The most legs of a route the locomotion follows (each at most max_gait_runs runs) before it gives up.
MAX_LEGS = 8
#: The most samples of the estimate's error over time a report holds.
ESTIMATE_SAMPLES = 200
#: How long the head holds still where it first looks for a marker (s).
LOOK_HOLD_S = 0.5
#: The kinds of phases in a loop's report ("servo": a correction of the head's final approach on the camera).
PHASE_KINDS = ("gait", "curl", "lift", "move", "hold", "servo")
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
    (:func:`snakehead.closed_loop.estimate.pose_error`) and the run itself."""

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
    fix's record (the estimate before it and its error, the fix's error; ``source`` "head camera" for the
    onboard one); plan: the plan of the head phases (None
    if the loop never got there); head: their simulation (:class:`~snakehead.sim.SimResult`); metrics: the head
    phases against their plan (:func:`snakehead.sim.compare`); head_t0_s: when the head phases began;
    corrections: how many times the loop went back to step 1 after a curl; planning_time_s: wall time spent
    planning; notes; failure: None when the head phases were planned and simulated, else why not; sensing: the
    loop's (SENSING); head_extra: (label, start time s, SimResult) of the head's runs outside its plan (the look,
    a lowering, the final approach's moves); servo: the final approach's looks (true and measured errors).
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
    sensing: str = "outside fix"
    head_extra: list = field(default_factory=list)
    servo: list = field(default_factory=list)
    routes: list = field(default_factory=list)

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

    def segments(self) -> list[dict]:
        """What MuJoCo ran, piece by piece in time order: each a dict of ``t`` (T,) s on the loop's clock,
        ``root`` (T, 4, 4) the root frame's true world pose, ``q`` (T, n) and ``qd`` (T, n) the joints (the
        ground phases' velocities by finite differences), ``estimate`` (T, 4, 4) the root pose the loop believed
        (the dead reckoning on the ground, NaN where a run kept none; the placement the head phases were planned
        from while lifted)."""
        out = []
        for run in self.ground_runs:
            if run.root_truth is None:  # every ground run of a loop records where the body truly was
                raise InternalError(f"the loop's ground run {run.name!r} has no recorded root pose")
            out.append({"t": run.t, "root": run.root_truth, "q": run.q,
                        "qd": np.gradient(run.q, run.t, axis=0) if len(run.t) > 1 else np.zeros_like(run.q),
                        "estimate": (run.root_estimate if run.root_estimate is not None
                                     else np.full((len(run.t), 4, 4), np.nan))})
        lifted = [(t0, r) for _, t0, r in self.head_extra]
        if self.head is not None:
            lifted.append((self.head_t0_s, self.head))
        for t0, r in lifted:
            if r.root_pose is None:
                continue
            believed = self.robot.root_pose(self.plan.base if self.plan is not None else r.base)
            out.append({"t": t0 + r.t - r.t[0], "root": r.root_pose, "q": r.q, "qd": r.qdot,
                        "estimate": np.repeat(believed[None], len(r.t), axis=0)})
        return sorted(out, key=lambda seg: float(seg["t"][0]))

    def timeline(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The whole sequence as MuJoCo ran it: t (T,) s, the root frame's world pose (T, 4, 4), the joints (T, n)."""
        segs = self.segments()
        if not segs:
            return np.zeros(0), np.zeros((0, 4, 4)), np.zeros((0, self.robot.n_joints))
        return (np.concatenate([s["t"] for s in segs]), np.concatenate([s["root"] for s in segs]),
                np.concatenate([s["q"] for s in segs]))

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

    def obstacle_distances(self, every: int = 5) -> tuple[np.ndarray, np.ndarray]:
        """The smallest distance (m) of the body's shapes to any obstacle of the scene over the whole run as
        MuJoCo ran it (:meth:`timeline`, every ``every``-th recorded tick and the last): t (T,) s, distance (T,)
        m (negative: penetration); empty without obstacles."""
        from ..collision.body_collisions import obstacle_shapes
        from ..geometry.shapes import pair_min_distances

        t, roots, qs = self.timeline()
        if not self.scene.obstacles or not len(t):
            return np.zeros(0), np.zeros(0)
        pick = np.unique(np.r_[np.arange(0, len(t), max(int(every), 1)), len(t) - 1])
        frames = np.einsum("tij,tljk->tlik", roots[pick], self.robot.body.fk_all_many(qs[pick]))
        shapes, _ = obstacle_shapes(list(self.scene.obstacles))
        mine = np.arange(len(self.robot.geometry.shapes))
        pairs = np.stack(np.meshgrid(mine, np.arange(len(shapes.shapes)), indexing="ij"), -1).reshape(-1, 2)
        d = pair_min_distances(frames, self.robot.geometry, np.eye(4)[None, None], shapes, pairs)
        return t[pick], np.asarray(d)

    @property
    def min_obstacle_distance_m(self) -> float | None:
        """The smallest distance of the body to any obstacle over the run (m; None without obstacles)."""
        _, d = self.obstacle_distances()
        return float(d.min()) if len(d) else None

    @property
    def min_obstacle_distance_ground_m(self) -> float | None:
        """The same over the ground phases alone (gaits and curls: the locomotion around the obstacles)."""
        t, d = self.obstacle_distances()
        on_ground = np.zeros(len(t), bool)
        for run in self.ground_runs:
            on_ground |= (t >= run.t[0] - 1e-9) & (t <= run.t[-1] + 1e-9)
        return float(d[on_ground].min()) if on_ground.any() else None

    def estimate_error_over_time(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The dead reckoning's error through the ground phases, at every recorded tick: t (T,) s, the body
        frame's position error (T,) m in the ground plane and its heading error (T,) deg (the estimate against
        MuJoCo's truth)."""
        ts, pos, yaw = [], [], []
        for run in self.ground_runs:
            if run.root_truth is None or run.root_estimate is None:
                continue
            B = self.robot.body_in_root
            truth, est = run.root_truth @ B, run.root_estimate @ B
            ts.append(run.t)
            pos.append(np.linalg.norm(est[:, :2, 3] - truth[:, :2, 3], axis=1))
            d = np.arctan2(est[:, 1, 0], est[:, 0, 0]) - np.arctan2(truth[:, 1, 0], truth[:, 0, 0])
            yaw.append(np.abs(np.degrees((d + np.pi) % (2 * np.pi) - np.pi)))
        if not ts:
            return np.zeros(0), np.zeros(0), np.zeros(0)
        return np.concatenate(ts), np.concatenate(pos), np.concatenate(yaw)

    def estimate_summary(self) -> dict:
        """The estimate's error: after every ground phase (dead reckoning, chained from the start or the last
        fix), the largest, at each fix, and over time (``over_time``: at most ESTIMATE_SAMPLES ticks, evenly
        picked, and its median and largest)."""
        errors = [p.estimate_error for p in self.phases if p.estimate_error is not None]
        out = {"after_ground_phases": [dict(name=p.name, **p.estimate_error) for p in self.phases
                                       if p.estimate_error is not None],
               "max_position_error_m": max((e["position_error_m"] for e in errors), default=None),
               "max_yaw_error_deg": max((e["yaw_error_deg"] for e in errors), default=None),
               "fixes": [dict(f) for f in self.fixes]}
        t, pos, yaw = self.estimate_error_over_time()
        pick = np.unique(np.linspace(0, max(len(t) - 1, 0), min(len(t), ESTIMATE_SAMPLES)).astype(int))
        out["over_time"] = {"t_s": t[pick].tolist(), "position_error_m": pos[pick].tolist(),
                            "yaw_error_deg": yaw[pick].tolist(),
                            "median_position_error_m": float(np.median(pos)) if len(t) else None,
                            "max_position_error_m": float(pos.max()) if len(t) else None,
                            "median_yaw_error_deg": float(np.median(yaw)) if len(t) else None,
                            "max_yaw_error_deg": float(yaw.max()) if len(t) else None}
        if self.fix is not None:
            out["fix"] = {"frame": self.fix.frame or self.robot.parts.base_end,
                          "position_noise_m": self.fix.position_noise_m, "yaw_noise_deg": self.fix.yaw_noise_deg}
        return out

    def report(self) -> dict:
        """The loop's part of a report entry: ``phases``, ``sim`` (``base_travel_m`` and the head's metrics),
        ``estimate``, ``start`` (its ``q_rad`` the description's angles, :meth:`SnakeRobot.description_angles` of
        ``q_start``, which like every array of the run holds the planner's), ``total_time_s``, ``corrections``."""
        sim = dict(self.metrics) if self.metrics is not None else {}
        sim.update(base_travel_m=self.base_travel_m, base_displacement_m=self.base_displacement_m,
                   total_time_s=self.total_time_s, sensing=self.sensing,
                   min_obstacle_distance_m=self.min_obstacle_distance_m,
                   min_obstacle_distance_ground_m=self.min_obstacle_distance_ground_m)
        return {"phases": [p.as_dict() for p in self.phases],
                "sim": sim,
                "estimate": self.estimate_summary(),
                "start": {"x_m": self.start.x, "y_m": self.start.y, "yaw_rad": self.start.yaw,
                          "q_rad": self.robot.description_angles(self.q_start).tolist()},  # the description's
                "believed_start": {"x_m": self.believed_start.x, "y_m": self.believed_start.y,
                                   "yaw_rad": self.believed_start.yaw},
                "total_time_s": self.total_time_s, "corrections": self.corrections,
                "loop_planning_time_s": self.planning_time_s, "loop_notes": list(self.notes),
                "loop_failure": self.failure, "final_approach": [dict(r) for r in self.servo],
                "routes": [r.tolist() for r in self.routes]}


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
    joint rate (rad/s). tolerance: the locomotion's (:class:`snakehead.locomotion.goals.Tolerance`).
    max_gait_runs: per correction; max_corrections: returns to step 2 after a curl before giving up.
    dynamics_check: simulate the head phases from the plan's own start before running them (step 6).
    sensing: one of SENSING (see the module; "outside fix" uses ``fix``, default a :class:`PoseFix`); sensor_seed:
    the onboard sensors' noise (:meth:`snakehead.sim.sensors.OnboardSensors.realistic`).
    imu_yaw_drift_deg_per_s, odometry and the other keywords (friction, ...) go to the
    :class:`~snakehead.sim.GaitSimulator`; the head phases' simulation uses the same ground.
    """

    def __init__(self, scene: Any, *, controller: HeadController | None = None, robot: SnakeRobot | None = None,
                 timing: dict[str, Any] | None = None, fix: PoseFix | None = None, sensing: str = "onboard",
                 sensor_seed: int | None = 0,
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
        if sensing not in SENSING:
            raise InputError(f"sensing must be one of {SENSING}, got {sensing!r}")
        self.sensing = sensing
        if fix is not None and not isinstance(fix, PoseFix):
            raise InputTypeError(f"fix must be a PoseFix or None, got {type(fix).__name__}")
        if fix is not None and sensing == "onboard":
            raise InputError('a PoseFix is the "outside fix" sensing: give sensing="outside fix" with it')
        if sensing == "outside fix" and fix is None:
            fix = PoseFix()
        if fix is not None and fix.frame is not None:
            self.robot.link_index(fix.frame)  # ValueError for a frame not on the body
        self.fix = fix
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
        self.simulator = GaitSimulator(self.robot, obstacles=self.obstacles, sensors=self.sensors, **self.sim_options)
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

    def _straight_failure(self, goal: BasePlacement, q_bend: np.ndarray) -> str | None:
        """Why the body cannot lie straight where the curl into ``q_bend`` must start to reach ``goal``, or cannot
        curl from there: the straight body, or the body at any CURL_CHECKS-th step of the curl where the friction
        model slides it (:func:`snakehead.dynamics.sliding.predict_slide`), would come within GOAL_CLEARANCE_M
        of an obstacle (the gaits bring it there within their execution margin, its estimate off by the drift);
        else None."""
        if not self.obstacles:
            return None
        from ..dynamics.sliding import predict_slide

        robot = self.robot
        straight = lc.straight_pose_for(robot, goal, q_bend)
        path = lc.curl_path(np.zeros(robot.n_joints), q_bend)
        slide = predict_slide(robot, path, straight)
        for k in list(range(0, len(path), CURL_CHECKS)) + [len(path) - 1]:
            d = coll.collision_check(robot, path[k][None], self.obstacles, slide[k], exact_within=1.0).distance[0]
            if d < gp.GOAL_CLEARANCE_M:
                where = "lie straight" if k == 0 else f"pass, {100 * k // (len(path) - 1)} % into its curl,"
                return (f"the body would {where} at {_fmt(slide[k])} {1000 * d:.0f} mm from an obstacle "
                        f"(straight at {_fmt(straight)} before its curl)")
        return None

    def _nearby_goal(self, goal: BasePlacement, q_bend: np.ndarray, rings: int = 1) -> BasePlacement | None:
        """A placement near ``goal`` (NEARBY_STEP_M along and across, NEARBY_STEP_DEG turned; ``rings`` times
        that at the most) from which the head phases are planned successfully and pass the dynamics check, and
        whose straight pose and curl keep clear of the obstacles (:meth:`_straight_failure`), the nearest first;
        None if there is none."""
        d, a = NEARBY_STEP_M, math.radians(NEARBY_STEP_DEG)
        for offset in [(f * x, f * y, f * t) for f in range(1, rings + 1)
                       for x, y, t in ((d, 0, 0), (-d, 0, 0), (0, d, 0), (0, -d, 0), (0, 0, a), (0, 0, -a))]:
            candidate = lc.compose(goal, BasePlacement(*offset))
            if self._straight_failure(candidate, q_bend) is not None:
                continue
            p = plan(self.scene, controller=self.controller, base=candidate, allow_relocation=False,
                     base_shape=q_bend, timing=self.timing)
            if self._goal_failure(p) is None:
                return candidate
        return None

    def _route(self, here: BasePlacement, straight_goal: BasePlacement, grid: gp.ClearanceGrid,
               routes: list[np.ndarray], say: Callable[[str], None]) -> gp.Route | None:
        """The route from ``here`` to ``straight_goal`` (root placements of the straight body):
        :func:`snakehead.locomotion.ground_path.plan_route` between their middles (None: the straight legs are clear),
        keeping CLEARANCE_M beyond the gaits' sweep, or where no such route exists EXECUTION_M alone; recorded in
        ``routes``. :class:`~snakehead.Infeasible` when there is none."""
        a, b = lc.compose(here, self._offset), lc.compose(straight_goal, self._offset)
        try:
            route = gp.plan_route(self.robot, self.obstacles, a, b, grid=grid)
        except Infeasible as exc:  # no room for the drift's budget: the execution margin alone, said so
            route = gp.plan_route(self.robot, self.obstacles, a, b, grid=grid, clearance=gp.EXECUTION_M)
            say(f"{exc}: the route keeps {1000 * gp.EXECUTION_M:.0f} mm beyond the gaits' sweep, without the dead "
                "reckoning's drift")
        if route is not None:
            routes.append(route.waypoints.copy())
            say(f"around the obstacles: {len(route.waypoints) - 1} legs of "
                f"{np.linalg.norm(np.diff(route.waypoints, axis=0), axis=1).sum():.2f} m")
        return route

    def _route_holds(self, route: gp.Route, k: int, here: BasePlacement, grid: gp.ClearanceGrid) -> bool:
        """Whether the body, its middle estimated at ``here``'s, can go on to waypoint ``k`` of ``route``: the
        leg from there keeps the route's clearance less EXECUTION_M (the waypoint tolerance) from the obstacles
        (``grid``: the route's). An escape or a staging leg holds (both run nearer than that by design; each run's
        sweep is checked)."""
        if (k == 1 and route.escape) or (route.staging and k == len(route.waypoints) - 1):
            return True
        m = lc.compose(here, self._offset)
        return gp.segment_clear(grid, np.array([m.x, m.y]), route.waypoints[k], route.clear_m - gp.EXECUTION_M)

    def _grid(self, here: BasePlacement, straight_goal: BasePlacement) -> gp.ClearanceGrid:
        """The obstacles' grid of one locomotion (:func:`snakehead.locomotion.ground_path.clearance_grid`): over the
        body's middle here and at the goal, reaching beyond the obstacles by the routes' clearance and more."""
        a, b = lc.compose(here, self._offset), lc.compose(straight_goal, self._offset)
        reach = gp.swept_radius(self.robot) + gp.CLEARANCE_M + gp.GRID_MARGIN_M
        return gp.clearance_grid(self.obstacles, [[a.x, a.y], [b.x, b.y]], reach)

    def _sweep_failure(self, here: BasePlacement, step: lc.LocomotionStep, rates: lc.GaitRates,
                       grid: gp.ClearanceGrid) -> str | None:
        """Why the gait run ``step`` from the estimated root placement ``here`` would sweep too near an obstacle
        (:func:`snakehead.locomotion.ground_path.sweep_clear` on its predicted end, on ``grid``), else None."""
        a = lc.compose(here, self._offset)
        b = rates.predicted(step, here, self._offset)
        if gp.sweep_clear(grid, self.robot, step.gait.name, a, b, step.scale):
            return None
        return (f"the {step.gait.name} run ({step.cycles:.0f} x {step.scale:.2f}) from {_fmt(a)} would sweep within "
                f"{1000 * gp.EXECUTION_M:.0f} mm of an obstacle")

    def _locomotion(self, sim: GaitSimulator, est: BodyPose, straight_goal: BasePlacement, tolerance: lc.Tolerance,
                    rates: lc.GaitRates, routes: list[np.ndarray], say: Callable[[str], None],
                    ground: Callable[[GaitRun, str, str], None], current_state: Callable[[], SimState]) -> str | None:
        """Step 2's gait runs to ``straight_goal``: along the route (:meth:`_route`), planned again from the
        estimate whenever the body drifts off it (:meth:`_route_holds`, after every run), each run's sweep checked before it runs (:meth:`_sweep_failure`: a run that fails it
        is made smaller, one cycle at half its amplitude, until it passes or is as small as a run gets);
        ``ground`` records each run and moves the estimate; ``current_state`` the simulation's state now. None
        when done (at the goal, or out of runs), else why the body cannot go on."""
        grid = self._grid(est.base, straight_goal) if self.obstacles else None
        route: gp.Route | None = None
        k = 0  # the route's waypoint the gaits go to
        planned = 0  # routes planned since the last run
        runs_here = 0  # gait runs towards the current waypoint
        for _ in range(self.max_gait_runs * MAX_LEGS):
            if grid is not None and (route is None or (not self._route_holds(route, k, est.base, grid)
                                                       and planned == 0)):
                # (a route just planned from here is followed even where its first leg does not keep the margin
                # on the grid's cells: each run's sweep is still checked)
                planned += 1
                try:  # the first, or the body drifted off its route: plan it again from the estimate
                    route, k, runs_here = self._route(est.base, straight_goal, grid, routes, say), 1, 0
                except Infeasible as exc:
                    return f"no route around the obstacles from {_fmt(est.base)}: {exc}"
            last = route is None or k == len(route.waypoints) - 1
            step = (None if runs_here >= self.max_gait_runs else
                    self._leg_step(est.base, route, k, straight_goal, tolerance, rates))
            if step is None:  # at the waypoint (or as near as max_gait_runs runs bring it): on to the next
                if last:
                    return None
                k, runs_here = k + 1, 0
                continue
            step, why = self._checked_step(est.base, step, rates, grid)
            if why is not None:
                return why
            before = est.base
            run = sim.run(current_state(), step.gait, step.cycles, start_estimate=est)
            direction = {1: "+", -1: "-"}[step.gait.direction]
            ground(run, f"{step.gait.name} {direction} ({'' if last else 'route, '}{step.leg}, {step.cycles:.0f} x "
                        f"{step.scale:.2f})", "gait")
            est, planned, runs_here = run.estimate, 0, runs_here + 1
            rates.update(step, before, est.base, self._offset)
        return None

    def _leg_step(self, here: BasePlacement, route: gp.Route | None, k: int, straight_goal: BasePlacement,
                  tolerance: lc.Tolerance, rates: lc.GaitRates) -> lc.LocomotionStep | None:
        """The next gait run from ``here`` towards waypoint ``k`` of ``route`` (the body's middle there, square
        to the leg that reaches it, within WAYPOINT_TOLERANCE; an escape along the axis creeps), or towards
        ``straight_goal`` within ``tolerance`` when it is the last (or there is no route); None when there."""
        if route is None or k == len(route.waypoints) - 1:
            creep = route is not None and route.staging_creep
            if creep and abs(math.degrees(math.remainder(straight_goal.yaw - here.yaw, 2 * math.pi))) \
                    > tolerance.yaw_deg:  # from a staging point on the goal's axis: turn to its heading first
                m = lc.compose(here, self._offset)
                facing = lc.compose(BasePlacement(m.x, m.y, straight_goal.yaw), lc.inverse(self._offset))
                return lc.next_step(self.robot, here, facing, rates, tolerance=tolerance, frequency=self.frequency)
            return lc.next_step(self.robot, here, straight_goal, rates, tolerance=tolerance, frequency=self.frequency,
                                creep=creep)
        w, h = route.waypoints[k], route.headings[k - 1]
        goal = lc.compose(BasePlacement(float(w[0]), float(w[1]), float(h)), lc.inverse(self._offset))
        return lc.next_step(self.robot, here, goal, rates, tolerance=WAYPOINT_TOLERANCE, frequency=self.frequency,
                            creep=route.creep and k == 1)

    def _checked_step(self, here: BasePlacement, step: lc.LocomotionStep, rates: lc.GaitRates,
                      grid: gp.ClearanceGrid | None) -> tuple[lc.LocomotionStep, str | None]:
        """``step`` when its sweep is clear (:meth:`_sweep_failure`), else one cycle at half its amplitude, and
        so on (a smaller run sweeps less: its waves are smaller, it goes less far; the next run goes on) down to
        MIN_AMPLITUDE_SCALE; and why the last tried is not clear (None when it is)."""
        if grid is None:
            return step, None
        why = self._sweep_failure(here, step, rates, grid)
        while why is not None and step.scale > lc.MIN_AMPLITUDE_SCALE:
            step = lc.gait_run(step.gait.name, step.gait.direction, 1.0, 1.0, max_cycles=1, frequency=self.frequency,
                               scale=0.5 * step.scale, leg=step.leg)
            why = self._sweep_failure(here, step, rates, grid)
        return step, why

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
        if coll.self_clearance(robot, q_now[None])[0] <= 0.0:
            raise InputError("q_start folds the body onto itself (two links overlap)")
        if self.obstacles and coll.collision_check(robot, q_now[None], self.obstacles, start,
                                                   exact_within=EXACT_DISTANCE_WITHIN).distance[0] <= 0.0:
            raise InputError(f"the body lying at {_fmt(start)} is inside an obstacle of the scene")
        inputs_checked()  # the loop plans and simulates from here: an InputError inside would be a bug
        ep = _Episode(self, start, believed, q_now, progress or (lambda text: None))
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
        return LoopRun(robot=robot, scene=self.scene, start=start, believed_start=believed, q_start=q_now,
                       phases=ep.phases, fixes=ep.fixes, plan=ep.head_plan, head=ep.head, metrics=ep.metrics,
                       head_t0_s=ep.head_t0, corrections=max(corrections, 0), planning_time_s=ep.planning,
                       notes=ep.notes, failure=failure, fix=self.fix, sensing=self.sensing, head_extra=ep.extra,
                       servo=ep.servo_log, routes=ep.routes)


class _Episode:
    """One run of :meth:`ClosedLoop.run`: the simulation's state and the estimate of the body's pose as they go,
    the joints commanded, the goal, and the record (phases, fixes, notes, the head's plan and its simulation); its
    methods are the loop's steps (1. the goal, 2. the gaits and the curl, 3.-5. the head phases planned from the
    estimate and a fix, 6. run in MuJoCo)."""

    def __init__(self, loop: ClosedLoop, start: BasePlacement, believed: BasePlacement, q_now: np.ndarray,
                 say: Callable[[str], None]) -> None:
        self.loop, self.robot, self.sim, self.say = loop, loop.robot, loop.simulator, say
        self.rng = np.random.default_rng(None if loop.fix is None else loop.fix.seed)
        self.q_now = q_now.copy()
        self.state = self.sim.lying(start, q_now)
        self.sim.restore(self.state)
        self.est = self.sim.estimator.reset(self.sim.measured_joints(), self.sim.measured_attitude(),
                                            (believed.x, believed.y), believed.yaw)
        self.phases: list[Phase] = []
        self.fixes: list[dict] = []
        self.notes: list[str] = []
        self.extra: list[tuple[str, float, SimResult]] = []  # the head's runs outside its plan: lift and look, servo
        self.servo_log: list[dict] = []
        self.routes: list[np.ndarray] = []
        self.rates = lc.GaitRates.first_guess(self.robot)
        self.planning = 0.0  # seconds spent planning
        self.goal: BasePlacement | None = None  # where the base must lie: a placement whose plan succeeds
        self.q_bend = bending_state(loop.controller, loop.controller.q_initial)
        self.tolerance = loop.tolerance
        self.head_plan: Plan | None = None
        self.head: SimResult | None = None
        self.metrics: dict | None = None
        self.head_t0 = 0.0
        self.head_sensor = None if loop.sensors is None else loop.sensors.head
        self.encoders = None if loop.sensors is None else loop.sensors.encoders

    def note(self, text: str) -> None:
        self.notes.append(text)
        self.say(text)

    # --- the record of the body's motion ---------------------------------------------------------------
    def ground(self, run: GaitRun, name: str, kind: str) -> None:
        """A run on the ground (a gait, a curl) recorded as a phase; the state and the estimate move on."""
        self.phases.append(Phase(name, kind, float(self.state.time), float(run.state.time), run.estimate_error, run))
        self.state, self.est = run.state, run.estimate
        e = run.estimate_error
        self.say(f"{name}: estimated at {_fmt(self.est.base)}; estimate off by {1000 * e['position_error_m']:.1f} "
                 f"mm, {e['yaw_error_deg']:.2f} deg")

    def curl(self, q_to: np.ndarray, name: str) -> None:
        duration = max(1.0, float(np.abs(q_to - self.q_now).max()) / self.loop.curl_speed)
        self.ground(self.sim.run_path(self.state, lc.curl_path(self.q_now, q_to), duration, start_estimate=self.est,
                                      name=name), name, "curl")
        self.q_now = q_to.copy()

    def simulate_from(self, at: SimState, t: np.ndarray, q: np.ndarray, base: BasePlacement, label: str,
                      kind: str, hold: float = 0.0) -> SimResult:
        """A joint motion of the lifted body in MuJoCo from the state ``at`` (then ``hold`` s still), recorded
        as a phase."""
        t0 = float(at.time)
        r = simulate_trajectory(self.robot, t, q, base, state=at, settle=0.0, hold=hold, obstacles=self.loop.obstacles,
                                **self.loop._ground_options)
        self.extra.append((label, t0, r))
        assert r.end_state is not None
        if self.phases and abs(self.phases[-1].t1_s - t0) < 0.01:  # the last phase ends at the last tick simulated
            self.phases[-1].t1_s = t0
        self.phases.append(Phase(label, kind, t0, float(r.end_state.time)))
        return r

    # --- 1. the goal -------------------------------------------------------------------------------------
    def choose_goal(self) -> str | None:
        """Where must the base go? The plan from where the curl would leave it, relocated if need be, checked in
        dynamics at its own start (a relocated base's plan can pass its static checks and still tip the body in
        MuJoCo: then every attempt to reach that goal fails); when it fails, the scene's own placement (the default
        one for a scene without); then placements near each plan that tipped or whose straight pose or curl came
        too near an obstacle. None when found, else why not."""
        loop, robot = self.loop, self.robot
        after_curl = lc.compose(self.est.base, lc.curl_displacement(robot, self.q_now, self.q_bend))
        tried, refused = [], []
        t0 = time.perf_counter()
        for candidate in (after_curl, as_base(loop.scene.base)):
            first = plan(loop.scene, controller=loop.controller, base=candidate, allow_relocation=True,
                         timing=loop.timing)
            why = loop._goal_failure(first)
            if why is None and first.failure is None:
                why = loop._straight_failure(first.base, first.states[0][2])
            if why is None:
                self.goal, self.q_bend = first.base, first.states[0][2].copy()
                break
            if first.failure is None:
                refused.append(first)
            tried.append(f"from {_fmt(candidate)}: {why}")
            self.note(f"the plan from {_fmt(candidate)} fails ({why})")
        for near in refused if self.goal is None else []:  # (two rings: an obstacle in the way needs a larger step)
            self.goal = loop._nearby_goal(near.base, near.states[0][2], rings=2)
            if self.goal is not None:
                self.q_bend = near.states[0][2].copy()
                break
        self.planning += time.perf_counter() - t0
        if self.goal is None:
            return "no plan reaches the targets " + "; nor ".join(tried)
        if self.goal != after_curl:
            self.say(f"the base must go to {_fmt(self.goal)}")
        return None

    def closer_goal(self) -> str | None:
        """A correction: closer to the goal than last time (a tighter tolerance), or another goal nearby when the
        gaits get no closer. None, else why there is none."""
        robot, goal = self.robot, self.goal
        assert goal is not None
        self.tolerance = self.tolerance.tighter()
        straight = lc.curl_displacement(robot, np.zeros(robot.n_joints), self.q_bend)
        straight_here = lc.compose(lc.compose(self.est.base, lc.curl_displacement(robot, self.q_now, self.q_bend)),
                                   lc.inverse(straight))
        straight_goal = lc.compose(goal, lc.inverse(straight))
        if lc.next_step(robot, straight_here, straight_goal, self.rates, tolerance=self.tolerance) is None:
            # as close to the goal as the gaits get, and the head phases still fail: another goal nearby
            t0 = time.perf_counter()
            nearby = self.loop._nearby_goal(goal, self.q_bend)
            self.planning += time.perf_counter() - t0
            if nearby is None:
                return f"no placement near {_fmt(goal)} gives head phases that succeed"
            self.goal = nearby
            self.say(f"the base must go to {_fmt(nearby)} instead")
        return None

    # --- 2. locomotion and the curl --------------------------------------------------------------------------
    def go_to_goal(self) -> str | None:
        """Gaits when the curl from here would not leave the base at the goal, then the curl into the bending
        state. None, else why the body cannot go on."""
        robot, goal = self.robot, self.goal
        assert goal is not None
        D = lc.curl_displacement(robot, np.zeros(robot.n_joints), self.q_bend)
        straight_goal = lc.compose(goal, lc.inverse(D))
        landing = lc.compose(self.est.base, lc.curl_displacement(robot, self.q_now, self.q_bend))
        if lc.next_step(robot, lc.compose(landing, lc.inverse(D)), straight_goal, self.rates,
                        tolerance=self.tolerance) is not None:
            if np.abs(self.q_now).max() > 0.0:
                self.curl(np.zeros(robot.n_joints), "uncurl")
            blocked = self.loop._locomotion(self.sim, self.est, straight_goal, self.tolerance, self.rates,
                                            self.routes, self.say, self.ground, lambda: self.state)
            if blocked is not None:
                return blocked
        if np.abs(self.q_bend - self.q_now).max() > 1e-9:
            self.curl(self.q_bend, "curl into the bending state")
        return None

    # --- 3.-5. the head phases planned -----------------------------------------------------------------------
    def plan_head_phases(self) -> tuple[SimState, float, int] | None:
        """The head phases planned from the estimate (dead reckoning), then from a fix (outside, or onboard: the
        head camera's, :meth:`look_first`): ``head_plan`` and where, when and from which sample its simulation
        starts; None when the plan fails (the loop corrects the base)."""
        loop = self.loop
        self.head_plan = self.head_plan_here("after the curl", loop.dynamics_check and loop.fix is None)
        if self.head_plan is None:
            return None
        if loop.fix is not None:
            dead_reckoned, truth = self.est, self.sim.true_pose()
            self.est = loop.fix.measure(self.sim, self.rng)
            self.fixes.append({"t_s": float(self.state.time), "dead_reckoning": pose_error(dead_reckoned, truth),
                               "fix": pose_error(self.est, truth)})
            self.say(f"the fix puts the base at {_fmt(self.est.base)} (dead reckoning said "
                     f"{_fmt(dead_reckoned.base)})")
            self.head_plan = self.head_plan_here("after the fix", loop.dynamics_check)
            if self.head_plan is None:
                return None
        elif self.head_sensor is not None:
            looked = self.look_first(self.head_plan)
            if looked is None:
                return None
            self.head_plan, head_state, plan_t0, first_sample = looked
            return head_state, plan_t0, first_sample
        return self.state, float(self.state.time), 0

    def head_plan_here(self, label: str, dynamics_check: bool, q_now: np.ndarray | None = None) -> Plan | None:
        """The head phases from the current estimate, the base kept, starting from the joints as they are
        (measured: they rest a few tenths of a degree from their commands, friction holding the links against
        the servos, which moves P0 by millimetres), checked in dynamics when asked. None when it fails.
        A joint commanded to its limit rests a fraction of a milliradian past it (the servo's error): the
        measured joints are clipped to the limits, which the retiming requires of every waypoint."""
        loop, robot = self.loop, self.robot
        t0 = time.perf_counter()
        q_measured = np.clip(self.sim.measured_joints() if q_now is None else q_now, robot.lower, robot.upper)
        p = plan(loop.scene, controller=loop.controller, base=self.est.base, allow_relocation=False,
                 start_q=q_measured, timing=loop.timing)
        self.planning += time.perf_counter() - t0
        why = p.failure if p.failure is not None else loop._dynamics_check(p) if dynamics_check else None
        if why is None:
            return p
        self.note(f"{label}: the head phases from {_fmt(self.est.base)} fail ({why})")
        return None

    def look(self, head_pose: np.ndarray, k: int) -> list:
        assert self.head_sensor is not None
        readings = [self.head_sensor.read(head_pose, k) for _ in range(sv.HEAD_FRAMES)]
        return [r for r in readings if r is not None]

    def look_first(self, p: Plan) -> tuple[Plan, SimState, float, int] | None:
        """The head phases run up to the first waypoint from which the plan expects a marker in the head
        camera's view (:func:`look_waypoint`), the head held still there; then the camera's fix from the nearest
        marker in view and the head phases planned again from there and the fixed pose. Returns the plan, the
        state its simulation starts from, the time its clock starts at and its first sample to simulate; with no
        marker in view, the rest of the plan from dead reckoning. None (back to step 2, the body lowered again
        along the plan) when the plan from the fixed pose fails."""
        head_sensor, encoders, robot, sim = self.head_sensor, self.encoders, self.robot, self.sim
        assert head_sensor is not None and encoders is not None
        k = look_waypoint(robot, p, head_sensor)
        if k is None:
            self.note("the plan never turns the head camera towards a marker: the head phases from dead reckoning")
            return p, self.state, float(self.state.time), 0
        start_t = float(self.state.time)
        looked = self.simulate_from(self.state, p.t[:k + 1], p.q[:k + 1], p.base, "head up to look", "lift",
                                    LOOK_HOLD_S)
        assert looked.end_state is not None and looked.root_pose is not None
        head_pose = looked.head_pose[-1]
        seen = head_sensor.visible(head_pose)
        q_look = encoders.read(looked.q[-1])
        if not seen:
            self.note("no marker in the head camera's view where the plan expected one: the head phases from dead "
                      "reckoning")
            self.phases.pop()  # the plan's own phases say it
            return p, looked.end_state, start_t + LOOK_HOLD_S, k
        nearest = min(seen, key=lambda j: float(np.linalg.norm(head_sensor.markers[j][:3, 3] - head_pose[:3, 3])))
        T_root = sv.root_from_head_reading(robot, self.look(head_pose, nearest), head_sensor.markers[nearest], q_look)
        dead_reckoned, truth = self.est, _true_pose(robot, looked.root_pose[-1], looked.q[-1])
        R_imu = T_root[:3, :3] @ robot.body.fk_all(q_look)[sim.estimator.imu_index][:3, :3]
        body = T_root @ robot.body_in_root
        self.est = sim.estimator.reset(q_look, R_imu, body[:2, 3], math.atan2(body[1, 0], body[0, 0]))
        self.fixes.append({"t_s": float(looked.end_state.time), "source": "head camera", "target": nearest,
                           "dead_reckoning": pose_error(dead_reckoned, truth), "fix": pose_error(self.est, truth)})
        self.say(f"the head camera puts the base at {_fmt(self.est.base)} (dead reckoning said "
                 f"{_fmt(dead_reckoned.base)})")
        again = self.head_plan_here("after the head camera's fix", self.loop.dynamics_check, q_look)
        if again is not None:
            return again, looked.end_state, float(looked.end_state.time), 0
        # lower the body again into the bending state, back along the plan, and go back to the locomotion
        lowered = self.simulate_from(looked.end_state, p.t[:k + 1], p.q[k::-1], p.base, "lower again", "lift", 0.5)
        assert lowered.end_state is not None
        self.state = lowered.end_state
        sim.restore(self.state)
        sim.reset_attitude(R_imu)
        return None

    # --- 6. the head phases in MuJoCo -------------------------------------------------------------------------
    def run_head_phases(self, head_state: SimState, plan_t0: float, first_sample: int) -> None:
        """``head_plan`` in MuJoCo from where the body is, compared with the plan placed where the body truly lies,
        then (onboard) the final approach on the head camera."""
        p, robot, loop = self.head_plan, self.robot, self.loop
        assert p is not None
        self.say(f"head phases planned from {_fmt(self.est.base)}: {p.duration_s:.1f} s; simulating")
        self.head_t0 = float(head_state.time)
        head = simulate_trajectory(robot, p.t[first_sample:], p.q[first_sample:], p.base, state=head_state,
                                   settle=0.0, obstacles=loop.obstacles, **loop._ground_options)
        self.head = head
        check_plan_span(p.t, [tg.time_s for tg in p.targets], head)
        targets = [(tg.time_s, tg.position, tg.direction) for tg in p.targets] or None
        # against the plan placed where the body truly lies (MuJoCo's, at the head phases' first tick): the
        # simulated ZMP is the true one, and the support polygon at the believed base would count the belief's
        # error (the camera's fix: tenths of a millimetre, 0.1 deg) as the ZMP leaving it
        lies = _true_pose(robot, head.root_pose[0], head.q[0]).base if head.root_pose is not None else p.base
        self.metrics = compare(robot, p.t, p.q, head, targets=targets, base=lies)
        self.phases += head_phases(p, plan_t0)
        assert head.end_state is not None
        self.phases[-1].t1_s = float(head.end_state.time)
        if self.head_sensor is not None:
            self.metrics.update(self.final_approach(p, head))

    def final_approach(self, p: Plan, head: SimResult) -> dict:
        """The head corrected on the camera's measurement of the last target (see :mod:`snakehead.closed_loop.servo`);
        the final errors against the truth."""
        assert self.encoders is not None and head.end_state is not None
        scene, robot = self.loop.scene, self.robot
        last = max(k for k, tg in enumerate(scene.targets) if not tg.via)
        target = sn.target_frame(scene.targets[last].position, scene.targets[last].direction)
        q_cmd, at, now = p.q[-1].copy(), head.end_state, head
        for it in range(sv.SERVO_ITERATIONS + 1):
            record, seen = self.servo_record(it, now, last, target)
            if seen is None:
                break
            q_new = np.clip(q_cmd + sv.servo_step(robot, self.encoders.read(now.q[-1]), seen), robot.lower,
                            robot.upper)
            t = np.array([0.0, sv.SERVO_MOVE_S, sv.SERVO_MOVE_S + sv.SERVO_HOLD_S])
            q = np.vstack([q_cmd, q_new, q_new])
            moved = self.simulate_from(at, t, q, p.base, f"final approach {it + 1}", "servo")
            check = compare(robot, t, q, moved, base=p.base)
            record["base_lift_m"] = check["base_lift_m"]
            assert moved.end_state is not None
            q_cmd, at, now = q_new, moved.end_state, moved
            if check["base_lift_m"] > CHECK_BASE_LIFT:
                self.notes.append(f"the final approach lifts the base {1000 * check['base_lift_m']:.1f} mm: stopped")
                break
        final = self.servo_log[-1]
        return {"final_position_error_m": final["true_position_error_m"],
                "final_direction_error_deg": final["true_direction_error_deg"],
                "final_approach_moves": sum(1 for r in self.servo_log if "base_lift_m" in r)}

    def servo_record(self, it: int, now: SimResult, last: int, target: np.ndarray) -> tuple[dict, np.ndarray | None]:
        """One look of the final approach, logged in ``servo_log`` (the true and measured errors), and the measured
        pose of the target in the head (None: stop here: not in view, too far, near enough or the last look)."""
        readings = self.look(now.head_pose[-1], last)
        true_error = sv.head_error(np.linalg.solve(now.head_pose[-1], target))
        record = {"iteration": it, "true_position_error_m": true_error[0], "true_direction_error_deg": true_error[1],
                  "in_view": bool(readings)}
        self.servo_log.append(record)
        if not readings:
            self.notes.append("the last target's marker is not in the head camera's view: no final approach")
            return record, None
        seen = sn.mean_pose([r.target_in_head for r in readings])
        record["measured_position_error_m"], record["measured_direction_error_deg"] = sv.head_error(seen)
        if record["measured_position_error_m"] > sv.SERVO_MAX_POSITION_M \
                or record["measured_direction_error_deg"] > sv.SERVO_MAX_DIRECTION_DEG:
            self.notes.append(f"the head camera sees the head {1000 * record['measured_position_error_m']:.0f} mm "
                              f"and {record['measured_direction_error_deg']:.1f} deg off: too far for the final "
                              "approach on the head chain alone")
            return record, None
        if (record["measured_position_error_m"] < sv.SERVO_POSITION_TOL_M
                and record["measured_direction_error_deg"] < sv.SERVO_DIRECTION_TOL_DEG) or it == sv.SERVO_ITERATIONS:
            return record, None
        return record, seen


def look_waypoint(robot: SnakeRobot, p: Plan, camera: sn.HeadSensor) -> int | None:
    """The sample of plan ``p`` at its first waypoint (after the bending state) from which the head camera would
    see a marker within half its field of view, the body where the plan believes it lies (the margin allows for
    the belief's error); None if there is none."""
    for label, t, q in p.states[1:]:
        head = robot.head_pose(q, p.base)
        for k in camera.visible(head):
            d = camera.markers[k][:3, 3] - head[:3, 3]
            if float(d @ head[:3, 0]) >= float(np.linalg.norm(d)) * math.cos(0.5 * camera.half_fov_rad):
                return int(np.argmin(np.abs(p.t - t)))
    return None


def _true_pose(robot: SnakeRobot, root: np.ndarray, q: np.ndarray) -> BodyPose:
    """The body's true pose (for the record only) from MuJoCo's root pose (4, 4) and joints (n,)."""
    frames = root @ robot.body.fk_all(q)
    centres = robot.link_centres(frames[None])[0]
    return BodyPose(root=root.copy(), chassis=virtual_chassis(centres, forward=centres[-1] - centres[0]),
                    body_in_root=robot.body_in_root)


def _fmt(b: BasePlacement) -> str:
    return f"({b.x:.3f}, {b.y:.3f}) m, {math.degrees(b.yaw):.1f} deg"

