"""
snakehead's C++ core: chain model, kinematics, TRAC-IK, workspace sweep, support polygons, box collisions, convex-shape distances (FCL), inverse dynamics, the neck's fit (Eq. 22), path checks, time-optimal path parameterization (TOPP-RA), the tracking interpolation's fit, piecewise polynomials, a timed motion's use of its limits, terrain surfaces (planes, heightfields, meshes), and the limits on what callers may ask for
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing
__all__: list[str] = ['Cancelled', 'ChainModel', 'Limits', 'PathChecker', 'ShapeSet', 'Terrain', 'ToppRaResult', 'TracIK', 'TrackingFit', 'WorkspaceOptions', 'ZmpPrefix', 'approach_frame', 'boundary', 'boundary_voxels', 'center_of_mass', 'compute_reachability', 'convex_hull', 'convex_hull_2d', 'convex_hulls', 'core_threads', 'evaluate_piecewise_polynomial', 'evaluate_voxels', 'fibonacci_directions', 'fit_neck', 'hull_margins', 'kdl_nr_jl_ik', 'limit_ratios', 'momenta', 'newton_euler', 'newton_euler_along', 'pose_error', 'read_urdf_file', 'sample_tip_positions', 'save_map', 'set_core_threads', 'shape_lowest_points', 'shape_lowest_z', 'shape_pair_distances', 'shape_pair_min_distances', 'solve_lp2d', 'topp_ra', 'topp_ra_canonical', 'urdf_root_link', 'zmp_check']
class ChainModel:
    """
    Immutable serial chain between two links of a URDF.
    """
    @staticmethod
    def from_urdf(urdf: str, base: str, tip: str) -> ChainModel:
        """
        urdf: an XML document or a file path
        """
    def fk(self, q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        ...
    def fk_all(self, q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]) -> numpy.typing.NDArray[numpy.float64]:
        ...
    def fk_all_many(self, qs: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"], origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"] | None = None) -> numpy.typing.NDArray[numpy.float64]:
        """
        Every link's pose (T, n_links, 4, 4) for configurations qs (T, n), in the chain's base frame or, given origin (the base frame's pose, 4x4), in origin's frame
        """
    def jacobian(self, q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    def kdl_fk(self, q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        Reference FK through KDL's ChainFkSolverPos_recursive.
        """
    def kdl_jacobian(self, q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Reference Jacobian through KDL's ChainJntToJacSolver.
        """
    @property
    def base(self) -> str:
        ...
    @property
    def body_hash(self) -> str:
        """
        digest of the links' masses, centres of mass, inertias and collision shapes
        """
    @property
    def effort(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def hash(self) -> str:
        """
        digest of the kinematics (what maps depend on)
        """
    @property
    def joint_axes(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (n, 3) unit joint axes, each in the frame of the link the joint moves
        """
    @property
    def joint_child_links(self) -> list[int]:
        """
        index into link_names of the link each joint moves (its frame is the joint frame)
        """
    @property
    def joint_names(self) -> list[str]:
        ...
    @property
    def joint_types(self) -> list[str]:
        ...
    @property
    def link_collisions(self) -> list:
        """
        per link (link_names order) its <collision> elements as (kind, origin 4x4 in the link frame, size, mesh filename): kind 'box' (size = extents), 'cylinder' (radius, length, 0; axis z), 'sphere' (radius, 0, 0) or 'mesh' (size = scale; filename as written in the URDF)
        """
    @property
    def link_coms(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def link_inertias(self) -> numpy.typing.NDArray[numpy.float64]:
        ...
    @property
    def link_masses(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def link_names(self) -> list[str]:
        ...
    @property
    def lower(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def n_joints(self) -> int:
        ...
    @property
    def reach(self) -> float:
        ...
    @property
    def tip(self) -> str:
        ...
    @property
    def total_mass(self) -> float:
        """
        sum of the link masses (kg); may be 0
        """
    @property
    def upper(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def velocity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class TracIK:
    """
    TRAC-IK on a chain: KDL-RR and SLSQP raced in a kept thread pool.
    """
    def __init__(self, model: ChainModel, timeout: typing.SupportsFloat | typing.SupportsIndex, epsilon: typing.SupportsFloat | typing.SupportsIndex, solve_type: str, bounds: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], seed: typing.SupportsInt | typing.SupportsIndex | None = None) -> None:
        ...
    def fk(self, q: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        ...
    def ik(self, pose: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"], q_init: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], bounds: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"] | None = None, timeout: typing.SupportsFloat | typing.SupportsIndex | None = None, algorithm: str = 'TRAC-IK') -> tuple[bool, typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], float]:
        """
        Returns (found, q, seconds); q is q_init when nothing was found.
        """
    def ik_many(self, poses: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], q_inits: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]", "flags.c_contiguous"], streams: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex] | None = None) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], numpy.typing.NDArray[numpy.bool]]:
        ...
    @property
    def bounds(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def epsilon(self) -> float:
        ...
    @property
    def lower(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def n_joints(self) -> int:
        ...
    @property
    def n_workers(self) -> int:
        ...
    @property
    def seed(self) -> int | None:
        ...
    @property
    def solve_type(self) -> str:
        ...
    @property
    def timeout(self) -> float:
        ...
    @property
    def upper(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class WorkspaceOptions:
    """
    Parameters of a reachability sweep (workspace.hpp).
    """
    any_roll: bool
    approach_axis: str
    free_roll: bool
    hull: str
    def __init__(self) -> None:
        ...
    def validate(self) -> None:
        ...
    @property
    def cloud_samples(self) -> int:
        ...
    @cloud_samples.setter
    def cloud_samples(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def directions(self) -> int:
        ...
    @directions.setter
    def directions(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def epsilon(self) -> float:
        ...
    @epsilon.setter
    def epsilon(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def map_shrink(self) -> float:
        ...
    @property
    def poses_per_voxel(self) -> int:
        ...
    @property
    def rolls(self) -> int:
        ...
    @rolls.setter
    def rolls(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def seed(self) -> int:
        ...
    @seed.setter
    def seed(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def shard_count(self) -> int:
        ...
    @shard_count.setter
    def shard_count(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def shard_index(self) -> int:
        ...
    @shard_index.setter
    def shard_index(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def shrink(self) -> float:
        ...
    @shrink.setter
    def shrink(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def threads(self) -> int:
        ...
    @threads.setter
    def threads(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def timeout(self) -> float:
        ...
    @timeout.setter
    def timeout(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def voxel_size(self) -> float:
        ...
    @voxel_size.setter
    def voxel_size(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class ShapeSet:
    """
    Convex collision shapes attached to frames (immutable; safe to share between threads)
    """
    def __getstate__(self) -> tuple:
        ...
    def __init__(self, kinds: collections.abc.Sequence[str], frames: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], origins: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], sizes: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], vertices: collections.abc.Sequence[typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None]) -> None:
        """
        kinds: list of 'box' | 'cylinder' | 'sphere' | 'convex'; frames (S,) int: the frame each is attached to; origins (S, 4, 4): each shape's frame in its frame; sizes (S, 3): box full extents, cylinder (radius, length, 0) along its z, sphere (radius, 0, 0), unused for convex; vertices: per shape a (V, 3) array (convex, in its frame) or None
        """
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def hull_faces(self, i: typing.SupportsInt | typing.SupportsIndex) -> numpy.typing.NDArray[numpy.int64]:
        """
        The hull's triangles (F, 3), indices into hull_vertices, counter-clockwise from outside
        """
    def hull_vertices(self, i: typing.SupportsInt | typing.SupportsIndex) -> numpy.typing.NDArray[numpy.float64]:
        """
        The convex hull's vertices (V, 3) in the shape's frame (convex shapes only)
        """
    @property
    def bounding_radii(self) -> numpy.typing.NDArray[numpy.float64]:
        ...
    @property
    def frames(self) -> numpy.typing.NDArray[numpy.int64]:
        ...
    @property
    def kinds(self) -> list[str]:
        ...
    @property
    def size(self) -> int:
        ...
class PathChecker:
    """
    Ground, self and obstacle clearances of a chain's configurations, per sample and proven along straight joint segments (path_check.hpp); immutable, safe to share between threads
    """
    def __init__(self, model: ChainModel, shapes: ShapeSet, origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"], ground_shapes: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], self_pairs: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], obstacles: ShapeSet | None, obstacle_pairs: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], ground_floor: typing.SupportsFloat | typing.SupportsIndex, obstacle_cutoff: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        model: the chain; shapes: its links' shapes; origin: the chain base's world pose (4, 4); ground_shapes (k,): shapes whose lowest point must stay >= ground_floor (m); self_pairs (P, 2): shape pairs that must stay apart; obstacles: a ShapeSet on one world frame (or None) and obstacle_pairs (Q, 2) (robot shape, obstacle shape); obstacle_cutoff (m): per-sample obstacle distances are exact below it
        """
    def check_motion(self, qs: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], first_step: typing.SupportsFloat | typing.SupportsIndex, floor_step: typing.SupportsFloat | typing.SupportsIndex = 0.001) -> dict:
        """
        Proves a sampled motion qs (T, n) clear at and between its samples (joined by straight joint segments; path_check.hpp): evaluated where a joint has travelled first_step (rad) since the last, each interval proven with the joints' total variation or halved. A dict as check_path's (without segments) and obstacle_lower (T,): a lower bound of the obstacle distance from each sample to the next
        """
    def check_path(self, waypoints: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], first_step: typing.SupportsFloat | typing.SupportsIndex = 0.05, floor_step: typing.SupportsFloat | typing.SupportsIndex = 0.001, stop_at_violation: bool = True) -> dict:
        """
        Proves the straight joint segments between waypoints (K, n) clear: a dict with clear, segments (K-1,) bool, samples evaluated, intervals proven / unproven (at the floor), violations (samples below a floor) and the smallest ground, self, obstacle values evaluated
        """
    def motion_bounds(self, qa: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], qb: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
        """
        Per robot shape: how far any of its points moves (m) and how far its lowest z changes (m) along the straight joint segment qa -> qb (proven bounds: path_check.hpp)
        """
    def sample(self, qs: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
        """
        Each configuration's (T, n) smallest ground clearance, self clearance and obstacle distance (m): three (T,) arrays, +inf where nothing is checked
        """
class ZmpPrefix:
    """
    What zmp_check computed sample by sample over the first samples of a motion, for a later check of a motion that begins with the same samples (zmp_check.hpp); immutable
    """
    @property
    def samples(self) -> int:
        """
        how many samples it holds
        """
class ToppRaResult:
    """
    The result of topp_ra
    """
    @property
    def K(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 2]"]:
        """
        (N+1, 2) controllable sets of x (NaN at failed_at and before when uncontrollable)
        """
    @property
    def failed_at(self) -> int:
        """
        the gridpoint where it failed; -1 when feasible
        """
    @property
    def lp_count(self) -> int:
        """
        LPs solved
        """
    @property
    def status(self) -> str:
        """
        'feasible', 'uncontrollable' (the backward pass found an empty controllable set), 'start_outside' (x_start is not in K_0) or 'forward_failed' (round-off: the forward pass found no u)
        """
    @property
    def u(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (N,) path accelerations of the stages, (x_{i+1} - x_i) / (2 delta_i)
        """
    @property
    def x(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (N+1,) squared path speeds (NaN where the forward pass did not reach)
        """
class TrackingFit:
    """
    The tracking interpolation's damped least-squares fit of the lifted joints to Eq. 41's points, with the ground, self-clearance and continuity terms (tracking_fit.hpp); immutable, safe to share between threads
    """
    def __init__(self, model: ChainModel, shapes: ShapeSet, origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"], lift: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], points: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], lifted_links: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], self_pairs: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], *, damping: typing.SupportsFloat | typing.SupportsIndex, iterations: typing.SupportsInt | typing.SupportsIndex, step_tolerance: typing.SupportsFloat | typing.SupportsIndex, clearance: typing.SupportsFloat | typing.SupportsIndex, ground_weight: typing.SupportsFloat | typing.SupportsIndex, continuity: typing.SupportsFloat | typing.SupportsIndex, self_clearance: typing.SupportsFloat | typing.SupportsIndex, self_step: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        model: the chain; shapes: its links' shapes; origin: the chain base's world pose (4, 4); lift (k,): the fitted joints; points (m,): links whose origins track the targets; lifted_links: links kept `clearance` (m) above the ground; self_pairs (P, 2): shape pairs kept `self_clearance` (m) apart; the settings: python/snakehead/motion/cartesian.py's TRACKING_* constants
        """
    def fit(self, q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], targets: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
        """
        q (S, n) with rows 1 .. S-2's lifted joints fitted to targets (S, m, 3), each sample warm-started from the previous one's fit (row 0's lifted joints are the start); a new array
        """
    def step(self, q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], current: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], target: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        """
        One damped least-squares step at q (n) towards target (m, 3) from the previous sample's lifted joints current (k): the stacked residual (rows,), its Jacobian (rows, k) and the step (k,), unclipped
        """
class Limits:
    """
    The C++ core's limits on what callers may ask for (include/snakehead/limits.hpp), as class attributes; snakehead.limits gives them their Python names.
    """
    MAX_CLOUD_SAMPLES: typing.ClassVar[int] = 10000000
    MAX_DIRECTIONS: typing.ClassVar[int] = 4096
    MAX_FRAMES_PER_VOXEL: typing.ClassVar[int] = 4096
    MAX_IK_JOINTS: typing.ClassVar[int] = 1000
    MAX_ROLLS: typing.ClassVar[int] = 360
    MAX_TERRAIN_CELLS: typing.ClassVar[int] = 1048576
    MAX_TERRAIN_TRIANGLES: typing.ClassVar[int] = 2000000
    MAX_THREADS: typing.ClassVar[int] = 256
    MAX_TIMEOUT_S: typing.ClassVar[float] = 86400.0
    MAX_URDF_BYTES: typing.ClassVar[int] = 8388608
    MAX_URDF_DEPTH: typing.ClassVar[int] = 100
    MAX_VOXELS_PER_AXIS: typing.ClassVar[int] = 256
class Terrain:
    """
    The ground as a surface: a plane, a heightfield (triangulated grid) or a triangle mesh (immutable; safe to share between threads). See include/snakehead/terrain.hpp.
    """
    @staticmethod
    def heightfield(heights: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], size: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> Terrain:
        """
        heights (nx, ny) m at x0 + i sx / (nx - 1), y0 + j sy / (ny - 1); size (sx, sy) m; origin (x0, y0, z0) m, z0 added to every height. Each cell is split along its diagonal from (i, j) to (i + 1, j + 1)
        """
    @staticmethod
    def mesh(vertices: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], faces: typing.Annotated[numpy.typing.ArrayLike, numpy.int64]) -> Terrain:
        """
        A triangle surface: vertices (V, 3) m, faces (F, 3) int (its normals by the right-hand rule point to the positive side)
        """
    @staticmethod
    def plane(normal: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], point: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> Terrain:
        """
        A plane through point (3,) with the upward normal (3,) (any length, n_z > 0)
        """
    def __getstate__(self) -> tuple:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def capsule_clearance(self, a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], radii: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
        """
        Capsules' clearance (m): segments a -> b (N, 3), radii (N,); see include/snakehead/terrain.hpp
        """
    def height(self, xy: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
        """
        The surface's z (m) under each point (N, 2) -> (N,); NaN where there is no surface
        """
    def normal(self, xy: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
        """
        The unit upward normal of the facet under each point (N, 2) -> (N, 3); NaN where none
        """
    def signed_distance(self, points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
        """
        Signed distance (m) of points (N, 3) to the surface, > 0 above -> (N,)
        """
    def sphere_clearance(self, centres: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], radii: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
        """
        Spheres' signed distance minus radius: centres (N, 3), radii (N,)
        """
    @property
    def faces(self) -> numpy.typing.NDArray[numpy.int64]:
        """
        The surface's triangles (F, 3) (none for a plane)
        """
    @property
    def kind(self) -> str:
        ...
    @property
    def vertices(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        The surface's triangles' vertices (V, 3) (none for a plane)
        """
class Cancelled(Exception):
    pass
def approach_frame(point: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], direction: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], roll: typing.SupportsFloat | typing.SupportsIndex = 0.0, axis: str = 'x') -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
    """
    4x4 frame at point whose x- (or z-) axis is direction, rolled by roll rad about it
    """
def boundary(points: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]", "flags.c_contiguous"], shrink: typing.SupportsFloat | typing.SupportsIndex = 0.5) -> dict:
    """
    The paper's boundary(P) of (n, 3) points (alpha_shape.hpp): its alpha and size, as a dict
    """
def boundary_voxels(points: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]", "flags.c_contiguous"], shrink: typing.SupportsFloat | typing.SupportsIndex, origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], voxel: typing.SupportsFloat | typing.SupportsIndex, n: typing.SupportsInt | typing.SupportsIndex) -> numpy.typing.NDArray[numpy.int64]:
    """
    Linear ids of the grid voxels whose centre lies inside the boundary of the points
    """
def center_of_mass(frames: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], masses: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], coms: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
    """
    The centre of mass (Eq. 23) of each sample (T, 3) from the links' frames (T, L, 4, 4), masses (L,) and centres of mass in the links' frames (L, 3): summed link by link in a fixed order, without BLAS, so that a sample's numbers do not depend on the samples around it, the machine or the thread count
    """
def compute_reachability(model: ChainModel, options: WorkspaceOptions, progress: typing.Any = None) -> dict:
    """
    Algorithm 1 over options' shard; returns the map's arrays and statistics as a dict
    """
def convex_hull(points: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]", "flags.c_contiguous"]) -> dict:
    """
    qhull's hull of (n, 3) points: facet planes normal . x + offset <= 0 inside, volume
    """
def convex_hull_2d(points: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 2]", "flags.c_contiguous"]) -> list[int]:
    """
    Counter-clockwise convex hull indices of (N, 2) points; edge points left out
    """
def convex_hulls(points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], active: typing.Annotated[numpy.typing.ArrayLike, numpy.bool]) -> tuple[numpy.typing.NDArray[numpy.int32], numpy.typing.NDArray[numpy.int32]]:
    """
    Each sample's counter-clockwise convex hull of its active points: vertex indices (T, N), -1 after the count, and the counts (T,)
    """
def core_threads() -> int:
    """
    The threads the core's batch work (TRAC-IK batches, a workspace sweep without a thread count) may use in this process: the value set, else SNAKEHEAD_NUM_THREADS, else OMP_NUM_THREADS, else every hardware thread.
    """
def evaluate_piecewise_polynomial(c: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], breaks: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
    """
    A piecewise polynomial's values at points (N,) -> (N, n), bit for bit what scipy.interpolate.PPoly(c, breaks) gives (nu = 0, extrapolating): c (k, m, n) highest power first, breaks (m + 1,) strictly increasing.
    """
def evaluate_voxels(model: ChainModel, options: WorkspaceOptions, centers: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]", "flags.c_contiguous"], stream_ids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], progress: typing.Any = None) -> dict:
    """
    Algorithm 1's lines 9-21 for spheres at the given centres; progress(done, total) -> bool
    """
def fibonacci_directions(n: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
    """
    n unit vectors spread evenly on the sphere (Fibonacci lattice), (n, 3)
    """
def fit_neck(neck: ChainModel, P0_frame: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"], P_d: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], r_d: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], q_init: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"] | None, *, h: typing.SupportsFloat | typing.SupportsIndex, grid_points: typing.SupportsInt | typing.SupportsIndex, grid_fraction: typing.SupportsFloat | typing.SupportsIndex, iterations: typing.SupportsInt | typing.SupportsIndex, tolerance: typing.SupportsFloat | typing.SupportsIndex, continuity_tolerance: typing.SupportsFloat | typing.SupportsIndex) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], float]:
    """
    Eq. 22 (neck_fit.hpp): the neck joints minimising |P_a - P_d|^2 + h |r_d x r_a|^2 within their limits, by a bounded Levenberg-Marquardt from q_init (None: none) and from the best point of a grid; (q, cost)
    """
def hull_margins(points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], active: typing.Annotated[numpy.typing.ArrayLike, numpy.bool], xy: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
    """
    Signed distance (> 0 inside) of each sample's xy to the convex hull of its active points: (T,)
    """
def kdl_nr_jl_ik(model: ChainModel, pose: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"], q_init: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], timeout: typing.SupportsFloat | typing.SupportsIndex = 0.005, epsilon: typing.SupportsFloat | typing.SupportsIndex = 1e-05) -> tuple[bool, typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
    """
    KDL's ChainIkSolverPos_NR_JL from q_init until converged or timeout: (found, q).
    """
def limit_ratios(qd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], qdd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], tau: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], Pdot: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], Ldot: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], com: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], normal: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], offset: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], velocity: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], acceleration: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], torque: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], Mg: typing.SupportsFloat | typing.SupportsIndex, friction: typing.SupportsFloat | typing.SupportsIndex, Mg_x: typing.SupportsFloat | typing.SupportsIndex = 0.0, Mg_y: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> dict:
    """
    Per sample (N,): the largest |value| / limit of qd, qdd and tau (N, n), the friction used (|dP_xy/dt - (Mg_x, Mg_y)| / (friction (Mg + dP_z/dt)), inf where the ground would pull; Mg_x, Mg_y: the weight along a slope's ground, zero on flat ground) and the ZMP's signed distance inside its polygon (normal (N, E, 2) inward, offset (N, E); -inf where the ground would pull): a dict of arrays.
    """
def momenta(frames: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], qd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], joint_child: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], axes: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], masses: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], coms: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], inertias: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    The momenta of Eqs. 25-31 and the CoM: P, L about the frames' origin, c, (T, 3) each
    """
def newton_euler(frames: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], qd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], qdd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], joint_child: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], axes: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], masses: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], coms: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], inertias: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], share: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None, gravity: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    Newton-Euler with the root link still: joint torques (T, n) and the inertial wrench across the first joint (force (T, 3), moment about the frames' origin (T, 3), in their axes; frames in an inertial frame where the root link is still)
    """
def newton_euler_along(model: ChainModel, origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"], q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], qd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], qdd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], joint_child: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], axes: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], masses: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], coms: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], inertias: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], lift_links: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex] | None, lift_points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None, ramp: typing.SupportsFloat | typing.SupportsIndex, gravity: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    newton_euler along configurations q (T, n), the link frames (origin times the model's FK) and the lifted shares (lift_links, lift_points (k, M, 3) in the links' frames, ramp m; None: every weight in full) computed in the core: torques (T, n), the inertial wrench across the first joint (force, moment (T, 3)) and the centre of mass (T, 3)
    """
def pose_error(target: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"], current: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    The IK pose error (vx vy vz wx wy wz) of `current` relative to `target`, in the target frame.
    """
def read_urdf_file(path: str) -> str:
    """
    The text of a URDF file: ValueError unless a readable regular file of at most 8 MiB
    """
def sample_tip_positions(model: ChainModel, samples: typing.SupportsInt | typing.SupportsIndex, seed: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
    ...
def save_map(path: str, command: str, options: WorkspaceOptions, centers: typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]", "flags.c_contiguous"], solved: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], voxel_ids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], reached: typing.Annotated[numpy.typing.ArrayLike, numpy.uint8] | None, tried: typing.SupportsInt | typing.SupportsIndex, grid_origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], grid_voxel: typing.SupportsFloat | typing.SupportsIndex, grid_n: typing.SupportsInt | typing.SupportsIndex, hull_voxels: typing.SupportsInt | typing.SupportsIndex, hull_facets: typing.SupportsInt | typing.SupportsIndex, alpha: typing.SupportsFloat | typing.SupportsIndex, reach: typing.SupportsFloat | typing.SupportsIndex, chain_hash: str, base: str, tip: str, ik_calls: typing.SupportsInt | typing.SupportsIndex, cheap_exits: typing.SupportsInt | typing.SupportsIndex, seconds: typing.SupportsFloat | typing.SupportsIndex, threads: typing.SupportsInt | typing.SupportsIndex, kind: str = 'head', base_joints: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None, base_placements: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None) -> None:
    """
    The one map writer (save_npz, also workspace_gen's): a map's arrays to an .npz that numpy.load reads
    """
def set_core_threads(n: typing.SupportsInt | typing.SupportsIndex) -> None:
    """
    Sets core_threads() for this process (1..MAX_THREADS; 0 restores the default); InputError otherwise.
    """
def shape_lowest_points(frames: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], set: ShapeSet, shapes: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], max_points: typing.SupportsInt | typing.SupportsIndex = 16) -> numpy.typing.NDArray[numpy.float64]:
    """
    Each listed shape's max_points lowest ground-contact candidates in the world, by z ascending (padded with the lowest): (T, k, max_points, 3)
    """
def shape_lowest_z(frames: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], set: ShapeSet, shapes: typing.Annotated[numpy.typing.ArrayLike, numpy.int64]) -> numpy.typing.NDArray[numpy.float64]:
    """
    The lowest world z of each listed shape: frames (T, L, 4, 4), shapes (k,) int -> (T, k)
    """
def shape_pair_distances(frames_a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], set_a: ShapeSet, frames_b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], set_b: ShapeSet, pairs: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], cutoff: typing.SupportsFloat | typing.SupportsIndex = ...) -> numpy.typing.NDArray[numpy.float64]:
    """
    Signed distances (m) of shape pairs (P, 2) (set_a index, set_b index): frames_a (T, La, 4, 4), frames_b (T or 1, Lb, 4, 4) -> (T, P); > 0 apart, < 0 minus the penetration depth; exact where the bounding spheres' lower bound is below cutoff, that bound elsewhere
    """
def shape_pair_min_distances(frames_a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], set_a: ShapeSet, frames_b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], set_b: ShapeSet, pairs: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], cutoff: typing.SupportsFloat | typing.SupportsIndex = ...) -> numpy.typing.NDArray[numpy.float64]:
    """
    The smallest of shape_pair_distances' values at each sample (pruned): (T,), +inf when there is no pair
    """
def solve_lp2d(v_u: typing.SupportsFloat | typing.SupportsIndex, v_x: typing.SupportsFloat | typing.SupportsIndex, rows: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], lo: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], hi: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"]) -> tuple[bool, float, float]:
    """
    max v_u u + v_x x subject to rows (m, 3) a u + b x <= c and lo <= (u, x) <= hi: (feasible, u, x)
    """
def topp_ra(grid: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], A: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], B: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], C: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], u_bounds: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], x_bounds: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], x_start: typing.SupportsFloat | typing.SupportsIndex = 0.0, x_end: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> ToppRaResult:
    """
    TOPP-RA over grid (N+1,) with stage rows A u + B x <= C (N, m each), u_bounds (N, 2), x_bounds (N+1, 2): the controllable sets and the greedy forward pass from x_start to x_end (include/snakehead/topp_ra.hpp)
    """
def topp_ra_canonical(grid: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], P: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], Q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], R: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], x_max: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], x_start: typing.SupportsFloat | typing.SupportsIndex = 0.0, x_end: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> ToppRaResult:
    """
    TOPP-RA over grid (N+1,) with the gridpoints' rows P u + Q x <= R (N+1, m each) and x <= x_max (N+1,), discretized as toppra's interpolation discretization in the core: topp_ra's result for the stage rows retiming._topp.interpolated makes, to the bit (include/snakehead/topp_ra.hpp)
    """
def urdf_root_link(urdf: str) -> str:
    """
    The root link of a URDF (an XML document or a file path)
    """
def zmp_check(checker: PathChecker, t: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], qd: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], contact_shapes: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], points_per_shape: typing.SupportsInt | typing.SupportsIndex, clearance_shapes: typing.Annotated[numpy.typing.ArrayLike, numpy.int64], ground_key: bool, key_joints: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], tolerance: typing.SupportsFloat | typing.SupportsIndex, chunk: typing.SupportsInt | typing.SupportsIndex, gravity: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], resume: ZmpPrefix | None = None, keep: typing.SupportsInt | typing.SupportsIndex = 0) -> dict:
    """
    The ZMP check of a sampled motion (Eqs. 25-40) in one pass (zmp_check.hpp): a dict of zmp (T, 2), margin (T,), P, L, com (T, 3) and clearance (T,): the lowest z of clearance_shapes; gravity (3,) m/s^2 in the ground frame (BasePlacement.gravity). resume: a ZmpPrefix whose samples this motion begins with (taken over when everything it was made from is the same, to the bit: resumed says how many samples); keep > 0: kept is the ZmpPrefix of the first keep samples (else None)
    """
