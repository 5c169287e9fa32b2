"""Where the base lies: :class:`BasePlacement` (x, y, yaw on the ground) and the :class:`GroundFrame` of a slope.

The planner works in the *ground frame*: the frame whose z = 0 plane is the plane the base rests on, z its upward
normal. On flat ground it is the world frame and gravity is (0, 0, -GRAVITY). On a slope (a plane terrain) the
body, the targets and the obstacles are expressed in the plane's frame, where the ground is flat again and gravity
leans: ``GroundFrame.gravity`` is the world's g turned into it. Every check that weighs the robot (the static
margin, the ZMP of Eqs. 39-40, the friction, the joint torques) reads gravity from the placement's ground frame, so
the same code serves flat ground (bit for bit) and slopes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .._errors import InputError
from .._validate import finite_array
from .physics import GRAVITY

__all__ = ["BasePlacement", "GroundFrame", "WORLD_FRAME", "WORLD_GRAVITY"]

#: g in the world frame (m/s^2); g in Eq. 38.
WORLD_GRAVITY = (0.0, 0.0, -GRAVITY)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


@dataclass(frozen=True)
class GroundFrame:
    """The frame of a plane the base rests on, as a world pose: ``rotation`` (3, 3) turns its axes into the world's
    (columns: its x, y and z = the plane's upward normal), ``origin`` (3,) m is its origin, a point of the plane.

    Build one with :meth:`of_plane`. Its x-axis is the world's x (or y, for a plane that holds no horizontal
    x-direction) laid on the plane, so a gentle slope's frame is close to the world's."""

    rotation: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)  # row-major, hashable
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        R = finite_array(self.rotation, "ground frame rotation", (9,)).reshape(3, 3)
        if not (np.allclose(R.T @ R, np.eye(3), atol=1e-9) and np.linalg.det(R) > 0):
            raise InputError("a ground frame's rotation must be a rotation matrix")
        object.__setattr__(self, "rotation", tuple(float(v) for v in R.ravel()))
        object.__setattr__(self, "origin", tuple(float(v) for v in finite_array(self.origin, "ground frame origin",
                                                                                  (3,))))

    @classmethod
    def of_plane(cls, unit_normal: npt.ArrayLike, point: npt.ArrayLike) -> "GroundFrame":
        """The frame of the plane through ``point`` with the upward normal ``unit_normal`` (n_z > 0); its origin the
        plane's point above (or below) the world's origin. The plane z = 0 gives the world frame exactly."""
        n = _unit(finite_array(unit_normal, "plane normal", (3,)))
        p = finite_array(point, "plane point", (3,))
        if not n[2] > 0:
            raise InputError(f"a ground plane's normal must point up (n_z > 0), got {n.tolist()}")
        if n[0] == 0.0 and n[1] == 0.0:
            x = np.array([1.0, 0.0, 0.0])
        else:
            ex = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
            x = _unit(ex - (ex @ n) * n)
        R = np.column_stack([x, np.cross(n, x), n])
        origin = np.array([0.0, 0.0, float(n @ p) / n[2]])
        return cls(tuple(R.ravel()), tuple(origin))

    @property
    def matrix(self) -> np.ndarray:
        """The frame's world pose (4, 4)."""
        T = np.eye(4)
        T[:3, :3] = np.reshape(self.rotation, (3, 3))
        T[:3, 3] = self.origin
        return T

    @property
    def is_world(self) -> bool:
        """Whether this is the world frame (flat ground at z = 0)."""
        return self == WORLD_FRAME

    @property
    def gravity(self) -> np.ndarray:
        """g (3,) m/s^2 in this frame: the world's (0, 0, -GRAVITY) turned into it."""
        if self.is_world:
            return np.array(WORLD_GRAVITY)
        return np.reshape(self.rotation, (3, 3)).T @ np.array(WORLD_GRAVITY)

    @property
    def slope_deg(self) -> float:
        """The plane's angle to the horizontal (degrees)."""
        return math.degrees(math.acos(min(1.0, self.rotation[8])))

    def to_ground(self, points: npt.ArrayLike) -> np.ndarray:
        """World points (..., 3) in this frame."""
        R = np.reshape(self.rotation, (3, 3))
        return (np.asarray(points, float) - np.array(self.origin)) @ R

    def to_world(self, points: npt.ArrayLike) -> np.ndarray:
        """Points (..., 3) of this frame in the world."""
        R = np.reshape(self.rotation, (3, 3))
        return np.asarray(points, float) @ R.T + np.array(self.origin)

    def direction_to_ground(self, directions: npt.ArrayLike) -> np.ndarray:
        """World directions (..., 3) in this frame."""
        return np.asarray(directions, float) @ np.reshape(self.rotation, (3, 3))

    def direction_to_world(self, directions: npt.ArrayLike) -> np.ndarray:
        """Directions (..., 3) of this frame in the world."""
        return np.asarray(directions, float) @ np.reshape(self.rotation, (3, 3)).T


#: The world frame: the ground frame of flat ground.
WORLD_FRAME = GroundFrame()


@dataclass(frozen=True, repr=False)
class BasePlacement:
    """Where the base lies on the ground: the body frame (:attr:`~snakehead.model.robot.SnakeRobot.body_in_root`; the root link's frame
    for snakes written along x) at planar position (x, y), turned by ``yaw``.

    x, y in m, yaw in rad about z, in the ground frame ``ground`` (the world frame on flat ground, the default).
    The root frame's height is the robot's (:attr:`~snakehead.model.robot.SnakeRobot.body_axis_height`: the base's shapes rest on the
    ground), so a placement fits any robot: ``robot.root_pose(base)`` is the 4x4 pose in the ground frame,
    ``ground.matrix @ robot.root_pose(base)`` in the world. The default puts the root frame (the tail end) at the
    origin with the body along +x.
    """

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0
    ground: GroundFrame = WORLD_FRAME

    def __post_init__(self) -> None:
        finite_array([self.x, self.y, self.yaw], "base placement (x, y, yaw)", (3,))
        for name in ("x", "y", "yaw"):
            object.__setattr__(self, name, float(getattr(self, name)))
        if not isinstance(self.ground, GroundFrame):
            raise InputError(f"a base placement's ground must be a GroundFrame, got {type(self.ground).__name__}")

    def __repr__(self) -> str:  # the ground named only off flat ground
        ground = "" if self.ground.is_world else f", ground={self.ground!r}"
        return f"BasePlacement(x={self.x!r}, y={self.y!r}, yaw={self.yaw!r}{ground})"

    def matrix(self, height: float) -> np.ndarray:
        """Pose (4, 4) in the ground frame of the root frame with its origin ``height`` m above the ground."""
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        T = np.eye(4)
        T[:2, :2] = [[c, -s], [s, c]]
        T[:3, 3] = (self.x, self.y, float(height))
        return T

    def moved(self, x: float, y: float, yaw: float) -> "BasePlacement":
        """The placement at (x, y, yaw) on the same ground."""
        return BasePlacement(x, y, yaw, self.ground)

    @property
    def gravity(self) -> np.ndarray:
        """g (3,) m/s^2 in the ground frame (:attr:`GroundFrame.gravity`)."""
        return self.ground.gravity

    @property
    def gravity_across(self) -> float:
        """g's part across the ground (m/s^2, > 0): GRAVITY on flat ground, GRAVITY cos(slope) on a slope."""
        return GRAVITY if self.on_flat_ground else float(-self.gravity[2])

    def below_along_gravity(self, points: np.ndarray) -> np.ndarray:
        """The points (..., 2) m of the ground plane z = 0 below ``points`` (..., 3) along gravity: their (x, y) on
        flat ground (the same array's columns), shifted by z g_xy / -g_z on a slope, where the weight leans. Static
        stability asks for the CoM's such point inside the support polygon."""
        if self.on_flat_ground:
            return points[..., :2]
        g = self.gravity
        return points[..., :2] + points[..., 2:3] * (g[:2] / -g[2])

    @property
    def on_flat_ground(self) -> bool:
        """Whether the ground frame is the world's (gravity along -z)."""
        return self.ground.is_world
