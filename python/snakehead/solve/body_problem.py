"""What the whole-body solve needs of one robot, computed once (:class:`BodyProblem`): which joints are free,
which links lie on the ground, the links' capsules and the pairs that may collide, the Jacobians of world points,
directions and the centre of mass, the static margin over the base's own support with its gradient (Eqs. 23-24),
the lifted chain's TRAC-IK and the necessary conditions of a pose (:mod:`.pose_bounds`)."""
from __future__ import annotations

import numpy as np

from ..dynamics import stability
from ..kinematics.ik import TracIK
from ..model.robot import PITCH, BasePlacement, SnakeRobot, as_robot
from ..model.robot_parts import joints_before
from . import base_support
from .pose_bounds import PoseBounds

__all__ = ["BodyProblem", "LIFTED_IK_TIMEOUT_S"]

#: TRAC-IK's budget per call (s) on the lifted chain. (It races its two solvers until one succeeds or this runs
#: out: the one part of a whole-body solve that depends on the machine's speed.)
LIFTED_IK_TIMEOUT_S = 0.002


class BodyProblem:
    """The geometry of one robot that the whole-body solve needs, computed once: which joints are free, which
    links lie on the ground, the links' capsules and the pairs that may collide."""

    def __init__(self, robot: SnakeRobot) -> None:
        self.robot = robot = as_robot(robot)
        n = robot.n_joints
        child = np.asarray(robot.body.model.joint_child_links)
        self.child = child
        first_lifted_link = base_support.first_lifted_link(robot)
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
        segment = np.array([joints_before(robot.body, int(k)) for k in shaped])
        i, j = np.triu_indices(len(shaped), k=1)
        # links two or more joints apart (links one joint apart touch at it; a module's links never move apart)
        far = segment[j] - segment[i] >= 2
        self.pairs = np.column_stack([i, j])[far]
        self.axis_local = np.asarray(robot.body.model.joint_axes, float)
        self.head_index = robot.link_index(robot.parts.head_tip)
        self._iks: dict = {}
        self._pose_bounds: PoseBounds | None = None

    @property
    def pose_bounds(self) -> PoseBounds:
        """The robot's necessary conditions of a pose (:class:`~.pose_bounds.PoseBounds`), made
        once: the solve asks them before an IK batch or a segmented solve that they prove cannot succeed."""
        if self._pose_bounds is None:
            self._pose_bounds = PoseBounds.of(self.robot, np.zeros(self.robot.n_joints))
        return self._pose_bounds

    def out_of_reach(self, q: np.ndarray, base: BasePlacement, position: np.ndarray, direction: np.ndarray) -> bool:
        """Whether no pose of the lifted chain from the frame it lifts from in ``q`` at ``base`` (the links before
        it kept) puts the head at ``position`` along ``direction`` within the checks' tolerances: the first frame
        rigid with the tip is then farther from that frame than the chain between them
        (``PoseBounds.out_of_reach``, its soundness tested in tests/solve/test_reach_bounds.py). The lifted chain's IK
        cannot succeed there either: its tolerance (``epsilon``, 1e-5 per axis) is inside the checks'."""
        origin = self.robot.frame(q, self.robot.lift_frame, base)[:3, 3]
        return bool(self.pose_bounds.out_of_reach(position, direction, origin)[0])

    def lifted_ik(self, seed: int = 0) -> TracIK:
        """TRAC-IK of the lifted chain (lift_frame -> head_tip), seeded (made once per seed)."""
        if seed not in self._iks:
            chain = self.robot.sub_chain(self.robot.lift_frame, self.robot.parts.head_tip)
            self._iks[seed] = TracIK.from_chain(chain, timeout=LIFTED_IK_TIMEOUT_S, seed=seed)
        return self._iks[seed]

    # --- kinematics of world points ---------------------------------------------------------------------------
    def frames(self, q: np.ndarray, base: BasePlacement) -> np.ndarray:
        """World frames (n_links, 4, 4) of configuration q (n,) at ``base``."""
        return self.robot.frames(q, base)

    def point_jacobians(self, F: np.ndarray, base: BasePlacement, points: np.ndarray, links: np.ndarray
                        ) -> np.ndarray:
        """d(point)/d(q, x, y, yaw) (P, 3, n + 3) of world points (P, 3) attached to ``links`` (P,)."""
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
        """World (P, 3) bottom points of the ground links' shapes and their links (P,)
        (:func:`~.base_support.contact_points`)."""
        return base_support.contact_points(self.robot, F, self.ground_links)

    def com_and_jacobian(self, F: np.ndarray, base: BasePlacement) -> tuple[np.ndarray, np.ndarray]:
        """The body's centre of mass (3,), world, and its Jacobian (3, n + 3)."""
        m = self.robot.masses
        heavy, c_i = base_support.link_coms(self.robot, F)
        M = m[heavy].sum()
        J = self.point_jacobians(F, base, c_i, heavy)
        return (m[heavy, None] * c_i).sum(0) / M, np.einsum("l,lij->ij", m[heavy], J) / M

    def margin(self, F: np.ndarray) -> float:
        """:meth:`margin_and_gradient`'s margin alone (no Jacobians: for checks), from the frames (n_links, 4, 4)."""
        return float(self.margins(F[None])[0])

    def margins(self, frames: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
        """:meth:`margin` of many configurations at once, from their world frames (K, n_links, 4, 4) at ``base``
        (default: on flat ground): (K,) (:func:`~.base_support.static_margins` over the ground links)."""
        return base_support.static_margins(self.robot, frames, self.ground_links, base)

    def margin_and_gradient(self, F: np.ndarray, base: BasePlacement) -> tuple[float, np.ndarray]:
        """Signed distance of the CoM's ground projection to the support polygon's nearest edge (> 0 inside) and
        its gradient (n + 3,) through the active edge. On a slope the projection is along gravity
        (``BasePlacement.below_along_gravity``)."""
        c, Jc = self.com_and_jacobian(F, base)
        if not base.on_flat_ground:
            lean = base.gravity[:2] / base.gravity_across  # d(projection)/d c_z
            c, Jc = c.copy(), Jc.copy()
            c[:2] += c[2] * lean
            Jc[:2] += lean[:, None] * Jc[2]
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
