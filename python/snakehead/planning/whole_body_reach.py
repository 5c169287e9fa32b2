"""The whole body's stable reachability: for voxels around the robot and directions per voxel, whether the planner
finds a stable, collision-free whole-body pose that puts the head there (and with which base shape and placement).

It answers what :func:`snakehead.plan` of one target answers when it chooses the base
(``planning.planner.choose_base``: the whole-body solve, ``solve.whole_body.solve_checked_target``, with the base as
it lies, else with the base moved by a relocation), as a map (``kinematics.reachability.reachability_map.ReachabilityMap`` of kind
``"whole-body"``, written by the one map writer) that ``map.reachable(positions, directions)`` queries and the viewer
shows. The base starts at ``BasePlacement()``: the map's frame is that world frame.

The poses are a head map's (``kinematics.reachability.reachability_map``): for voxel centre c and the Fibonacci directions d_k, the head
tip at c + (voxel / 2) d_k pointing along d_k (its roll free). The grid is a cube of side 2 x the body's length
around the base's origin, from the ground up; voxels above the lifted chain's reach from the ground (the neck lifts
from a frame at the body's axis height) are left out: no base placement reaches them.

Making it cheap without changing what it means (no obstacles, a flat ground):

* the checks of a pose (stability, ground, self-collision) do not change when the body is moved over the ground, so
  a pose reached with a moved base is reached at every other position of the same height by the same base moved
  alike. The planner's relocation (the whole-body solve with the base moved) depends on the pose's height, its
  direction and the angle between the direction's heading and the bearing from the base to the target (the base is
  turned towards the target first): it is solved once per layer, direction and one of :data:`BEARING_BINS` relative
  bearings, for a target beyond the base's own reach, and carried over to the voxels of that layer;
* with the base kept, only poses within the lifted chain's reach of the frame it lifts from can be reached: those
  not reached by a relocation are solved one by one (as the planner's first step does);
* poses that no whole-body pose can reach are not solved (:mod:`~snakehead.solve.pose_bounds`: necessary
  conditions of the solve's exact checks): with any base, the tip's shape below the ground for every roll, or the
  last joint higher (lower) than the lifted chain reaches from the frame it lifts from; with the base kept, also
  that joint beyond the chain's reach of that frame, or a centre of mass that cannot lie inside the support
  polygon by the margin.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .. import _core, limits
from .. import sweep_defaults as defaults
from .._errors import InputError, InputTypeError
from .._executors import as_executor, run_tasks, worker_count
from ..kinematics import reachability as ws
from ..model.robot import BasePlacement, SnakeRobot
from ..scenes.scene import Target
from ..solve.pose_bounds import PoseBounds
from .plan_many import WORKERS, RobotRecipe, plan_many

__all__ = ["compute_reach", "check_reach", "check_options", "reach_grid", "top_height", "estimated_solves", "unreachable", "ReachGrid", "ReachCheck", "relocation_task", "kept_task", "BEARING_BINS", "MIN_VOXEL_M", "MAX_DIRECTIONS", "MAX_SOLVES", "MAX_WORKERS", "KEPT_CHUNK"]

from ..margins import DETOUR_MARGIN
from ..solve.head_controller import HeadController
from ..solve.whole_body import LIFTED_IK_TIMEOUT_S, POSITION_TOLERANCE

#: Relative bearings (the direction's heading minus the bearing from the base to the target) at which the
#: relocation is solved per layer and direction; a voxel takes the nearest one's answer.
BEARING_BINS = 4
#: The finest voxel and the most directions of a reach map, and the most whole-body solves one may need (each up to
#: the whole-body solve's budget, ``solve.whole_body.SOLVE_BUDGET`` solves): bounds on its run time, checked
#: before any work.
MIN_VOXEL_M = 0.02
MAX_DIRECTIONS = 64
MAX_SOLVES = 200_000
#: Worker processes of a pool on one machine (``snakehead reach --workers``): at most the core's worker threads.
MAX_WORKERS = limits.MAX_THREADS
#: Poses with the base kept solved per task: ~0.6 s of work each on the default robot at 0.1 m and 12 directions (36
#: tasks), small enough that the workers finish together (that stage waits for the relocation table).
KEPT_CHUNK = 4

#: Called as ``progress(stage, done, total)``: stage "relocation" (the table of moved bases) or "base kept".
ReachProgress = Callable[[str, int, int], None]


@dataclass
class ReachGrid:
    """The voxels of a reach map: ``n`` per axis of edge ``voxel`` from ``origin``; the kept voxels' ``ids`` (M,),
    ``centers`` (M, 3) and ``layers`` (M,) (their z index); the ``directions`` (N, 3)."""

    origin: np.ndarray
    voxel: float
    n: int
    ids: np.ndarray
    centers: np.ndarray
    layers: np.ndarray
    directions: np.ndarray

    def poses(self) -> np.ndarray:
        """(M, N, 3): the head tip's position of every (voxel, direction) pose."""
        return self.centers[:, None, :] + 0.5 * self.voxel * self.directions[None, :, :]


def _lift_reach(robot: SnakeRobot) -> float:
    return float(robot.sub_chain(robot.lift_frame, robot.parts.head_tip).reach)


def top_height(robot: SnakeRobot) -> float:
    """The highest the head tip gets over the ground, for any base placement (m): the lifted chain's reach above the
    frame it lifts from, which lies on the body's axis."""
    return float(robot.body_axis_height) + _lift_reach(robot)


def check_options(robot: Any, voxel: Any = defaults.REACH_VOXEL_M,
                  directions: Any = defaults.REACH_DIRECTIONS) -> tuple[float, int]:
    """``voxel`` (m) and ``directions`` checked (InputError naming the option) before any work; returns them."""
    if not isinstance(robot, SnakeRobot):
        raise InputTypeError(f"robot must be a SnakeRobot, got {type(robot).__name__}")
    voxel = ws.checked_real("voxel", voxel)
    directions = ws.checked_count("directions", directions, 1, MAX_DIRECTIONS)
    side = 2.0 * robot.body_length
    if not (math.isfinite(voxel) and MIN_VOXEL_M <= voxel <= side / ws.MIN_VOXELS_PER_AXIS):
        raise InputError(f"voxel must be within [{MIN_VOXEL_M:g}, {side / ws.MIN_VOXELS_PER_AXIS:.4g}] m (at least "
                         f"{ws.MIN_VOXELS_PER_AXIS} voxels across the grid of side 2 x the body's length), got {voxel!r}")
    grid = reach_grid(robot, voxel, directions)
    solves = estimated_solves(robot, grid)
    if solves > MAX_SOLVES:
        raise InputError(f"voxel {voxel:g} m and {directions} directions need up to {solves} whole-body solves, at "
                         f"most {MAX_SOLVES}: take a larger voxel or fewer directions")
    return voxel, directions


def reach_grid(robot: SnakeRobot, voxel: float, directions: int) -> ReachGrid:
    """The grid of a reach map: a cube of side >= 2 x the body's length, centred over the base's origin, from the
    ground up; its voxels whose sphere can hold a pose no higher than :func:`top_height`."""
    n = max(ws.MIN_VOXELS_PER_AXIS, math.ceil(2.0 * robot.body_length / voxel - 1e-9))
    origin = np.array([-0.5 * n * voxel, -0.5 * n * voxel, 0.0])
    layers = int(min(n, math.ceil((top_height(robot) + 0.5 * voxel) / voxel)))
    i, j, k = np.meshgrid(np.arange(n), np.arange(n), np.arange(layers), indexing="ij")
    ids = np.sort(((i * n + j) * n + k).ravel())
    ijk = np.stack([ids // (n * n), (ids // n) % n, ids % n], axis=1)
    return ReachGrid(origin, float(voxel), int(n), ids.astype(np.int64), origin + (ijk + 0.5) * voxel,
                     ijk[:, 2].astype(np.int64), _core.fibonacci_directions(int(directions)))


def _near(grid: ReachGrid, lift_xy: np.ndarray, reach: float) -> np.ndarray:
    """(M, N) bool: poses within the lifted chain's reach (horizontally) of where it lifts from at the start."""
    d = np.linalg.norm(grid.poses()[..., :2] - lift_xy, axis=-1)
    return d <= reach + 1e-4


def estimated_solves(robot: SnakeRobot, grid: ReachGrid) -> int:
    """The most whole-body solves a reach map of ``grid`` makes: the relocation table and every pose within the
    base's own reach."""
    layers = int(grid.layers.max()) + 1 if len(grid.layers) else 0
    lift_xy, reach = _start_lift(robot)
    return layers * len(grid.directions) * BEARING_BINS + int(_near(grid, lift_xy, reach).sum())


def _start_lift(robot: SnakeRobot) -> tuple[np.ndarray, float]:
    """Where the neck lifts from when the base lies at ``BasePlacement()`` in the planner's initial configuration,
    (2,) xy, and the lifted chain's reach."""
    controller = WORKERS.get(RobotRecipe.of(robot), None, "rotated", 1)
    return (robot.frame(controller.q_initial, robot.lift_frame, BasePlacement())[:2, 3], _lift_reach(robot))


def unreachable(robot: SnakeRobot, positions: np.ndarray, directions: np.ndarray, *, kept: bool) -> np.ndarray:
    """(N,) bool: the (position, direction) poses that no whole-body pose can reach (:class:`PoseBounds`'s
    necessary conditions): with any base lying flat, or (``kept``) with the base as it lies at the start (the
    planner's initial configuration at ``BasePlacement()``, its margin ``DETOUR_MARGIN``), where the solve with the
    base kept cannot succeed."""
    controller = WORKERS.get(RobotRecipe.of(robot), None, "rotated", 1)
    q0, start = controller.q_initial, BasePlacement()
    bounds = PoseBounds.of(robot, q0)
    p, d = np.reshape(positions, (-1, 3)), np.reshape(directions, (-1, 3))
    out = bounds.below_ground(p, d) | bounds.out_of_reach(p, d)
    if kept:
        out |= bounds.out_of_reach(p, d, robot.frame(q0, robot.lift_frame, start)[:3, 3])
        rest = np.flatnonzero(~out)
        out[rest] = bounds.unstable(p[rest], q0, start, DETOUR_MARGIN)
    return out


# --- the work, in workers ---------------------------------------------------------------------------------------
def _controller(recipe: RobotRecipe, method: str, seed: int | None) -> HeadController:
    c = WORKERS.get(recipe, None, method, seed)
    c.base = BasePlacement()  # (a plan made with this controller may have moved it)
    return c


def _witness(controller: HeadController, base: BasePlacement, q_shape: np.ndarray) -> tuple:
    robot = controller.robot
    return (np.array([base.x, base.y, base.yaw]), np.asarray(q_shape[:robot.lift_joints.start], float).copy())


def relocation_task(recipe: RobotRecipe, method: str, seed: int | None, poses: list) -> list:
    """The planner's choice of base for each (position, direction) of ``poses``, each beyond the base's own reach
    (module level, for executors): (reached, placement (3,) or None, base joints or None) each."""
    from .base_choice import choose_base

    controller = _controller(recipe, method, seed)
    out = []
    for p, d in poses:
        target = Target("reach", np.asarray(p, float), np.asarray(d, float))
        base, q_shape, relocation, notes = choose_base(controller, [target])
        ok = relocation is not None or not notes
        out.append((ok, *(_witness(controller, base, q_shape) if ok else (None, None))))
    return out


def kept_task(recipe: RobotRecipe, method: str, seed: int | None, poses: list) -> list:
    """Whether the base as it lies reaches each (position, direction) of ``poses`` (the planner's first step;
    module level, for executors): (reached, placement, base joints) each."""
    from .base_choice import choose_base

    controller = _controller(recipe, method, seed)
    out = []
    for p, d in poses:
        target = Target("reach", np.asarray(p, float), np.asarray(d, float))
        base, q_shape, _, notes = choose_base(controller, [target], allow_relocation=False)
        ok = not notes
        out.append((ok, *(_witness(controller, base, q_shape) if ok else (None, None))))
    return out


# --- the map ----------------------------------------------------------------------------------------------------
def compute_reach(robot: SnakeRobot, *, voxel: float = defaults.REACH_VOXEL_M,
                  directions: int = defaults.REACH_DIRECTIONS, executor: Any = None,
                  method: str = "rotated", seed: int | None = 1, progress: ReachProgress | None = None,
                  prune: bool = True) -> ws.ReachabilityMap:
    """The whole body's stable reachability map of ``robot`` (see the module's doc): kind ``"whole-body"``; its
    ``reached`` bits say which (voxel, direction) poses are reached, ``base_placements`` (M, N, 3) and
    ``base_joints`` (M, N, k) with which base (a relocated base where one reaches the pose, else the start's).

    executor: None (here), a ``concurrent.futures`` executor or a Dask ``distributed.Client``. ``method``, ``seed``:
    the head IK's, as :func:`snakehead.plan`'s. ``progress(stage, done, total)`` as tasks finish. ``prune=False``
    solves the poses that :func:`unreachable` proves unreachable too (the same map, slower: for comparisons)."""
    t0 = time.perf_counter()
    voxel, directions = check_options(robot, voxel, directions)
    if method not in ("rotated", "free_roll"):
        raise InputError(f"method must be 'rotated' or 'free_roll', got {method!r}")
    if progress is not None and not callable(progress):
        raise InputTypeError("progress must be a function (stage, done, total) or None")
    pool = None if executor is None else as_executor(executor)
    recipe = RobotRecipe.of(robot)
    grid = reach_grid(robot, voxel, directions)
    lift_xy, reach = _start_lift(robot)
    poses = grid.poses()
    M, N = poses.shape[:2]
    table = _relocation_table(robot, recipe, grid, lift_xy, reach, pool, method, seed, progress, prune)
    reached = np.zeros((M, N), bool)
    placements = np.full((M, N, 3), np.nan)
    k_joints = robot.lift_joints.start
    joints = np.full((M, N, k_joints), np.nan)
    # the relocation's answer, carried over by the translation from its target to each pose
    bins = _bearing_bins(poses, grid.directions, lift_xy)
    layers = np.broadcast_to(grid.layers[:, None], (M, N))
    dirs = np.broadcast_to(np.arange(N)[None, :], (M, N))
    for (layer, k, b), (ok, target, place, qb) in table.items():
        sel = (layers == layer) & (dirs == k) & (bins == b)
        if not ok or not sel.any():
            continue
        reached[sel] = True
        shift = poses[sel][:, :2] - target[:2]
        placements[sel] = np.column_stack([place[0] + shift[:, 0], place[1] + shift[:, 1],
                                           np.full(len(shift), place[2])])
        joints[sel] = qb
    # the base kept, for the poses within its reach that no relocation reaches
    near = _near(grid, lift_xy, reach) & ~reached
    rows, cols = np.nonzero(near)
    if prune:
        keep = ~unreachable(robot, poses[rows, cols], grid.directions[cols], kept=True)
        rows, cols = rows[keep], cols[keep]
    chunks = [list(zip(rows[i:i + KEPT_CHUNK], cols[i:i + KEPT_CHUNK])) for i in range(0, len(rows), KEPT_CHUNK)]
    tasks = [(recipe, method, seed, [(poses[v, k], grid.directions[k]) for v, k in chunk]) for chunk in chunks]
    results = _run(pool, kept_task, tasks, "base kept", progress)
    for chunk, res in zip(chunks, results):
        for (v, k), (ok, place, qb) in zip(chunk, res):
            if ok:
                reached[v, k], placements[v, k], joints[v, k] = True, place, qb
    workers = 1 if pool is None else (worker_count(pool) or -1)
    return _as_map(robot, grid, reached, placements, joints, seed, time.perf_counter() - t0, workers,
                   f"snakehead.planning.whole_body_reach.compute_reach(voxel={voxel:g}, directions={directions})")


def _bearing_bins(poses: np.ndarray, directions: np.ndarray, lift_xy: np.ndarray) -> np.ndarray:
    """(M, N): the relative-bearing bin of each pose: its direction's heading minus the bearing from the start's
    lift frame to it, to the nearest of BEARING_BINS."""
    rel = poses[..., :2] - lift_xy
    bearing = np.arctan2(rel[..., 1], rel[..., 0])
    heading = np.arctan2(directions[:, 1], directions[:, 0])[None, :]
    step = 2 * np.pi / BEARING_BINS
    return np.round(np.mod(heading - bearing, 2 * np.pi) / step).astype(np.int64) % BEARING_BINS


def _relocation_table(robot: SnakeRobot, recipe: RobotRecipe, grid: ReachGrid, lift_xy: np.ndarray, reach: float,
                      pool: Any, method: str, seed: int | None, progress: ReachProgress | None, prune: bool = True
                      ) -> dict:
    """(layer, direction, bearing bin) -> (reached, target (3,), placement (3,), base joints): the planner's
    relocation for a target of that layer's height, direction and relative bearing, beyond the base's own reach."""
    layers = sorted(set(grid.layers.tolist()))
    keys, poses = [], []
    for layer in layers:
        cz = grid.origin[2] + (layer + 0.5) * grid.voxel
        for k, d in enumerate(grid.directions):
            heading = math.atan2(d[1], d[0])
            for b in range(BEARING_BINS):
                bearing = heading - b * 2 * np.pi / BEARING_BINS
                far = reach + 2 * grid.voxel  # beyond the base's own reach
                p = np.array([lift_xy[0] + far * math.cos(bearing), lift_xy[1] + far * math.sin(bearing),
                              cz + 0.5 * grid.voxel * d[2]])
                keys.append((layer, k, b))
                poses.append((p, d))
    # poses no base reaches (the same for every bearing of a layer and direction) are not solved
    todo = np.arange(len(poses))
    if prune:
        todo = todo[~unreachable(robot, np.array([p for p, _ in poses]), np.array([d for _, d in poses]), kept=False)]
    tasks = [(recipe, method, seed, [poses[i]]) for i in todo]
    results: list = [[(False, None, None)]] * len(poses)
    for i, res in zip(todo, _run(pool, relocation_task, tasks, "relocation", progress)):
        results[i] = res
    return {key: (res[0][0], pose[0], res[0][1], res[0][2]) for key, pose, res in zip(keys, poses, results)}


def _run(pool: Any, fn: Callable[..., list], tasks: list, stage: str, progress: ReachProgress | None) -> list:
    count = [0]

    def done(i: int, result: Any) -> None:
        count[0] += 1
        if progress is not None:
            progress(stage, count[0], len(tasks))

    if pool is None:
        out = []
        for i, task in enumerate(tasks):
            out.append(fn(*task))
            done(i, out[-1])
        return out
    return run_tasks(pool, fn, tasks, done)


def _as_map(robot: SnakeRobot, grid: ReachGrid, reached: np.ndarray, placements: np.ndarray, joints: np.ndarray,
            seed: int | None, seconds: float, workers: int, command: str) -> ws.ReachabilityMap:
    M, N = reached.shape
    params = dict(voxel_size=grid.voxel, directions=N, rolls=0, any_roll=True, free_roll=True, approach_axis="x",
                  timeout=LIFTED_IK_TIMEOUT_S, epsilon=POSITION_TOLERANCE, cloud_samples=ws.MIN_CLOUD_SAMPLES,
                  seed=0 if seed is None else int(seed), hull="convex", shrink=0.0)
    return ws.ReachabilityMap(
        centers=grid.centers, solved=reached.sum(axis=1).astype(np.int32), voxel_ids=grid.ids, tried=N,
        grid_origin=grid.origin, grid_size=grid.n * grid.voxel, grid_shape=(grid.n,) * 3, hull_voxels=M,
        chain_hash=robot.body.hash, base="world", tip=robot.parts.head_tip, params=params, command=command,
        stats={"seconds": seconds, "threads": workers, "reach": top_height(robot)},
        reached=np.packbits(reached, axis=1, bitorder="little"), kind=ws.KIND_WHOLE_BODY,
        base_joints=joints, base_placements=placements)


# --- the spot check by full plans ---------------------------------------------------------------------------------
@dataclass
class ReachCheck:
    """Full plans of sampled poses against the map: ``poses`` (K, 3), ``directions`` (K, 3), what the map says
    (``mapped``) and whether :func:`snakehead.plan` succeeded (``planned``), the plans' failures."""

    positions: np.ndarray
    directions: np.ndarray
    mapped: np.ndarray
    planned: np.ndarray
    failures: list

    @property
    def agreement(self) -> float:
        return float(np.mean(self.mapped == self.planned)) if len(self.mapped) else 1.0

    def agreement_interval(self, z: float = 1.96) -> tuple[float, float]:
        """The Wilson score interval of the agreement (default 95 %: z = 1.96), as shares."""
        n = len(self.mapped)
        if n == 0:
            return (0.0, 1.0)
        p = self.agreement
        centre = (p + z * z / (2 * n)) / (1 + z * z / n)
        half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
        return (max(0.0, centre - half), min(1.0, centre + half))

    def summary(self) -> str:
        r = self.mapped
        lo, hi = self.agreement_interval()
        return (f"{len(r)} poses ({int(r.sum())} reachable by the map, {int((~r).sum())} not): full plans agree on "
                f"{100 * self.agreement:.1f} % (95 % interval {100 * lo:.1f}-{100 * hi:.1f} %; reachable: "
                f"{_share(self.planned[r])}, not: {_share(~self.planned[~r])})")


def _share(a: np.ndarray) -> str:
    return f"{int(a.sum())}/{len(a)}"


def check_reach(m: ws.ReachabilityMap, robot: SnakeRobot, count: int, *, seed: int = 0, executor: Any = None,
                progress: Callable[[Any], None] | None = None) -> ReachCheck:
    """Plan ``count`` sampled (voxel, direction) poses of the whole-body map ``m`` with :func:`snakehead.plan` (half
    among those the map reaches, half among the others, as far as there are) and compare."""
    m = ws.require_map(m, robot, needs=("poses",), kind=ws.KIND_WHOLE_BODY, what="the reach map")
    count = ws.checked_count("count", count, 1, 100_000)
    bits = m.reached_units()
    rng = np.random.default_rng(seed)
    yes, no = np.argwhere(bits), np.argwhere(~bits)
    take_yes = min(len(yes), max(count - len(no), (count + 1) // 2))
    picks = [yes[rng.choice(len(yes), take_yes, replace=False)]] if take_yes else []
    if count - take_yes:
        picks.append(no[rng.choice(len(no), min(len(no), count - take_yes), replace=False)])
    vk = np.concatenate(picks) if picks else np.zeros((0, 2), np.int64)
    dirs = m.sphere_directions[vk[:, 1]]
    pos = m.centers[vk[:, 0]] + 0.5 * m.voxel_size * dirs
    plans = plan_many([[(p, d)] for p, d in zip(pos, dirs)], robot=robot, executor=executor, progress=progress)
    planned = np.array([p.success for p in plans], bool)
    mapped = bits[vk[:, 0], vk[:, 1]]
    failures = [p.failure for p in plans if not p.success]
    return ReachCheck(pos, dirs, mapped, planned, failures)
