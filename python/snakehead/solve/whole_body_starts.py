"""Where the whole-body solve starts from: whole-body configurations that put the head at the target with the
base as it is (the lifted chain's IK towards frames rolled about the direction, Fig. 9, or continued from the
current joints), other flat shapes of the base, and base placements from which the lifted chain reaches the target.
"""
from __future__ import annotations

import numpy as np

from ..kinematics.ik import FREE_ROLL, TracIK
from ..model.robot import BasePlacement
from .body_problem import BodyProblem
from .head import frame_along
from .head_controller import HeadController

__all__ = ["CANDIDATE_ROLLS", "CANDIDATE_SEEDS", "base_shapes", "continue_from", "lifted_candidates", "placements",
           "rolled_frames", "rolls_reached"]

#: Rolled frames (Fig. 9) and starts per roll of the lifted chain's IK that give the whole-body solve its
#: candidates.
CANDIDATE_ROLLS = 8
CANDIDATE_SEEDS = 2


def lifted_candidates(prob: BodyProblem, q_now: np.ndarray, base: BasePlacement, position: np.ndarray,
                      direction: np.ndarray, seed: int = 0) -> list[np.ndarray]:
    """Whole-body configurations that put the head at the target with the base as it is: TRAC-IK on the lifted
    chain (the neck from where it lifts, and the head: ``lift_frame -> head_tip``) towards ``CANDIDATE_ROLLS``
    frames rolled about the direction (Fig. 9), each from the current joints, and from random joints the rolls
    reached from the current ones (:func:`rolls_reached`)."""
    robot = prob.robot
    if prob.out_of_reach(q_now, base, position, direction):
        return []  # (what the batch would find: every IK fails)
    ik = prob.lifted_ik(seed)
    start = robot.lift_joints.start
    T0 = robot.frame(q_now, robot.lift_frame, base)
    target = np.linalg.inv(T0) @ frame_along(position, direction)
    angles = 2 * np.pi * np.arange(CANDIDATE_ROLLS) / CANDIDATE_ROLLS
    poses = np.concatenate([rolled_frames(target, angles)] * CANDIDATE_SEEDS)
    rng = np.random.default_rng(seed)
    inits = np.vstack([np.tile(q_now[start:], (CANDIDATE_ROLLS, 1))]
                      + [rng.uniform(ik.lower, ik.upper, (CANDIDATE_ROLLS, ik.n_joints))
                         for _ in range(CANDIDATE_SEEDS - 1)])
    qs, ok = rolls_reached(ik, poses, inits)
    out = []
    for qk in qs[ok]:
        q = q_now.copy()
        q[start:] = qk
        out.append(q)
    return out


def rolls_reached(ik: TracIK, poses: np.ndarray, inits: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`lifted_candidates`' IK: first every roll from the current joints, then the random starts of the rolls
    that the current joints' start reached (a roll it missed within its budget is nearly always out of the chain's
    reach with its limits, and a failing target costs the IK's whole budget): (q (T, m), ok (T,)), the targets
    left out not found. Each target keeps its index in the batch as its stream (the same answers as one batch)."""
    first = np.arange(CANDIDATE_ROLLS)
    qs, ok = inits.copy(), np.zeros(len(poses), bool)
    qs[first], ok[first] = ik.ik_many(poses[first], inits[first], streams=first)
    rest = np.flatnonzero(np.tile(ok[first], CANDIDATE_SEEDS - 1)) + CANDIDATE_ROLLS
    if len(rest):
        qs[rest], ok[rest] = ik.ik_many(poses[rest], inits[rest], streams=rest)
    return qs, ok


def rolled_frames(T: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """``head.roll_about_x`` of a frame (4, 4) made here (valid) by each of ``angles`` (rad): (k, 4, 4), the same
    arithmetic without checking the frame again for every angle."""
    out = np.repeat(T[None], len(angles), axis=0)
    for k, angle in enumerate(angles):
        c, s = np.cos(float(angle)), np.sin(float(angle))
        out[k, :3, :3] = T[:3, :3] @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    return out


def continue_from(prob: BodyProblem, q_now: np.ndarray, base: BasePlacement, position: np.ndarray,
                  direction: np.ndarray, seed: int) -> np.ndarray | None:
    """The lifted chain's IK from the current joints, the roll about the direction free: the nearest solution."""
    robot = prob.robot
    start = robot.lift_joints.start
    T0 = robot.frame(q_now, robot.lift_frame, base)
    target = np.linalg.inv(T0) @ frame_along(position, direction)
    qk = prob.lifted_ik(seed).ik(target, q_init=np.clip(q_now[start:], robot.lower[start:], robot.upper[start:]),
                                 bounds=FREE_ROLL)
    if qk is None:
        return None
    q = q_now.copy()
    q[start:] = qk
    return q


def base_shapes(controller: HeadController) -> list[np.ndarray]:
    """Base joint vectors to start from besides the controller's: its arc turned the other way, a straight base,
    and arcs of a half and of one and a half times its central angle."""
    robot = controller.robot
    qb = controller.q_initial[robot.parts.base]
    lo, hi = robot.lower[robot.parts.base], robot.upper[robot.parts.base]
    return [-qb, np.zeros_like(qb), 0.5 * qb, np.clip(1.5 * qb, lo, hi)]


def placements(prob: BodyProblem, P0_local: np.ndarray, position: np.ndarray, direction: np.ndarray
               ) -> list[BasePlacement]:
    """Base placements that put the frame the neck lifts from (``P0_local``: its pose in the root frame, for the
    base's shape) a few horizontal distances short of the target, its body axis pointing at the target along the
    head's direction or its opposite's horizontal part: where the lifted chain can reach the target whatever its
    height (the accepted range of Section 3.3 (3) has none for targets higher than the neck and the dexterous
    centre reach)."""
    robot = prob.robot
    reach = robot.sub_chain(robot.lift_frame, robot.parts.head_tip).reach
    dz = position[2] - (robot.body_axis_height + P0_local[2, 3])
    span = np.sqrt(max(reach * reach - dz * dz, 0.0))
    if span <= 0:
        return []
    axis_heading = np.arctan2(P0_local[1, 0], P0_local[0, 0])
    dxy = np.asarray(direction[:2], float)
    headings = [np.arctan2(dxy[1], dxy[0])] if np.linalg.norm(dxy) > 1e-6 else [0.0]
    headings += [headings[0] + np.pi / 2, headings[0] - np.pi / 2]
    out = []
    for h in (0.5 * span, 0.25 * span, 0.75 * span):
        for heading in headings:
            yaw = heading - axis_heading
            c, s = np.cos(yaw), np.sin(yaw)
            P0_xy = position[:2] - h * np.array([np.cos(heading), np.sin(heading)])
            x, y = P0_xy - np.array([[c, -s], [s, c]]) @ P0_local[:2, 3]
            out.append(BasePlacement(float(x), float(y), float(np.arctan2(s, c))))
    return out
