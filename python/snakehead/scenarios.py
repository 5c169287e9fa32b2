"""The paper's Section 4, end to end: catching two virtual spheres, and getting the head through a hole in a wall.

Each scenario strings the control process of Section 3.3 together: up to the initial state of Section 3.3 (1)
(the base on its optimised arc, the neck and head on the Bezier backbone, ``backbone.initial_configuration``),
the head targets are solved by ``HeadController`` and joined by whole-body moves (Section 3.2: the Cartesian
interpolation of Eqs. 41-44 where it is valid, else joint space; see ``_Plan.move``), sampled at the 2 ms
control period by the multi-segment interpolation; the result is checked for the ZMP inside the support
polygon, ground clearance and (for the hole) collision with the wall.

Both scenarios start in the bending state (Figs. 17b, 22a: the base on its arc, the neck and head curled flat on
the ground inside it: ``bending_state``) and lift the head to the initial state. On the default robot the neck and
head (1.7 kg) outweigh the base (1.5 kg): lifted as a cantilever beyond P0 they would tip the body, so they are
curled over the base before they rise. Getting from an arbitrary lying state into the bending state is a
reconfiguration on the ground (the paper's rolling gait or turning in place): with the tail held still it is a
plain joint motion, but in the MuJoCo check the free body slides as it curls (the head ended 1.1 m off), so it is
not part of these fixed-base plans.

Choices the paper leaves open, and ours:
- The spheres are caught with the head pointing along +y, the scene's forward direction (as for the hole);
  sphere 1 is released by backing the head off 6 cm along that direction.
- The wall stands on the ground, 0.7 m wide, 0.58 m high, 0.01 m thick, facing +y, with the hole's centre
  (0.2, 0.5, 0.4) on its vertical centre line; the head approaches along +y, the hole's axis.
- The head link is "through" when the head tip is 0.033 m beyond the wall's far face (link_16 is 0.046 m
  long: its proximal joint stays 2 mm in front of the wall, so no other link enters the hole).
- Segment durations grow with the largest joint change (``speed``), with a floor; each target is held.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from . import stability
from . import trajectory as tr
from ._validate import positive, unit_vector3
from .controller import HeadController, HeadSolution
from .robot import BasePlacement, SnakeRobot

SPHERE_1 = np.array([-4.05e-2, 0.5443, 0.3])  # m, Section 4.1
SPHERE_2 = np.array([0.1505, 0.5076, 0.3954])
SPHERE_DIAMETER = 0.04
SPHERE_DIRECTION = np.array([0.0, 1.0, 0.0])  # our choice: the scene's forward direction, as for the hole
RELEASE_DISTANCE = 0.06  # m the head backs off along its direction to release sphere 1
HOLE_CENTRE = np.array([0.2, 0.5, 0.4])  # m, Section 4.2
HOLE_DIAMETER = 0.07
WALL_SIZE = np.array([0.7, 0.58, 0.01])  # width, height, thickness (m)
HOLE_AXIS = np.array([0.0, 1.0, 0.0])
WALL_CLEARANCE = 0.002  # m: the least distance a solved configuration keeps from the wall
DETOUR_MARGIN = 0.005  # m: static margin every planned configuration keeps
DETOUR_TRIALS = 256  # candidate detour waypoints tried for a move whose straight path is unstable
DETOUR_SPREAD = 0.4  # rad: spread of the neck and head joints of a detour waypoint around the midpoint
DETOUR_SEED = 20211  # fixed: the same inputs give the same plan
LIFT_STEPS = 16  # waypoints of the lift from the bending state to the initial state
BENDING_GRID_DEG = 15.0  # deg: grid of the neck and head's yaw joints searched for the bending state
BENDING_CLEARANCE = 0.005  # m: least gap between non-neighbouring links of the bending state
BASE_STEPS = (0.05, 0.1, 0.15, 0.2)  # m: how far choose_base tries stepping the base back from the targets


@dataclass
class TargetResult:
    """One head target of a scenario and how well the plan reaches it."""

    name: str
    position: np.ndarray  # (3,) m
    direction: np.ndarray  # (3,) unit
    time: float  # s: when the plan arrives
    solution: HeadSolution

    @property
    def position_error_m(self) -> float:
        return self.solution.position_error

    @property
    def direction_error_deg(self) -> float:
        return self.solution.direction_error


@dataclass
class ScenarioResult:
    """A planned scenario: the 2 ms joint trajectory, its states and targets, and its checks."""

    name: str
    base: BasePlacement
    t: np.ndarray  # (T,) s
    q: np.ndarray  # (T, 16) rad
    qd: np.ndarray  # (T, 16) rad/s
    states: list  # (label, time s, q (16,)) of every waypoint
    targets: list  # TargetResult
    stability: stability.DynamicStability
    ground_clearance: np.ndarray  # (T,) m: lowest neck/head box corner above the ground
    obstacles: list = field(default_factory=list)
    obstacle_distance: np.ndarray | None = None  # (T,) m, None without obstacles
    planning_time_s: float = 0.0
    notes: list = field(default_factory=list)
    segments: list = field(default_factory=list)  # (segment, interpolation used)

    @property
    def min_zmp_margin_m(self) -> float:
        return float(self.stability.min_margin)

    @property
    def min_ground_clearance_m(self) -> float:
        return float(self.ground_clearance.min())

    @property
    def touches_obstacle(self) -> bool:
        return self.obstacle_distance is not None and bool((self.obstacle_distance <= 0).any())

    @property
    def success(self) -> bool:
        return (all(tg.solution.success for tg in self.targets) and self.stability.stable
                and self.min_ground_clearance_m > -tr.GROUND_TOLERANCE and not self.touches_obstacle)


class _Plan:
    """Accumulates waypoints (label, q) with durations, then samples them at the control period."""

    def __init__(self, robot: SnakeRobot, base: BasePlacement, speed: float, min_segment: float):
        self.robot, self.base = robot, base
        self.speed, self.min_segment = speed, min_segment
        self.labels: list[str] = []
        self.qs: list[np.ndarray] = []
        self.times: list[float] = []
        self.methods: list[tuple[str, str]] = []  # (segment, interpolation used)

    def start(self, label: str, q):
        self.labels, self.qs, self.times = [label], [np.asarray(q, float)], [0.0]

    def move_joint(self, label: str, q, duration: float | None = None):
        q = np.asarray(q, float)
        step = np.abs(q - self.qs[-1]).max()
        self.qs.append(q)
        self.labels.append(label)
        self.times.append(self.times[-1] + (duration or max(self.min_segment, step / self.speed)))

    def move(self, label: str, q, n: int = 12) -> str:
        """A whole-body move from the last state to q (Section 3.2); returns the method used.

        The Cartesian interpolation of Eqs. 41-44 (n configurations) is used when its configurations stay
        within the joint limits without clipping, above the ground and statically stable; otherwise (the
        interpolated joint points are closer than the links are long, so the links cannot follow them, and
        clipped angles jump between limits) the move is a joint-space one, through a detour waypoint when the
        straight joint path would leave the support polygon (see ``_joint_path``).
        """
        q = np.asarray(q, float)
        path = tr.cartesian_interpolation(self.robot, self.qs[-1], q, n, self.base, aim="points", full_output=True)
        if not path.clipped.any() and self._feasible(path.q).all():
            qs, method = path.q, "cartesian (Eqs. 41-44)"
        else:
            qs, method = self._joint_path(self.qs[-1], q, n)
        steps = np.abs(np.diff(qs, axis=0)).max(axis=1) / self.speed
        floor = self.min_segment / (len(qs) - 1)
        for k in range(1, len(qs)):
            self.qs.append(qs[k])
            self.labels.append(label if k == len(qs) - 1 else f"{label} ({k}/{len(qs) - 1})")
            self.times.append(self.times[-1] + max(floor, steps[k - 1]))
        self.methods.append((label, method))
        return method

    def _margins(self, qs: np.ndarray) -> np.ndarray:
        """Static margins (m) of configurations qs (m, 16): the CoM's distance inside the support polygon of
        every link lying on the ground (``contact="ground"``; once the head is up, the base's footprint)."""
        still = np.zeros_like(qs)
        dyn = stability.dynamic_stability(self.robot, np.arange(len(qs), dtype=float), qs, self.base, still,
                                          contact="ground")
        return dyn.margin  # with no motion the ZMP is the CoM's ground projection

    def _feasible(self, qs: np.ndarray) -> np.ndarray:
        """(m,) bool: above the ground, no two non-neighbouring links overlapping, and statically stable with
        DETOUR_MARGIN to spare."""
        clearance = tr.ground_clearance(self.robot, qs, self.base)[:, tr.non_base_links(self.robot)].min(axis=1)
        return ((clearance >= -tr.GROUND_TOLERANCE) & (tr.self_clearance(self.robot, qs, self.base) > 0.0)
                & (self._margins(qs) >= DETOUR_MARGIN))

    def _joint_path(self, qa: np.ndarray, qb: np.ndarray, n: int) -> tuple[np.ndarray, str]:
        """A joint-space path qa -> qb of about n configurations that stays stable and above the ground.

        The straight path when it does; else the shortest of DETOUR_TRIALS two-piece paths through a waypoint
        drawn around the midpoint (neck and head joints perturbed, seeded: plans are reproducible) whose every
        configuration passes; else the one with the largest worst margin (the scenario's checks report it).
        """
        s = np.linspace(0.0, 1.0, n)[:, None]
        straight = qa + s * (qb - qa)
        if self._feasible(straight).all():
            return straight, "joint space"
        movable = np.arange(self.robot.parts.neck.start, self.robot.parts.head.stop)
        rng = np.random.default_rng(DETOUR_SEED)
        W = np.tile(0.5 * (qa + qb), (DETOUR_TRIALS, 1))
        W[:, movable] += rng.normal(0.0, DETOUR_SPREAD, (DETOUR_TRIALS, len(movable)))
        W = np.clip(W, self.robot.lower, self.robot.upper)
        paths = np.concatenate([qa + s[None] * (W[:, None] - qa), W[:, None] + s[None, 1:] * (qb - W[:, None])], axis=1)
        flat = paths.reshape(-1, qa.size)
        ok = self._feasible(flat).reshape(len(W), -1).all(axis=1)
        if ok.any():
            length = np.abs(np.diff(paths, axis=1)).sum(axis=(1, 2))
            k = int(np.argmin(np.where(ok, length, np.inf)))
            return paths[k], "joint space via a stable detour"
        worst = self._margins(flat).reshape(len(W), -1).min(axis=1)
        return paths[int(np.argmax(worst))], "joint space (no stable detour found)"

    def hold(self, seconds: float):
        self.move_joint(self.labels[-1] + " (hold)", self.qs[-1], seconds)

    def sample(self, notes: list) -> tr.JointTrajectory:
        """The multi-segment interpolation through the waypoints at 2 ms (``trajectory.MonotoneQuintic``:
        dense Cartesian waypoints often sit on joint limits, and it never overshoots them)."""
        traj = tr.joint_trajectory(np.array(self.times), np.array(self.qs), method="monotone")
        lo, hi = self.robot.lower, self.robot.upper
        over = float(max((lo - traj.q).max(), (traj.q - hi).max(), 0.0))
        if over > 1e-9:
            notes.append(f"the spline overshot a joint limit by up to {np.degrees(over):.3f} deg; clipped")
            np.clip(traj.q, lo, hi, out=traj.q)
        return traj


def _finish(name, plan: _Plan, targets, t_start, obstacles=(), notes=()) -> ScenarioResult:
    robot, base = plan.robot, plan.base
    notes = list(notes)
    traj = plan.sample(notes)
    dyn = stability.dynamic_stability(robot, traj.t, traj.q, base, traj.qd, contact="ground")
    clearance = tr.ground_clearance(robot, traj.q, base)[:, tr.non_base_links(robot)].min(axis=1)
    distance = None
    if obstacles:
        # exact distances only near the obstacles: the verdict needs the sign, the note the least clearance
        distance = tr.collision_check(robot, traj.q, list(obstacles), base, exact_within=0.005).distance
    states = [(lab, float(t), q) for lab, t, q in zip(plan.labels, plan.times, plan.qs)]
    return ScenarioResult(name=name, base=base, t=traj.t, q=traj.q, qd=traj.qd, states=states, targets=targets,
                          stability=dyn, ground_clearance=clearance, obstacles=list(obstacles),
                          obstacle_distance=distance, planning_time_s=time.perf_counter() - t_start,
                          notes=notes, segments=list(plan.methods))


def bending_state(controller: HeadController) -> np.ndarray:
    """The bending state (Figs. 17b, 22a): the base on its arc and the neck and head curled flat on the ground
    inside it, so that lifting them keeps their mass over the base (16,).

    On the default robot the neck and head (1.7 kg) outweigh the base (1.5 kg): lifted from a straight line
    beyond P0 they tip the body. Here the pitch joints are 0 (everything lies on the ground) and the neck and
    head's yaw joints are chosen on a 15 deg grid for the largest static margin over the base's support polygon
    alone (the support left once they are lifted), among the curls in which no two non-neighbouring links
    overlap. Deterministic."""
    robot = controller.robot
    q = np.zeros(robot.n_joints)
    q[robot.parts.base] = controller.q_initial[robot.parts.base]
    up = np.arange(robot.parts.neck.start, robot.parts.head.stop)
    yaw = up[np.abs(np.asarray(robot.body.model.joint_axes)[up, 2]) > 0.5]  # about the link's z: yaw when flat
    grid = np.radians(np.arange(-90.0, 90.0 + 1e-9, BENDING_GRID_DEG))
    combos = np.stack(np.meshgrid(*[grid] * len(yaw), indexing="ij"), -1).reshape(-1, len(yaw))
    qs = np.tile(q, (len(combos), 1))
    qs[:, yaw] = np.clip(combos, robot.lower[yaw], robot.upper[yaw])
    poly = stability.support_polygon(robot, q)  # the base's, placement-independent in its own frame
    com = stability.center_of_mass(robot, qs)
    pts = np.broadcast_to(poly, (len(qs),) + poly.shape)
    margin = stability.polygon_margin_many(pts, np.ones(pts.shape[:2], bool), com[:, :2])
    order = np.argsort(-margin)
    for chunk in np.array_split(order[margin[order] > 0], max(1, int(np.sum(margin > 0)) // 500 + 1)):
        ok = tr.self_clearance(robot, qs[chunk]) > BENDING_CLEARANCE
        if ok.any():
            return qs[chunk[np.argmax(ok)]]
    raise ValueError("no curl of the neck and head on the ground keeps their mass over the base")


def _target(controller: HeadController, name, position, direction, q_prev, base, plan: _Plan,
            targets: list, notes: list, cartesian: bool = True, accept=None) -> np.ndarray:
    sol = controller.solve(position, direction, q_prev=q_prev, base=base, accept=accept)
    if sol.base_moved:
        notes.append(f"{name}: the base would have to move to {sol.base}; kept at {base}")
    if not sol.success:
        notes.append(f"{name}: {sol.message}")
    if cartesian:
        plan.move(name, sol.q)
    else:
        plan.move_joint(name, sol.q)
    targets.append(TargetResult(name, np.asarray(position, float), unit_vector3(direction, "direction"),
                                plan.times[-1], sol))
    return sol.q


def choose_base(controller: HeadController, targets, accept=None) -> tuple[BasePlacement, list[str]]:
    """One base placement for a whole scenario: the controller's when every target (position, direction) is
    solved from it with the body statically stable (and passing ``accept(q, base)`` when given); otherwise the
    first that does among the planar moves that bring a target (or their mean) into the accepted range, and
    those placements stepped back from the targets by BASE_STEPS (room for the body in front of an obstacle).
    Returns the placement and notes."""
    from . import neck as nk

    robot = controller.robot
    q = controller.q_initial
    P0 = robot.frame(q, robot.parts.base_end, controller.base)
    P0_local = np.linalg.inv(controller.base.matrix()) @ P0
    positions = [np.asarray(p, float) for p, _ in targets]
    mean = np.mean(positions, axis=0)
    candidates = [controller.base]
    for p in [mean] + positions:
        moved = nk.base_move_into_range(p, P0_local, controller.base, controller.Lc, controller.neck_length,
                                        controller.slack)
        if moved is not None:
            candidates.append(moved)
    for base in list(candidates):
        away = (base.matrix() @ P0_local)[:2, 3] - mean[:2]
        if np.linalg.norm(away) > 1e-9:
            away /= np.linalg.norm(away)
            candidates += [BasePlacement(float(base.x + d * away[0]), float(base.y + d * away[1]), base.yaw)
                           for d in BASE_STEPS]
    for k, base in enumerate(candidates):
        sols = [controller.solve(p, d, base=base, accept=accept) for p, d in targets]
        if all(s.success and s.static_stable and not s.base_moved for s in sols):
            note = [] if k == 0 else [f"the base was moved to {base} (rolling / turning in place) so that every "
                                      "target is reached"]
            return base, note
    return controller.base, ["no single base placement reaches every target stably; kept the controller's"]


def catch_spheres(controller: HeadController | None = None, *, speed: float = 0.12, min_segment: float = 2.0,
                  hold: float = 2.0) -> ScenarioResult:
    """Section 4.1: from the current state to the initial state, catch sphere 1, release it, catch sphere 2.

    ``speed`` (rad/s) is the largest joint rate a segment is planned for; ``min_segment`` (s) the shortest
    segment; ``hold`` (s) how long each sphere is held.
    """
    t_start = time.perf_counter()
    controller = controller if controller is not None else HeadController()
    speed, min_segment, hold = positive(speed, "speed"), positive(min_segment, "min_segment"), positive(hold, "hold")
    robot = controller.robot
    base, notes = choose_base(controller, [(SPHERE_1, SPHERE_DIRECTION), (SPHERE_2, SPHERE_DIRECTION)])
    plan = _Plan(robot, base, speed, min_segment)
    plan.start("bending state", bending_state(controller))
    plan.move("initial state (head lifted)", controller.q_initial, n=LIFT_STEPS)
    targets: list[TargetResult] = []

    q = _target(controller, "sphere 1", SPHERE_1, SPHERE_DIRECTION, controller.q_initial, base, plan, targets, notes)
    plan.hold(hold)
    release = SPHERE_1 - RELEASE_DISTANCE * SPHERE_DIRECTION
    q = _target(controller, "release sphere 1", release, SPHERE_DIRECTION, q, base, plan, [], notes)
    q = _target(controller, "sphere 2", SPHERE_2, SPHERE_DIRECTION, q, base, plan, targets, notes)
    plan.hold(hold)
    return _finish("spheres", plan, targets, t_start, notes=notes)


def hole_wall() -> tr.WallWithHole:
    """The wall of Section 4.2 as placed here: standing on the ground, the hole on its vertical centre line."""
    facing = tr.WallWithHole(centre=HOLE_CENTRE, normal=HOLE_AXIS, size=WALL_SIZE, hole_diameter=HOLE_DIAMETER)
    # hole_offset is the wall centre's position relative to the hole along the wall's own (width, height)
    # axes; the wall's centre is half its height above the ground, straight below the hole.
    centre = np.array([HOLE_CENTRE[0], HOLE_CENTRE[1], WALL_SIZE[1] / 2])
    offset = (centre - HOLE_CENTRE) @ facing.rotation[:, :2]
    return tr.WallWithHole(centre=HOLE_CENTRE, normal=HOLE_AXIS, size=WALL_SIZE, hole_diameter=HOLE_DIAMETER,
                           hole_offset=offset)


def through_hole(controller: HeadController | None = None, *, speed: float = 0.12, min_segment: float = 2.0,
                 approach: float = 0.12, step: float = 0.01) -> ScenarioResult:
    """Section 4.2: lift the head, put it on the hole's axis ``approach`` m in front of the hole, then move it
    along the axis in ``step`` m increments (each solved from the previous joints, keeping the smallest joint
    change) until the head link is through the wall."""
    t_start = time.perf_counter()
    controller = controller if controller is not None else HeadController()
    speed, min_segment = positive(speed, "speed"), positive(min_segment, "min_segment")
    approach, step = positive(approach, "approach"), positive(step, "step")
    robot = controller.robot
    wall = hole_wall()
    straight = robot.frames(np.zeros(robot.n_joints))
    head_link = robot.body.model.joint_child_links[-1]  # the link the last joint moves: the head link
    head_length = float(np.linalg.norm(straight[-1, :3, 3] - straight[head_link, :3, 3]))
    through = HOLE_CENTRE[1] + WALL_SIZE[2] / 2 + head_length - 0.013  # head tip beyond the far face
    start = HOLE_CENTRE - approach * HOLE_AXIS
    def clear_of_wall(q, b) -> bool:  # the solutions kept must leave every link clear of the wall
        return bool(tr.collision_check(robot, q[None], [wall], b, exact_within=0.005).distance[0] > WALL_CLEARANCE)

    deepest = HOLE_CENTRE + (through - HOLE_CENTRE[1]) * HOLE_AXIS
    base, notes = choose_base(controller, [(deepest, HOLE_AXIS), (start, HOLE_AXIS)], accept=clear_of_wall)
    plan = _Plan(robot, base, speed, min_segment)
    plan.start("bending state", bending_state(controller))
    plan.move("initial state (head lifted)", controller.q_initial, n=LIFT_STEPS)
    targets: list[TargetResult] = []

    # Poses along the axis, from the approach point to through the wall.
    distances = np.arange(approach, HOLE_CENTRE[1] - through - 1e-9, -step)
    distances = np.append(distances, HOLE_CENTRE[1] - through)
    names = [f"along the axis, {d * 100:+.0f} cm" for d in distances]
    names[0], names[-1] = "in front of the hole", "through the hole"
    entering = int(np.argmin(np.abs(distances)))
    names[entering] = "entering the hole"
    # Solve them backwards, from the deepest pose (the most constrained: only the head link may be in the
    # hole) out to the approach point, each from the previous joints: a branch of solutions that clears the
    # wall deep in the hole also clears it further out, while one chosen from the outside may run into it.
    solutions = [None] * len(distances)
    q = controller.q_initial
    for k in range(len(distances) - 1, -1, -1):
        solutions[k] = controller.solve(HOLE_CENTRE - distances[k] * HOLE_AXIS, HOLE_AXIS, q_prev=q, base=base,
                                        accept=clear_of_wall)
        if solutions[k].success:
            q = solutions[k].q
        else:
            notes.append(f"{names[k]}: {solutions[k].message}")
    for k, sol in enumerate(solutions):
        if k == 0:
            plan.move(names[k], sol.q)
        else:
            plan.move_joint(names[k], sol.q)
        if k in (0, entering, len(distances) - 1):
            targets.append(TargetResult(names[k], HOLE_CENTRE - distances[k] * HOLE_AXIS, HOLE_AXIS,
                                        plan.times[-1], sol))
    plan.hold(1.0)
    return _finish("hole", plan, targets, t_start, obstacles=[wall], notes=notes)


def reach_target(controller: HeadController | None = None, position=None, direction=None, *, name: str = "target",
                 speed: float = 0.12, min_segment: float = 2.0, hold: float = 1.0, obstacles=()) -> ScenarioResult:
    """One head target end to end, as the scenarios do it: from the controller's initial state, solve the head
    at ``position`` (3,) m pointing along ``direction`` (3,) (Section 3.3 steps 3-4, the base placement chosen by
    :func:`choose_base`), move there by :meth:`_Plan.move` (Section 3.2), hold ``hold`` s, sample at 2 ms and check
    stability, ground clearance and the optional ``obstacles`` (``trajectory`` obstacles: the solution must
    clear them). ``speed`` rad/s and ``min_segment`` s as in :func:`catch_spheres`."""
    from ._validate import vector3

    t_start = time.perf_counter()
    controller = controller if controller is not None else HeadController()
    position, direction = vector3(position, "position"), unit_vector3(direction, "direction")
    speed, min_segment, hold = positive(speed, "speed"), positive(min_segment, "min_segment"), positive(hold, "hold")
    robot = controller.robot
    obstacles = list(obstacles)
    def clear(q, b) -> bool:
        return bool(tr.collision_check(robot, q[None], obstacles, b, exact_within=0.005).distance[0] > WALL_CLEARANCE)

    accept = clear if obstacles else None
    base, notes = choose_base(controller, [(position, direction)], accept=accept)
    plan = _Plan(robot, base, speed, min_segment)
    plan.start("initial state (head lifted)", controller.q_initial)
    targets: list[TargetResult] = []
    _target(controller, name, position, direction, controller.q_initial, base, plan, targets, notes, accept=accept)
    plan.hold(hold)
    return _finish(name, plan, targets, t_start, obstacles=obstacles, notes=notes)
