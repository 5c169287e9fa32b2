"""What a closed loop (:class:`snakehead.closed_loop.loop.ClosedLoop`) records and reports: its phases
(:class:`Phase`: gait, curl, lift, move, hold, servo) and the whole run (:class:`LoopRun`: where the body truly lay and
where the loop believed it did, the fixes, the head phases' plan and simulation, and what MuJoCo ran piece by piece).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from .._errors import InternalError
from ..collision.body_collisions import obstacle_shapes
from ..geometry.shapes import pair_min_distances
from ..model.robot import BasePlacement, SnakeRobot
from ..planning.plan_result import Plan
from ..scenes.scene import Scene
from ..sim.tracking import SimResult
from .gait_runner import GaitRun
from .pose_fix import PoseFix

__all__ = ["PHASE_KINDS", "ESTIMATE_SAMPLES", "Phase", "LoopRun", "head_phases", "placement_text"]

#: The most samples of the estimate's error over time a report holds.
ESTIMATE_SAMPLES = 200
#: The kinds of phases in a loop's report ("servo": a correction of the head's final approach on the camera).
PHASE_KINDS = ("gait", "curl", "lift", "move", "hold", "servo")


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
    """What a closed loop did (see :mod:`snakehead.closed_loop.loop`).

    start / believed_start: where the body truly lay and where the loop believed it did; phases; fixes: each
    fix's record (the estimate before it and its error, the fix's error; ``source`` "head camera" for the
    onboard one); plan: the plan of the head phases (None if the loop never got there); head: their simulation
    (:class:`~snakehead.sim.SimResult`); metrics: the head phases against their plan
    (:func:`snakehead.sim.compare`); head_t0_s: when the head phases began; corrections: how many times the loop
    went back to step 1 after a curl; planning_time_s: wall time spent planning; notes; failure: None when the
    head phases were planned and simulated, else why not; sensing: the loop's
    (:data:`~snakehead.closed_loop.loop.SENSING`); head_extra: (label, start time s, SimResult) of the head's runs
    outside its plan (the look, a lowering, the final approach's moves); servo: the final approach's looks (true
    and measured errors); routes: the routes around the obstacles the locomotion planned, (k, 2) m each.
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


def placement_text(b: BasePlacement) -> str:
    """A placement as the loop's notes and progress lines write it: "(x, y) m, yaw deg"."""
    return f"({b.x:.3f}, {b.y:.3f}) m, {math.degrees(b.yaw):.1f} deg"
