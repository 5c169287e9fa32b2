"""The path checks in C++ batches (collision.path_proof, _core.PathChecker, _core.zmp_check) against brute force and
the Python reference: per-sample minima equal the collision module's, the motion bound is never exceeded (100x finer
sampling), a proven-clear path is clear at every fine sample, and the ZMP check equals an independent computation
(tests/zmp_reference.py: pinocchio's momenta, each shape's contact candidates in numpy, scipy's hull) and the Python
dynamic_stability."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from snakehead import set_core_threads
from snakehead.collision import body_collisions as coll
from snakehead.collision import path_proof as path_check
from snakehead.dynamics import stability
from snakehead.geometry import BoxObstacle
from snakehead.geometry.shapes import shape_points
from snakehead.ground_contact import GROUND_TOLERANCE
from snakehead.margins import EXACT_DISTANCE_WITHIN
from snakehead.model.robot import BasePlacement, SnakeRobot
from snakehead.samples.published import write_robot

FINE = 100  # brute force: points per interval


@pytest.fixture(scope="module")
def robots(tmp_path_factory: pytest.TempPathFactory) -> dict[str, SnakeRobot]:
    """The default robot and published-style snakes: cylinders along x (reu), modules along z (sea), meshes."""
    folder = Path(tmp_path_factory.mktemp("published"))
    out = {"default": SnakeRobot.default()}
    for style in ("reu", "sea", "mesh"):
        out[style] = SnakeRobot.from_file(write_robot(style, folder / style))
    return out


def _near_start(robot: SnakeRobot, rng: np.random.Generator, spread: float) -> np.ndarray:
    """A configuration near the straight body, the neck and head lifted a little (close to the ground)."""
    q = rng.normal(0.0, spread, robot.n_joints)
    return np.clip(q, robot.lower, robot.upper)


def _world_points(robot: SnakeRobot, frames: np.ndarray) -> list[np.ndarray]:
    """Per shape, its points (T, P, 3) in the world (convex hulls of shapes: the extreme points of each)."""
    out = []
    for s in robot.geometry.shapes:
        P = shape_points(s, 32)
        F = frames[:, s.frame]
        out.append(np.einsum("tij,pj->tpi", F[:, :3, :3], P) + F[:, None, :3, 3])
    return out


def test_sample_minima_equal_the_collision_module(robots: dict[str, SnakeRobot]) -> None:
    rng = np.random.default_rng(5)
    for name, robot in robots.items():
        base = BasePlacement(0.1, -0.2, 0.3)
        qs = np.array([_near_start(robot, rng, 0.4) for _ in range(40)])
        box = BoxObstacle(centre=(0.5, 0.0, 0.1), size=(0.1, 0.3, 0.2))
        ground, self_, obstacle = path_check.sample_clearances(robot, qs, base, [box])
        ref = coll.ground_clearance(robot, qs, base)[:, robot.lifted_links].min(axis=1)
        np.testing.assert_array_equal(ground, ref, err_msg=name)
        np.testing.assert_allclose(self_, coll.self_clearance(robot, qs, base), atol=1e-12, err_msg=name)
        d = coll.collision_check(robot, qs, [box], base, exact_within=EXACT_DISTANCE_WITHIN).distance
        near = d < EXACT_DISTANCE_WITHIN  # exact there; both report lower bounds above it
        np.testing.assert_allclose(obstacle[near], d[near], atol=1e-12, err_msg=name)
        assert (obstacle[~near] >= EXACT_DISTANCE_WITHIN).all()
        assert near.any() and (d <= 0).any(), f"{name}: the obstacle must be met by some samples"


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(seed=st.integers(0, 2**32 - 1), which=st.sampled_from(["default", "reu", "sea", "mesh"]),
       spread=st.sampled_from([0.02, 0.1, 0.4]))
def test_motion_bound_is_never_exceeded(robots: dict[str, SnakeRobot], seed: int, which: str, spread: float) -> None:
    """Every point of every shape moves at most B_S and its lowest z changes at most Z_S along the segment, and the
    true minimum of a clearance over the interval is at least the ends' minus the bound."""
    robot = robots[which]
    rng = np.random.default_rng(seed)
    base = BasePlacement(*rng.uniform(-1, 1, 3))
    qa = _near_start(robot, rng, 0.5)
    qb = np.clip(qa + rng.normal(0.0, spread, robot.n_joints), robot.lower, robot.upper)
    B, Z = path_check.checker(robot, base).motion_bounds(qa, qb)
    s = np.linspace(0.0, 1.0, FINE + 1)[:, None]
    frames = robot.frames_many(qa + s * (qb - qa), base)
    for i, W in enumerate(_world_points(robot, frames)):
        moved = np.linalg.norm(W - W[:1], axis=2).max()
        low = W[..., 2].min(axis=1)
        assert moved <= B[i] + 1e-12
        assert np.abs(low - low[0]).max() <= Z[i] + 1e-12
        assert low.min() >= 0.5 * (low[0] + low[-1] - Z[i]) - 1e-12  # the cones' meeting point


@pytest.mark.parametrize("which", ["default", "reu", "sea", "mesh"])
def test_a_proven_clear_path_is_clear_at_every_fine_sample(robots: dict[str, SnakeRobot], which: str) -> None:
    robot = robots[which]
    base = BasePlacement()
    box = BoxObstacle(centre=(robot.body_length * 0.6, 0.25, 0.1), size=(0.1, 0.1, 0.2))
    proven = 0
    for seed in range(8):
        rng = np.random.default_rng(seed)
        W = np.array([_near_start(robot, rng, 0.15) for _ in range(3)])
        W[:, robot.lift_joints.start] = -np.abs(W[:, robot.lift_joints.start])  # the neck's first pitch, one way
        for obstacles in ([], [box]):
            report = path_check.check_path(robot, W, base, obstacles, stop_at_violation=False)
            for k in np.flatnonzero(report.segments):
                proven += 1
                s = np.linspace(0.0, 1.0, FINE + 1)[:, None]
                qs = W[k] + s * (W[k + 1] - W[k])
                assert coll.ground_clearance(robot, qs, base)[:, robot.lifted_links].min() >= -coll.GROUND_TOLERANCE
                assert coll.self_clearance(robot, qs, base).min() > 0.0
                if obstacles:
                    assert coll.collision_check(robot, qs, obstacles, base, exact_within=np.inf).distance.min() > 0.0
    assert proven > 0, "no segment proven: the test would check nothing"


def test_check_path_finds_a_violation_between_clear_waypoints() -> None:
    """Two waypoints clear of a thin wall, the straight path between them through it: not proven, a violation."""
    robot = SnakeRobot.default()
    H = robot.head_pose(np.zeros(robot.n_joints))
    wall = BoxObstacle(centre=(H[0, 3] - 0.1, 0.0, 0.02), size=(0.01, 0.02, 0.04))
    qa, qb = np.zeros(robot.n_joints), np.zeros(robot.n_joints)
    yaw = [j for j in range(robot.lift_joints.start, robot.n_joints) if robot.joint_kinds[j] == "yaw"][0]
    qa[yaw], qb[yaw] = 0.6, -0.6
    ends = path_check.sample_clearances(robot, np.array([qa, qb]), None, [wall])[2]
    assert (ends > 0).all()
    report = path_check.check_path(robot, np.array([qa, qb]), None, [wall])
    assert not report.clear and report.violations >= 1 and report.obstacle <= 0.0


def _lifted(robot: SnakeRobot, angle: float) -> np.ndarray:
    """The straight body with the neck's first pitch joint at +-angle, the sign that raises the head."""
    q = np.zeros(robot.n_joints)
    q[robot.lift_joints.start] = angle
    return q if robot.head_pose(q)[2, 3] >= robot.head_pose(-q)[2, 3] else -q


def _smooth_motion(robot: SnakeRobot, rng: np.random.Generator, samples: int, spread: float) -> np.ndarray:
    """A smooth motion (samples, n) through three random configurations with the head raised (the neck's first
    pitch lifting by 0.3-0.7 rad, the joints after it spread around 0, the base's yaw joints a little): a cubic
    spline, as a timed motion's path."""
    from scipy.interpolate import CubicSpline

    pitch = robot.lift_joints.start
    W = np.array([_lifted(robot, rng.uniform(0.3, 0.7)) for _ in range(3)])
    W[:, pitch + 1:] += rng.normal(0.0, spread, (3, robot.n_joints - pitch - 1))
    yaw = [j for j in range(pitch) if robot.joint_kinds[j] == "yaw"]  # the base stays flat on the ground
    W[:, yaw] += rng.normal(0.0, 0.05, (3, len(yaw)))
    q = CubicSpline([0.0, 0.5, 1.0], W, axis=0)(np.linspace(0.0, 1.0, samples))
    return np.clip(q, robot.lower, robot.upper)


@settings(max_examples=16, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(seed=st.integers(0, 2**32 - 1), which=st.sampled_from(["default", "reu", "sea", "mesh"]),
       first_step=st.sampled_from([0.05, 0.2, 0.6]), spread=st.sampled_from([0.1, 0.3]))
@example(seed=3353050, which="default", first_step=0.05, spread=0.1)  # 125 configurations for 60 samples: splits
def test_check_motion_is_a_proof_against_brute_force(robots: dict[str, SnakeRobot], seed: int, which: str,
                                                     first_step: float, spread: float) -> None:
    """check_motion (coarse samples, total-variation bound) against brute force at 8 points of every straight
    segment between consecutive samples: a motion it proves clear is clear at every fine point (ground, self and
    exact obstacle distances), and its obstacle_lower[k] is at most the exact smallest distance from sample k to
    k + 1."""
    robot = robots[which]
    rng = np.random.default_rng(seed)
    base = BasePlacement(*rng.uniform(-0.2, 0.2, 3))
    q = _smooth_motion(robot, rng, 60, spread)
    Hq = robot.frames_many(q[::20], base)[:, -1, :3, 3]  # near the head's path: close calls
    box = BoxObstacle(centre=Hq[rng.integers(len(Hq))] + rng.normal(0.0, 0.15, 3) * [1, 1, 0.3],
                      size=rng.uniform(0.02, 0.1, 3))
    report = path_check.check_motion(robot, q, base, [box], first_step=first_step)
    alone = path_check.check_motion(robot, q, base, [], first_step=first_step)  # ground and self only
    fine = 8
    s = (np.arange(fine) / fine)[None, :, None]
    qs = np.concatenate([(q[:-1, None] + s * (q[1:] - q[:-1])[:, None]).reshape(-1, robot.n_joints), q[-1:]])
    ground = coll.ground_clearance(robot, qs, base)[:, robot.lifted_links].min(axis=1)
    self_ = coll.self_clearance(robot, qs, base)
    d = coll.collision_check(robot, qs, [box], base, exact_within=np.inf).distance
    if alone.clear:
        assert ground.min() >= -coll.GROUND_TOLERANCE and self_.min() > 0.0
    if report.clear:
        assert alone.clear and d.min() > 0.0
    # per interval [k, k + 1]: its fine points and sample k + 1
    per = np.minimum(np.append(d[:-1].reshape(len(q) - 1, fine).min(axis=1), d[-1]),
                     np.append(d[fine::fine], np.inf))
    assert (report.obstacle_lower <= per + 1e-9).all()
    # every configuration evaluated is one of the T samples or the midpoint of an interval split into two: each split
    # adds a leaf (an interval proven, violated or unproven), so at most T + leaves - 1 (not a fixed allowance: two
    # leaves split to the floor near a box already exceed T + 64)
    leaves = report.proven + report.unproven + report.violations
    assert report.samples <= len(q) + max(leaves - 1, 0)


def test_check_motion_catches_a_thin_obstacle_between_coarse_samples() -> None:
    """The head sweeps sideways through a 2 mm plate. Densely sampled (0.01 rad steps) and evaluated every 0.2 rad,
    none of the evaluated samples touches it: the proof finds it (halving); sampled sparsely so that no sample
    touches it at all (what a check at the samples would pass), the proof still finds it between them."""
    robot = SnakeRobot.default()
    q0 = _lifted(robot, 0.5)
    pitch = robot.lift_joints.start
    yaw = [j for j in range(pitch, robot.n_joints) if robot.joint_kinds[j] == "yaw"][0]
    H = robot.head_pose(q0)
    plate = BoxObstacle(centre=H[:3, 3], size=(0.1, 0.002, 0.1))
    sweep = np.linspace(-0.3, 0.3, 61)
    q = np.repeat(q0[None], len(sweep), axis=0)
    q[:, yaw] = sweep
    evaluated = q[::20]  # where some joint has travelled 0.2 rad
    assert (path_check.sample_clearances(robot, evaluated, None, [plate])[2] > 0).all()
    dense = path_check.check_motion(robot, q, None, [plate], first_step=0.2)
    assert not dense.clear and dense.violations >= 1 and dense.obstacle_lower.min() <= 0.0
    sparse = q[[0, 15, 45, 60]]  # yaw -0.3, -0.15, 0.15, 0.3
    assert (path_check.sample_clearances(robot, sparse, None, [plate])[2] > 0).all()
    report = path_check.check_motion(robot, sparse, None, [plate], first_step=0.2)
    assert not report.clear and report.obstacle_lower[1] <= 0.0
    assert (report.obstacle_lower[[0, 2]] > 0.0).all()  # the other intervals stay clear of it
    clear = path_check.check_motion(robot, sparse, None, [], first_step=0.2)
    assert clear.clear and np.isinf(clear.obstacle_lower).all()


def _lift_then_other(robot: SnakeRobot, rng: np.random.Generator):
    """A motion ``lift`` (301 samples over 2 s) and ``q``: its first m = 120 samples, then another motion's: t, lift,
    its velocities, the other motion, q, its velocities, m."""
    t = np.linspace(0.0, 2.0, 301)
    lift = _smooth_motion(robot, rng, 301, 0.2)
    qd_lift = np.gradient(lift, t, axis=0)
    other = _smooth_motion(robot, rng, 301, 0.2)
    m = 120
    q = np.concatenate([lift[:m], other[m:]])
    qd = np.concatenate([qd_lift[:m], np.gradient(other, t, axis=0)[m:]])
    return t, lift, qd_lift, other, q, qd, m


def test_zmp_check_takes_over_a_kept_prefix_to_the_bit() -> None:
    """A check that takes over the first samples' part of an earlier one (KeptSamples: a motion beginning with the
    same samples) equals the check from scratch bit for bit; a motion whose first samples differ is computed from
    scratch; at another placement on the ground the prefix is moved there (test below)."""
    robot = SnakeRobot.default()
    rng = np.random.default_rng(3)
    t, lift, qd_lift, other, q, qd, m = _lift_then_other(robot, rng)
    base = BasePlacement(0.1, 0.2, 0.3)
    kept = stability.KeptSamples(m)
    stability.dynamic_stability_with_clearance(robot, t, lift, base, qd_lift, kept=kept)
    assert kept.core is not None and kept.core.samples == m and kept.resumed == 0
    for motion, velocity, where, takes_over in ((q, qd, base, True), (other, np.gradient(other, t, axis=0), base, False)):
        fresh, fresh_clear = stability.dynamic_stability_with_clearance(robot, t, motion, where, velocity)
        again, clear = stability.dynamic_stability_with_clearance(robot, t, motion, where, velocity, kept=kept)
        assert kept.resumed == (m if takes_over else 0)
        for name in ("zmp", "margin", "P", "L", "com"):
            np.testing.assert_array_equal(getattr(again, name), getattr(fresh, name), err_msg=name)
        np.testing.assert_array_equal(clear, fresh_clear)
        assert (again.argmin, again.stable) == (fresh.argmin, fresh.stable)
    runs = stability.contact_configurations(robot, lift[:m], base, "ground", GROUND_TOLERANCE)[2].max() + 1
    assert runs > 2, "the kept samples must hold several contact runs"


@pytest.mark.parametrize("which", ["default", "sea"])
def test_zmp_check_moves_a_prefix_kept_at_another_placement(robots: dict[str, SnakeRobot], which: str) -> None:
    """A prefix kept at one placement, taken over at others (the base turned about z and moved on the ground: a lift
    checked once for every placement of a base shape): the momenta, CoM, ZMP and margins equal the check from scratch
    to round-off (1e-12), the clearances and the verdict exactly; a placement off the ground plane's motions (another
    height) is computed from scratch. (sea: a rotated root.)"""
    robot = robots[which]
    rng = np.random.default_rng(8)
    t, lift, qd_lift, other, q, qd, m = _lift_then_other(robot, rng)
    kept = stability.KeptSamples(m)
    stability.dynamic_stability_with_clearance(robot, t, lift, BasePlacement(0.1, 0.2, 0.3), qd_lift, kept=kept)
    for where in (BasePlacement(-1.3, 0.7, -2.9), BasePlacement(0.1, 0.2, 0.31), BasePlacement(25.0, -40.0, 1.0)):
        fresh, fresh_clear = stability.dynamic_stability_with_clearance(robot, t, q, where, qd)
        again, clear = stability.dynamic_stability_with_clearance(robot, t, q, where, qd, kept=kept)
        assert kept.resumed == m
        scale = max(1.0, abs(where.x), abs(where.y))
        for name in ("zmp", "margin", "P", "L", "com"):
            np.testing.assert_allclose(getattr(again, name), getattr(fresh, name), rtol=0, atol=1e-12 * scale,
                                       err_msg=name)
        np.testing.assert_array_equal(clear, fresh_clear)
        assert again.stable == fresh.stable and again.argmin == fresh.argmin
        assert np.abs(again.margin[:m] - again.margin[:m].mean()).max() > 1e-4  # the prefix's margins vary: compared
    # an origin 1 cm higher (not a placement on the ground: the heights differ): computed from scratch
    from snakehead import _core
    from snakehead.collision.body_collisions import GROUND_TOLERANCE
    from snakehead.margins import EXACT_DISTANCE_WITHIN

    origin = robot.root_pose(BasePlacement(0.1, 0.2, 0.3))
    origin[2, 3] += 0.01
    g = robot.geometry
    high = _core.PathChecker(robot.body.model, g.core, origin, g.shapes_of(robot.lifted_links),
                             np.ascontiguousarray(robot.self_collision_pairs, np.int64), None,
                             np.zeros((0, 2), np.int64), -GROUND_TOLERANCE, EXACT_DISTANCE_WITHIN)
    stability.dynamic_stability_with_clearance(robot, t, q, BasePlacement(0.1, 0.2, 0.3), qd, made=high, kept=kept)
    assert kept.resumed == 0


def independent_zmp_check(robot: SnakeRobot, t, q, qd, base, contact: str, qdd=None) -> dict[str, np.ndarray]:
    """tests/zmp_reference.py's ZMP check (pinocchio's momenta, np.gradient, Eqs. 39-40, each shape's candidates in
    numpy, scipy's hull, point-to-segment margins; per sample, no contact runs) with the core's contact model: every
    shaped link for "ground", the base's for "footprint"."""
    pytest.importorskip("pinocchio")
    import zmp_reference

    links = sorted({s.frame for s in robot.geometry.shapes}) if contact == "ground" else robot.base_links
    return zmp_reference.zmp_check(robot, t, q, qd, base, links, robot.geometry.contact_points_per_shape,
                                   GROUND_TOLERANCE, qdd=qdd)


def test_zmp_check_equals_the_python_reference(robots: dict[str, SnakeRobot]) -> None:
    """The C++ dynamic stability (contact "ground" and "footprint") against an independent computation
    (independent_zmp_check): momenta and CoM to 1e-12 (measured: 6e-16), ZMP and margins to 1e-11 (measured: 1.3e-15
    and 1.1e-15, through samples inside and outside the polygon); its ZMP against Eqs. 39-40 on pinocchio's exact
    momentum rate to 1e-8 inside and 2e-8 at the ends (np.gradient's O(dt^2) and one-sided ends; measured 3.6e-9
    and 7.2e-9). And it equals the Python path (the one of contact "endpoints") to 1e-9: the same contact runs
    (chunks of a few samples, to cross their boundaries), ZMP and margins."""
    for name in ("default", "reu"):
        robot = robots[name]
        q0 = np.zeros(robot.n_joints)  # flat and straight: every link on the ground
        q1 = q0.copy()
        pitch = robot.lift_joints.start
        q1[pitch] = 0.5  # the neck rises (the sign that lifts the head, below)
        q1[pitch] = -q1[pitch] if robot.head_pose(q1)[2, 3] < robot.head_pose(-q1)[2, 3] else q1[pitch]
        t = np.linspace(0.0, 2.0, 401)
        s = (3 * (t / 2) ** 2 - 2 * (t / 2) ** 3)[:, None]  # rest to rest: the head lifts off the ground
        q, qd = q0 + s * (q1 - q0), (6 * (t / 2) * (1 - t / 2) / 2)[:, None] * (q1 - q0)
        qdd = ((6 - 12 * (t / 2)) / 4)[:, None] * (q1 - q0)
        base = BasePlacement(0.2, 0.1, 0.4)
        for contact in ("ground", "footprint"):
            core, _ = stability.dynamic_stability_with_clearance(robot, t, q, base, qd, contact=contact)
            ind = independent_zmp_check(robot, t, q, qd, base, contact, qdd)
            for key in ("P", "L", "com"):
                np.testing.assert_allclose(getattr(core, key), ind[key], atol=1e-12, rtol=0, err_msg=f"{name} {key}")
            np.testing.assert_allclose(core.zmp, ind["zmp"], atol=1e-11, rtol=0, err_msg=f"{name} {contact}")
            np.testing.assert_allclose(core.margin, ind["margin"], atol=1e-11, rtol=0, err_msg=f"{name} {contact}")
            assert core.argmin == int(np.argmin(ind["margin"])) and core.stable == bool((ind["margin"] > 0).all())
            if name == "default" and contact == "ground":  # the ZMP inside the polygon and outside it
                assert 0 < (ind["margin"] > 0).sum() < len(t)
            np.testing.assert_allclose(core.zmp[1:-1], ind["zmp_exact"][1:-1], atol=1e-8, rtol=0)
            np.testing.assert_allclose(core.zmp, ind["zmp_exact"], atol=2e-8, rtol=0)
            old = stability.SAMPLE_CHUNK
            stability.SAMPLE_CHUNK = 37
            try:
                core, clearance = stability.dynamic_stability_with_clearance(robot, t, q, base, qd, contact=contact)
                ref = stability.dynamic_stability_in_python(robot, t, q, base, qd, contact, GROUND_TOLERANCE,
                                                           None, None)
            finally:
                stability.SAMPLE_CHUNK = old
            np.testing.assert_allclose(core.margin, ref.margin, atol=1e-9, rtol=0, err_msg=f"{name} {contact}")
            np.testing.assert_allclose(core.zmp, ref.zmp, atol=1e-9, rtol=0)
            np.testing.assert_allclose(core.P, ref.P, atol=1e-9, rtol=0)
            np.testing.assert_allclose(core.L, ref.L, atol=1e-9, rtol=0)
            np.testing.assert_allclose(core.com, ref.com, atol=1e-12, rtol=0)
            assert core.argmin == ref.argmin and core.stable == ref.stable
            lowest = robot.lowest_z(robot.frames_many(q, base), robot.lifted_links).min(axis=1)
            np.testing.assert_array_equal(clearance, lowest)
        runs = stability.contact_configurations(robot, q, base, "ground", GROUND_TOLERANCE)[2].max() + 1
        assert runs > 2, "the motion must change its contacts (the head lifts)"


def test_zmp_check_with_a_still_base_and_a_moving_one_equals_the_python_reference() -> None:
    """The C++ check builds each run's polygon from the kept hull of the contact shapes that lay still and the points
    of the others (the neck lifting off a still base: a run per sample); where the base then turns (a base yaw: the
    shapes after it move, the kept hull is made again) and the neck lifts again, the ZMP and margins still equal an
    independent computation's, sample by sample from all the points (independent_zmp_check), to 1e-11, and the
    Python path's to 1e-9."""
    robot = SnakeRobot.default()
    pitch = robot.lift_joints.start
    yaw = [j for j in range(pitch) if robot.joint_kinds[j] == "yaw"]
    q0 = np.zeros(robot.n_joints)
    q1 = _lifted(robot, 0.6)
    q2 = q1.copy()
    q2[yaw[len(yaw) // 2]] += 0.3  # the base turns in the middle: its links after that joint move
    q3 = _lifted(robot, 0.2)
    q3[yaw[len(yaw) // 2]] += 0.3
    t = np.linspace(0.0, 3.0, 601)
    s = np.clip(t % 1.0 + (t >= 3.0), 0.0, 1.0)
    ease = (3 * s ** 2 - 2 * s ** 3)[:, None]
    leg = np.minimum(t.astype(int), 2)
    starts, ends = np.array([q0, q1, q2]), np.array([q1, q2, q3])
    q = starts[leg] + ease * (ends[leg] - starts[leg])
    qd = np.gradient(q, t, axis=0)
    base = BasePlacement(-0.3, 0.5, 1.1)
    core, _ = stability.dynamic_stability_with_clearance(robot, t, q, base, qd)
    # against the independent computation (per sample: no runs, no kept hulls): measured 3.8e-15 (ZMP), 4.0e-15
    # (margins, 93 of 601 samples inside)
    ind = independent_zmp_check(robot, t, q, qd, base, "ground")
    np.testing.assert_allclose(core.zmp, ind["zmp"], atol=1e-11, rtol=0)
    np.testing.assert_allclose(core.margin, ind["margin"], atol=1e-11, rtol=0)
    assert core.argmin == int(np.argmin(ind["margin"])) and 0 < (ind["margin"] > 0).sum() < len(t)
    ref = stability.dynamic_stability_in_python(robot, t, q, base, qd, "ground", GROUND_TOLERANCE, None,
                                               None)
    np.testing.assert_allclose(core.margin, ref.margin, atol=1e-9, rtol=0)
    assert core.argmin == ref.argmin and core.stable == ref.stable
    runs = stability.contact_configurations(robot, q, base, "ground", GROUND_TOLERANCE)[2]
    assert runs.max() + 1 > 200, "the neck must lift through many runs"


def test_checker_refuses_bad_input() -> None:
    robot = SnakeRobot.default()
    from snakehead import InputError, _core

    with pytest.raises(InputError, match="ground"):
        _core.PathChecker(robot.body.model, robot.geometry.core, np.eye(4), np.array([10**6]),
                          np.zeros((0, 2), np.int64), None, np.zeros((0, 2), np.int64), -1e-3, np.inf)
    c = path_check.checker(robot)
    with pytest.raises(InputError, match="first_step"):
        c.check_path(np.zeros((2, robot.n_joints)), 0.0, 1e-3, True)
    with pytest.raises(InputError, match="waypoints"):
        c.check_path(np.zeros((2, 3)), 0.5, 1e-3, True)


def test_zmp_check_takes_gravity_from_the_caller() -> None:
    """The core's ZMP uses the gravity vector it is given (BasePlacement.gravity from Python: (0, 0, -GRAVITY) on flat
    ground, leaning on a slope): Eqs. 39-40 with that g from the core's own momenta (np.gradient's rates), plus
    M g_xy c_z when g leans; a bad gravity is an InputError."""
    from snakehead import InputError, _core
    from snakehead.model.physics import GRAVITY

    robot = SnakeRobot.default()
    q0 = np.zeros(robot.n_joints)
    q1 = q0.copy()
    q1[robot.lift_joints.start] = 0.3
    t = np.linspace(0.0, 1.0, 101)
    s = (3 * t ** 2 - 2 * t ** 3)[:, None]
    q, qd = q0 + s * (q1 - q0), (6 * t * (1 - t))[:, None] * (q1 - q0)
    g = robot.geometry
    args = (path_check.checker(robot), t, q, qd, g.shapes_of(robot.shaped_links), g.contact_points_per_shape,
            g.shapes_of(robot.lifted_links), True, [], GROUND_TOLERANCE, stability.SAMPLE_CHUNK)
    M = robot.total_mass
    for g_vec in ((0.0, 0.0, -GRAVITY), (0.0, 0.0, -3.0 * GRAVITY), (1.5, -0.8, -0.98 * GRAVITY)):
        out = _core.zmp_check(*args, np.array(g_vec))
        Pdot, Ldot = np.gradient(out["P"], t, axis=0, edge_order=2), np.gradient(out["L"], t, axis=0, edge_order=2)
        gravity = -g_vec[2]
        c = out["com"]
        den = M * gravity + Pdot[:, 2]
        zmp = np.column_stack([(M * gravity * c[:, 0] + M * g_vec[0] * c[:, 2] - Ldot[:, 1]) / den,
                               (M * gravity * c[:, 1] + M * g_vec[1] * c[:, 2] + Ldot[:, 0]) / den])
        np.testing.assert_allclose(out["zmp"], zmp, atol=1e-9, rtol=0)
    for bad in ((0.0, 0.0, np.nan), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, -np.inf), (np.nan, 0.0, -9.8)):
        with pytest.raises(InputError, match="gravity"):
            _core.zmp_check(*args, np.array(bad))


def test_zmp_check_on_several_threads_equals_one_thread_to_the_bit() -> None:
    """zmp_check splits its samples over the core's threads (then builds the contact runs in order), in blocks: the
    same momenta, CoM, ZMP, margins and clearances as on one thread, from scratch and taking over a kept prefix."""
    robot = SnakeRobot.default()
    rng = np.random.default_rng(4)
    t, m = np.linspace(0.0, 18.0, 9001), 700  # past one block of the core's (8192 samples)
    lift, other = _smooth_motion(robot, rng, len(t), 0.2), _smooth_motion(robot, rng, len(t), 0.2)
    qd_lift = np.gradient(lift, t, axis=0)
    q = np.concatenate([lift[:m], other[m:]])
    qd = np.concatenate([qd_lift[:m], np.gradient(other, t, axis=0)[m:]])
    base = BasePlacement(0.1, 0.2, 0.3)
    results = []
    try:
        for threads in (1, 3):
            set_core_threads(threads)
            kept = stability.KeptSamples(m)
            stability.dynamic_stability_with_clearance(robot, t, lift, base, qd_lift, kept=kept)
            results.append([stability.dynamic_stability_with_clearance(robot, t, q, base, qd),
                            stability.dynamic_stability_with_clearance(robot, t, q, base, qd, kept=kept)])
            assert kept.resumed == m
    finally:
        set_core_threads(None)
    for one, several in zip(*results):
        for name in ("zmp", "margin", "P", "L", "com"):
            np.testing.assert_array_equal(getattr(several[0], name), getattr(one[0], name), err_msg=name)
        np.testing.assert_array_equal(several[1], one[1])
    assert len(t) - m > 2 * 256, "enough samples after the prefix to be split"
