"""A scene on a slope (or at the foot of a staircase) rewritten in its ground frame, where the planner works
(``model.placement``).

A scene's targets, obstacles and base are written in the world. On a plane terrain the planner plans in the plane's
frame (:class:`~snakehead.model.placement.GroundFrame`): the ground is z = 0 there and gravity leans. This module
turns a scene into that frame: the targets' positions and directions, the boxes' and meshes' poses, and the base's
placement (given in the world as the point of the slope under (x, y) and the heading of the body's course seen from
above). At the foot of a staircase up (a ``"steps"`` terrain rising from the base's level) the ground frame is that
level and the steps become box obstacles (``StepsTerrain.risen_blocks``): the body lies on the level, the neck and
head keep clear of the steps. Flat ground is the world frame: the scene comes back as it is.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._errors import Infeasible, InputError
from ..geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole
from ..model.placement import WORLD_FRAME, BasePlacement, GroundFrame
from ..terrain.surfaces import FlatGround, PlaneTerrain, StepsTerrain
from .scene import Scene

__all__ = ["ground_frame_of", "base_on_slope", "scene_in_ground_frame"]


def ground_frame_of(scene: Scene) -> GroundFrame:
    """The frame the planner plans ``scene`` in: the world's on flat ground, the plane's on a plane terrain;
    InputError naming the scene for a terrain it cannot plan on yet (heightfields, meshes, steps)."""
    terrain = scene.terrain
    if isinstance(terrain, FlatGround):
        return WORLD_FRAME
    if isinstance(terrain, PlaneTerrain):
        return GroundFrame.of_plane(terrain.unit_normal, terrain.point)
    if isinstance(terrain, StepsTerrain) and terrain.step_height > 0:
        return GroundFrame.of_plane((0.0, 0.0, 1.0), terrain.start)  # the level at the staircase's foot
    raise InputError(f"scene {scene.name!r}: its [terrain] is {type(terrain).__name__}"
                     f"{' (a staircase down)' if isinstance(terrain, StepsTerrain) else ''}; this release plans on "
                     "flat ground, on planes and at the foot of a staircase up only")


def _check_at_the_foot(scene: Scene, steps: StepsTerrain, base: BasePlacement) -> None:
    """Infeasible unless the base's placement (world) lies on the staircase's apron, below its first riser."""
    h = math.radians(steps.heading_deg)
    dx, dy = base.x - steps.start[0], base.y - steps.start[1]
    u, v = dx * math.cos(h) + dy * math.sin(h), -dx * math.sin(h) + dy * math.cos(h)
    if not (-steps.apron <= u < 0.0 and abs(v) <= steps.width / 2):
        raise Infeasible(f"scene {scene.name!r}: the base at ({base.x:g}, {base.y:g}) m does not lie at the foot of "
                         f"its staircase (the apron, {steps.apron:g} m before the first riser); this release plans "
                         "from there only")


def base_on_slope(base: BasePlacement, frame: GroundFrame) -> BasePlacement:
    """A placement written in the world (x, y the point of the slope under it, yaw the heading of the body's course
    seen from above) as the placement in ``frame`` (a plane's ground frame). A placement already in ``frame`` is
    kept; one in another ground frame is an InputError."""
    if base.ground == frame:
        return base
    if not base.on_flat_ground:
        raise InputError(f"the base placement's ground frame {base.ground!r} is not the terrain's {frame!r}")
    n = np.reshape(frame.rotation, (3, 3))[:, 2]
    height = float(frame.origin[2] - (n[0] * base.x + n[1] * base.y) / n[2])
    u, v, _ = frame.to_ground([base.x, base.y, height])
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    course = frame.direction_to_ground([c, s, -(n[0] * c + n[1] * s) / n[2]])  # along the slope, (c, s) from above
    return BasePlacement(float(u), float(v), math.atan2(course[1], course[0]), frame)


def _obstacle_in(ob: object, frame: GroundFrame, scene: str) -> object:
    if isinstance(ob, BoxObstacle):
        return BoxObstacle(frame.to_ground(ob.centre), ob.size, frame.direction_to_ground(ob.rotation.T).T)
    if isinstance(ob, MeshObstacle):
        return dataclasses.replace(ob, pose=np.linalg.inv(frame.matrix) @ ob.pose)
    if isinstance(ob, WallWithHole):  # its width axis is set by the world's up, which a slope's frame does not keep
        raise InputError(f"scene {scene!r}: a wall with a hole on a slope is not supported; give the wall as boxes")
    raise InputError(f"scene {scene!r}: an obstacle of type {type(ob).__name__} cannot be placed on a slope")


def scene_in_ground_frame(scene: Scene) -> tuple[Scene, GroundFrame]:
    """``scene`` in the frame the planner plans it in (:func:`ground_frame_of`) and that frame: on a slope the
    targets, obstacles and base in the plane's frame and the terrain flat there; on flat ground ``scene`` itself."""
    frame = ground_frame_of(scene)
    risen: list = []
    if isinstance(scene.terrain, StepsTerrain):  # the steps are obstacles above the foot's level
        _check_at_the_foot(scene, scene.terrain, scene.base if scene.base is not None else BasePlacement())
        risen = scene.terrain.risen_blocks()
    if frame.is_world and not risen:
        return scene, frame
    targets = tuple(dataclasses.replace(t, position=frame.to_ground(t.position),
                                        direction=frame.direction_to_ground(t.direction)) for t in scene.targets)
    obstacles = tuple(_obstacle_in(ob, frame, scene.name) for ob in (*scene.obstacles, *risen))
    base = base_on_slope(scene.base if scene.base is not None else BasePlacement(), frame)
    return dataclasses.replace(scene, targets=targets, obstacles=obstacles, base=base, terrain=FlatGround()), frame
