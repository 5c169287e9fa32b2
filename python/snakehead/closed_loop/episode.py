"""One run of the closed loop (:class:`snakehead.closed_loop.loop.ClosedLoop`, whose module says the steps): the
body's state and its estimated pose as they go, each step taken from the estimate after the last, and the record that
becomes the :class:`~snakehead.closed_loop.loop_run.LoopRun`. The onboard fix and the final approach read the head
camera (:class:`~snakehead.sim.sensors.HeadSensor`, :mod:`snakehead.closed_loop.servo`).
"""
from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Callable

import numpy as np

from ..locomotion import goals as lc
from ..locomotion.gaits import virtual_chassis
from ..model.robot import BasePlacement, SnakeRobot, as_base
from ..planning.plan_result import Plan
from ..planning.planner import plan
from ..planning.start_state import bending_state
from ..sim import sensors as sn
from ..sim.compare import check_plan_span, compare
from ..sim.tracking import SimResult, SimState, simulate_trajectory
from . import servo as sv
from .estimate import BodyPose, pose_error
from .gait_runner import GaitRun
from .goal_checks import CHECK_BASE_LIFT
from .loop_run import Phase, head_phases, placement_text

if TYPE_CHECKING:  # the loop runs its episodes: the annotation only, no import at run time
    from .loop import ClosedLoop

__all__ = ["LOOK_HOLD_S", "Episode", "look_waypoint"]

#: How long the head holds still where it first looks for a marker (s).
LOOK_HOLD_S = 0.5


class Episode:
    """One run of :meth:`ClosedLoop.run <snakehead.closed_loop.loop.ClosedLoop.run>` from the body lying at
    ``start`` with joints ``q_now``, the loop believing it lies at ``believed``; ``say`` tells each step. It holds
    the simulation's state and the estimate of the body's pose as they go, the joints commanded, the goal, and the
    record (phases, fixes, notes, the head's plan and its simulation: what
    :class:`~snakehead.closed_loop.loop_run.LoopRun` reports); its methods
    are the loop's steps (see :mod:`snakehead.closed_loop.loop`): 1. the goal (:meth:`choose_goal`,
    :meth:`closer_goal`), 2. the gaits and the curl (:meth:`go_to_goal`), 3.-5. the head phases planned from the
    estimate and a fix (:meth:`plan_head_phases`), 6.-7. run in MuJoCo and the final approach
    (:meth:`run_head_phases`)."""

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
        # on a slope: the curl from straight into a bending state as the body last did it (q_bend, the root's motion
        # in its own starting frame, estimated); the friction model's prediction knows no slope
        self.curl_seen: tuple[np.ndarray, BasePlacement] | None = None

    def note(self, text: str) -> None:
        """A note of the run's report, told as well."""
        self.notes.append(text)
        self.say(text)

    # --- the record of the body's motion ---------------------------------------------------------------
    def ground(self, run: GaitRun, name: str, kind: str) -> None:
        """A run on the ground (a gait, a curl) recorded as a phase; the state and the estimate move on."""
        self.phases.append(Phase(name, kind, float(self.state.time), float(run.state.time), run.estimate_error, run))
        self.state, self.est = run.state, run.estimate
        e = run.estimate_error
        self.say(f"{name}: estimated at {placement_text(self.est.base)}; estimate off by "
                 f"{1000 * e['position_error_m']:.1f} mm, {e['yaw_error_deg']:.2f} deg")

    def curl(self, q_to: np.ndarray, name: str) -> None:
        duration = max(1.0, float(np.abs(q_to - self.q_now).max()) / self.loop.curl_speed)
        before, straight = self.est.base, not np.any(self.q_now)
        self.ground(self.sim.run_path(self.state, lc.curl_path(self.q_now, q_to), duration, start_estimate=self.est,
                                      name=name), name, "curl")
        if straight and not self.loop.ground.is_world:
            self.curl_seen = (q_to.copy(), lc.relative(before, self.est.base))
        self.q_now = q_to.copy()

    def curl_motion(self, q_from: np.ndarray, q_to: np.ndarray) -> BasePlacement:
        """Where the curl from ``q_from`` to ``q_to`` takes the root, in its starting frame: the friction model's
        prediction (:func:`snakehead.locomotion.goals.curl_displacement`), or on a slope, once the body curled from
        straight into ``q_to``, the motion it was seen to make (the weight's pull down the slope turns and carries
        the curl by more than the model says: docs/closed_loop.rst, "On slopes")."""
        seen = self.curl_seen
        if seen is not None and not np.any(q_from) and np.array_equal(seen[0], q_to):
            return seen[1]
        return lc.curl_displacement(self.robot, q_from, q_to)

    def simulate_from(self, at: SimState, t: np.ndarray, q: np.ndarray, base: BasePlacement, label: str,
                      kind: str, hold: float = 0.0) -> SimResult:
        """A joint motion of the lifted body in MuJoCo from the state ``at`` (then ``hold`` s still), recorded
        as a phase."""
        t0 = float(at.time)
        r = simulate_trajectory(self.robot, t, q, base, state=at, settle=0.0, hold=hold, obstacles=self.loop.obstacles,
                                **self.loop.ground_options)
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
        loop = self.loop
        after_curl = lc.compose(self.est.base, self.curl_motion(self.q_now, self.q_bend))
        tried, refused = [], []
        t0 = time.perf_counter()
        for candidate in (after_curl, as_base(loop.scene.base)):
            first = plan(loop.scene, controller=loop.controller, base=candidate, allow_relocation=True,
                         timing=loop.timing)
            why = loop.goal_checks.goal_failure(first)
            if why is None and first.failure is None:
                why = loop.goal_checks.straight_failure(first.base, first.states[0][2])
            if why is None:
                self.goal, self.q_bend = first.base, first.states[0][2].copy()
                break
            if first.failure is None:
                refused.append(first)
            tried.append(f"from {placement_text(candidate)}: {why}")
            self.note(f"the plan from {placement_text(candidate)} fails ({why})")
        for near in refused if self.goal is None else []:  # (two rings: an obstacle in the way needs a larger step)
            self.goal = loop.goal_checks.nearby_goal(near.base, near.states[0][2], rings=2)
            if self.goal is not None:
                self.q_bend = near.states[0][2].copy()
                break
        self.planning += time.perf_counter() - t0
        if self.goal is None:
            return "no plan reaches the targets " + "; nor ".join(tried)
        if self.goal != after_curl:
            self.say(f"the base must go to {placement_text(self.goal)}")
        return None

    def closer_goal(self) -> str | None:
        """A correction: closer to the goal than last time (a tighter tolerance), or another goal nearby when the
        gaits get no closer. None, else why there is none."""
        robot, goal = self.robot, self.goal
        assert goal is not None
        self.tolerance = self.tolerance.tighter()
        straight = self.curl_motion(np.zeros(robot.n_joints), self.q_bend)
        straight_here = lc.compose(lc.compose(self.est.base, self.curl_motion(self.q_now, self.q_bend)),
                                   lc.inverse(straight))
        straight_goal = lc.compose(goal, lc.inverse(straight))
        if lc.next_step(robot, straight_here, straight_goal, self.rates, tolerance=self.tolerance) is None:
            # as close to the goal as the gaits get, and the head phases still fail: another goal nearby
            t0 = time.perf_counter()
            nearby = self.loop.goal_checks.nearby_goal(goal, self.q_bend)
            self.planning += time.perf_counter() - t0
            if nearby is None:
                return f"no placement near {placement_text(goal)} gives head phases that succeed"
            self.goal = nearby
            self.say(f"the base must go to {placement_text(nearby)} instead")
        return None

    # --- 2. locomotion and the curl --------------------------------------------------------------------------
    def go_to_goal(self) -> str | None:
        """Gaits when the curl from here would not leave the base at the goal, then the curl into the bending
        state. None, else why the body cannot go on."""
        robot, goal = self.robot, self.goal
        assert goal is not None
        D = self.curl_motion(np.zeros(robot.n_joints), self.q_bend)
        straight_goal = lc.compose(goal, lc.inverse(D))
        landing = lc.compose(self.est.base, self.curl_motion(self.q_now, self.q_bend))
        if lc.next_step(robot, lc.compose(landing, lc.inverse(D)), straight_goal, self.rates,
                        tolerance=self.tolerance) is not None:
            if np.abs(self.q_now).max() > 0.0:
                self.curl(np.zeros(robot.n_joints), "uncurl")
            blocked = self.loop.route_follower.follow(self.sim, self.est, straight_goal, self.tolerance, self.rates,
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
            self.say(f"the fix puts the base at {placement_text(self.est.base)} (dead reckoning said "
                     f"{placement_text(dead_reckoned.base)})")
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
        why = p.failure if p.failure is not None else loop.goal_checks.dynamics_failure(p) if dynamics_check else None
        if why is None:
            return p
        self.note(f"{label}: the head phases from {placement_text(self.est.base)} fail ({why})")
        return None

    def look(self, head_pose: np.ndarray, k: int) -> list:
        """The head camera's readings of marker ``k`` from ``head_pose`` (4, 4), HEAD_FRAMES frames, those that
        saw it."""
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
        dead_reckoned, truth = self.est, _true_pose(robot, looked.root_pose[-1], looked.q[-1], p.base)
        R_imu = T_root[:3, :3] @ robot.body.fk_all(q_look)[sim.estimator.imu_index][:3, :3]
        ground = self.loop.ground
        if not ground.is_world:  # the fix's orientation is the ground frame's; the IMU's filter holds the world's
            R_imu = ground.matrix[:3, :3] @ R_imu
        body = T_root @ robot.body_in_root
        self.est = sim.estimator.reset(q_look, R_imu, body[:2, 3], math.atan2(body[1, 0], body[0, 0]))
        self.fixes.append({"t_s": float(looked.end_state.time), "source": "head camera", "target": nearest,
                           "dead_reckoning": pose_error(dead_reckoned, truth), "fix": pose_error(self.est, truth)})
        self.say(f"the head camera puts the base at {placement_text(self.est.base)} (dead reckoning said "
                 f"{placement_text(dead_reckoned.base)})")
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
        self.say(f"head phases planned from {placement_text(self.est.base)}: {p.duration_s:.1f} s; simulating")
        self.head_t0 = float(head_state.time)
        head = simulate_trajectory(robot, p.t[first_sample:], p.q[first_sample:], p.base, state=head_state,
                                   settle=0.0, obstacles=loop.obstacles, **loop.ground_options)
        self.head = head
        check_plan_span(p.t, [tg.time_s for tg in p.targets], head)
        targets = [(tg.time_s, tg.position, tg.direction) for tg in p.targets] or None
        # against the plan placed where the body truly lies (MuJoCo's, at the head phases' first tick): the
        # simulated ZMP is the true one, and the support polygon at the believed base would count the belief's
        # error (the camera's fix: tenths of a millimetre, 0.1 deg) as the ZMP leaving it
        lies = _true_pose(robot, head.root_pose[0], head.q[0], p.base).base if head.root_pose is not None else p.base
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


def _true_pose(robot: SnakeRobot, root: np.ndarray, q: np.ndarray, base: BasePlacement) -> BodyPose:
    """The body's true pose (for the record only) from MuJoCo's root pose (4, 4; in the ground frame of ``base``,
    as a simulation of a plan records it) and joints (n,)."""
    frames = root @ robot.body.fk_all(q)
    centres = robot.link_centres(frames[None])[0]
    return BodyPose(root=root.copy(), chassis=virtual_chassis(centres, forward=centres[-1] - centres[0]),
                    body_in_root=robot.body_in_root, ground=base.ground)
