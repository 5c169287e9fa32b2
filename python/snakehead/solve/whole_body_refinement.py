"""The whole-body optimisation (SLSQP) of one target from given starts: every joint and, optionally, the base's
placement at once:

    maximise   the static margin of the centre of mass in the support polygon (Eqs. 23-24)
    over       the base's yaw joints (its flat shape: pitch joints flat, the base lying on the ground), the
               neck and head joints, and (optionally) the base placement (x, y, yaw)
    such that  the head is at the position pointing along the direction (roll free, or fixed),
               margin >= ``min_margin``, every lifted link above the ground, no two links closer than
               ``self_clearance``, every link ``obstacle_clearance`` from every obstacle, joints within limits.

It is solved by SciPy's SLSQP with analytic gradients (the Jacobians of world points of the body, the centre of
mass and the polygon's active edge; the obstacles' distance fields by central differences). Links are capsules in
the optimisation (``SnakeRobot.link_capsules``: inside their shapes along the body, what sticks out of them (a box's
corners) added to the clearance); every solution is then checked exactly (:mod:`.solution_checks`).
"""
from __future__ import annotations

import time
from typing import Any, Sequence

import numpy as np
import numpy.typing as npt
from scipy import optimize

from .._errors import InputError, InternalError
from .._validate import finite_float, integer, unit_vector3, vector3
from ..collision import body_collisions as coll
from ..geometry.obstacles import BoxObstacle
from ..margins import OBSTACLE_CLEARANCE, SELF_CLEARANCE
from ..model.robot import BasePlacement, SnakeRobot, as_robot
from .body_problem import BodyProblem
from .solution_checks import MIN_MARGIN, check_solutions
from .whole_body_solution import STAGES, WholeBodySolution, check_rank

__all__ = ["MAX_ITERATIONS", "PAIR_RANGE", "RefinementProblem", "SOLVE_BUDGET", "refine", "solve_whole_body"]

#: SLSQP's iteration budget per start.
MAX_ITERATIONS = 40
#: Capsule pairs farther apart than this at a start (m) are left out of that start's constraints (and checked
#: exactly at the end like every pair).
PAIR_RANGE = 0.25
#: The most solves (a segmented solve, a batch of the lifted chain's IK, an SLSQP run from one start) the whole-body
#: solve makes with the base moved (stage 3 of ``target_search.solve_target``; stages 1 and 2 make at most four),
#: and the most starts :func:`solve_whole_body` refines: the bound on the work for a target out of reach, counted
#: rather than timed so that the same inputs and seed give the same answer whatever the machine's load. 60 is stage
#: 3's whole search on the default robot (five base shapes, each one segmented solve and ten placements' IK, then
#: five refinements); a caller that needs a tighter bound passes a smaller ``budget`` (40 leaves out the
#: refinements).
SOLVE_BUDGET = 60


def _direction_basis(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors orthogonal to d and to each other."""
    helper = np.array([0.0, 0.0, 1.0]) if abs(d[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(d, e1)


class RefinementProblem:
    """The optimisation problem of one target from one start (q_template, base0), variables z = (free joints,
    [x, y, yaw] when the base moves): its objective, constraints and their Jacobians for SLSQP."""

    def __init__(self, prob: BodyProblem, q_template: np.ndarray, base0: BasePlacement, position: np.ndarray,
                 direction: np.ndarray, move_base: bool, obstacles: Sequence[Any], min_margin: float,
                 self_clearance: float, obstacle_clearance: float, regularise: np.ndarray | None) -> None:
        self.prob, self.r = prob, prob.robot
        self.q_template = q_template.copy()
        self.q_template[prob.flat] = 0.0
        self.base0 = base0
        self.p_des, self.d_des = position, direction
        self.e1, self.e2 = _direction_basis(direction)
        self.move_base = move_base
        self.obstacles = list(obstacles)
        self.min_margin, self.self_gap, self.obs_gap = min_margin, self_clearance, obstacle_clearance
        # the base kept: its placement and its flat shape (the ground links' yaw joints) stay as they are
        self.free = np.flatnonzero(prob.free if move_base else prob.free & ~prob.ground_yaw)
        self.n = self.r.n_joints
        self.reg = regularise
        self._cache_z: np.ndarray | None = None
        self._cache: dict | None = None
        # the capsule pairs that can come near: not two ground links when the base is kept (they do not move
        # relative to each other), and not farther apart at the start than a few links can close in one solve
        F = prob.frames(self.q_template, base0)
        ends = prob.capsules(F)
        i, j = prob.pairs[:, 0], prob.pairs[:, 1]
        s_, t_ = coll.segment_closest(ends[i, 0], ends[i, 1], ends[j, 0], ends[j, 1])
        gap = np.linalg.norm(ends[i, 0] + s_[:, None] * (ends[i, 1] - ends[i, 0])
                             - ends[j, 0] - t_[:, None] * (ends[j, 1] - ends[j, 0]), axis=1)
        ground = np.isin(prob.shaped[i], prob.ground_links) & np.isin(prob.shaped[j], prob.ground_links)
        keep = gap < PAIR_RANGE
        if not move_base:
            keep &= ~ground
        self.pairs = prob.pairs[keep]

    def unpack(self, z: np.ndarray) -> tuple[np.ndarray, BasePlacement]:
        """The configuration (n,) and placement of variables z."""
        q = self.q_template.copy()
        q[self.free] = z[:len(self.free)]
        if self.move_base:
            x, y, yaw = z[len(self.free):]
            return q, self.base0.moved(float(x), float(y), float(yaw))
        return q, self.base0

    def pack(self, q: np.ndarray, base: BasePlacement) -> np.ndarray:
        """The variables z of a configuration q (n,) and placement."""
        z = q[self.free]
        return np.concatenate([z, [base.x, base.y, base.yaw]]) if self.move_base else z.copy()

    def columns(self) -> np.ndarray:
        """Indices into the (n + 3) gradient of the variables."""
        cols = [int(c) for c in self.free]
        if self.move_base:
            cols += [self.n, self.n + 1, self.n + 2]
        return np.array(cols)

    def bounds(self) -> list:
        """SLSQP's bounds of the variables: the free joints' limits, the placement unbounded."""
        lo, hi = self.r.lower[self.free], self.r.upper[self.free]
        b = list(zip(lo, hi))
        if self.move_base:
            b += [(None, None)] * 3
        return b

    def evaluate(self, z: np.ndarray) -> dict:
        """At variables z: the head's residuals ``eq`` (5,) (position, direction across its two normals) and the
        inequalities ``ineq`` (>= 0 when met: margin, lifted links' ground clearance, capsule pairs' clearance,
        obstacles' clearance), each with its Jacobian over z, and the margin with its gradient. Kept for the last
        z (SLSQP asks for each part separately)."""
        if self._cache is not None and self._cache_z is not None and np.array_equal(z, self._cache_z):
            return self._cache
        prob = self.prob
        cols = self.columns()
        q, base = self.unpack(z)
        F = prob.frames(q, base)
        out: dict = {"q": q, "base": base, "F": F}
        out["eq"], out["eq_jac"] = self._head_rows(F, base, cols)
        margin, g = prob.margin_and_gradient(F, base)
        out["margin"], out["margin_jac"] = margin, g[cols]
        ineq, ineq_jac = [np.array([margin - self.min_margin])], [g[cols][None]]
        rows = self._ground_rows(F, base, cols)
        if rows is not None:
            out["ground"] = float(rows[0].min())
        ends = prob.capsules(F)
        rows_all = [rows, self._self_rows(F, base, cols, ends)]
        if self.obstacles:
            rows_all += self._obstacle_rows(F, base, cols, ends)
        for row in rows_all:
            if row is not None:
                ineq.append(row[0])
                ineq_jac.append(row[1])
        out["ineq"] = np.concatenate(ineq)
        out["ineq_jac"] = np.vstack(ineq_jac)
        self._cache_z, self._cache = z.copy(), out
        return out

    def _head_rows(self, F: np.ndarray, base: BasePlacement, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The head's position error (3,) and its direction across the desired one (2,), and their Jacobian."""
        prob = self.prob
        H = F[prob.head_index]
        p, x = H[:3, 3], H[:3, 0]
        Jp = prob.point_jacobians(F, base, p[None], np.array([prob.head_index]))[0][:, cols]
        Jx = prob.vector_jacobian(F, x, prob.head_index)[:, cols]
        return np.concatenate([p - self.p_des, [x @ self.e1, x @ self.e2]]), np.vstack([Jp, self.e1 @ Jx, self.e2 @ Jx])

    def _ground_rows(self, F: np.ndarray, base: BasePlacement, cols: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray] | None:
        """The height of the lowest point of every lifted link's shapes, and its Jacobian (None: no lifted link)."""
        lifted = self.prob.lifted_links
        if not len(lifted):
            return None
        low = self.r.lowest_point_per_link(F, lifted)
        Jg = self.prob.point_jacobians(F, base, low, lifted)[:, 2, :][:, cols]
        return low[:, 2], Jg

    def _self_rows(self, F: np.ndarray, base: BasePlacement, cols: np.ndarray, ends: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
        """The kept capsule pairs' distances less what they need (radii, corner excess, ``self_clearance``), and
        their Jacobian; ``ends`` (k, 2, 3): the capsules' world axes."""
        prob = self.prob
        i, j = self.pairs[:, 0], self.pairs[:, 1]
        s, t = coll.segment_closest(ends[i, 0], ends[i, 1], ends[j, 0], ends[j, 1])
        pa = ends[i, 0] + s[:, None] * (ends[i, 1] - ends[i, 0])
        pb = ends[j, 0] + t[:, None] * (ends[j, 1] - ends[j, 0])
        diff = pa - pb
        dist = np.linalg.norm(diff, axis=1)
        u = diff / np.maximum(dist, 1e-12)[:, None]
        need = prob.radius[i] + prob.radius[j] + prob.corner_excess[i] + prob.corner_excess[j] + self.self_gap
        links = prob.shaped
        JA = prob.point_jacobians(F, base, pa, links[i])
        JB = prob.point_jacobians(F, base, pb, links[j])
        return dist - need, np.einsum("pi,pij->pj", u, JA - JB)[:, cols]

    def _obstacle_rows(self, F: np.ndarray, base: BasePlacement, cols: np.ndarray, ends: np.ndarray
                       ) -> list[tuple[np.ndarray, np.ndarray]]:
        """Per obstacle, the clearance of points along every capsule (less its radius, corner excess and
        ``obstacle_clearance``) by the obstacle's distance field, and its Jacobian."""
        prob = self.prob
        samples = np.linspace(0.0, 1.0, 4)
        pts = (ends[:, None, 0] + samples[None, :, None] * (ends[:, None, 1] - ends[:, None, 0])).reshape(-1, 3)
        plinks = np.repeat(prob.shaped, len(samples))
        prad = np.repeat(prob.radius + prob.corner_excess, len(samples))
        Jpts = prob.point_jacobians(F, base, pts, plinks)[:, :, cols]
        rows = []
        for ob in self.obstacles:
            dist_o, grad_o = _distance_and_gradient(ob, pts)
            rows.append((dist_o - prad - self.obs_gap, np.einsum("pi,pij->pj", grad_o, Jpts)))
        return rows

    def objective(self, z: np.ndarray) -> Any:
        """SLSQP's objective: minus the static margin, plus a small pull towards the start."""
        e = self.evaluate(z)
        f = -e["margin"]
        if self.reg is not None:
            d = z - self.reg
            f += 1e-3 * float(d @ d)
        return f

    def objective_jac(self, z: np.ndarray) -> Any:
        """The gradient of :meth:`objective` over z."""
        e = self.evaluate(z)
        g = -e["margin_jac"].copy()
        if self.reg is not None:
            g += 2e-3 * (z - self.reg)
        return g


def _distance_and_gradient(ob: Any, pts: np.ndarray, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """An obstacle's distance at points (P, 3) and its gradient by central differences."""
    def dist(x: np.ndarray) -> Any:
        if isinstance(ob, BoxObstacle):
            loc = (x - ob.centre) @ ob.rotation
            q = np.abs(loc) - ob.size / 2
            outside = np.linalg.norm(np.maximum(q, 0.0), axis=-1)
            inside = np.minimum(q.max(axis=-1), 0.0)
            return outside + inside
        return ob.distance_to_points(x)

    d0 = dist(pts)
    g = np.empty_like(pts)
    for k in range(3):
        dx = np.zeros(3)
        dx[k] = h
        g[:, k] = (dist(pts + dx) - dist(pts - dx)) / (2 * h)
    return d0, g


def refine(prob: BodyProblem, q0: np.ndarray, base0: BasePlacement, position: np.ndarray, direction: np.ndarray, *,
           move_base: bool, obstacles: Sequence[Any] = (), min_margin: float = MIN_MARGIN,
           self_clearance: float = SELF_CLEARANCE, obstacle_clearance: float = OBSTACLE_CLEARANCE,
           max_iterations: int = MAX_ITERATIONS) -> tuple[np.ndarray, BasePlacement]:
    """One SLSQP run from (q0, base0): the configuration and placement it ends at."""
    obj = RefinementProblem(prob, q0, base0, position, direction, move_base, obstacles, min_margin, self_clearance,
                            obstacle_clearance, None)
    z0 = np.clip(obj.pack(q0, base0), [b[0] if b[0] is not None else -np.inf for b in obj.bounds()],
                 [b[1] if b[1] is not None else np.inf for b in obj.bounds()])
    obj.reg = z0.copy()
    cons = [{"type": "eq", "fun": lambda z: obj.evaluate(z)["eq"], "jac": lambda z: obj.evaluate(z)["eq_jac"]},
            {"type": "ineq", "fun": lambda z: obj.evaluate(z)["ineq"], "jac": lambda z: obj.evaluate(z)["ineq_jac"]}]
    res = optimize.minimize(obj.objective, z0, jac=obj.objective_jac, bounds=obj.bounds(), constraints=cons,
                            method="SLSQP", options={"maxiter": int(max_iterations), "ftol": 1e-9})
    return obj.unpack(res.x)


def solve_whole_body(robot: SnakeRobot, position: npt.ArrayLike, direction: npt.ArrayLike, starts: Sequence[Any], *,
                     move_base: bool = True, obstacles: Sequence[Any] = (), min_margin: float = MIN_MARGIN,
                     self_clearance: float = SELF_CLEARANCE, obstacle_clearance: float = OBSTACLE_CLEARANCE,
                     problem: BodyProblem | None = None, budget: int = SOLVE_BUDGET) -> WholeBodySolution:
    """The whole-body solve from ``starts``, a sequence of (q (n,), BasePlacement) in the order to try; the first
    whose refined solution passes every exact check is returned (stage "whole-body, base kept" when its base is
    the first start's, else "whole-body, base moved"), else the best attempt with the reason it fails.
    At most ``budget`` starts are refined (a count, not a time: the answer does not depend on the machine's load)."""
    t0 = time.perf_counter()
    robot = as_robot(robot)
    position, direction = vector3(position, "position"), unit_vector3(direction, "direction")
    prob = problem if problem is not None else BodyProblem(robot)
    min_margin = finite_float(min_margin, "min_margin")
    budget = integer(budget, "budget", least=1)
    starts = list(starts)
    if not starts:
        raise InputError("the whole-body solve needs at least one start (q, base)")
    base_first = starts[0][1]
    best: tuple[np.ndarray, BasePlacement, dict] | None = None
    best_key: tuple[int, float] | None = None
    tried = 0
    for q0, b0 in starts[:budget]:
        tried += 1
        q, b = refine(prob, np.asarray(q0, float), b0, position, direction, move_base=move_base, obstacles=obstacles,
                      min_margin=min_margin, self_clearance=self_clearance, obstacle_clearance=obstacle_clearance)
        q = np.clip(q, robot.lower, robot.upper)
        chk = check_solutions(robot, q[None], b, position, direction, obstacles, min_margin=min_margin,
                              obstacle_clearance=obstacle_clearance)[0]
        key = check_rank(chk)
        if best is None or best_key is None or key > best_key:
            best, best_key = (q, b, chk), key
        if chk["reason"] is None:
            break
    if best is None:
        raise InternalError("the whole-body solve refined no start")
    q, b, chk = best
    same = b == base_first
    stage = None if chk["reason"] else (STAGES[1] if same else STAGES[2])
    return WholeBodySolution(q=q, base=b, stage=stage, reason=chk["reason"], position_error_m=chk["position_error_m"],
                             direction_error_deg=chk["direction_error_deg"], static_margin_m=chk["static_margin_m"],
                             ground_clearance_m=chk["ground_clearance_m"], self_clearance_m=chk["self_clearance_m"],
                             obstacle_clearance_m=chk["obstacle_clearance_m"], starts=tried,
                             seconds=time.perf_counter() - t0)
