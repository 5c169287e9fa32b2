"""Newton-Euler along a path q(s), split into TOPP-RA's form: with the joint velocities q' s' and accelerations
q' s'' + q'' s'^2, the inertial torques and momentum rates are a s'' + b s'^2, a the pass at (q, 0, q') and b the
pass at (q, q', q'') (gravity apart: it holds the body still, a term of its own)."""
from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..dynamics.inverse_dynamics import InverseDynamics, newton_euler
from ..model.robot import BasePlacement, SnakeRobot

__all__ = ["path_dynamics", "momentum_rate_coefficients"]


def path_dynamics(robot: SnakeRobot, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray, base: BasePlacement | None,
                  frames: np.ndarray | None = None) -> tuple[InverseDynamics, InverseDynamics]:
    """Newton-Euler's inertial terms along q(s): (the pass at (q, 0, q'), the pass at (q, q', q'')); their torques
    and momentum rates are the coefficients of s'' and of s'^2."""
    zero = np.zeros_like(q)
    return (newton_euler(robot, q, zero, dq, base, gravity="none", frames=frames),
            newton_euler(robot, q, dq, ddq, base, gravity="none", frames=frames))


def momentum_rate_coefficients(robot: SnakeRobot, q: npt.ArrayLike, dq: npt.ArrayLike, ddq: npt.ArrayLike,
                               base: BasePlacement | None = None, frames: np.ndarray | None = None
                               ) -> tuple[np.ndarray, np.ndarray]:
    """w = (dP/dt, dL/dt) along a path q(s) as a s'' + b s'^2: a, b (N, 6) at points q, dq = q'(s), ddq = q''(s)
    (N, n) each. With qd = q' s' and qdd = q' s'' + q'' s'^2, the momentum rates of Newton-Euler (inertial part:
    :func:`~snakehead.dynamics.inverse_dynamics.newton_euler`) split into a = w(q, 0, q') and b = w(q, q', q'').
    ``frames``: the world frames of q when the caller has them."""
    a, b = path_dynamics(robot, np.asarray(q, float), np.asarray(dq, float), np.asarray(ddq, float), base, frames)
    return np.hstack([a.Pdot, a.Ldot]), np.hstack([b.Pdot, b.Ldot])
