"""The reference for snakehead's TOPP-RA (snakehead._core.topp_ra via snakehead.retiming.topp_ra): toppra's own TOPPRA
with its seidel solver over the same constraints, built with toppra's constraint classes as snakehead.retiming
did before the core solved them (toppra's joint velocity constraint with the x cap, its joint acceleration
constraint, and the torque and stability rows as canonical linear constraints, all with toppra's interpolation
discretization).

``toppra_solve_grid`` has the signature of ``gridpoints.solve_grid``; ``toppra_solver()`` swaps it in for a block, so
that a whole ``retime`` runs on toppra (tests/retiming/test_topp_ra.py, bench/timing.py --solvers).
"""
from __future__ import annotations

import contextlib
import logging
from typing import Any, Callable, Iterator

import numpy as np
import toppra.algorithm as algo
from toppra.constraint import DiscretizationType, JointAccelerationConstraint, JointVelocityConstraint, LinearConstraint
from toppra.constraint.linear_constraint import canlinear_colloc_to_interpolate
from toppra.interpolator import AbstractGeometricPath

from snakehead.retiming import gridpoints, rest_to_rest, timing, topp_ra

#: toppra needs finite limits: "none" is a limit no motion here comes near.
BIG = 1e6

logging.getLogger("toppra").setLevel(logging.ERROR)  # toppra warns on every infeasible path


class GridPath(AbstractGeometricPath):
    """A path known at its gridpoints only (toppra evaluates the path there and nowhere else): q' and q''."""

    def __init__(self, points: timing.GridPoints) -> None:
        self.points = points

    def __call__(self, path_positions: Any, order: int = 0) -> np.ndarray:
        s = np.atleast_1d(np.asarray(path_positions, float))
        k = np.searchsorted(self.points.s, s)
        assert np.array_equal(self.points.s[k], s), "toppra asked for the path off its grid"
        out = {0: self.points.q, 1: self.points.dq, 2: self.points.ddq}[order][k]
        return out[0] if np.ndim(path_positions) == 0 else out

    @property
    def dof(self) -> int:
        return int(self.points.q.shape[1])

    @property
    def path_interval(self) -> np.ndarray:
        return np.array([self.points.s[0], self.points.s[-1]])


class RowsConstraint(LinearConstraint):
    """a u + b x + c = v, F v <= g at every gridpoint (a, b, c (N, m); F (k, m), g (k,) when identical, else per
    gridpoint), with toppra's interpolation discretization."""

    def __init__(self, a: np.ndarray, b: np.ndarray, c: np.ndarray, F: np.ndarray, g: np.ndarray, identical: bool
                 ) -> None:
        super().__init__()
        self.params = (a, b, c, F, g)
        self.dof, self.identical = a.shape[1], identical
        self.set_discretization_type(DiscretizationType.Interpolation)

    def compute_constraint_params(self, path: GridPath, gridpoints: np.ndarray, *args: Any, **kwargs: Any) -> tuple:
        a, b, c, F, g = self.params
        return canlinear_colloc_to_interpolate(a, b, c, F, g, None, None, np.asarray(gridpoints, float),
                                               identical=self.identical)


class CappedVelocityConstraint(JointVelocityConstraint):
    """toppra's joint velocity constraint with x = s'^2 also capped at x_cap."""

    def __init__(self, limit: np.ndarray, x_cap: float) -> None:
        super().__init__(np.column_stack([-limit, limit]))
        self.x_cap = float(x_cap)

    def compute_constraint_params(self, path: GridPath, gridpoints: np.ndarray, *args: Any) -> tuple:
        params = list(super().compute_constraint_params(path, gridpoints))
        params[6] = np.column_stack([params[6][:, 0], np.minimum(params[6][:, 1], self.x_cap)])
        return tuple(params)


def toppra_constraints(robot: Any, points: timing.GridPoints, limits: timing.RetimingLimits) -> list:
    """The constraints of ``gridpoints.solve_grid`` as toppra's constraint objects."""
    path_limits = gridpoints.path_limits(limits)
    n = robot.n_joints
    box_F, tau = np.vstack([np.eye(n), -np.eye(n)]), np.minimum(path_limits.torque, BIG)
    F, g = timing.stability_rows(robot, points.support, gridpoints.stability_limits(limits), timing.SOLVE_ZMP_EXTRA_M)
    acc = np.minimum(path_limits.acceleration, BIG)
    return [CappedVelocityConstraint(np.minimum(path_limits.velocity, BIG), path_limits.x_cap),
            JointAccelerationConstraint(np.column_stack([-acc, acc]),
                                        discretization_scheme=DiscretizationType.Interpolation),
            RowsConstraint(points.tau_a, points.tau_b, points.tau_hold, box_F, np.r_[tau, tau], identical=True),
            RowsConstraint(points.w_a, points.w_b, np.zeros_like(points.w_a), F, g, identical=False)]


def toppra_solve_grid(robot: Any, points: timing.GridPoints, limits: timing.RetimingLimits) -> topp_ra.Solution:
    """``gridpoints.solve_grid`` by toppra: TOPPRA with the seidel solver, rest to rest."""
    instance = algo.TOPPRA(toppra_constraints(robot, points, limits), GridPath(points), gridpoints=points.s,
                           solver_wrapper="seidel")
    _, sd, _, K = instance.compute_parameterization(0.0, 0.0, return_data=True)
    if sd is not None and not np.isnan(sd).any():
        return topp_ra.Solution(sd, K, -1)
    bad = np.flatnonzero(np.isnan(K).any(axis=1))
    return topp_ra.Solution(None, K, int(bad.max()) if bad.size else 0)


@contextlib.contextmanager
def toppra_solver(solve: Callable = toppra_solve_grid) -> Iterator[None]:
    """retime solves with ``solve`` (toppra by default) inside the block."""
    saved = rest_to_rest.solve_grid
    rest_to_rest.solve_grid = solve
    try:
        yield
    finally:
        rest_to_rest.solve_grid = saved
