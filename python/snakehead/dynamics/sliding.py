"""The body sliding over the ground under Coulomb friction, quasi-statically: where a change of shape on the ground
(a curl, a gait) carries the body.

The model. Each contact i (a link resting on the ground) carries a normal load N_i; where it slips with velocity
v_i the ground pushes it back with a friction force of magnitude mu N_i against v_i. A slow motion has no inertia
to speak of, so the body moves such that the friction forces balance. For a change of shape that moves contact i
by d_i in the body's own frame, and a rigid motion of the whole body (translation t, rotation w about the
vertical), the slip of contact i is v_i = d_i + t + w x r_i, and the balance is the stationary point of the
dissipation

    D(t, w) = sum_i N_i |d_i + t + w x r_i|            (convex: a sum of norms)

(the principle of minimum dissipation of quasi-static sliding; Peshkin and Sanderson, "The motion of a pushed,
sliding workpiece", IEEE J. Robotics and Automation 4(6), 1988). Two uses:

* :func:`balance_translation` -- the rotation known (an IMU measures it), only t: the minimiser is the weighted
  geometric median of the displacements -d_i that would keep each contact still. It passes through one of them
  when that contact's load outweighs the others' pull: the contact sticks, as heavy contacts do. Where every
  contact sticks (no slip), it is the no-slip answer.
* :func:`balance_motion` -- t and w both unknown (a prediction, no sensor): iteratively reweighted least squares.

:func:`predict_slide` runs the second over a joint path of a body lying flat, giving where the root frame goes:
the planner of a closed loop uses it to know where a curl on the ground will leave the body
(:mod:`snakehead.locomotion.goals`), and the pose estimate (:mod:`snakehead.closed_loop.estimate`) uses the first.
Loads are the links' weights (uniform friction, the body flat on the ground); the model ignores inertia and the
pressure's spread under each link.
"""
from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from .._errors import InputError
from .._validate import finite_array
from ..ground_contact import RESTING_TOLERANCE
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot

__all__ = ["SLIP_FLOOR", "TRANSLATION_TOLERANCE", "balance_translation", "balance_motion",
           "resting_contacts", "predict_slide"]

#: Slips below this share of the largest shift count as none in the reweighting (keeps the weights finite).
SLIP_FLOOR = 1e-9
#: The iteration stops when a step is below this share of the largest shift.
TRANSLATION_TOLERANCE = 1e-7


def _loads(weights: npt.ArrayLike, k: int) -> np.ndarray:
    w = finite_array(weights, "weights", (k,))
    if np.any(w < 0) or w.sum() <= 0:
        raise InputError("weights (normal loads) must be >= 0 with a positive sum")
    return w


def balance_translation(shifts: npt.ArrayLike, weights: npt.ArrayLike) -> np.ndarray:
    """The translation t (2,) that balances the friction of contacts whose no-slip shifts are ``shifts`` (k, 2)
    with loads ``weights`` (k,): the minimiser of sum_i w_i |t - s_i| (the weighted geometric median).

    A contact sticks (t = s_i) when its load is at least the pull of the others,
    |sum_{j != i} w_j (s_i - s_j) / |s_i - s_j|| <= w_i; otherwise Newton's method from the weighted mean (with
    Weiszfeld's step where Newton's does not lower the dissipation).
    """
    s = finite_array(shifts, "shifts", (None, 2))
    if len(s) == 0:
        raise InputError("shifts must hold at least one contact")
    w = _loads(weights, len(s))
    if len(s) == 1:
        return s[0].copy()
    # a sticking contact: the median sits on it (Weiszfeld would only creep towards it)
    diff = s[:, None, :] - s[None, :, :]  # (i, j, 2): s_i - s_j
    dist = np.sqrt(diff[..., 0] ** 2 + diff[..., 1] ** 2)
    same = dist == 0.0
    unit = diff / np.where(same, 1.0, dist)[..., None]  # coincident points pull nothing
    pull = np.sqrt(((w[None, :, None] * unit).sum(axis=1) ** 2).sum(axis=1))
    load = (same * w[None, :]).sum(axis=1)  # the point's own load (and its duplicates')
    sticking = np.flatnonzero((pull <= load + 1e-12) & (w > 0))
    if sticking.size:
        return s[sticking[0]].copy()
    # Newton's method on the dissipation from the weighted mean, halving a step that does not lower it, and a
    # Weiszfeld step where Newton's cannot (next to a contact that nearly sticks, the curvature is huge)
    scale = max(float(np.abs(s).max()), 1e-12)

    def dissipation(t: np.ndarray) -> float:
        return float(w @ np.sqrt(((s - t) ** 2).sum(axis=1)))

    t = w @ s / w.sum()
    f = dissipation(t)
    for _ in range(100):
        r = t - s
        d = np.maximum(np.sqrt(r[:, 0] ** 2 + r[:, 1] ** 2), SLIP_FLOOR * scale)
        u = r / d[:, None]
        a = w / d
        g = w @ u
        hxx, hyy, hxy = (a * u[:, 1] ** 2).sum(), (a * u[:, 0] ** 2).sum(), -(a * u[:, 0] * u[:, 1]).sum()
        det = hxx * hyy - hxy * hxy
        moved = False
        if det > 0:
            step = -np.array([hyy * g[0] - hxy * g[1], hxx * g[1] - hxy * g[0]]) / det
            for _ in range(20):
                f_new = dissipation(t + step)
                if f_new < f:
                    t, f, moved = t + step, f_new, True
                    break
                step = 0.5 * step
        if not moved:
            step = a @ s / a.sum() - t  # Weiszfeld: never raises the dissipation
            f_new = dissipation(t + step)
            if f_new >= f:
                break
            t, f = t + step, f_new
        if abs(step[0]) + abs(step[1]) <= TRANSLATION_TOLERANCE * scale:
            break
    return t


def balance_motion(before: npt.ArrayLike, after: npt.ArrayLike, weights: npt.ArrayLike, iterations: int = 300
                   ) -> tuple[np.ndarray, float]:
    """The planar rigid motion (t (2,), angle w rad) that, applied to contact points ``after`` (k, 2) (the shape
    changed in the body's frame), best keeps them where they were (``before`` (k, 2)) in the sense of friction:
    the minimiser of sum_i N_i |R(w) a_i + t - b_i|, by iteratively reweighted least squares (Gauss-Newton on the
    rotation, relinearised at every iteration). When a contact sticks at the optimum the iteration converges only
    linearly, hence the default of 300 iterations (with margin over what matches SciPy's minimiser)."""
    b = finite_array(before, "before", (None, 2))
    a = finite_array(after, "after", b.shape)
    N = _loads(weights, len(b))
    t, w = np.zeros(2), 0.0
    J = np.zeros((len(a), 2, 3))
    J[:, 0, 0] = J[:, 1, 1] = 1.0
    scale = max(float(np.abs(a - b).max()), 1e-12)
    for _ in range(int(iterations)):
        c, s = math.cos(w), math.sin(w)
        ra = a @ np.array([[c, s], [-s, c]])  # R(w) a_i, row-wise
        slip = ra + t - b
        J[:, :, 2] = np.column_stack([-ra[:, 1], ra[:, 0]])  # d(R(w) a)/dw
        g = N / np.maximum(np.linalg.norm(slip, axis=1), SLIP_FLOOR * scale)
        A = np.einsum("i,ikj,ikl->jl", g, J, J)
        rhs = -np.einsum("i,ikj,ik->j", g, J, slip)
        try:
            step = np.linalg.solve(A, rhs)
        except np.linalg.LinAlgError:  # every contact on one point: the rotation is free; keep it
            step = np.linalg.lstsq(A, rhs, rcond=None)[0]
        t, w = t + step[:2], w + float(step[2])
        if np.abs(step).max() <= 1e-13 * max(scale, 1.0):
            break
    return t, w


def resting_contacts(robot: SnakeRobot, q: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Where a body lying flat with joints ``q`` (n,) touches the ground: the centres (k, 2) of its links' collision
    capsules in the body frame's ground plane (m), and their loads (the links' masses, kg). ValueError unless every
    link with shapes rests on the ground (its bottom within RESTING_TOLERANCE of the lowest): the model is for flat
    shapes."""
    robot = as_robot(robot)
    F = robot.frames(np.asarray(q, float), BasePlacement())[None]  # the default placement: the body frame
    low = robot.lowest_z(F)[0]
    links = robot.shaped_links
    if low.max() > low.min() + RESTING_TOLERANCE:
        k = int(np.argmax(low))
        raise InputError(f"the shape is not flat on the ground: the link {robot.link_names[links[k]]!r} "
                         f"is {1000 * (low[k] - low.min()):.1f} mm above the lowest (keep the pitch joints at 0)")
    return robot.link_centres(F)[0, :, :2], robot.masses[links]


def predict_slide(robot: SnakeRobot, q_path: npt.ArrayLike, start: BasePlacement | None = None
                  ) -> list[BasePlacement]:
    """Where the root frame goes while a body lying on the ground changes its shape along ``q_path`` (T, n) (flat
    shapes: the joints that would lift it kept at zero), starting at ``start``: the placement at every
    configuration (T,), by :func:`balance_motion` between consecutive configurations. Sample the path finely
    (a few degrees per step): each step is linearised."""
    robot = as_robot(robot)
    qs = finite_array(q_path, "q_path", (None, robot.n_joints))
    if len(qs) == 0:
        raise InputError("q_path must hold at least one configuration")
    start = as_base(start)
    x, y, yaw = start.x, start.y, start.yaw
    out = [BasePlacement(x, y, yaw)]
    prev, _ = resting_contacts(robot, qs[0])
    for q in qs[1:]:
        now, loads = resting_contacts(robot, q)
        t, w = balance_motion(prev, now, loads)
        # the root frame of the new shape, in the old one's coordinates: the rigid motion (t, w) itself
        c, s = math.cos(yaw), math.sin(yaw)
        x, y, yaw = x + c * t[0] - s * t[1], y + s * t[0] + c * t[1], yaw + w
        out.append(BasePlacement(x, y, yaw))
        prev = now
    return out
