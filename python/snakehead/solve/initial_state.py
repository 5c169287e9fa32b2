"""The initial state of Section 3.3 (1) held on the body's actual ground contacts.

``backbone.initial_configuration`` chooses the base arc's central angle on Eq. 24's support polygon of the base
links' end points (``stability.static_margin``'s default contact model): the modules' own sections lying on the
ground. The plans check every configuration on the points of the collision shapes that actually touch the ground
(``contact="ground"``, and the base's own support: :mod:`.base_support`). On a body whose lowest
points are not on its modules (passive wheels, skids, sensor pods hanging below it: the ``wheeled`` sample's wheels
reach 1 mm below the modules, at the middle of each one) the two polygons differ: the wheels' polygon lacks the
half module at each end of the base, and with the neck and head lifted the centre of mass lies near P0, at the
base's front end: the paper's optimum (theta = 2.97 rad) stands 2 cm inside the end points' polygon but 1.6 cm
outside the wheels'. The planner then cannot lift the head into the initial state (it is not a stable state) and
moves from the neck and head curled on the ground straight to each target, through the ground.

:func:`stable_initial_configuration` keeps the paper's configuration whenever it stands on the actual contacts by
``DETOUR_MARGIN`` (every robot whose modules lie on the ground: nothing changes for them); otherwise it changes the
paper's configuration least: the central angle (on a grid over the yaw joints' limits, the up curve kept) nearest
the paper's among those that keep the centre of mass ``INITIAL_MARGIN`` inside the actual contacts' polygon, the
lifted links above the ground and the body clear of itself (the largest support polygon, Eq. 2's objective, is
not the criterion: on the ``wheeled`` sample it curls the base so tightly that the neck's wheels brush the tail's
as the head lifts); and when no angle does, the up-curve shape
(``backbone.initial.SHAPE_SEARCH``) and angle with the largest margin.
"""
from __future__ import annotations

import math

import numpy as np

from .. import backbone
from .._errors import Infeasible
from ..backbone.base_arc import arc_angle_limit, arc_joint_angles, optimize_base_arc
from ..backbone.initial import SHAPE_SEARCH, UpCurveShape
from ..collision import body_collisions as coll
from ..dynamics import stability
from ..ground_contact import GROUND_TOLERANCE
from ..margins import DETOUR_MARGIN, ZMP_MARGIN
from ..model.robot import BasePlacement, SnakeRobot
from .base_support import ground_links, static_margins

__all__ = ["ANGLE_GRID", "INITIAL_MARGIN", "initial_margins", "stable_initial_configuration"]

#: m: the static margin (on the actual ground contacts) the initial state keeps when the paper's configuration
#: does not keep DETOUR_MARGIN: the plan's static margin and the ZMP's on top, room for the lift's dynamics.
INITIAL_MARGIN = DETOUR_MARGIN + ZMP_MARGIN
#: Central angles of the base arc tried, evenly over (0.05 rad, the yaw joints' limit].
ANGLE_GRID = 41


def initial_margins(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
    """(K,) m: how far each configuration qs (K, n) of a lifted neck and head stands, as the plan checks it: the
    smaller static margin of the polygon of the shape points touching the ground and of the base's own (the links
    lying on the ground whatever the pose); -inf where a lifted link dips into the ground (more than
    GROUND_TOLERANCE) or two links overlap."""
    base = BasePlacement() if base is None else base
    qs = np.atleast_2d(np.asarray(qs, float))
    frames = robot.frames_many(qs, base)
    com = stability.center_of_mass(robot, qs, base, frames=frames)
    margin = np.minimum(stability.static_margins_of_frames(robot, frames, com, "ground", GROUND_TOLERANCE, base),
                        static_margins(robot, frames, ground_links(robot), base))
    ground = coll.ground_clearance(robot, qs, base)[:, robot.lifted_links].min(axis=1, initial=np.inf)
    clear = (ground >= -coll.GROUND_TOLERANCE) & (coll.self_clearance(robot, qs, base) > 0.0)
    return np.where(clear, margin, -np.inf)


def stable_initial_configuration(robot: SnakeRobot) -> np.ndarray:
    """The initial configuration q (n,) of Section 3.3 (1) (``backbone.initial_configuration``), its base arc
    chosen on the body's actual ground contacts when the paper's does not stand on them (see the module)."""
    q0 = backbone.initial_configuration(robot)
    if initial_margins(robot, q0)[0] >= DETOUR_MARGIN:
        return q0
    thetas = np.linspace(0.05, arc_angle_limit(robot), ANGLE_GRID)
    nb = len(arc_joint_angles(robot.base_length, float(thetas[0]), robot))
    paper = optimize_base_arc(robot, q0[nb:]).central_angle  # the paper's angle (initial_configuration's)

    def arcs(q_up: np.ndarray) -> np.ndarray:  # the configurations of every angle with this up curve
        qs = np.tile(q_up, (len(thetas), 1))
        qs[:, :nb] = [arc_joint_angles(robot.base_length, float(t), robot) for t in thetas]
        return qs

    qs = arcs(q0)
    margins = initial_margins(robot, qs)
    ok = np.flatnonzero(margins >= INITIAL_MARGIN)
    if ok.size:
        return qs[ok[int(np.argmin(np.abs(thetas[ok] - paper)))]]
    best, best_margin = q0, float(initial_margins(robot, q0)[0])
    L = backbone.up_length(robot)
    shapes = [UpCurveShape.for_robot(robot)] + [
        UpCurveShape(height=h * L, reach=r * L, tip_angle=math.radians(a)) for h, r, a in SHAPE_SEARCH]
    for shape in shapes:
        try:
            q_up = backbone.initial_configuration(robot, shape=shape, central_angle=float(thetas[len(thetas) // 2]))
        except (Infeasible, ValueError):
            continue
        qs = arcs(q_up)
        within = np.all((qs >= robot.lower - 1e-12) & (qs <= robot.upper + 1e-12), axis=1)
        margins = np.where(within, initial_margins(robot, qs), -np.inf)
        k = int(np.argmax(margins))
        if margins[k] > best_margin:
            best, best_margin = qs[k], float(margins[k])
    return best
