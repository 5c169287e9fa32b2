"""Joint torques of a snake lying on the ground: Newton-Euler over the body chain, many samples at once.

The root link lies still on the ground (the base does not move), so the chain is a fixed-base arm rooted at it.
What differs from an arm is gravity: a link that rests on the ground is carried by the ground, not by the joints,
and so is everything beyond it that hangs from it. Each link has a *lifted share* w in [0, 1] (:func:`lift_shares`:
0 on the ground, 1 once its distal face is :data:`LIFT_RAMP` m up); a joint carries the weight of each link beyond
it by the product of the shares from the joint's child link to that link (:func:`carried_weights`): the lifted run
of links that hangs from the joint, up to the first link resting on the ground. Inertial terms count in full.

* :func:`inverse_dynamics` -- joint torques tau (T, n) from q, qd, qdd (T, n): a forward pass of velocities and
  accelerations from the root, a backward pass of forces and moments to it, with gravity "carried" (the rule
  above; the default), "full" (every link's weight, as for an arm: pinocchio's RNEA) or "none";
  :func:`newton_euler` -- the same pass, returning also the rates of the momenta (dP/dt, dL/dt) of Eqs. 33-34,
  exactly: the inertial part of the wrench that the root link exerts on the rest of the body.
* :func:`lift_shares`, :func:`carried_weights` -- the lifted shares; the same rule drives the gravity compensation
  of the MuJoCo controller (:mod:`snakehead.sim.tracking`).

All arrays are laid out component-major inside, (3, T), so that each step is one contiguous vector operation over
the samples; the Python loops run over the links, never over time.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .._validate import finite_array, positive
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from .stability import GRAVITY

#: Ramp (m) of the lifted share: a link whose distal face's lowest corner is this high is fully carried by the
#: joints; on the ground (height 0) not at all; linear in between.
LIFT_RAMP = 0.005

#: Gravity models of :func:`inverse_dynamics`.
GRAVITY_MODELS = ("carried", "full", "none")


# ------------------------------------------------------------------------------------------------
# the lifted share of each link's weight
# ------------------------------------------------------------------------------------------------
def lift_shares(robot: SnakeRobot, frames: np.ndarray, ramp: float = LIFT_RAMP) -> np.ndarray:
    """How much of each link's weight the joints carry: w (T, n_links) in [0, 1] from world frames
    (T, n_links, 4, 4).

    A link with a box: w = clip(h / ramp, 0, 1), h the height of the lowest corner of its box's distal face (+x
    end). The distal face, not the whole box: a link pitched up about its proximal joint still touches the ground
    with its proximal edge, right under the joint's axis, where the ground's reaction has no moment about the joint,
    so the joint carries the link from the first degrees of lift. Links without a box (marker frames): w = 1.
    """
    ramp = positive(ramp, "ramp")
    L = len(robot.link_names)
    boxed = np.all(robot.box_sizes > 0, axis=1)
    Bz = np.einsum("tkj,kjl->tkl", frames[:, boxed, 2, :], robot.box_origins[boxed])  # the boxes' poses' z rows
    half = 0.5 * robot.box_sizes[boxed]
    low = (Bz[..., 3] + Bz[..., 0] * half[:, 0]
           - np.abs(Bz[..., 1]) * half[:, 1] - np.abs(Bz[..., 2]) * half[:, 2])
    w = np.ones((frames.shape[0], L))
    w[:, boxed] = np.clip(low / ramp, 0.0, 1.0)
    return w


def carried_weights(robot: SnakeRobot, frames: np.ndarray, ramp: float = LIFT_RAMP) -> np.ndarray:
    """How much of each joint's distal links' weight the joint carries: W (T, n, n_links) in [0, 1].

    frames (T, n_links, 4, 4): world poses. Joint j carries link i (i at or after j's child link in chain order)
    by the product of the :func:`lift_shares` w over the links from j's child to i: the weight of the lifted run of
    links that hangs from the joint, up to the first link resting on the ground, which the ground carries instead.
    """
    w = lift_shares(robot, frames, ramp)
    child = np.asarray(robot.body.model.joint_child_links, int)
    W = np.zeros((frames.shape[0], robot.n_joints, w.shape[1]))
    for j, c in enumerate(child):
        W[:, j, c:] = np.cumprod(w[:, c:], axis=1)
    return W


# ------------------------------------------------------------------------------------------------
# Newton-Euler
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class InverseDynamics:
    """What :func:`newton_euler` computes.

    tau (T, n) N m: the joint torques. Pdot (T, 3) N and Ldot (T, 3) N m: the rates of the linear momentum and of the
    angular momentum about the world origin (world axes) of the body (Eqs. 33-34): the inertial part of the wrench
    that the root link exerts on the rest of the body across the first joint (the rest of that wrench holds the
    carried weight).
    """

    tau: np.ndarray
    Pdot: np.ndarray
    Ldot: np.ndarray


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of (3, T) arrays."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _samples(robot: SnakeRobot, x: npt.ArrayLike, name: str, n_samples: int | None) -> np.ndarray:
    a = finite_array(x, name)
    n = robot.n_joints
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != n or a.shape[0] < 1:
        raise ValueError(f"{name} has shape {np.shape(x)}; expected ({n},) or (T, {n})")
    if n_samples is not None and a.shape[0] != n_samples:
        raise ValueError(f"{name} has {a.shape[0]} samples; q has {n_samples}")
    return a


def inverse_dynamics(robot: SnakeRobot, q: npt.ArrayLike, qd: npt.ArrayLike, qdd: npt.ArrayLike,
                     base: BasePlacement | None = None, *, gravity: str = "carried", ramp: float = LIFT_RAMP
                     ) -> np.ndarray:
    """Joint torques (N m) that move the body along q, qd, qdd with the root link lying still on the ground.

    q (rad), qd (rad/s), qdd (rad/s^2): (T, n) each, or (n,) each (-> (n,)). ``base``: where the root lies (its
    height and yaw; gravity is along the world's -z). ``gravity``: "carried" (default: each link's weight counts by
    its lifted share, :func:`carried_weights`: a link resting on the ground, and what lies beyond it, is carried by
    the ground), "full" (every link's weight: the body as a fixed-base arm) or "none" (inertial terms only).
    Inertial terms (the links' accelerations, Coriolis and centrifugal terms) always count in full.

    Returns tau (T, n) N m (or (n,)). :func:`newton_euler` returns the momentum rates too.
    """
    return newton_euler(robot, q, qd, qdd, base, gravity=gravity, ramp=ramp).tau


def newton_euler(robot: SnakeRobot, q: npt.ArrayLike, qd: npt.ArrayLike, qdd: npt.ArrayLike,
                 base: BasePlacement | None = None, *, gravity: str = "carried", ramp: float = LIFT_RAMP
                 ) -> InverseDynamics:
    """:func:`inverse_dynamics`'s pass, returning the joint torques and the momentum rates (Eqs. 33-34) of the
    body: an :class:`InverseDynamics` (arrays of one sample when q, qd, qdd are (n,))."""
    robot = as_robot(robot)
    base = as_base(base)
    if gravity not in GRAVITY_MODELS:
        raise ValueError(f"gravity must be one of {GRAVITY_MODELS}, got {gravity!r}")
    single = np.ndim(q) == 1
    qs = _samples(robot, q, "q", None)
    T = qs.shape[0]
    qds = _samples(robot, qd, "qd", T)
    qdds = _samples(robot, qdd, "qdd", T)

    model = robot.body.model
    child = np.asarray(model.joint_child_links, int)  # joint j turns link_names[child[j]] about its frame's origin
    axes = np.asarray(model.joint_axes, float)  # (n, 3) in the child link's frame
    masses, coms, inertias = robot.masses, robot.coms, robot.inertias
    F = robot.body.fk_all_many(qs)  # (T, L, 4, 4), root frame
    L = F.shape[1]
    G = np.ascontiguousarray(F[:, :, :3, :].transpose(1, 2, 3, 0))  # (L, 3, 4, T)
    W0 = robot.root_pose(base)
    R0, p0 = W0[:3, :3], W0[:3, 3]
    g_root = R0.T @ np.array([0.0, 0.0, -GRAVITY])  # gravity in the root frame
    share = None
    if gravity == "carried":
        share = lift_shares(robot, W0 @ F, ramp).T  # (L, T)
    joint_of = np.full(L, -1)
    joint_of[child] = np.arange(len(child))

    # forward pass: angular velocity and acceleration of each link, acceleration of each frame's origin
    omega = np.zeros((L, 3, T))
    alpha = np.zeros((L, 3, T))
    acc = np.zeros((L, 3, T))
    z = np.zeros((L, 3, T))
    first = int(child[0])  # links before the first joint's child are the root link(s): still
    for link in range(first, L):
        r = G[link, :, 3] - G[link - 1, :, 3]
        w_prev, a_prev = omega[link - 1], alpha[link - 1]
        acc[link] = acc[link - 1] + _cross(a_prev, r) + _cross(w_prev, _cross(w_prev, r))
        j = joint_of[link]
        if j >= 0:
            z[link] = (G[link, :, :3] * axes[j][None, :, None]).sum(axis=1)  # the axis in the root frame
            wz = z[link] * qds[:, j]
            omega[link] = w_prev + wz
            alpha[link] = a_prev + z[link] * qdds[:, j] + _cross(w_prev, wz)
        else:
            omega[link], alpha[link] = w_prev, a_prev

    # backward pass: force and moment (about the frame's origin) that each link's parent exerts on it and on
    # everything beyond it; the weight's part separately, scaled link by link by the lifted share
    f_in, n_in = np.zeros((3, T)), np.zeros((3, T))  # inertial
    f_g, n_g = np.zeros((3, T)), np.zeros((3, T))  # holding the weight
    tau = np.zeros((T, len(child)))
    for link in range(L - 1, first - 1, -1):
        o = G[link, :, 3]
        if link + 1 < L:  # move the distal link's wrench to this frame's origin
            d = G[link + 1, :, 3] - o
            n_in = n_in + _cross(d, f_in)
            n_g = n_g + _cross(d, f_g)
        m = masses[link]
        if m > 0.0:
            R = G[link, :, :3]
            rc = (R * coms[link][None, :, None]).sum(axis=1)  # CoM offset from the origin, root axes
            w, a = omega[link], alpha[link]
            ac = acc[link] + _cross(a, rc) + _cross(w, _cross(w, rc))
            Iw = (R * (inertias[link] @ (R * w[:, None, :]).sum(axis=0))[None]).sum(axis=1)  # R I R^T omega
            Ia = (R * (inertias[link] @ (R * a[:, None, :]).sum(axis=0))[None]).sum(axis=1)
            f_in = f_in + m * ac
            n_in = n_in + Ia + _cross(w, Iw) + _cross(rc, m * ac)
            if gravity != "none":
                hold = -m * g_root[:, None] * np.ones((1, T))  # the force that holds the link against gravity
                f_g = f_g + hold
                n_g = n_g + _cross(rc, hold)
        if share is not None:
            f_g = f_g * share[link]
            n_g = n_g * share[link]
        j = joint_of[link]
        if j >= 0:
            tau[:, j] = ((n_in + n_g) * z[link]).sum(axis=0)
    tau = tau[0] if single else tau
    # the inertial wrench across the first joint is the momentum rate (the root link does not move): moved from
    # the first joint's frame origin to the root frame's, then to the world (about the world origin)
    n_origin = n_in + _cross(G[first, :, 3], f_in)
    Pdot = (R0 @ f_in).T
    Ldot = (R0 @ n_origin).T + np.cross(p0, Pdot)
    if single:
        Pdot, Ldot = Pdot[0], Ldot[0]
    return InverseDynamics(tau, Pdot, Ldot)


# ------------------------------------------------------------------------------------------------
# momentum rates (Eqs. 33-34) from the momenta of Eqs. 25-31
# ------------------------------------------------------------------------------------------------
#: Step (rad) of the largest joint in the central difference of :func:`momentum_rates`.
MOMENTUM_STEP = 1e-5


def momentum_rates(robot: SnakeRobot, q: npt.ArrayLike, qd: npt.ArrayLike, qdd: npt.ArrayLike,
                   base: BasePlacement | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Rates of the linear and angular momentum (about the world origin) of Eqs. 33-34: (dP/dt, dL/dt), (T, 3) each.

    q, qd, qdd (T, n) (or (n,) -> (3,)). The momenta of Eqs. 25-31 (:func:`stability.momenta_from_velocities`) are
    linear in the joint velocities, P = A(q) qd, so dP/dt = A(q) qdd + (dA/dq . qd) qd: the first term is the
    momentum of the velocity qdd, the second the derivative of P(q, v) at fixed v = qd along qd, taken here by a
    central difference (step :data:`MOMENTUM_STEP` rad on the largest joint; the error is of its square).
    :func:`newton_euler` computes the same rates exactly; this path uses the paper's equations.
    """
    from .stability import momenta_from_velocities

    robot = as_robot(robot)
    base = as_base(base)
    single = np.ndim(q) == 1
    qs = _samples(robot, q, "q", None)
    qds = _samples(robot, qd, "qd", qs.shape[0])
    qdds = _samples(robot, qdd, "qdd", qs.shape[0])
    scale = np.abs(qds).max(axis=1, keepdims=True)
    h = MOMENTUM_STEP / np.where(scale > 0, scale, 1.0)  # (T, 1): a step of MOMENTUM_STEP rad on the fastest joint
    both = np.concatenate([qs, qs + h * qds, qs - h * qds])
    vel = np.concatenate([qdds, qds, qds])
    P, L = momenta_from_velocities(robot, both, vel, base)
    T = qs.shape[0]
    Pdot = P[:T] + (P[T:2 * T] - P[2 * T:]) / (2 * h)
    Ldot = L[:T] + (L[T:2 * T] - L[2 * T:]) / (2 * h)
    return (Pdot[0], Ldot[0]) if single else (Pdot, Ldot)
