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

The pass runs in the C++ core (``snakehead._core.newton_euler``, sample by sample, without the GIL) from the links'
frames that FK gives and the lifted shares computed here; the tests hold it against pinocchio's RNEA, the lifted
share sums and the momenta's finite differences.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .. import _core
from .._errors import InputError
from .._validate import finite_array, positive
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from .stability import momenta_from_velocities

__all__ = ["LIFT_RAMP", "GRAVITY_MODELS", "lift_shares", "carried_weights", "InverseDynamics", "inverse_dynamics",
           "newton_euler", "MOMENTUM_STEP", "momentum_rates"]

#: Ramp (m) of the lifted share: a link whose distal points' lowest is this high is fully carried by the
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

    A link with collision shapes: w = clip(h / ramp, 0, 1), h the height of the lowest of its distal points (the
    points of its shapes farthest along the body: a box's distal face, a cylinder's distal rim). The distal end,
    not the whole link: a link pitched up about its proximal joint still touches the ground with its proximal edge,
    right under the joint's axis, where the ground's reaction has no moment about the joint, so the joint carries
    the link from the first degrees of lift. Links without shapes (marker frames): w = 1.
    """
    ramp = positive(ramp, "ramp")
    L = len(robot.link_names)
    links, points = robot.distal_points  # (k,), (k, M, 3) in the link frames
    homogeneous = np.concatenate([points, np.ones(points.shape[:2] + (1,))], axis=2)  # (k, M, 4)
    w = np.ones((frames.shape[0], L))
    for i, link in enumerate(links):  # the points' heights: the frame's z row times (p, 1), one product per link
        w[:, link] = np.clip((frames[:, link, 2, :] @ homogeneous[i].T).min(axis=1) / ramp, 0.0, 1.0)
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
    carried weight). com (T, 3) m: the centre of mass (Eq. 23) when the pass ran along q without frames (else None).
    """

    tau: np.ndarray
    Pdot: np.ndarray
    Ldot: np.ndarray
    com: np.ndarray | None = None


def _samples(robot: SnakeRobot, x: npt.ArrayLike, name: str, n_samples: int | None) -> np.ndarray:
    a = finite_array(x, name)
    n = robot.n_joints
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != n or a.shape[0] < 1:
        raise InputError(f"{name} has shape {np.shape(x)}; expected ({n},) or (T, {n})")
    if n_samples is not None and a.shape[0] != n_samples:
        raise InputError(f"{name} has {a.shape[0]} samples; q has {n_samples}")
    return a


def inverse_dynamics(robot: SnakeRobot, q: npt.ArrayLike, qd: npt.ArrayLike, qdd: npt.ArrayLike,
                     base: BasePlacement | None = None, *, gravity: str = "carried", ramp: float = LIFT_RAMP,
                     frames: np.ndarray | None = None) -> np.ndarray:
    """Joint torques (N m) that move the body along q, qd, qdd with the root link lying still on the ground.

    q (rad), qd (rad/s), qdd (rad/s^2): (T, n) each, or (n,) each (-> (n,)). ``base``: where the root lies (its
    height and yaw; gravity is its ground frame's, along -z but on a slope). ``gravity``: "carried" (default: each link's weight counts by
    its lifted share, :func:`carried_weights`: a link resting on the ground, and what lies beyond it, is carried by
    the ground), "full" (every link's weight: the body as a fixed-base arm) or "none" (inertial terms only).
    Inertial terms (the links' accelerations, Coriolis and centrifugal terms) always count in full.

    ``frames``: the world frames of q (T, n_links, 4, 4) when the caller has them (``robot.frames_many(q, base)``).

    Returns tau (T, n) N m (or (n,)). :func:`newton_euler` returns the momentum rates too.
    """
    return newton_euler(robot, q, qd, qdd, base, gravity=gravity, ramp=ramp, frames=frames).tau


def newton_euler(robot: SnakeRobot, q: npt.ArrayLike, qd: npt.ArrayLike, qdd: npt.ArrayLike,
                 base: BasePlacement | None = None, *, gravity: str = "carried", ramp: float = LIFT_RAMP,
                 frames: np.ndarray | None = None) -> InverseDynamics:
    """:func:`inverse_dynamics`'s pass, returning the joint torques and the momentum rates (Eqs. 33-34) of the
    body: an :class:`InverseDynamics` (arrays of one sample when q, qd, qdd are (n,)). ``frames``: as for
    :func:`inverse_dynamics`."""
    robot = as_robot(robot)
    base = as_base(base)
    if gravity not in GRAVITY_MODELS:
        raise InputError(f"gravity must be one of {GRAVITY_MODELS}, got {gravity!r}")
    single = np.ndim(q) == 1
    qs = _samples(robot, q, "q", None)
    T = qs.shape[0]
    qds = _samples(robot, qd, "qd", T)
    qdds = _samples(robot, qdd, "qdd", T)

    # in the world frame: the root link is still, so its frame is as good as any inertial one, and the momentum rates
    # come out about the world origin (Eqs. 33-34) directly
    g = base.gravity if gravity != "none" else np.zeros(3)  # (0, 0, -GRAVITY) but on a slope
    chain = robot.body.model
    masses = (list(chain.joint_child_links), chain.joint_axes, robot.masses, robot.coms, robot.inertias)
    # the pass itself (C++ core, per sample): forward, the links' angular velocities and accelerations and their
    # frames' accelerations from the root; backward, the wrench each link's parent exerts on it and on everything
    # beyond it, the weight's part scaled link by link by the lifted share. The inertial wrench across the first
    # joint (its moment about the world origin) is the momentum rate: the root link does not move
    shape = (T, len(robot.link_names), 4, 4)
    com = None
    if frames is None or np.shape(frames) != shape:
        # no frames given: the core computes each sample's frames, lifted shares and CoM in place (no (T, L, 4, 4)
        # array in between)
        links, points = robot.distal_points if gravity == "carried" else (None, None)
        tau, Pdot, Ldot, com = _core.newton_euler_along(
            chain, robot.root_pose(base), np.ascontiguousarray(qs), np.ascontiguousarray(qds),
            np.ascontiguousarray(qdds), *masses, None if links is None else [int(k) for k in links], points,
            positive(ramp, "ramp"), g)
    else:
        F = np.asarray(frames, float)
        share = lift_shares(robot, F, ramp) if gravity == "carried" else None  # (T, L)
        tau, Pdot, Ldot = _core.newton_euler(F, qds, qdds, *masses, share, g)
    if single:
        return InverseDynamics(tau[0], Pdot[0], Ldot[0], None if com is None else com[0])
    return InverseDynamics(tau, Pdot, Ldot, com)


# ------------------------------------------------------------------------------------------------
# momentum rates (Eqs. 33-34) from the momenta of Eqs. 25-31
# ------------------------------------------------------------------------------------------------
#: Step (rad) of the largest joint in the central difference of :func:`momentum_rates`.
MOMENTUM_STEP = 1e-5


def momentum_rates(robot: SnakeRobot, q: npt.ArrayLike, qd: npt.ArrayLike, qdd: npt.ArrayLike,
                   base: BasePlacement | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Rates of the linear and angular momentum (about the world origin) of Eqs. 33-34: (dP/dt, dL/dt), (T, 3) each.

    q, qd, qdd (T, n) (or (n,) -> (3,)). The momenta of Eqs. 25-31 (:func:`~snakehead.dynamics.stability.momenta_from_velocities`) are
    linear in the joint velocities, P = A(q) qd, so dP/dt = A(q) qdd + (dA/dq . qd) qd: the first term is the
    momentum of the velocity qdd, the second the derivative of P(q, v) at fixed v = qd along qd, taken here by a
    central difference (step :data:`MOMENTUM_STEP` rad on the largest joint; the error is of its square).
    :func:`newton_euler` computes the same rates exactly; this path uses the paper's equations.
    """
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
