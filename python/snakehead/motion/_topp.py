"""The TOPP-RA side of :mod:`snakehead.motion.timing`: the path and constraint types toppra asks for.

Kept apart so that toppra (which imports matplotlib's pyplot) is imported only when a path is retimed.
Each constraint computes its coefficients at all gridpoints at once from a function of the path's points
(q, dq/ds, d2q/ds2), and uses toppra's *interpolation* discretization: the constraint of gridpoint i+1 is also
imposed on the state that stage i reaches there (x_i + 2 delta_i u_i, with u_i), so that the constant path
acceleration of a stage keeps the limits at both of its ends.
"""
from __future__ import annotations

import logging
from typing import Any, Callable

import numpy as np
import numpy.typing as npt
import toppra.algorithm as algo
from toppra.constraint import (DiscretizationType, JointAccelerationConstraint, JointVelocityConstraint,
                               LinearConstraint)
from toppra.constraint.linear_constraint import canlinear_colloc_to_interpolate
from toppra.interpolator import AbstractGeometricPath

#: q(s) and its derivatives: f(s (N,), order 0, 1 or 2) -> (N, n).
PathFunction = Callable[[np.ndarray, int], np.ndarray]
#: (q, dq/ds, d2q/ds2) at N points -> a, b, c (N, m), F, g of a linear constraint (see PointwiseLinearConstraint).
ParamsFunction = Callable[[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, ...]]

# toppra logs every infeasible path as a warning; the caller turns it into a ValueError that says where
logging.getLogger("toppra").setLevel(logging.ERROR)


class GeometricPath(AbstractGeometricPath):
    """A joint path q(s), s in [0, length], from a callable ``f(s (N,), order) -> (N, n)`` (order 0, 1, 2)."""

    def __init__(self, f: PathFunction, length: float, dof: int) -> None:
        self._f, self._length, self._dof = f, float(length), int(dof)

    def __call__(self, path_positions: npt.ArrayLike, order: int = 0) -> np.ndarray:
        s = np.asarray(path_positions, float)
        out = self._f(np.atleast_1d(s), order)
        return out[0] if s.ndim == 0 else out

    @property
    def dof(self) -> int:
        return self._dof

    @property
    def path_interval(self) -> np.ndarray:
        return np.array([0.0, self._length])


class PointwiseLinearConstraint(LinearConstraint):
    """A toppra LinearConstraint ``a u + b x + c = v, F v <= g`` whose parameters come from ``params(q, dq, ddq)``
    evaluated at every gridpoint at once (q, dq = dq/ds, ddq = d2q/ds2, each (N, n)).

    ``params`` returns a, b, c (N, m) and F (N, k, m), g (N, k), or F (k, m), g (k,) when ``identical``.
    """

    def __init__(self, params: ParamsFunction, dof: int, identical: bool, name: str) -> None:
        super().__init__()
        self._params, self.dof, self.identical, self.name = params, int(dof), bool(identical), name
        self.set_discretization_type(DiscretizationType.Interpolation)
        self._format_string = f"    {name}\n"

    def compute_constraint_params(self, path: GeometricPath, gridpoints: np.ndarray, *args: Any, **kwargs: Any
                                  ) -> tuple:
        grid = np.asarray(gridpoints, float)
        a, b, c, F, g = self._params(path(grid, 0), path(grid, 1), path(grid, 2))
        return canlinear_colloc_to_interpolate(a, b, c, F, g, None, None, grid, identical=self.identical)


def box_constraint(limit: np.ndarray, coefficients: ParamsFunction, dof: int, name: str) -> PointwiseLinearConstraint:
    """|a u + b x + c| <= limit, joint by joint, with (a, b, c) = coefficients(q, dq, ddq) (e.g. joint torques)."""
    n = len(limit)
    F = np.vstack([np.eye(n), -np.eye(n)])
    g = np.concatenate([limit, limit])

    def params(q: np.ndarray, dq: np.ndarray, ddq: np.ndarray) -> tuple[np.ndarray, ...]:
        a, b, c = coefficients(q, dq, ddq)
        return a, b, c, F, g

    return PointwiseLinearConstraint(params, dof, identical=True, name=name)


class CappedVelocityConstraint(JointVelocityConstraint):
    """toppra's joint velocity constraint, with the squared path velocity also capped at ``x_cap``: where the path
    stands still (q'(s) = 0, at a cusp of the path where every joint turns back or stops) the joint limits leave
    the path velocity unbounded, and toppra's solver turns the unbounded set into NaN."""

    def __init__(self, limit: np.ndarray, x_cap: float) -> None:
        super().__init__(np.column_stack([-limit, limit]))
        self.x_cap = float(x_cap)

    def compute_constraint_params(self, path: GeometricPath, gridpoints: np.ndarray) -> tuple:
        params = list(super().compute_constraint_params(path, gridpoints))
        params[6] = np.column_stack([params[6][:, 0], np.minimum(params[6][:, 1], self.x_cap)])
        return tuple(params)


def velocity_constraint(limit: np.ndarray, x_cap: float) -> CappedVelocityConstraint:
    return CappedVelocityConstraint(limit, x_cap)


def acceleration_constraint(limit: np.ndarray) -> JointAccelerationConstraint:
    return JointAccelerationConstraint(np.column_stack([-limit, limit]),
                                       discretization_scheme=DiscretizationType.Interpolation)


def solve(path: GeometricPath, constraints: list, gridpoints: np.ndarray) -> tuple[np.ndarray | None, np.ndarray]:
    """Time-optimal rest-to-rest path velocities: sd (N,) at the gridpoints (None when infeasible) and the
    controllable sets K (N, 2) of squared path velocities (NaN from where the path cannot be followed)."""
    instance = algo.TOPPRA(constraints, path, gridpoints=gridpoints, solver_wrapper="seidel")
    _, sd, _, K = instance.compute_parameterization(0.0, 0.0, return_data=True)
    return sd, K
