"""`SnakeRobot`: the whole snake from its URDF, its three parts, and whole-body kinematics.

This is the one place that knows how the body divides into base, neck and head (paper, Section 2 and
DESIGN.md). Everything else asks it.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ._validate import finite_array, joint_vector
from .chain import Chain

#: Height of the body axis above the ground when a module lies flat (half the 0.043 m section).
BODY_AXIS_HEIGHT = 0.0215


def default_urdf_path() -> Path:
    """Path of the shipped ``snake16.urdf`` (package data; the source tree's copy when run in place)."""
    packaged = Path(__file__).with_name("urdf") / "snake16.urdf"
    if packaged.exists():
        return packaged
    in_tree = Path(__file__).resolve().parents[2] / "urdf" / "snake16.urdf"
    if in_tree.exists():
        return in_tree
    raise FileNotFoundError("snake16.urdf is neither installed with the package nor in the source tree")


@dataclass(frozen=True)
class BasePlacement:
    """Where the base lies on the ground: the tail link's frame at (x, y, BODY_AXIS_HEIGHT), yawed.

    x, y in m (world), yaw in rad about the world z-axis. The default puts the tail at the origin with the
    body initially pointing along world +x.
    """

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0

    def __post_init__(self):
        finite_array([self.x, self.y, self.yaw], "base placement (x, y, yaw)", (3,))

    def matrix(self) -> np.ndarray:
        """World pose of the root link's frame, (4, 4)."""
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        T = np.eye(4)
        T[:2, :2] = [[c, -s], [s, c]]
        T[:3, 3] = (self.x, self.y, BODY_AXIS_HEIGHT)
        return T


@dataclass(frozen=True)
class RobotParts:
    """How the joint vector splits into the paper's parts, and the frames that bound them.

    Joint ranges are Python slices into the whole-body joint vector (chain order, 0-based).
    """

    base: slice
    neck: slice
    head: slice
    root_link: str
    base_end: str  # P0: end frame of the base part
    neck_end: str  # B0: end frame of the neck part = base frame of the head part
    head_tip: str  # head link frame; its x-axis is the head's direction
    head6_root: str  # base of the 6-DOF head variant (Section 2.2)


SNAKE16_PARTS = RobotParts(
    base=slice(0, 7), neck=slice(7, 9), head=slice(9, 16),
    root_link="link_0", base_end="base_end", neck_end="neck_end", head_tip="head_tip", head6_root="link_10",
)


class SnakeRobot:
    """A snake robot: whole-body chain (root link to head tip), its parts, mass data and world placement."""

    def __init__(self, urdf: str | os.PathLike, parts: RobotParts = SNAKE16_PARTS):
        self.urdf = os.fspath(urdf) if isinstance(urdf, os.PathLike) else urdf
        self.parts = parts
        self.body = Chain.from_urdf(self.urdf, parts.root_link, parts.head_tip)
        n = self.body.n_joints
        for name in ("base", "neck", "head"):
            sl: slice = getattr(parts, name)
            if not (0 <= sl.start < sl.stop <= n):
                raise ValueError(f"the {name} part's joints {sl.start}..{sl.stop - 1} do not fit {n} joints")
        for name in (parts.base_end, parts.neck_end):
            self.body.link_index(name)
        self._chains: dict[tuple[str, str], Chain] = {}

    @classmethod
    def default(cls) -> "SnakeRobot":
        """The shipped 16-joint robot of the paper (urdf/snake16.urdf)."""
        return cls(default_urdf_path(), SNAKE16_PARTS)

    # --- parts -------------------------------------------------------------------------------
    @property
    def n_joints(self) -> int:
        return self.body.n_joints

    def sub_chain(self, base: str, tip: str) -> Chain:
        """The chain between two frames of the body (cached; chains are immutable)."""
        key = (base, tip)
        if key not in self._chains:
            self._chains[key] = Chain.from_urdf(self.urdf, base, tip)
        return self._chains[key]

    @property
    def head_chain(self) -> Chain:
        """The head part, neck_end -> head_tip (7 DOF on the default robot)."""
        return self.sub_chain(self.parts.neck_end, self.parts.head_tip)

    @property
    def head6_chain(self) -> Chain:
        """The 6-DOF head variant of Section 2.2 (link_10 -> head_tip on the default robot)."""
        return self.sub_chain(self.parts.head6_root, self.parts.head_tip)

    @property
    def neck_chain(self) -> Chain:
        """The neck part, base_end (P0) -> neck_end (B0)."""
        return self.sub_chain(self.parts.base_end, self.parts.neck_end)

    @property
    def lower(self) -> np.ndarray:
        return self.body.lower

    @property
    def upper(self) -> np.ndarray:
        return self.body.upper

    @property
    def link_names(self) -> list[str]:
        """Every frame of the body in chain order: links and the marker frames between them."""
        return self.body.link_names

    # --- mass and geometry (per entry of link_names) --------------------------------------------
    @property
    def masses(self) -> np.ndarray:
        """(n_links,) kg."""
        return self.body.model.link_masses

    @property
    def total_mass(self) -> float:
        return float(self.masses.sum())

    @property
    def coms(self) -> np.ndarray:
        """(n_links, 3) centre of mass of each link in its own frame (m)."""
        return self.body.model.link_coms

    @property
    def inertias(self) -> np.ndarray:
        """(n_links, 3, 3) inertia about each link's centre of mass, link-frame axes (kg m^2)."""
        return self.body.model.link_inertias

    @property
    def box_sizes(self) -> np.ndarray:
        """(n_links, 3) collision box extents (m); zeros for links without a box (marker frames)."""
        return self.body.model.link_box_sizes

    @property
    def box_origins(self) -> np.ndarray:
        """(n_links, 4, 4) pose of each collision box's centre in its link frame."""
        return self.body.model.link_box_origins

    # --- whole-body kinematics -----------------------------------------------------------------
    def frames(self, q, base: BasePlacement | None = None) -> np.ndarray:
        """World poses of every frame in ``link_names`` at joint vector ``q`` (16,): (n_links, 4, 4)."""
        q = joint_vector(q, self.n_joints)
        return self._world(base) @ self.body.fk_all(q)

    def frames_many(self, qs, base: BasePlacement | None = None) -> np.ndarray:
        """``frames`` along a trajectory: qs (T, 16) -> (T, n_links, 4, 4)."""
        return self._world(base) @ self.body.fk_all_many(qs)

    def frame(self, q, name: str, base: BasePlacement | None = None) -> np.ndarray:
        """World pose (4, 4) of one named frame (a link or a marker)."""
        k = self.body.link_index(name)
        return self.frames(q, base)[k]

    def head_pose(self, q, base: BasePlacement | None = None) -> np.ndarray:
        return self.frame(q, self.parts.head_tip, base)

    @staticmethod
    def _world(base: BasePlacement | None) -> np.ndarray:
        return as_base(base).matrix()

    def __repr__(self) -> str:
        return f"SnakeRobot({self.urdf!r}, {self.n_joints} joints)"


def as_robot(robot) -> SnakeRobot:
    """``robot`` itself if it is a SnakeRobot, else TypeError (the check every planning function makes)."""
    if not isinstance(robot, SnakeRobot):
        raise TypeError(f"robot must be a SnakeRobot, got {type(robot).__name__}")
    return robot


def as_base(base) -> BasePlacement:
    """``base`` if it is a BasePlacement, the default placement for None, else TypeError."""
    if base is None:
        return BasePlacement()
    if not isinstance(base, BasePlacement):
        raise TypeError(f"base must be a BasePlacement or None, got {type(base).__name__}")
    return base
