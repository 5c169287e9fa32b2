"""The body frame of a straight snake and the aligned twins of the frames the planner reads.

At q = 0 a snake lies straight: every frame on one line. :func:`body_frame` finds that line whatever way the
description's link frames turn (modules along x, y or z, a rotated dummy root): x along it towards the head, z up
(the joint-axis direction nearest the root frame's z, then x, then y). :func:`aligned_frames` adds fixed marker
frames ``NAME__aligned`` in line with ``base_end``, ``neck_end``, the neck's lift frame and ``head_tip`` when
those turn another way (x along the body and z up at q = 0; the head tip's x along its ``head_axis``), so that
the planner can read their axes as the paper does.
"""
from __future__ import annotations

import numpy as np

from .._errors import InputError
from .chain import Chain
from .description import add_fixed_frames

from pathlib import Path

#: How far (rad) a joint axis may be from the body frame's y- or z-axis, and how far (m) a frame may be from the
#: body axis at q = 0, for the body to count as a straight snake with yaw and pitch joints (URDFs write pi/2 as
#: 1.5708: 4e-6 rad off).
STRAIGHT_TOLERANCE = 1e-4

#: The suffix of the aligned twin of a frame.
ALIGNED_SUFFIX = "__aligned"

#: The head frame's axes that may point where the head looks (the robot file's ``head_axis``).
HEAD_AXES = {"x": 0, "y": 1, "z": 2, "-x": 0, "-y": 1, "-z": 2}


def body_frame(body: Chain) -> np.ndarray:
    """The body frame (4, 4) in the root frame: x along the straight body's line (from the first joint to the head
    tip) towards the head, z the joint-axis direction nearest the root frame's z (then x, then y), origin the
    root's projection on the line.
    InputError when the body is not straight at q = 0 or a joint axis is not across it."""
    if set(body.joint_types) - {"revolute"}:
        raise InputError(f"a snake robot's joints are revolute with limits; this body has "
                         f"{sorted(set(body.joint_types))} joints (give continuous joints limits in the robot file's "
                         "[limits] table)")
    F = body.fk_all(np.zeros(body.n_joints))
    p = F[:, :3, 3]
    child = np.asarray(body.model.joint_child_links)
    # the line runs from the first joint (its link's origin) to the head tip; frames before the first joint (a
    # dummy root, a base link placed elsewhere) may lie off it
    first = int(child[0]) if len(child) else 0
    d = p[-1] - p[first]
    if not np.linalg.norm(d) > STRAIGHT_TOLERANCE:
        raise InputError("the head tip lies on the first joint at q = 0: the body has no length")
    d /= np.linalg.norm(d)
    s = (p[first:] - p[first]) @ d
    off = np.linalg.norm((p[first:] - p[first]) - np.outer(s, d), axis=1)
    if off.max() > STRAIGHT_TOLERANCE or np.any(np.diff(s) < -STRAIGHT_TOLERANCE):
        k = int(np.argmax(off)) if off.max() > STRAIGHT_TOLERANCE else int(np.argmin(np.diff(s))) + 1
        raise InputError(f"the body does not lie straight at q = 0: frame {body.link_names[first + k]!r} is "
                         f"{1000 * off[k]:.2f} mm off the line from the first joint to the head tip (or out of "
                         "order); a snake's frames lie on one line, in order, when its joints are at zero")
    axes = np.einsum("jik,jk->ji", F[child, :3, :3], np.asarray(body.model.joint_axes, float))
    across = axes - np.outer(axes @ d, d)
    up = None
    for hint in np.eye(3)[[2, 0, 1]]:
        h = hint - (hint @ d) * d
        if np.linalg.norm(h) < 0.5 or len(axes) == 0:
            continue
        k = int(np.argmax(np.abs(across @ h)))
        if abs(across[k] @ h) > 0.5 * np.linalg.norm(h):
            up = np.sign(across[k] @ h) * across[k] / np.linalg.norm(across[k])
            break
    if up is None:
        up = np.eye(3)[2] - d[2] * d
        up = up / np.linalg.norm(up) if np.linalg.norm(up) > 0.5 else np.cross(d, np.eye(3)[1])
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2] = d, np.cross(up, d), up
    T[:3, 3] = p[first] - ((p[first] - p[0]) @ d) * d  # the root's projection on the line
    return T


def _lift_frame_name(body: Chain, F: np.ndarray, neck: slice) -> str | None:
    """The frame just before the neck's first pitch joint (``SnakeRobot.lift_frame``), from frames F at q = 0 in
    the body frame; None when the neck has no pitch joint."""
    child = np.asarray(body.model.joint_child_links)
    local = np.asarray(body.model.joint_axes, float)
    for j in range(neck.start, neck.stop):
        axis = F[child[j], :3, :3] @ local[j]
        if abs(axis[2]) <= 0.5:  # pitch: across the body and horizontal
            return body.link_names[child[j] - 1]
    return None


def _aligned_rotation(R_frame: np.ndarray, axis: str | None) -> np.ndarray:
    """The rotation (in the frame R_frame's coordinates) of its aligned twin: the body frame's orientation at
    q = 0 (R_frame is the frame's orientation in the body frame); with ``axis``, the twin's x is that axis of
    the frame and its z the body's up made perpendicular to it."""
    if axis is None:
        return R_frame.T
    sign = -1.0 if axis.startswith("-") else 1.0
    x = sign * np.eye(3)[HEAD_AXES[axis]]
    up = R_frame.T @ np.array([0.0, 0.0, 1.0])  # the body's up in the frame's coordinates
    z = up - (up @ x) * x
    if np.linalg.norm(z) < 1e-6:  # looking straight up or down: keep the body's x as the twin's -z... any normal
        z = R_frame.T @ np.array([-1.0, 0.0, 0.0]) * np.sign(up @ x)
        z = z - (z @ x) * x
    z /= np.linalg.norm(z)
    return np.stack([x, np.cross(z, x), z], axis=1)


def aligned_frames(text: str, body: Chain, body_in_root: np.ndarray, parts: list[slice], names: dict[str, str],
                    head_axis: str) -> tuple[dict[str, str], str]:
    """The frames the planner uses for base_end, neck_end and head_tip (the URDF's where they are aligned, else
    twins added to the text) and the text."""
    F = np.linalg.inv(body_in_root) @ body.fk_all(np.zeros(body.n_joints))  # frames in the body frame at q = 0
    out = dict(names)
    twins = []
    frames = dict(names)
    lift = _lift_frame_name(body, F, parts[1])
    if lift is not None and lift not in names.values():
        frames["lift_frame"] = lift  # Eqs. 18-22 pivot on it and read its direction
    for key in frames:
        R = F[body.link_index(frames[key]), :3, :3]
        axis = head_axis if key == "head_tip" else None
        Ra = _aligned_rotation(R, axis)
        if np.allclose(Ra, np.eye(3), atol=STRAIGHT_TOLERANCE):
            continue
        out[key] = frames[key] + ALIGNED_SUFFIX
        twins.append((frames[key], out[key], Ra))
    if twins:
        text = add_fixed_frames(text if text.lstrip().startswith("<") else Path(text).read_text(encoding="utf-8"), twins)
    return out, text
