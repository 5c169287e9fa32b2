"""The ground support of the path's configurations, as the retiming's ZMP constraint and its check read it: each
support polygon of the links on the ground (``stability.support_polygons(..., contact="ground")``) as edges
n . p >= d, the centre of mass, its static margin, and the margin the ZMP must keep there (:func:`required_margins`).

Where the centre of mass itself is closer than twice the ZMP margin to the polygon's edge (a barely stable path),
the ZMP is asked to keep less: at rest the ZMP is the CoM's projection, so no motion can do better there.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np
import numpy.typing as npt

from .._errors import Infeasible
from ..dynamics import stability
from ..model.robot import BasePlacement, SnakeRobot

__all__ = ["ZMP_DYNAMIC_ROOM", "Support", "required_margins"]

#: Where the CoM itself is less than 2 ZMP_MARGIN inside the support polygon, the ZMP must keep ZMP_MARGIN while the
#: CoM keeps this much more (m) of room for the motion's dynamic terms, or else half the CoM's margin.
ZMP_DYNAMIC_ROOM = 0.002


@dataclass(frozen=True)
class Support:
    """The ground support of configurations q (N, n), computed once: each polygon's edges (padded to one count by
    repeating the first) as inward unit normals (N, E, 2) and offsets d (N, E) (inside: n . p >= d); the centre of
    mass (N, 3), on a slope moved along gravity to the ground point below it at its own height (so that Eqs. 39-40
    with M g's part across the ground give the slope's ZMP: ``BasePlacement.below_along_gravity``); its static
    margin (N,) m; the margin (N,) m the ZMP must keep there (:func:`required_margins`); the weight M g (N, 3) N in
    the ground frame (the same at every configuration: (0, 0, -M GRAVITY) on flat ground)."""

    normal: np.ndarray
    offset: np.ndarray
    com: np.ndarray
    static: np.ndarray
    required: np.ndarray
    weight: np.ndarray

    @classmethod
    def of(cls, robot: SnakeRobot, q: np.ndarray, base: BasePlacement, zmp_margin: float,
           frames: np.ndarray | None = None) -> "Support":
        """``frames``: the world frames of q, when the caller has them."""
        frames = robot.frames_many(q, base) if frames is None else frames
        V, count = stability.support_polygons(robot, q, base, contact="ground", frames=frames)
        if np.any(count < 3):
            k = int(np.argmax(count < 3))
            raise Infeasible(f"the links on the ground span no polygon at path point {k} ({count[k]} distinct "
                             "contact points): the body cannot stand there")
        h = np.arange(V.shape[1])[None, :]
        start = np.where(h < count[:, None], h, 0)  # padding repeats the first edge
        stop = np.where(start + 1 < count[:, None], start + 1, 0)
        a = np.take_along_axis(V, start[..., None], axis=1)
        e = np.take_along_axis(V, stop[..., None], axis=1) - a
        normal = np.stack([-e[..., 1], e[..., 0]], axis=-1) / np.linalg.norm(e, axis=-1, keepdims=True)  # inside
        offset = (normal * a).sum(-1)
        com = stability.center_of_mass(robot, q, base, frames=frames)
        if not base.on_flat_ground:
            com = np.column_stack([base.below_along_gravity(com), com[:, 2]])
        static = ((normal * com[:, None, :2]).sum(-1) - offset).min(axis=1)
        weight = np.broadcast_to(robot.total_mass * base.gravity, (len(com), 3)).copy()
        return cls(normal, offset, com, static, required_margins(static, zmp_margin), weight)

    def take(self, index: np.ndarray) -> "Support":
        """The support of the configurations ``index`` (an index array into the N)."""
        return Support(*(getattr(self, f.name)[index] for f in fields(self)))

    def joined(self, other: "Support") -> "Support":
        """Both supports, one after the other; the polygons padded to one edge count (repeating the first edge)."""
        edges = max(self.offset.shape[1], other.offset.shape[1])
        a, b = self.padded(edges), other.padded(edges)
        return Support(*(np.concatenate([getattr(a, f.name), getattr(b, f.name)]) for f in fields(self)))

    def padded(self, edges: int) -> "Support":
        """The same support with each polygon padded to ``edges`` edges by repeating its first edge."""
        extra = edges - self.offset.shape[1]
        if extra == 0:
            return self
        pad = np.zeros(self.offset.shape[1] + extra, int)
        pad[:self.offset.shape[1]] = np.arange(self.offset.shape[1])
        return replace(self, normal=self.normal[:, pad], offset=self.offset[:, pad])

    def margins(self, xy: np.ndarray) -> np.ndarray:
        """Signed distance (m) of points xy (N, 2) inside each polygon: exact inside (the nearest edge), negative
        outside (by the edge line crossed most)."""
        return ((self.normal * xy[:, None, :]).sum(-1) - self.offset).min(axis=1)


def required_margins(static: npt.ArrayLike, zmp_margin: float) -> np.ndarray:
    """The margin (m) the ZMP must keep inside the support polygon where the CoM keeps ``static`` m:
    ``zmp_margin`` where the CoM leaves ZMP_DYNAMIC_ROOM more, else the larger of half the CoM's own margin and
    the CoM's margin less ZMP_DYNAMIC_ROOM. Where the time-optimal motion keeps ``zmp_margin`` anyway, the
    constraint is inactive and the motion the same."""
    static = np.asarray(static, float)
    return np.minimum(zmp_margin, np.maximum(0.5 * static, static - ZMP_DYNAMIC_ROOM))
