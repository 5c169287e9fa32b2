"""The body at q = 0, straight along the body frame's x-axis (:func:`.body_frame.body_frame`): where its frames and
joints sit along it, which way each joint turns, how long its links are.

Each joint turns about the body frame's z-axis (:data:`YAW`) or its y-axis (:data:`PITCH`), read within
:data:`.body_frame.AXIS_TOLERANCE_DEG`; the description's true axes are kept (:func:`axis_deviations`).
"""
from __future__ import annotations

import numpy as np

from .chain import Chain

__all__ = ["YAW", "PITCH", "straight_frames", "joint_axes", "joint_kinds", "joint_signs", "axis_deviations",
           "joint_arc_lengths", "link_lengths"]

#: A joint that turns about the body frame's z-axis: it bends the body in the ground plane while the body lies flat.
YAW = "yaw"
#: A joint that turns about the body frame's y-axis: it lifts the body off the ground.
PITCH = "pitch"


def straight_frames(body: Chain, body_in_root: np.ndarray) -> np.ndarray:
    """Every frame (n_links, 4, 4) of ``body`` at q = 0 in the body frame ``body_in_root`` (4, 4; the body along its
    x-axis from the origin, z up); read-only."""
    F = np.linalg.inv(body_in_root) @ body.fk_all(np.zeros(body.n_joints))
    F.setflags(write=False)
    return F


def joint_axes(body: Chain, straight: np.ndarray) -> np.ndarray:
    """(n, 3) each joint's axis in the body frame at q = 0, from the straight frames (:func:`straight_frames`)."""
    child = np.asarray(body.model.joint_child_links)
    local = np.asarray(body.model.joint_axes, float)
    axes = np.einsum("jik,jk->ji", straight[child, :3, :3], local)
    axes.setflags(write=False)
    return axes


def joint_kinds(axes: np.ndarray) -> tuple[str, ...]:
    """Each joint's kind from its axis (n, 3) in the body frame: ``"yaw"`` (axis +-z) or ``"pitch"`` (+-y)."""
    return tuple(YAW if abs(a[2]) > 0.5 else PITCH for a in axes)


def joint_signs(axes: np.ndarray) -> np.ndarray:
    """(n,) +1 where the axis (n, 3) is +z (yaw) or +y (pitch), -1 where it is -z or -y."""
    return np.where(np.where(np.abs(axes[:, 2]) > 0.5, axes[:, 2], axes[:, 1]) > 0, 1.0, -1.0)


def axis_deviations(axes: np.ndarray) -> np.ndarray:
    """(n,) each joint axis's angle (rad) from the nearest of the body frame's y- and z-axes; read-only."""
    a = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    out = np.arccos(np.clip(np.maximum(np.abs(a[:, 1]), np.abs(a[:, 2])), -1.0, 1.0))
    out.setflags(write=False)
    return out


def joint_arc_lengths(body: Chain, straight: np.ndarray) -> np.ndarray:
    """(n,) each joint's distance (m) from the root frame along the straight body: its body arc length."""
    child = np.asarray(body.model.joint_child_links)
    return straight[child, 0, 3] - straight[0, 0, 3]


def link_lengths(straight: np.ndarray) -> np.ndarray:
    """(n_links,) each frame's distance (m) to the next frame along the straight body (0 for the last)."""
    x = straight[:, 0, 3]
    return np.append(np.diff(x), 0.0)
