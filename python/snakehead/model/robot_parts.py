"""The body's parts (paper, Section 2): which joints and links make the base, the neck and the head, and the part of
the neck that lifts.

The joint ranges come from the frames that bound the parts (:func:`part_slices`); the link sets and the lifting
joints are read from a built :class:`~snakehead.model.robot.SnakeRobot`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Mapping

import numpy as np

from .._errors import InputError
from .chain import Chain
from .straight_body import PITCH

if TYPE_CHECKING:  # robot.py builds on this module
    from .robot import SnakeRobot

__all__ = ["RobotParts", "joints_before", "part_slices", "part_links", "part_bodies", "lift_joints",
           "lift_frame"]

@dataclass(frozen=True)
class RobotParts:
    """How the joint vector splits into the paper's parts, and the frames that bound them.

    Joint ranges are Python slices into the whole-body joint vector (chain order, 0-based).
    """

    base: slice
    neck: slice
    head: slice
    root: str
    base_end: str  # P0: end frame of the base part
    neck_end: str  # B0: end frame of the neck part = base frame of the head part
    head_tip: str  # head link frame; its x-axis is the head's direction


def joints_before(body: Chain, link_index: int) -> int:
    """How many joints lie between the root and the frame ``link_names[link_index]``."""
    child = np.asarray(body.model.joint_child_links)
    return int(np.sum(child <= link_index))


def part_slices(body: Chain, root: str, names: Mapping[str, str]) -> list[slice]:
    """The joint slices of the base, neck and head parts (InputError for frames missing or out of order, or a
    part without joints)."""
    link_names = body.link_names
    order = [("root", root)] + [(key, names[key]) for key in ("base_end", "neck_end", "head_tip")]
    for key, name in order:
        if name not in link_names:
            raise InputError(f"{key} {name!r} is not a frame on the chain from the root {root!r} to the head tip "
                             f"{names['head_tip']!r} (frames: {', '.join(link_names)})")
    idx = [link_names.index(name) for _, name in order]
    slices = []
    for (ka, na), (kb, nb), a, b in zip(order, order[1:], idx, idx[1:]):
        if not a < b:
            raise InputError(f"frames out of order: {kb} {nb!r} must come after {ka} {na!r} along the body "
                             "(root -> base_end -> neck_end -> head_tip)")
        start, stop = joints_before(body, a), joints_before(body, b)
        part = {"base_end": "base", "neck_end": "neck", "head_tip": "head"}[kb]
        if stop <= start:
            raise InputError(f"the {part} part ({ka} {na!r} -> {kb} {nb!r}) has no joint")
        slices.append(slice(start, stop))
    return slices


def part_links(robot: SnakeRobot, start: str | None, stop: str | None) -> np.ndarray:
    """Indices (link_names) of the frames from ``start`` up to ``stop`` (None: the first frame, past the last)."""
    n = len(robot.link_names)
    a = 0 if start is None else robot.link_index(start)
    b = n if stop is None else robot.link_index(stop)
    return np.arange(a, b)


def part_bodies(robot: SnakeRobot, links: np.ndarray) -> np.ndarray:
    """The entries of ``links`` that carry a body: a mass or collision shapes."""
    keep = (robot.masses[links] > 0) | np.isin(links, robot.shaped_links)
    return links[keep]


def lift_joints(robot: SnakeRobot) -> slice:
    """The neck joints that lift and aim it: from the neck's first pitch joint to the neck's end.

    A neck that begins with yaw joints has links before its first pitch joint that cannot leave the ground (no joint
    lifts them): turning them would drag them, loaded by the lifted body, across the ground and push the base. They
    are held where the initial configuration puts them, like the base's joints.
    """
    neck = robot.parts.neck
    first = next((j for j in range(neck.start, neck.stop) if robot.joint_kinds[j] == PITCH), neck.stop)
    return slice(first, neck.stop)


def lift_frame(robot: SnakeRobot) -> str:
    """The frame just before the neck's first pitch joint (:attr:`SnakeRobot.lift_frame`)."""
    start = robot.lift_joints.start
    if start == robot.parts.neck.stop:
        return robot.parts.neck_end
    child = int(robot.body.model.joint_child_links[start])
    return robot.link_names[child - 1]
