"""The exact checks of a whole-body solution: the head within its position and direction tolerances, the static
margin of the support polygon (Eqs. 23-24), the lifted links above the ground, the body clear of itself and of the
obstacles (the shapes' signed distances), and the verdict. The whole-body solve optimises over capsules; what it
returns is checked here on the shapes themselves.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from .._validate import finite_float, joint_vector, unit_vector3, vector3
from ..collision import body_collisions as coll
from ..dynamics import stability
from ..geometry.shapes import pair_min_distances
from ..ground_contact import GROUND_TOLERANCE
from ..margins import EXACT_DISTANCE_WITHIN, OBSTACLE_CLEARANCE, SOLUTION_MARGIN
from ..model.frames import forward_kinematics_unchecked
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot

if TYPE_CHECKING:  # (annotations only: body_problem builds on pose_bounds, which takes this module's tolerances)
    from .body_problem import BodyProblem

__all__ = ["DIRECTION_TOLERANCE", "MIN_MARGIN", "POSITION_TOLERANCE", "check_solution", "check_solutions",
           "clear_of_obstacles"]

#: Default required static margin of a solution (m): the plans' (``margins.SOLUTION_MARGIN``).
MIN_MARGIN = SOLUTION_MARGIN
#: Tolerances of a solution: head position (m) and direction (rad).
POSITION_TOLERANCE = 1e-4
DIRECTION_TOLERANCE = np.radians(0.05)


def clear_of_obstacles(robot: SnakeRobot, q: np.ndarray, obstacles: Sequence[Any], base: BasePlacement,
                       clearance: float = OBSTACLE_CLEARANCE) -> bool:
    """Whether configuration q (n,) at ``base`` keeps more than ``clearance`` m from every obstacle (True without
    obstacles)."""
    if not obstacles:
        return True
    return bool(coll.collision_check(robot, q[None], list(obstacles), base,
                                     exact_within=EXACT_DISTANCE_WITHIN).distance[0] > clearance)


def check_solution(robot: SnakeRobot, q: np.ndarray, base: BasePlacement, position: np.ndarray, direction: np.ndarray,
                   obstacles: Sequence[Any] = (), *, min_margin: float = MIN_MARGIN, self_clearance: float = 0.0,
                   obstacle_clearance: float = OBSTACLE_CLEARANCE, problem: BodyProblem | None = None) -> dict:
    """Exact checks of a configuration: head errors, static margin (support polygon of the boxes lying on the
    ground), lowest lifted box corner, separating-axis self clearance, obstacle clearance, and the verdict
    (None or one of ``whole_body_solution.REASONS``).

    With ``problem``, the static margin is also taken without the lifted links (only the links that lie on the
    ground whatever the pose: ``BodyProblem.ground_links``), and the smaller one counts: a pose that stands only
    because a lifted link rests on the ground cannot be reached from the air (the body tips just before the link
    touches down), so a planner must not be given one."""
    robot = as_robot(robot)
    q = joint_vector(q, robot.n_joints)
    checks = check_solutions(robot, q[None], as_base(base), vector3(position, "position"),
                             unit_vector3(direction, "direction"), obstacles,
                             min_margin=finite_float(min_margin, "min_margin"),
                             self_clearance=finite_float(self_clearance, "self_clearance"),
                             obstacle_clearance=finite_float(obstacle_clearance, "obstacle_clearance"), problem=problem)
    return checks[0]


def check_solutions(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement, position: np.ndarray,
                    direction: np.ndarray, obstacles: Sequence[Any] = (), *, min_margin: float = MIN_MARGIN,
                    self_clearance: float = 0.0, obstacle_clearance: float = OBSTACLE_CLEARANCE,
                    problem: BodyProblem | None = None) -> list[dict]:
    """:func:`check_solution` of many configurations qs (K, n) at one placement, each check over the whole batch
    in one call (the frames by the core's batched forward kinematics, the support polygons by its hull, the shapes'
    lowest points and distances by its shape sets): the library's inner loop (the whole-body solve's candidates),
    whose arguments were checked where they entered (float64, finite, of the right shapes)."""
    frames = forward_kinematics_unchecked(robot, qs, base)
    head = frames[:, robot.link_index(robot.parts.head_tip)]
    pe = np.linalg.norm(head[:, :3, 3] - position, axis=1)
    de = np.degrees(np.arccos(np.clip(head[:, :3, 0] @ direction, -1.0, 1.0)))
    com = stability.center_of_mass(robot, qs, base, frames=frames)
    margin = stability.static_margins_of_frames(robot, frames, com, "ground", GROUND_TOLERANCE, base)
    if problem is not None:
        margin = np.minimum(margin, problem.margins(frames, base))
    lifted = robot.lifted_links
    ground = robot.geometry.lowest_z(frames, lifted).min(axis=1) if len(lifted) else np.full(len(qs), np.inf)
    selfc = pair_min_distances(frames, robot.geometry, frames, robot.geometry, robot.self_collision_pairs)
    obst = (coll.collision_check(robot, qs, list(obstacles), base, exact_within=0.01).distance if obstacles
            else None)
    out = []
    for k in range(len(qs)):
        o = None if obst is None else float(obst[k])
        if pe[k] > POSITION_TOLERANCE or np.radians(de[k]) > DIRECTION_TOLERANCE:
            reason: str | None = "out of reach"
        elif margin[k] < min_margin:
            reason = "no stable pose"
        elif (ground[k] < -coll.GROUND_TOLERANCE or selfc[k] <= self_clearance
              or (o is not None and o <= obstacle_clearance)):
            reason = "no clear pose"
        else:
            reason = None
        out.append({"position_error_m": float(pe[k]), "direction_error_deg": float(de[k]),
                    "static_margin_m": float(margin[k]), "ground_clearance_m": float(ground[k]),
                    "self_clearance_m": float(selfc[k]), "obstacle_clearance_m": o, "reason": reason})
    return out
