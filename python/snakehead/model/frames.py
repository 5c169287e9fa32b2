"""Forward kinematics of a robot's frames in the world, their Jacobians, and the poses of its root and body frames
when its base lies on the ground at a :class:`~snakehead.model.robot.BasePlacement`.

Free functions of a :class:`~snakehead.model.robot.SnakeRobot` (the model) and a placement already checked
(:func:`~snakehead.model.robot.as_base`); the robot's methods of the same names call them.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from .._errors import InputError, invariant
from .._validate import finite_array, joint_vector
from .description import origin_matrix

if TYPE_CHECKING:  # robot.py delegates to this module
    from .robot import BasePlacement, SnakeRobot

__all__ = ["body_pose", "root_pose", "forward_kinematics", "forward_kinematics_many", "forward_kinematics_unchecked",
           "frame_placement", "joint_axes_world", "point_jacobians", "description_root_on_body",
           "description_root_pose"]


def body_pose(robot: SnakeRobot, base: BasePlacement) -> np.ndarray:
    """World pose (4, 4) of the body frame when the base lies on the ground at ``base``."""
    return base.matrix(robot.body_axis_height)


def root_pose(robot: SnakeRobot, base: BasePlacement) -> np.ndarray:
    """World pose (4, 4) of the root frame when the base lies on the ground at ``base``."""
    return body_pose(robot, base) @ robot.root_in_body


def forward_kinematics(robot: SnakeRobot, q: npt.ArrayLike, base: BasePlacement) -> np.ndarray:
    """World poses (n_links, 4, 4) of every frame in ``link_names`` at joint vector ``q`` (n,)."""
    q = joint_vector(q, robot.n_joints)
    return root_pose(robot, base) @ robot.body.fk_all(q)


def forward_kinematics_many(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement) -> np.ndarray:
    """:func:`forward_kinematics` along a trajectory: qs (T, n) -> (T, n_links, 4, 4)."""
    return robot.body.fk_all_many(qs, root_pose(robot, base))


def forward_kinematics_unchecked(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement) -> np.ndarray:
    """:func:`forward_kinematics_many` of joint vectors already checked where they entered (float64 (T, n),
    finite): the core's batched forward kinematics without checking them again (the library's inner loops, e.g.
    the whole-body solve's checks of its candidates)."""
    return robot.body.model.fk_all_many(np.ascontiguousarray(qs, dtype=np.float64), root_pose(robot, base))


def frame_placement(robot: SnakeRobot, q: npt.ArrayLike, name: str, base: BasePlacement) -> np.ndarray:
    """World pose (4, 4) of one named frame (a link or a marker) at ``q`` (n,)."""
    k = robot.link_index(name)
    return forward_kinematics(robot, q, base)[k]


def joint_axes_world(robot: SnakeRobot, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World axes (n, 3) and origins (n, 3) of the joints, from the world frames (n_links, 4, 4) of one
    configuration (:func:`forward_kinematics`)."""
    child = np.asarray(robot.body.model.joint_child_links)
    local = np.asarray(robot.body.model.joint_axes, float)
    return np.einsum("jik,jk->ji", frames[child, :3, :3], local), frames[child, :3, 3]


def point_jacobians(robot: SnakeRobot, frames: np.ndarray, points: npt.ArrayLike, links: Any) -> np.ndarray:
    """d(point)/d(q, x, y, yaw) of world points (P, 3) rigidly attached to ``links`` (indices into link_names),
    for the configuration of ``frames`` (n_links, 4, 4): (P, 3, n + 3). The last three columns are the base
    placement's x, y and yaw.

    A revolute joint j moves the points distal to it by a_j x (p - o_j) (a_j its world axis, o_j its origin);
    the base's placement moves every point by (1, 0, 0), (0, 1, 0) and e_z x (p - root).
    """
    points = np.asarray(points, float).reshape(-1, 3)
    a, o = joint_axes_world(robot, frames)
    n = len(a)
    child = np.asarray(robot.body.model.joint_child_links)
    J = np.zeros((len(points), 3, n + 3))
    moved = child[None, :] <= np.asarray(links).reshape(-1)[:, None]  # (P, n): joint j moves point's link
    r = points[:, None, :] - o[None, :, :]  # (P, n, 3)
    J[:, 0, :n] = (a[None, :, 1] * r[..., 2] - a[None, :, 2] * r[..., 1]) * moved
    J[:, 1, :n] = (a[None, :, 2] * r[..., 0] - a[None, :, 0] * r[..., 2]) * moved
    J[:, 2, :n] = (a[None, :, 0] * r[..., 1] - a[None, :, 1] * r[..., 0]) * moved
    root = (frames[0] @ robot.body_in_root)[:3, 3]  # the placement's pivot: the body frame's origin
    J[:, 0, n] = 1.0
    J[:, 1, n + 1] = 1.0
    J[:, 0, n + 2] = -(points[:, 1] - root[1])  # e_z x (p - root)
    J[:, 1, n + 2] = points[:, 0] - root[0]
    return J


def description_root_on_body(robot: SnakeRobot) -> tuple[int, np.ndarray]:
    """(k, F): the description's root link (:attr:`SnakeRobot.description_root`) is F (4, 4, read-only) in the
    body frame ``link_names[k]``, the nearest body frame above it in :attr:`SnakeRobot.urdf_text` (every link of
    the description keeps its frame there; the joints off the body are fixed there, moving branch joints at the
    value they are held at)."""
    up: dict[str, tuple[ET.Element, str]] = {}
    for joint in ET.fromstring(robot.urdf_text).findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is not None and child is not None:
            up[child.get("link", "")] = (joint, parent.get("link", ""))
    on_body = set(robot.link_names)
    link, F = robot.description_root, np.eye(4)
    while link not in on_body:
        invariant(link in up, f"the description's root {robot.description_root!r} is not below the body's root "
                              f"{robot.parts.root!r} in the internal URDF")
        joint, link = up[link]
        invariant(joint.get("type") == "fixed", f"joint {joint.get('name')!r} off the body is not fixed in the "
                                                "internal URDF")
        F = origin_matrix(joint, f"joint {joint.get('name')!r}") @ F
    F.setflags(write=False)
    return robot.link_index(link), F


def description_root_pose(robot: SnakeRobot, root_pose: npt.ArrayLike, q: npt.ArrayLike | None = None,
                          on_body: tuple[int, np.ndarray] | None = None) -> np.ndarray:
    """World pose (4, 4) of the description's root link (:attr:`SnakeRobot.description_root`) when the root frame
    (``parts.root``) has the world pose ``root_pose`` (4, 4) and the body's joints are at ``q`` (the planner's
    angles (n,); default 0, the home pose): it moves with the joints when the description's tree starts from the
    head. Along a motion, ``q`` (T, n) with ``root_pose`` (T, 4, 4) or (4, 4) gives (T, 4, 4). ``on_body``:
    :func:`description_root_on_body` of the robot, when the caller keeps it."""
    T = np.asarray(root_pose, dtype=float)
    if T.shape[-2:] != (4, 4) or T.ndim > 3 or not np.isfinite(T).all():
        raise InputError(f"root_pose must be finite (4, 4) or (T, 4, 4), got shape {T.shape}")
    k, F = description_root_on_body(robot) if on_body is None else on_body
    if q is None or np.ndim(q) <= 1:
        q = np.zeros(robot.n_joints) if q is None else joint_vector(q, robot.n_joints)
        return T @ (robot.body.fk_all(q)[k] @ F)
    qs = finite_array(q, "q", (None, robot.n_joints))
    return T @ (robot.body.fk_all_many(qs)[:, k] @ F)
