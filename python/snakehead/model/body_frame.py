"""The body frame of a straight snake and the aligned twins of the frames the planner reads.

At q = 0 a snake lies straight: every frame on one line. :func:`body_frame` finds that line whatever way the
description's link frames turn (modules along x, y or z, a rotated dummy root): x along it towards the head, z up
(the joint-axis direction nearest the root frame's z, then x, then y). :func:`aligned_frames` adds fixed marker
frames ``NAME__aligned`` in line with ``base_end``, ``neck_end``, the neck's lift frame and ``head_tip`` when
those turn another way (x along the body and z up at q = 0; the head tip's x along its ``head_axis``), so that
the planner can read their axes as the paper does.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from .._errors import InputError
from .chain import Chain
from .description import add_fixed_frames

__all__ = ["STRAIGHT_TOLERANCE", "AXIS_TOLERANCE_DEG", "ALIGNED_SUFFIX", "HEAD_AXES", "Straightness", "NotStraight",
           "straightness", "suggest_home", "body_frame", "aligned_frames"]

#: Below this (rad, m) two frames turn and sit alike: a frame within it of the body frame's orientation needs no
#: aligned twin (URDFs write pi/2 as 1.5708: 4e-6 rad off).
STRAIGHT_TOLERANCE = 1e-4

#: How far (deg) a joint axis may be from the body frame's y- or z-axis to count as a pitch or yaw joint. Published
#: descriptions write right angles as 1.57 (0.05 deg off) or drift by a few tenths of a degree in CAD exports;
#: the kinematics keeps the true axes, the planner's yaw/pitch split reads them within this.
AXIS_TOLERANCE_DEG = 1.0

#: The suffix of the aligned twin of a frame.
ALIGNED_SUFFIX = "__aligned"

#: The head frame's axes that may point where the head looks (the robot file's ``head_axis``).
HEAD_AXES = {"x": 0, "y": 1, "z": 2, "-x": 0, "-y": 1, "-z": 2}


@dataclass(frozen=True)
class Straightness:
    """How far the body at q = 0 is from a straight line: the largest side offset of a frame from the fitted line
    (m) and that frame, and the frames out of order along it."""

    offset: float
    frame: str
    out_of_order: tuple[str, ...] = ()


class NotStraight(InputError):
    """The body does not lie straight at the robot's zero (its home pose): the message says where; ``chain`` is
    the body, for :func:`suggest_home`."""

    def __init__(self, message: str, chain: Chain, home: np.ndarray | None = None, max_offset: float = 0.0) -> None:
        super().__init__(message)
        self.chain = chain
        #: How far (m) a frame may lie to the side of the body's line (the base's half-section).
        self.max_offset = max_offset
        #: The home angles (n,) the chain was already turned by (the description's angles = chain's + these).
        self.home = np.zeros(chain.n_joints) if home is None else np.asarray(home, float)


def _body_line(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The line fitted to points p (k, 3) by least squares: a point on it and its unit direction, pointing from
    the first point towards the last."""
    centre = p.mean(axis=0)
    d = np.linalg.svd(p - centre)[2][0] if len(p) > 2 else p[-1] - p[0]
    d = d / np.linalg.norm(d)
    return centre, d if (p[-1] - p[0]) @ d >= 0 else -d


def straightness(body: Chain, q: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, Straightness]:
    """The body's line at ``q`` (default 0): a point on it, its direction (first joint -> head tip) and how far the
    frames are from it. Frames before the first joint (a dummy root, a base link placed elsewhere) are left out."""
    F = body.fk_all(np.zeros(body.n_joints) if q is None else q)
    p = F[:, :3, 3]
    child = np.asarray(body.model.joint_child_links)
    first = int(child[0]) if len(child) else 0
    if not np.linalg.norm(p[-1] - p[first]) > STRAIGHT_TOLERANCE:
        raise InputError("the head tip lies on the first joint at q = 0: the body has no length")
    centre, d = _body_line(p[first:])
    rel = p[first:] - centre
    s = rel @ d
    off = np.linalg.norm(rel - np.outer(s, d), axis=1)
    k = int(np.argmax(off))
    back = tuple(body.link_names[first + i + 1] for i in np.flatnonzero(np.diff(s) < -STRAIGHT_TOLERANCE))
    return centre, d, Straightness(float(off[k]), body.link_names[first + k], back)


def suggest_home(body: Chain) -> np.ndarray:
    """Joint angles (n,) at which the body lies straight, by least squares from q = 0 within the limits: the side
    offsets of the frames from the line through the root (or the first joint) and the head tip, the joint axes
    across it, with a small pull towards 0."""
    child = np.asarray(body.model.joint_child_links)
    first = int(child[0]) if len(child) else 0
    reach = max(body.reach, STRAIGHT_TOLERANCE)

    local = np.asarray(body.model.joint_axes, float)
    # the root link's origin joins the line when it is not on the first joint (a module, not a dummy root)
    start = 0 if np.linalg.norm(body.fk_all(np.zeros(body.n_joints))[first, :3, 3]) > STRAIGHT_TOLERANCE else first

    def residuals(q: np.ndarray) -> np.ndarray:
        F = body.fk_all(q)
        p = F[start:, :3, 3]
        d = p[-1] - p[0]
        d = d / max(np.linalg.norm(d), STRAIGHT_TOLERANCE)
        rel = p - p[0]
        across = np.einsum("jik,jk->ji", F[child, :3, :3], local) @ d  # each joint axis across the line
        return np.concatenate([(rel - np.outer(rel @ d, d)).ravel() / reach, across, 1e-3 * q])

    lo = np.where(np.isfinite(body.lower), body.lower, -np.pi)
    hi = np.where(np.isfinite(body.upper), body.upper, np.pi)
    return least_squares(residuals, np.clip(np.zeros(body.n_joints), lo, hi), bounds=(lo, hi), x_scale=1.0).x


def body_frame(body: Chain) -> np.ndarray:
    """The body frame (4, 4) in the root frame: x along the line fitted to the frames at q = 0 (from the first joint
    towards the head tip), z the joint-axis direction nearest the root frame's z (then x, then y), origin the
    root's projection on the line. How straight the body is: :func:`straightness` (SnakeRobot checks it against
    the body's section). InputError for joints that are not revolute."""
    if set(body.joint_types) - {"revolute"}:
        raise InputError(f"a snake robot's joints are revolute with limits; this body has "
                         f"{sorted(set(body.joint_types))} joints (give continuous joints limits in the robot file's "
                         "[limits] table)")
    F = body.fk_all(np.zeros(body.n_joints))
    p = F[:, :3, 3]
    child = np.asarray(body.model.joint_child_links)
    centre, d, _ = straightness(body)
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
    T[:3, 3] = centre + ((p[0] - centre) @ d) * d  # the root's projection on the line
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
        xml = text if text.lstrip().startswith("<") else Path(text).read_text(encoding="utf-8")
        text = add_fixed_frames(xml, twins)
    return out, text
