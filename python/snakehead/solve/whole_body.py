"""The stability-aware whole-body solve: every joint and the base's placement at once.

The paper's segmented solve (:class:`~snakehead.solve.head_controller.HeadController`: the base on its arc, the neck
by Eqs. 18-22, the head by TRAC-IK) reaches many targets in milliseconds, but it checks stability instead of
seeking it and keeps the base where it is. When it fails, leaves the centre of mass outside the support polygon,
puts a link in the ground or into an obstacle, this module solves one optimisation problem:

    maximise   the static margin of the centre of mass in the support polygon (Eqs. 23-24)
    over       the base's yaw joints (its flat shape: pitch joints flat, the base lying on the ground), the
               neck and head joints, and (optionally) the base placement (x, y, yaw)
    such that  the head is at the position pointing along the direction (roll free, or fixed),
               margin >= ``min_margin``, every lifted link above the ground, no two links closer than
               ``self_clearance``, every link ``obstacle_clearance`` from every obstacle, joints within limits.

It is solved by SciPy's SLSQP with analytic gradients (the Jacobians of world points of the body, the centre of
mass and the polygon's active edge) from several starts: the segmented solution, the current configuration, and
the segmented solutions from base placements that bring the target into the neck's accepted range and from
other base arcs. Links are capsules in the optimisation (``SnakeRobot.link_capsules``: inside their shapes along the
body, what sticks out of them (a box's corners) added to the clearance); every solution is then checked exactly
(the shapes' signed distances, the support polygon of their ground footprint).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize

from .. import _core
from .._validate import finite_float, integer, joint_vector, unit_vector3, vector3
from ..dynamics import stability
from ..collision import body_collisions as coll
from .. import margins
from ..margins import EXACT_DISTANCE_WITHIN, OBSTACLE_CLEARANCE, SELF_CLEARANCE
from ..geometry.shapes import pair_min_distances
from ..model.robot import PITCH, BasePlacement, SnakeRobot, as_base, as_robot

import numpy.typing as npt
from typing import TYPE_CHECKING, Any, Callable, Sequence
from .._errors import InputError, InternalError

if TYPE_CHECKING:
    from .head_controller import HeadController

#: Default required static margin of a solution (m): the plans' (``margins.SOLUTION_MARGIN``).
MIN_MARGIN = margins.SOLUTION_MARGIN
#: A ground link's shape points within this height (m) of its lowest point touch the ground (its support).
CONTACT_BAND = 1e-3
#: Tolerances of a solution: head position (m) and direction (rad).
POSITION_TOLERANCE = 1e-4
DIRECTION_TOLERANCE = np.radians(0.05)
#: SLSQP's iteration budget per start.
MAX_ITERATIONS = 40
#: The most solves (a segmented solve, a batch of the lifted chain's IK, an SLSQP run from one start) the whole-body
#: solve makes with the base moved (stage 3 of :func:`solve_target`; stages 1 and 2 make at most four), and the most
#: starts :func:`solve_whole_body` refines: the bound on the work for a target out of reach, counted rather than
#: timed so that the same inputs and seed give the same answer whatever the machine's load. 60 is stage 3's whole
#: search on the default robot (five base shapes, each one segmented solve and ten placements' IK, then five
#: refinements; ~2 s of CPU when nothing passes), which the 3 s time budget it replaces allowed on an idle machine;
#: targets reachable by construction take at most 8 (bench/plan_speed.py's sets). A caller that needs a tighter
#: bound passes a smaller ``budget`` (40 leaves out the refinements: ~0.5 s).
SOLVE_BUDGET = 60
#: TRAC-IK's budget per call (s) on the lifted chain. (It races its two solvers until one succeeds or this runs
#: out: the one part of a whole-body solve that still depends on the machine's speed.)
LIFTED_IK_TIMEOUT_S = 0.002
#: Capsule pairs farther apart than this at a start (m) are left out of that start's constraints (and checked
#: exactly at the end like every pair).
PAIR_RANGE = 0.25

STAGES = ("segmented", "whole-body, base kept", "whole-body, base moved")
REASONS = ("out of reach", "no stable pose", "no clear pose")


@dataclass
class WholeBodySolution:
    """A whole-body solution (or the best attempt).

    q (n,) rad and base: the configuration and the base placement. stage: which of ``STAGES`` solved it (None
    when unsolved). reason: None when solved, else one of ``REASONS`` (what the best attempt lacked).
    position_error_m, direction_error_deg: of the head; static_margin_m (support polygon of the links on the
    ground), ground_clearance_m (lowest lifted box corner), self_clearance_m (separating-axis gap),
    obstacle_clearance_m (None without obstacles). starts: how many starts were tried; seconds: solve time.
    """

    q: np.ndarray
    base: BasePlacement
    stage: str | None
    reason: str | None
    position_error_m: float
    direction_error_deg: float
    static_margin_m: float
    ground_clearance_m: float
    self_clearance_m: float
    obstacle_clearance_m: float | None
    starts: int = 0
    seconds: float = 0.0
    notes: list = field(default_factory=list)
    #: the paper's segmented solution (a ``HeadSolution``) tried first, when there was one
    segmented: object | None = None
    #: the desired head frame (4, 4) (x-axis the direction)
    desired_frame: np.ndarray | None = None

    @property
    def success(self) -> bool:
        return self.reason is None

    @property
    def message(self) -> str:
        if self.success:
            return f"solved ({self.stage})"
        return (f"{self.reason}: head {1000 * self.position_error_m:.1f} mm / {self.direction_error_deg:.2f} deg off, "
                f"static margin {1000 * self.static_margin_m:.1f} mm, ground clearance "
                f"{1000 * self.ground_clearance_m:.1f} mm, self clearance {1000 * self.self_clearance_m:.1f} mm")

    @property
    def neck_goal(self) -> Any:
        """Eqs. 18-20's goal of the segmented solve, when that solve is the solution (for Fig. 8)."""
        return getattr(self.segmented, "neck_goal", None) if self.stage == STAGES[0] else None

    @property
    def neck(self) -> Any:
        return getattr(self.segmented, "neck", None) if self.stage == STAGES[0] else None


class PlanSolves:
    """The solves of one plan's targets that its steps share (the base's choice, the relocation's search and the
    targets' solves ask for the same ones): the whole-body solves with the base kept (``kept``: the planner's
    :func:`~snakehead.planning.target_solves.solve_kept` keys them), and the segmented solves
    (:meth:`HeadController.solve_checked <snakehead.solve.head_controller.HeadController.solve_checked>`) and the lifted
    chain's IK candidates (:func:`lifted_candidates`) of :func:`solve_checked_target`. Every one is deterministic
    (the same arguments give the same solution: the IK is seeded, its searches bounded by counts), so an entry
    stands for a solve again. Owned by one plan: its controller and obstacles are fixed for its life, and it
    is dropped with the plan (no bound on its size: a plan solves a bounded number of targets)."""

    def __init__(self) -> None:
        self.kept: dict[tuple, WholeBodySolution] = {}
        self.segmented: dict[tuple, Any] = {}
        self.candidates: dict[tuple, list[np.ndarray]] = {}


class BodyProblem:
    """The geometry of one robot that the whole-body solve needs, computed once: which joints are free, which
    links lie on the ground, the links' capsules and the pairs that may collide."""

    def __init__(self, robot: SnakeRobot) -> None:
        self.robot = robot = as_robot(robot)
        n = robot.n_joints
        child = np.asarray(robot.body.model.joint_child_links)
        self.child = child
        first_lifted_link = int(child[robot.lift_joints.start]) if robot.lift_joints.start < n else len(child) + 10**6
        ground_joint = np.arange(n) < robot.lift_joints.start
        kinds = np.array(robot.joint_kinds)
        #: joints held at zero: the pitch joints of the links lying on the ground (the base lies flat)
        self.flat = ground_joint & (kinds == PITCH)
        #: free joints: the ground links' yaw joints (the base's flat shape) and every lifted joint
        self.free = ~self.flat
        self.ground_yaw = ground_joint & ~self.flat
        shaped = robot.shaped_links
        self.ground_links = shaped[shaped < first_lifted_link]
        self.lifted_links = shaped[shaped >= first_lifted_link]
        self.shaped = shaped
        ends, radius, excess = robot.link_capsules
        # a capsule inside each link's shapes along the body (radius the smallest half-width across it)
        self.capsule_ends = ends[shaped]
        self.radius = radius[shaped]
        #: how far the shapes stick out of their capsule (sqrt(2) - 1 of the radius for a box of square section)
        self.corner_excess = excess[shaped]
        segment = np.array([robot._joints_before(int(k)) for k in shaped])
        i, j = np.triu_indices(len(shaped), k=1)
        # links two or more joints apart (links one joint apart touch at it; a module's links never move apart)
        far = segment[j] - segment[i] >= 2
        self.pairs = np.column_stack([i, j])[far]
        self.axis_local = np.asarray(robot.body.model.joint_axes, float)
        self.head_index = robot.link_index(robot.parts.head_tip)
        self._iks: dict = {}
        self._pose_bounds: Any = None

    @property
    def pose_bounds(self) -> Any:
        """The robot's necessary conditions of a pose (``solve.pose_bounds.PoseBounds``), made once: the solve
        asks them before an IK batch or a segmented solve that they prove cannot succeed."""
        if self._pose_bounds is None:
            from .pose_bounds import PoseBounds

            self._pose_bounds = PoseBounds.of(self.robot, np.zeros(self.robot.n_joints))
        return self._pose_bounds

    def out_of_reach(self, q: np.ndarray, base: BasePlacement, position: np.ndarray, direction: np.ndarray) -> bool:
        """Whether no pose of the lifted chain from the frame it lifts from in ``q`` at ``base`` (the links before
        it kept) puts the head at ``position`` along ``direction`` within the checks' tolerances: the first frame
        rigid with the tip is then farther from that frame than the chain between them
        (``PoseBounds.out_of_reach``, its soundness tested in tests/test_reach_bounds.py). The lifted chain's IK
        cannot succeed there either: its tolerance (``epsilon``, 1e-5 per axis) is inside the checks'."""
        origin = self.robot.frame(q, self.robot.lift_frame, base)[:3, 3]
        return bool(self.pose_bounds.out_of_reach(position, direction, origin)[0])

    def lifted_ik(self, seed: int = 0) -> Any:
        """TRAC-IK of the lifted chain (lift_frame -> head_tip), seeded (made once per seed)."""
        from ..kinematics.ik import TracIK

        if seed not in self._iks:
            chain = self.robot.sub_chain(self.robot.lift_frame, self.robot.parts.head_tip)
            self._iks[seed] = TracIK.from_chain(chain, timeout=LIFTED_IK_TIMEOUT_S, seed=seed)
        return self._iks[seed]

    # --- kinematics of world points ---------------------------------------------------------------------------
    def frames(self, q: np.ndarray, base: BasePlacement) -> np.ndarray:
        return self.robot.frames(q, base)

    def point_jacobians(self, F: np.ndarray, base: BasePlacement, points: np.ndarray, links: np.ndarray
                        ) -> np.ndarray:
        return self.robot.point_jacobians(F, points, links)

    def vector_jacobian(self, F: np.ndarray, v: np.ndarray, link: int) -> np.ndarray:
        """d(v)/d(q, x, y, yaw) of a world direction v attached to ``link``: (3, n + 3)."""
        a, _ = self.robot.joint_axes_world(F)
        n = len(a)
        J = np.zeros((3, n + 3))
        J[:, :n] = (np.cross(a, v) * (self.child <= link)[:, None]).T
        J[:, n + 2] = np.cross([0.0, 0.0, 1.0], v)
        return J

    def capsules(self, F: np.ndarray) -> np.ndarray:
        """World end points (k, 2, 3) of the links' capsule axes."""
        G = F[self.shaped]
        return np.einsum("kij,kej->kei", G[:, :3, :3], self.capsule_ends) + G[:, None, :3, 3]

    # --- the support polygon and the static margin ---------------------------------------------------------
    def contact_points(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World (P, 3) bottom points of the ground links' shapes (within CONTACT_BAND of each link's lowest: a
        box's bottom corners, a cylinder's bottom line) and their links (P,)."""
        pts, owner = self.robot.lowest_points(F[None], self.ground_links)
        pts = pts[0]
        lowest = np.full(len(self.robot.link_names), np.inf)
        np.minimum.at(lowest, owner, pts[:, 2])
        keep = pts[:, 2] <= lowest[owner] + CONTACT_BAND
        return pts[keep], owner[keep]

    def _link_coms(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The links that have a mass (k,) and their centres of mass (..., k, 3), world, from frames
        (..., n_links, 4, 4)."""
        r = self.robot
        heavy = np.flatnonzero(r.masses > 0)
        G = F[..., heavy, :, :]
        return heavy, G[..., :3, 3] + np.einsum("...lij,lj->...li", G[..., :3, :3], r.coms[heavy])

    def com_and_jacobian(self, F: np.ndarray, base: BasePlacement) -> tuple[np.ndarray, np.ndarray]:
        m = self.robot.masses
        heavy, c_i = self._link_coms(F)
        M = m[heavy].sum()
        J = self.point_jacobians(F, base, c_i, heavy)
        return (m[heavy, None] * c_i).sum(0) / M, np.einsum("l,lij->ij", m[heavy], J) / M

    def margin(self, F: np.ndarray) -> float:
        """:meth:`margin_and_gradient`'s margin alone (no Jacobians: for checks), from the frames (n_links, 4, 4)."""
        return float(self.margins(F[None])[0])

    def margins(self, frames: np.ndarray) -> np.ndarray:
        """:meth:`margin` of many configurations at once, from their world frames (K, n_links, 4, 4): (K,). The
        contacts of each (:meth:`contact_points`: a ground link's shape points within CONTACT_BAND of its lowest)
        are masked, and every polygon's margin is taken in one call of the core's hull (``hull_margins``); a
        polygon of fewer than three vertices (collinear contacts) has no interior: -inf."""
        m = self.robot.masses
        pts, owner = self.robot.lowest_points(frames, self.ground_links)  # (K, P, 3), (P,)
        z = pts[..., 2]
        lowest = np.empty_like(z)
        for link in np.unique(owner):
            mine = owner == link
            lowest[:, mine] = z[:, mine].min(axis=1, keepdims=True)
        keep = z <= lowest + CONTACT_BAND
        heavy, c_i = self._link_coms(frames)
        c = (m[heavy, None] * c_i).sum(-2) / m[heavy].sum()
        xy = np.ascontiguousarray(pts[..., :2])
        margins = _core.hull_margins(xy, np.ascontiguousarray(keep), np.ascontiguousarray(c[:, :2]))
        # a degenerate hull's margin (minus the distance to its segment) is <= 0: only those samples are looked at
        for k in np.flatnonzero(margins <= 0):
            if len(_core.convex_hull_2d(np.ascontiguousarray(xy[k, keep[k]]))) < 3:
                margins[k] = -np.inf
        return margins

    def margin_and_gradient(self, F: np.ndarray, base: BasePlacement) -> tuple[float, np.ndarray]:
        """Signed distance of the CoM's ground projection to the support polygon's nearest edge (> 0 inside) and
        its gradient (n + 3,) through the active edge."""
        c, Jc = self.com_and_jacobian(F, base)
        pts, links = self.contact_points(F)
        idx = stability.hull_indices(pts[:, :2])
        if len(idx) < 3:
            return -np.inf, np.zeros(Jc.shape[1])
        A = pts[idx, :2]
        B = np.roll(A, -1, axis=0)
        e = B - A
        ell = np.linalg.norm(e, axis=1)
        t = e / ell[:, None]
        nrm = np.column_stack([-t[:, 1], t[:, 0]])  # inward for a counter-clockwise polygon
        d = np.einsum("ki,ki->k", nrm, c[:2] - A)
        # outside: the distance to the polygon (edge segments); inside: to the nearest edge line
        if np.all(d >= 0):
            k = int(np.argmin(d))
            margin = float(d[k])
        else:
            u = np.clip(np.einsum("ki,ki->k", c[:2] - A, t), 0.0, ell)
            closest = A + u[:, None] * t
            dist = np.linalg.norm(c[:2] - closest, axis=1)
            k = int(np.argmin(dist))
            margin = -float(dist[k])
        ka, kb = idx[k], idx[(k + 1) % len(idx)]
        Jp = self.point_jacobians(F, base, pts[[ka, kb]], links[[ka, kb]])[:, :2, :]  # (2, 2, m)
        if margin >= 0:
            n_k, a_k, t_k, l_k = nrm[k], A[k], t[k], ell[k]
            # d margin = n . (dc - da) + (c - a) . dn,  dn = R90 (I - t t^T)(db - da) / l
            R90 = np.array([[0.0, -1.0], [1.0, 0.0]])
            P = R90 @ (np.eye(2) - np.outer(t_k, t_k)) / l_k
            g = n_k @ (Jc[:2] - Jp[0]) + (c[:2] - a_k) @ P @ (Jp[1] - Jp[0])
        else:
            diff = c[:2] - closest[k]
            dn = diff / max(np.linalg.norm(diff), 1e-12)
            s = u[k] / ell[k]
            g = -(dn @ (Jc[:2] - ((1 - s) * Jp[0] + s * Jp[1])))
        return margin, g


def _direction_basis(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors orthogonal to d and to each other."""
    helper = np.array([0.0, 0.0, 1.0]) if abs(d[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(d, e1)


class _Objective:
    """The optimisation problem for one target, variables z = (free joints, [x, y, yaw] when the base moves)."""

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
        q = self.q_template.copy()
        q[self.free] = z[:len(self.free)]
        if self.move_base:
            x, y, yaw = z[len(self.free):]
            return q, BasePlacement(float(x), float(y), float(yaw))
        return q, self.base0

    def pack(self, q: np.ndarray, base: BasePlacement) -> np.ndarray:
        z = q[self.free]
        return np.concatenate([z, [base.x, base.y, base.yaw]]) if self.move_base else z.copy()

    def columns(self) -> np.ndarray:
        """Indices into the (n + 3) gradient of the variables."""
        cols = [int(c) for c in self.free]
        if self.move_base:
            cols += [self.n, self.n + 1, self.n + 2]
        return np.array(cols)

    def bounds(self) -> list:
        lo, hi = self.r.lower[self.free], self.r.upper[self.free]
        b = list(zip(lo, hi))
        if self.move_base:
            b += [(None, None)] * 3
        return b

    def evaluate(self, z: np.ndarray) -> dict:
        if self._cache is not None and self._cache_z is not None and np.array_equal(z, self._cache_z):
            return self._cache
        prob, r = self.prob, self.r
        cols = self.columns()
        q, base = self.unpack(z)
        F = prob.frames(q, base)
        out: dict = {"q": q, "base": base, "F": F}
        # head position and direction
        H = F[prob.head_index]
        p, x = H[:3, 3], H[:3, 0]
        Jp = prob.point_jacobians(F, base, p[None], np.array([prob.head_index]))[0][:, cols]
        Jx = prob.vector_jacobian(F, x, prob.head_index)[:, cols]
        out["eq"] = np.concatenate([p - self.p_des, [x @ self.e1, x @ self.e2]])
        out["eq_jac"] = np.vstack([Jp, self.e1 @ Jx, self.e2 @ Jx])
        # static margin
        margin, g = prob.margin_and_gradient(F, base)
        out["margin"], out["margin_jac"] = margin, g[cols]
        ineq, ineq_jac = [np.array([margin - self.min_margin])], [g[cols][None]]
        # ground: the lowest point of every lifted link's shapes above the ground
        lifted = prob.lifted_links
        if len(lifted):
            low = r.lowest_point_per_link(F, lifted)
            Jg = prob.point_jacobians(F, base, low, lifted)[:, 2, :][:, cols]
            ineq.append(low[:, 2])
            ineq_jac.append(Jg)
            out["ground"] = float(low[:, 2].min())
        # self: capsule distances of the pairs
        ends = prob.capsules(F)
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
        ineq.append(dist - need)
        ineq_jac.append(np.einsum("pi,pij->pj", u, JA - JB)[:, cols])
        # obstacles: points along every capsule against each obstacle's distance field
        if self.obstacles:
            samples = np.linspace(0.0, 1.0, 4)
            pts = (ends[:, None, 0] + samples[None, :, None] * (ends[:, None, 1] - ends[:, None, 0])).reshape(-1, 3)
            plinks = np.repeat(links, len(samples))
            prad = np.repeat(prob.radius + prob.corner_excess, len(samples))
            Jpts = prob.point_jacobians(F, base, pts, plinks)[:, :, cols]
            for ob in self.obstacles:
                dist_o, grad_o = _distance_and_gradient(ob, pts)
                ineq.append(dist_o - prad - self.obs_gap)
                ineq_jac.append(np.einsum("pi,pij->pj", grad_o, Jpts))
        out["ineq"] = np.concatenate(ineq)
        out["ineq_jac"] = np.vstack(ineq_jac)
        self._cache_z, self._cache = z.copy(), out
        return out

    def objective(self, z: np.ndarray) -> Any:
        e = self.evaluate(z)
        f = -e["margin"]
        if self.reg is not None:
            d = z - self.reg
            f += 1e-3 * float(d @ d)
        return f

    def objective_jac(self, z: np.ndarray) -> Any:
        e = self.evaluate(z)
        g = -e["margin_jac"].copy()
        if self.reg is not None:
            g += 2e-3 * (z - self.reg)
        return g


def _distance_and_gradient(ob: Any, pts: np.ndarray, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """An obstacle's distance at points (P, 3) and its gradient by central differences."""
    from ..geometry.obstacles import BoxObstacle

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


def clear_of_obstacles(robot: SnakeRobot, q: np.ndarray, obstacles: Sequence[Any], base: BasePlacement,
                       clearance: float = OBSTACLE_CLEARANCE) -> bool:
    """Whether configuration q (n,) at ``base`` keeps more than ``clearance`` m from every obstacle (True without
    obstacles)."""
    if not obstacles:
        return True
    return bool(coll.collision_check(robot, q[None], list(obstacles), base,
                                     exact_within=EXACT_DISTANCE_WITHIN).distance[0] > clearance)


def check_solution(robot: SnakeRobot, q: np.ndarray, base: BasePlacement, position: np.ndarray, direction: np.ndarray,
                   obstacles: Sequence[Any] = (), *, min_margin: float = MIN_MARGIN, self_clearance: float = 0.0,
                   obstacle_clearance: float = OBSTACLE_CLEARANCE, problem: BodyProblem | None = None) -> dict:
    """Exact checks of a configuration: head errors, static margin (support polygon of the boxes lying on the
    ground), lowest lifted box corner, separating-axis self clearance, obstacle clearance, and the verdict
    (None or one of ``REASONS``).

    With ``problem``, the static margin is also taken without the lifted links (only the links that lie on the
    ground whatever the pose: ``BodyProblem.ground_links``), and the smaller one counts: a pose that stands only
    because a lifted link rests on the ground cannot be reached from the air (the body tips just before the link
    touches down), so a planner must not be given one."""
    robot = as_robot(robot)
    q = joint_vector(q, robot.n_joints)
    checks = check_solutions(robot, q[None], as_base(base), vector3(position, "position"),
                             unit_vector3(direction, "direction"), obstacles,
                             min_margin=finite_float(min_margin, "min_margin"),
                             self_clearance=finite_float(self_clearance, "self_clearance"),
                             obstacle_clearance=finite_float(obstacle_clearance, "obstacle_clearance"), problem=problem)
    return checks[0]


def check_solutions(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement, position: np.ndarray,
                    direction: np.ndarray, obstacles: Sequence[Any] = (), *, min_margin: float = MIN_MARGIN,
                    self_clearance: float = 0.0, obstacle_clearance: float = OBSTACLE_CLEARANCE,
                    problem: BodyProblem | None = None) -> list[dict]:
    """:func:`check_solution` of many configurations qs (K, n) at one placement, each check over the whole batch
    in one call (the frames by the core's batched forward kinematics, the support polygons by its hull, the shapes'
    lowest points and distances by its shape sets): the library's inner loop (the whole-body solve's candidates),
    whose arguments were checked where they entered (float64, finite, of the right shapes)."""
    frames = robot._frames_many_checked(qs, base)
    head = frames[:, robot.link_index(robot.parts.head_tip)]
    pe = np.linalg.norm(head[:, :3, 3] - position, axis=1)
    de = np.degrees(np.arccos(np.clip(head[:, :3, 0] @ direction, -1.0, 1.0)))
    com = stability.center_of_mass(robot, qs, base, frames=frames)
    margin = stability.static_margins_of_frames(robot, frames, com, "ground", stability.CONTACT_TOLERANCE)
    if problem is not None:
        margin = np.minimum(margin, problem.margins(frames))
    lifted = robot.lifted_links
    ground = robot.geometry.lowest_z(frames, lifted).min(axis=1) if len(lifted) else np.full(len(qs), np.inf)
    selfc = pair_min_distances(frames, robot.geometry, frames, robot.geometry, robot.self_collision_pairs)
    obst = (coll.collision_check(robot, qs, list(obstacles), base, exact_within=0.01).distance if obstacles
            else None)
    out = []
    for k in range(len(qs)):
        o = None if obst is None else float(obst[k])
        if pe[k] > POSITION_TOLERANCE or np.radians(de[k]) > DIRECTION_TOLERANCE:
            reason: str | None = "out of reach"
        elif margin[k] < min_margin:
            reason = "no stable pose"
        elif (ground[k] < -coll.GROUND_TOLERANCE or selfc[k] <= self_clearance
              or (o is not None and o <= obstacle_clearance)):
            reason = "no clear pose"
        else:
            reason = None
        out.append({"position_error_m": float(pe[k]), "direction_error_deg": float(de[k]),
                    "static_margin_m": float(margin[k]), "ground_clearance_m": float(ground[k]),
                    "self_clearance_m": float(selfc[k]), "obstacle_clearance_m": o, "reason": reason})
    return out


def refine(prob: BodyProblem, q0: np.ndarray, base0: BasePlacement, position: np.ndarray, direction: np.ndarray, *,
           move_base: bool, obstacles: Sequence[Any] = (), min_margin: float = MIN_MARGIN,
           self_clearance: float = SELF_CLEARANCE, obstacle_clearance: float = OBSTACLE_CLEARANCE,
           max_iterations: int = MAX_ITERATIONS) -> tuple[np.ndarray, BasePlacement]:
    """One SLSQP run from (q0, base0): the configuration and placement it ends at."""
    obj = _Objective(prob, q0, base0, position, direction, move_base, obstacles, min_margin, self_clearance,
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
        key = _rank_of(chk)
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


def _base_shapes(controller: HeadController) -> list[np.ndarray]:
    """Base joint vectors to start from besides the controller's: its arc turned the other way, a straight base,
    and arcs of a half and of one and a half times its central angle."""
    robot = controller.robot
    qb = controller.q_initial[robot.parts.base]
    lo, hi = robot.lower[robot.parts.base], robot.upper[robot.parts.base]
    return [-qb, np.zeros_like(qb), 0.5 * qb, np.clip(1.5 * qb, lo, hi)]


#: Rolled frames (Fig. 9) and starts per roll of the lifted chain's IK that give the whole-body solve its
#: candidates.
CANDIDATE_ROLLS = 8
CANDIDATE_SEEDS = 2


def lifted_candidates(prob: BodyProblem, q_now: np.ndarray, base: BasePlacement, position: np.ndarray,
                      direction: np.ndarray, seed: int = 0) -> list[np.ndarray]:
    """Whole-body configurations that put the head at the target with the base as it is: TRAC-IK on the lifted
    chain (the neck from where it lifts, and the head: ``lift_frame -> head_tip``) towards ``CANDIDATE_ROLLS``
    frames rolled about the direction (Fig. 9), each from the current joints, and from random joints the rolls
    reached from the current ones (:func:`_rolls_reached`)."""
    from .head import frame_along

    robot = prob.robot
    if prob.out_of_reach(q_now, base, position, direction):
        return []  # (what the batch would find: every IK fails)
    ik = prob.lifted_ik(seed)
    start = robot.lift_joints.start
    T0 = robot.frame(q_now, robot.lift_frame, base)
    target = np.linalg.inv(T0) @ frame_along(position, direction)
    angles = 2 * np.pi * np.arange(CANDIDATE_ROLLS) / CANDIDATE_ROLLS
    poses = np.concatenate([_rolled(target, angles)] * CANDIDATE_SEEDS)
    rng = np.random.default_rng(seed)
    inits = np.vstack([np.tile(q_now[start:], (CANDIDATE_ROLLS, 1))]
                      + [rng.uniform(ik.lower, ik.upper, (CANDIDATE_ROLLS, ik.n_joints))
                         for _ in range(CANDIDATE_SEEDS - 1)])
    qs, ok = _rolls_reached(ik, poses, inits)
    out = []
    for qk in qs[ok]:
        q = q_now.copy()
        q[start:] = qk
        out.append(q)
    return out


def _rolls_reached(ik: Any, poses: np.ndarray, inits: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`lifted_candidates`' IK: first every roll from the current joints, then the random starts of the rolls
    that the current joints' start reached (a roll it missed within its budget is out of the chain's reach with
    its limits nearly always: in 30 plans of bench/plan_speed.py's "shape" set, 67 of 69 such rolls failed from
    the random start too; and a failing target costs the IK's whole budget): (q (T, m), ok (T,)), the targets
    left out not found. Each target keeps its index in the batch as its stream (the same answers as one batch)."""
    first = np.arange(CANDIDATE_ROLLS)
    qs, ok = inits.copy(), np.zeros(len(poses), bool)
    qs[first], ok[first] = ik.ik_many(poses[first], inits[first], streams=first)
    rest = np.flatnonzero(np.tile(ok[first], CANDIDATE_SEEDS - 1)) + CANDIDATE_ROLLS
    if len(rest):
        qs[rest], ok[rest] = ik.ik_many(poses[rest], inits[rest], streams=rest)
    return qs, ok


def _rolled(T: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """``head.roll_about_x`` of a frame (4, 4) made here (valid) by each of ``angles`` (rad): (k, 4, 4), the same
    arithmetic without checking the frame again for every angle."""
    out = np.repeat(T[None], len(angles), axis=0)
    for k, angle in enumerate(angles):
        c, s = np.cos(float(angle)), np.sin(float(angle))
        out[k, :3, :3] = T[:3, :3] @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    return out


def _continue_from(prob: BodyProblem, q_now: np.ndarray, base: BasePlacement, position: np.ndarray,
                   direction: np.ndarray, seed: int) -> np.ndarray | None:
    """The lifted chain's IK from the current joints, the roll about the direction free: the nearest solution."""
    from ..kinematics.ik import FREE_ROLL
    from .head import frame_along

    robot = prob.robot
    start = robot.lift_joints.start
    T0 = robot.frame(q_now, robot.lift_frame, base)
    target = np.linalg.inv(T0) @ frame_along(position, direction)
    qk = prob.lifted_ik(seed).ik(target, q_init=np.clip(q_now[start:], robot.lower[start:], robot.upper[start:]),
                                 bounds=FREE_ROLL)
    if qk is None:
        return None
    q = q_now.copy()
    q[start:] = qk
    return q


def solve_target(controller: HeadController, position: npt.ArrayLike, direction: npt.ArrayLike, *,
                 q_prev: npt.ArrayLike | None = None, base: BasePlacement | None = None, obstacles: Sequence[Any] = (),
                 allow_base_move: bool = True, min_margin: float = MIN_MARGIN, budget: int = SOLVE_BUDGET,
                 problem: BodyProblem | None = None, seed: int = 0, near: bool = False,
                 shape_ok: Callable[[np.ndarray], bool] | None = None) -> WholeBodySolution:
    """Every joint (and, when allowed, the base's placement and flat shape) for one head target.

    Stages, the first that passes every exact check wins:

    1. the paper's segmented solve (:meth:`HeadController.solve`) from the base as it is;
    2. the base kept: the lifted chain's IK candidates (:func:`lifted_candidates`), then the whole-body
       optimisation over the lifted joints from the best of them and from the segmented solution;
    3. the base moved (when ``allow_base_move``): for the base's shape and other flat shapes (:func:`_base_shapes`),
       the placement that brings the target into the neck's accepted range (Section 3.3 (3)), the segmented
       solution and the IK candidates from there, then the whole-body optimisation over the base's yaw joints,
       its placement and the lifted joints.

    With ``near`` (for poses close to the previous one, e.g. along a line), a first attempt continues from
    ``q_prev``: the lifted chain's IK started from its joints with the roll free, kept when it passes every check
    (stage "whole-body, base kept"), so that consecutive poses stay on one branch of solutions.

    ``shape_ok``: a test of a moved base's flat shape (called with a configuration; only its joints before the
    lift count) that a solution of stage 3 must pass, e.g. the planner's: the shape holds a stable curl of the
    neck and head on the ground to lift them from. Shapes that fail it are not started from, and solutions whose
    shape fails it are not accepted (the search goes on).

    The result says which stage solved it, or why the best attempt fails (``REASONS``).
    """
    return solve_checked_target(controller, vector3(position, "position"), unit_vector3(direction, "direction"),
                                q_prev=q_prev, base=base, obstacles=obstacles, allow_base_move=allow_base_move,
                                min_margin=finite_float(min_margin, "min_margin"),
                                budget=integer(budget, "budget", least=1), problem=problem, seed=seed, near=near,
                                shape_ok=shape_ok)


def solve_checked_target(controller: HeadController, position: np.ndarray, direction: np.ndarray, *,
                         q_prev: npt.ArrayLike | None = None, base: BasePlacement | None = None,
                         obstacles: Sequence[Any] = (), allow_base_move: bool = True, min_margin: float = MIN_MARGIN,
                         budget: int = SOLVE_BUDGET, problem: BodyProblem | None = None, seed: int = 0,
                         near: bool = False, shape_ok: Callable[[np.ndarray], bool] | None = None,
                         kept: WholeBodySolution | None = None, memo: PlanSolves | None = None
                         ) -> WholeBodySolution:
    """:func:`solve_target` of a target already checked where it entered (a :class:`~snakehead.scenes.Target`'s
    position (3,) and unit direction (3,)): the planner's entry, which does not check them again.

    ``kept``: this solve's result with the base kept (the same arguments with ``allow_base_move=False``), when the
    caller has it (:func:`~snakehead.planning.target_solves.solve_kept`): stages 1 and 2 are not repeated (they are
    deterministic: the same arguments give the same solution), and a solution among them is returned as it is.
    ``memo``: the plan's :class:`PlanSolves`, whose segmented solves this solve shares."""
    search = _TargetSearch(controller, position, direction, q_prev, base, obstacles, min_margin, budget,
                           problem, seed, shape_ok, memo)
    if kept is not None:
        if kept.success:
            return kept
        search.best, search.segmented = kept, kept.segmented
        found = None
    else:
        found = search.base_kept(near and q_prev is not None)
    if found is None and allow_base_move:
        found = search.base_moved()
    return found if found is not None else _attempted(search.best)


class _TargetSearch:
    """One whole-body solve of :func:`solve_checked_target`: the target, the body as it is, the limits, and the best
    attempt so far (:meth:`consider`); its stages are :meth:`base_kept` (the near continuation, stages 1 and 2)
    and :meth:`base_moved` (stage 3), each returning the first solution that passes every check, else None."""

    def __init__(self, controller: HeadController, position: np.ndarray, direction: np.ndarray,
                 q_prev: npt.ArrayLike | None, base: BasePlacement | None, obstacles: Sequence[Any],
                 min_margin: float, budget: int, problem: BodyProblem | None, seed: int,
                 shape_ok: Callable[[np.ndarray], bool] | None, memo: PlanSolves | None = None) -> None:
        self.t0 = time.perf_counter()
        self.controller, self.robot = controller, controller.robot
        self.position, self.direction = position, direction
        self.base = controller.base if base is None else base
        self.q_now = controller.q_initial.copy() if q_prev is None else np.asarray(q_prev, float).copy()
        self.prob = problem if problem is not None else BodyProblem(self.robot)
        self.obstacles = list(obstacles)
        self.min_margin, self.budget, self.seed, self.shape_ok = min_margin, budget, seed, shape_ok
        self.spent = 0  # the solves of stage 3 so far (SOLVE_BUDGET)
        self.memo = memo
        self.best: WholeBodySolution | None = None
        self.segmented: Any = None  # the segmented solution, once stage 1 has run
        self.rejected_shapes: set = set()  # shapes that failed shape_ok (its cost may be that of a search)

    def afford(self) -> bool:
        """Whether stage 3 may make one more solve (a segmented solve, a batch of IK, a refinement) within its
        ``budget``; counts it when it may."""
        if self.out_of_work():
            return False
        self.spent += 1
        return True

    def out_of_work(self) -> bool:
        """Whether stage 3 has made its ``budget`` of solves."""
        return self.spent >= self.budget

    def check(self, q: np.ndarray, b: BasePlacement) -> dict:
        return self.check_many([q], b)[0]

    def check_many(self, qs: Sequence[np.ndarray], b: BasePlacement) -> list[dict]:
        """:func:`check_solutions` of configurations at one placement (one batch)."""
        if not len(qs):
            return []
        return check_solutions(self.robot, np.asarray(qs, float), b, self.position, self.direction, self.obstacles,
                               min_margin=self.min_margin, problem=self.prob)

    def consider(self, q: np.ndarray, b: BasePlacement, stage: str, starts: int,
                 chk: dict | None = None) -> WholeBodySolution | None:
        """Check a configuration (unless its check ``chk`` is given); keep the best attempt; return the solution
        when it passes."""
        chk = self.check(q, b) if chk is None else chk
        if chk["reason"] is not None and self.best is not None and _rank_of(chk) <= _rank(self.best):
            return None  # neither a solution nor a better attempt
        sol = WholeBodySolution(q=q, base=b, stage=stage if chk["reason"] is None else None, reason=chk["reason"],
                                position_error_m=chk["position_error_m"],
                                direction_error_deg=chk["direction_error_deg"],
                                static_margin_m=chk["static_margin_m"], ground_clearance_m=chk["ground_clearance_m"],
                                self_clearance_m=chk["self_clearance_m"],
                                obstacle_clearance_m=chk["obstacle_clearance_m"], starts=starts,
                                seconds=time.perf_counter() - self.t0)
        sol.segmented = self.segmented
        sol.desired_frame = None if self.segmented is None else self.segmented.desired_frame
        if self.best is None or _rank(sol) > _rank(self.best):
            self.best = sol
        return sol if sol.success else None

    def beyond_reach(self) -> bool:
        """With the base kept, the frame the neck lifts from stays where it is: whether the target is out of the
        lifted chain's reach from there (:meth:`BodyProblem.out_of_reach`), where stages 1 and 2 cannot succeed and
        their IK would spend its whole budget finding so. The segmented solve lifts the neck from the initial
        configuration's joints before the lift (``HeadController.solve_checked``): the target must be out of reach
        from that frame too."""
        q = self.q_now
        lift = self.robot.lift_joints.start
        neck = self.robot.parts.neck.start
        if not self.prob.out_of_reach(q, self.base, self.position, self.direction):
            return False
        if neck >= lift or np.array_equal(q[neck:lift], self.controller.q_initial[neck:lift]):
            return True
        q = q.copy()
        q[neck:lift] = self.controller.q_initial[neck:lift]
        return self.prob.out_of_reach(q, self.base, self.position, self.direction)

    def base_kept(self, near: bool) -> WholeBodySolution | None:
        """The base as it is: with ``near``, the lifted chain's IK continued from the current joints
        (:func:`_continue_from`); 1. the paper's segmented solve; 2. the lifted chain's IK candidates, then the
        whole-body optimisation from the best attempt when it reached the head."""
        if self.beyond_reach():
            self.consider(self.q_now, self.base, STAGES[1], 0)  # the attempt to report: out of reach
        else:
            if near:
                q = _continue_from(self.prob, self.q_now, self.base, self.position, self.direction, self.seed)
                if q is not None and (found := self.consider(q, self.base, STAGES[1], 1)):
                    return found
            if found := self.segmented_solve():
                return found
            candidates = self.candidates_at(self.q_now, self.base)
            for k, (q, chk) in enumerate(zip(candidates, self.check_many(candidates, self.base))):
                if found := self.consider(q, self.base, STAGES[1], k + 1, chk):
                    return found
        return self.refine_kept()

    def segmented_solve(self) -> WholeBodySolution | None:
        """Stage 1: the paper's segmented solve (:meth:`HeadController.solve_checked`) from the base as it is,
        clear of the obstacles."""
        seg = self.segmented_at(self.q_now, self.base, clear=True)
        self.segmented = seg
        return self.consider(seg.q, seg.base, STAGES[0], 0)

    def candidates_at(self, q: np.ndarray, base: BasePlacement) -> list[np.ndarray]:
        """:func:`lifted_candidates` from ``q`` at ``base`` (copies), kept in the plan's :class:`PlanSolves`: the
        relocation's search and the solve with the base kept at the base it finds solve the same batch."""
        key = (self.position.tobytes(), self.direction.tobytes(), q.tobytes(), base, self.seed)
        found = None if self.memo is None else self.memo.candidates.get(key)
        if found is None:
            found = lifted_candidates(self.prob, q, base, self.position, self.direction, self.seed)
            if self.memo is not None:
                self.memo.candidates[key] = found
        return [c.copy() for c in found]

    def segmented_at(self, q_prev: np.ndarray, base: BasePlacement, clear: bool) -> Any:
        """The segmented solve (:meth:`HeadController.solve_checked`, the base kept) from ``q_prev`` at ``base``,
        its solution required to clear the obstacles when ``clear``; kept in the plan's :class:`PlanSolves` (the
        relocation's search and the solve at the base it finds ask for the same one)."""
        clear = clear and bool(self.obstacles)
        key = (self.position.tobytes(), self.direction.tobytes(), np.asarray(q_prev, float).tobytes(), base, clear)
        if self.memo is not None and key in self.memo.segmented:
            return self.memo.segmented[key]
        accept = (lambda q, b: clear_of_obstacles(self.robot, q, self.obstacles, b)) if clear else None
        seg = self.controller.solve_checked(self.position, self.direction, q_prev=q_prev, base=base, accept=accept,
                                            allow_base_move=False)
        if self.memo is not None:
            self.memo.segmented[key] = seg
        return seg

    def refine_kept(self) -> WholeBodySolution | None:
        """The whole-body optimisation over the lifted joints from the best attempt, only when it reached the head
        and failed stability or clearance (a local optimisation can move the body from there; a target out of
        reach from this base is the placement's problem: stage 3)."""
        starts = [self.best.q] if self.best is not None and self.best.reason != "out of reach" else []
        for q0 in starts:  # (stages 1 and 2 make at most four solves: no budget)
            q, b = refine(self.prob, q0, self.base, self.position, self.direction, move_base=False,
                          obstacles=self.obstacles, min_margin=self.min_margin)
            if found := self.consider(np.clip(q, self.robot.lower, self.robot.upper), b, STAGES[1], len(starts)):
                return found
        return None

    def shape_passes(self, q: np.ndarray) -> bool:
        """Whether the flat shape of q (its joints before the lift) passes ``shape_ok`` (remembered when not)."""
        key = q[:self.robot.lift_joints.start].tobytes()
        if key in self.rejected_shapes:
            return False
        if self.shape_ok is not None and not self.shape_ok(q):
            self.rejected_shapes.add(key)
            return False
        return True

    def moved(self, q: np.ndarray, b: BasePlacement, starts: int, chk: dict | None = None
              ) -> WholeBodySolution | None:
        """:meth:`consider` for a moved base, whose shape must pass ``shape_ok`` too (asked only of a configuration
        that passes every other check; one whose shape fails is not kept as the best attempt either). ``chk``: its
        check, when made already."""
        chk = self.check(q, b) if chk is None else chk
        if self.shape_ok is not None and chk["reason"] is None and not self.shape_passes(q):
            return None
        return self.consider(q, b, STAGES[2], starts, chk)

    def base_moved(self) -> WholeBodySolution | None:
        """Stage 3: for the base's shape and other flat shapes (:func:`_base_shapes`), placements that bring the
        target into reach (:meth:`from_shape`), then the whole-body optimisation over the base's yaw joints, its
        placement and the lifted joints from the segmented solutions found there."""
        moved_starts: list[tuple[np.ndarray, BasePlacement]] = []
        for qb in [self.q_now[self.robot.parts.base]] + _base_shapes(self.controller):
            if found := self.from_shape(qb, moved_starts):
                return found
            if self.out_of_work():
                break
        for q0, b0 in moved_starts:
            if not self.afford():
                break
            q, b = refine(self.prob, q0, b0, self.position, self.direction, move_base=True, obstacles=self.obstacles,
                          min_margin=self.min_margin)
            if found := self.moved(np.clip(q, self.robot.lower, self.robot.upper), b, len(moved_starts)):
                return found
        return None

    def from_shape(self, qb: np.ndarray, moved_starts: list[tuple[np.ndarray, BasePlacement]]
                   ) -> WholeBodySolution | None:
        """The base with base joints qb: the placement that brings the target into the neck's accepted range
        (Section 3.3 (3)) and its segmented solution (added to ``moved_starts``), then the lifted chain's IK
        candidates there and at the other candidate placements (:func:`placements`), while the shape passes and
        the budget lasts (:meth:`afford`)."""
        from . import neck as nk

        robot, controller, base = self.robot, self.controller, self.base
        q = self.q_now.copy()
        q[robot.parts.base] = qb
        P0_local = np.linalg.inv(robot.body_pose(base)) @ robot.frame(q, robot.lift_frame, base)
        placed = None if controller.neck_length <= 0 else nk.base_move_into_range(
            self.position, P0_local, base, controller.Lc, controller.neck_length, controller.slack,
            robot.body_axis_height)
        if placed is not None and self.afford():
            s = self.segmented_at(q, placed, clear=False)
            if s.success and (found := self.moved(s.q, placed, 0)):
                return found
            moved_starts.append((s.q, placed))
        for b in ([placed] if placed is not None else []) + placements(self.prob, P0_local, self.position,
                                                                      self.direction):
            if q[:robot.lift_joints.start].tobytes() in self.rejected_shapes or not self.afford():
                break
            candidates = self.candidates_at(q, b)
            for qc, chk in zip(candidates, self.check_many(candidates, b)):
                if found := self.moved(qc, b, 0, chk):
                    return found
        return None


def _attempted(best: WholeBodySolution | None) -> WholeBodySolution:
    """The best attempt of :func:`solve_checked_target` (every path through it tries at least one pose)."""
    if best is None:
        raise InternalError("the whole-body solve tried no pose")
    return best


def placements(prob: BodyProblem, P0_local: np.ndarray, position: np.ndarray, direction: np.ndarray
               ) -> list[BasePlacement]:
    """Base placements that put the frame the neck lifts from (``P0_local``: its pose in the root frame, for the
    base's shape) a few horizontal distances short of the target, its body axis pointing at the target along the
    head's direction or its opposite's horizontal part: where the lifted chain can reach the target whatever its
    height (the accepted range of Section 3.3 (3) has none for targets higher than the neck and the dexterous
    centre reach)."""
    robot = prob.robot
    reach = robot.sub_chain(robot.lift_frame, robot.parts.head_tip).reach
    dz = position[2] - (robot.body_axis_height + P0_local[2, 3])
    span = np.sqrt(max(reach * reach - dz * dz, 0.0))
    if span <= 0:
        return []
    axis_heading = np.arctan2(P0_local[1, 0], P0_local[0, 0])
    dxy = np.asarray(direction[:2], float)
    headings = [np.arctan2(dxy[1], dxy[0])] if np.linalg.norm(dxy) > 1e-6 else [0.0]
    headings += [headings[0] + np.pi / 2, headings[0] - np.pi / 2]
    out = []
    for h in (0.5 * span, 0.25 * span, 0.75 * span):
        for heading in headings:
            yaw = heading - axis_heading
            c, s = np.cos(yaw), np.sin(yaw)
            P0_xy = position[:2] - h * np.array([np.cos(heading), np.sin(heading)])
            x, y = P0_xy - np.array([[c, -s], [s, c]]) @ P0_local[:2, 3]
            out.append(BasePlacement(float(x), float(y), float(np.arctan2(s, c))))
    return out


_ORDER = {None: 3, "no clear pose": 2, "no stable pose": 1, "out of reach": 0}


def _rank(s: WholeBodySolution) -> tuple:
    """How good an attempt is: solved, then the reason's order, then its margin (or, out of reach, how near)."""
    return _ORDER[s.reason], s.static_margin_m if s.reason != "out of reach" else -s.position_error_m


def _rank_of(chk: dict) -> tuple:
    """:func:`_rank` of a check (:func:`check_solutions`) before it is made a solution."""
    reason = chk["reason"]
    return _ORDER[reason], chk["static_margin_m"] if reason != "out of reach" else -chk["position_error_m"]
