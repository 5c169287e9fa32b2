"""The retiming's stability constraint, linear in the momentum rates w = (dP/dt, dL/dt) (Eqs. 33-34, L about the
world origin): the ZMP (Eqs. 39-40, p_z = 0) inside the ground support polygon by its required margin, the base's
friction, and the ground pushing.

Why the ZMP is a linear constraint: the ZMP lies on the inner side of a polygon edge n . p >= d + m exactly when,
multiplied through by M g + dP_z/dt > 0, n_x (M g c_x - dL_y/dt) + n_y (M g c_y + dL_x/dt) - (d + m)(M g + dP_z/dt)
>= 0 -- linear in w. Along a path q(s), w = a(s) s'' + b(s) s'^2
(:func:`~snakehead.retiming.path_dynamics.momentum_rate_coefficients`): exactly TOPP-RA's form, one row per edge.
Polygons are padded to one edge count by repeating an edge. A snake's base slides when it is pushed, so the
horizontal momentum rate is held within the friction the ground can give it, |dP_xy/dt| <= mu (M g + dP_z/dt), and
the ground must push, M g + dP_z/dt >= :data:`MIN_NORMAL_SHARE` M g.
"""
from __future__ import annotations

import numpy as np

from ..model.physics import GRAVITY
from ..model.robot import SnakeRobot
from .retiming_limits import RetimingLimits
from .support_polygon import Support, required_margins

__all__ = ["MIN_NORMAL_SHARE", "FRICTION_SIDES", "stability_rows", "zmp_rows", "friction_rows"]

#: The ground must push with at least this share of the weight (M g + dP_z/dt >= MIN_NORMAL_SHARE M g).
MIN_NORMAL_SHARE = 0.1
#: Sides of the polygon inscribed in the friction circle |dP_xy/dt| <= mu N (a linear constraint).
FRICTION_SIDES = 8


def stability_rows(robot: SnakeRobot, support: Support, limits: RetimingLimits, extra_margin: float = 0.0
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The stability constraints at N configurations as F w <= g on w = (dP/dt, dL/dt) (N, 6):
    F (N, E + FRICTION_SIDES + 1, 6), g (N, E + FRICTION_SIDES + 1): the ZMP's rows (:func:`zmp_rows`), then the
    friction's and the normal force's (:func:`friction_rows`)."""
    N = support.offset.shape[0]
    weight = support.weight[0] if N else np.array([0.0, 0.0, -robot.total_mass * GRAVITY])
    Mg = float(-weight[2])  # the weight across the ground: M GRAVITY on flat ground
    F_zmp, g_zmp = zmp_rows(Mg, support, limits.zmp_margin, extra_margin)
    F_fr, g_fr = friction_rows(Mg, limits.friction, weight[:2])
    F = np.concatenate([F_zmp, np.broadcast_to(F_fr, (N,) + F_fr.shape)], axis=1)
    g = np.concatenate([g_zmp, np.broadcast_to(g_fr, (N, len(g_fr)))], axis=1)
    return F, g


def zmp_rows(Mg: float, support: Support, zmp_margin: float, extra_margin: float = 0.0
             ) -> tuple[np.ndarray, np.ndarray]:
    """F (N, E, 6), g (N, E): one row per support-polygon edge, the ZMP at least the margin that ``zmp_margin``
    requires (:func:`~snakehead.retiming.support_polygon.required_margins`), plus ``extra_margin`` m (at most 90 % of
    the CoM's own margin), inside it, multiplied through by M g + dP_z/dt. ``Mg``: the weight (N)."""
    N, E = support.offset.shape
    margin = np.minimum(required_margins(support.static, zmp_margin) + extra_margin, 0.9 * support.static)
    off = support.offset + margin[:, None]
    normal = support.normal
    F_zmp = np.zeros((N, E, 6))
    F_zmp[..., 2] = off  # (d + m) dP_z/dt - n_y dL_x/dt + n_x dL_y/dt <= M g (n . c - d - m)
    F_zmp[..., 3] = -normal[..., 1]
    F_zmp[..., 4] = normal[..., 0]
    g_zmp = Mg * ((normal * support.com[:, None, :2]).sum(-1) - off)
    return F_zmp, g_zmp


def friction_rows(Mg: float, friction: float, weight_along: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """F (FRICTION_SIDES + 1, 6), g (FRICTION_SIDES + 1,), the same at every configuration: the polygon inscribed in
    |dP_xy/dt - M g_xy| <= ``friction`` (M g + dP_z/dt), then M g + dP_z/dt >= MIN_NORMAL_SHARE M g. ``Mg``: the
    weight across the ground (N); ``weight_along``: M g_xy (2,) N, its part along a slope (None: flat ground)."""
    theta = 2 * np.pi * np.arange(FRICTION_SIDES) / FRICTION_SIDES
    mu = friction * np.cos(np.pi / FRICTION_SIDES)  # the inscribed polygon's apothem
    F_fr = np.zeros((FRICTION_SIDES + 1, 6))
    F_fr[:-1, 0], F_fr[:-1, 1], F_fr[:-1, 2] = np.cos(theta), np.sin(theta), -mu  # u . dP_xy/dt <= mu N
    F_fr[-1, 2] = -1.0  # -dP_z/dt <= (1 - MIN_NORMAL_SHARE) M g
    g_fr = np.r_[np.full(FRICTION_SIDES, mu * Mg), (1.0 - MIN_NORMAL_SHARE) * Mg]
    if weight_along is not None and (weight_along[0] != 0.0 or weight_along[1] != 0.0):
        g_fr[:-1] += np.cos(theta) * weight_along[0] + np.sin(theta) * weight_along[1]  # u . (dP_xy/dt - M g_xy)
    return F_fr, g_fr
