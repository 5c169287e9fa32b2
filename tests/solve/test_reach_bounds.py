"""The reach map's prunes (solve.pose_bounds): necessary conditions of a whole-body pose.

Two independent checks: (1) brute force -- random configurations are real poses, and a test that would exclude
the pose of one that passes the exact checks (its ground clearance, its static margin) is unsound; (2) full
whole-body solves of pruned poses (the planner's, through reach.kept_task and reach.relocation_task) all fail."""
from __future__ import annotations

import numpy as np
import pytest

import snakehead as sh
from snakehead.collision import body_collisions as coll
from snakehead.margins import DETOUR_MARGIN
from snakehead.planning import whole_body_reach as reach
from snakehead.solve.pose_bounds import PoseBounds
from snakehead.solve.whole_body import BodyProblem


@pytest.fixture(scope="module")
def robot() -> sh.SnakeRobot:
    return sh.SnakeRobot.default()


@pytest.fixture(scope="module")
def q0(robot: sh.SnakeRobot) -> np.ndarray:
    return reach.WORKERS.get(reach.RobotRecipe.of(robot), None, "rotated", 1).q_initial


@pytest.fixture(scope="module")
def bounds(robot: sh.SnakeRobot, q0: np.ndarray) -> PoseBounds:
    return PoseBounds.of(robot, q0)


@pytest.fixture(scope="module")
def kept_poses(robot: sh.SnakeRobot, q0: np.ndarray) -> dict:
    """Random configurations with the base as it lies at the start (the lifted joints random): their tip poses,
    lowest points of the lifted links and static margins (over the ground links, as the solve's check takes)."""
    rng = np.random.default_rng(3)
    start = robot.lift_joints.start
    qs = np.array([robot.random_configuration(rng) for _ in range(3000)])
    qs[:, :start] = q0[:start]
    base = sh.BasePlacement()
    prob = BodyProblem(robot)
    H = np.array([robot.head_pose(q, base) for q in qs])
    margins = np.array([prob.margin(prob.frames(q, base)) for q in qs])
    ground = coll.ground_clearance(robot, qs, base)[:, robot.lifted_links].min(axis=1)
    return {"q": qs, "p": H[:, :3, 3], "d": H[:, :3, 0], "margin": margins, "ground": ground}


def test_chain_numbers(robot: sh.SnakeRobot, bounds: PoseBounds) -> None:
    """The last joint is the head link's length behind the tip; its chain length and the centres of mass's chain
    distances add up to the lifted chain's reach (the chain's own number)."""
    reach_m = robot.sub_chain(robot.lift_frame, robot.parts.head_tip).reach
    np.testing.assert_allclose(bounds.joint_point, [-robot.head_link_length, 0, 0], atol=1e-12)
    assert bounds.joint_reach == pytest.approx(reach_m - robot.head_link_length)
    np.testing.assert_allclose(bounds.to_lift + bounds.to_tip, reach_m, atol=1e-9)  # coms on the links' axes
    assert len(bounds.tip_points) >= 8  # the head link's box corners


def test_bounds_never_exclude_a_real_pose(robot: sh.SnakeRobot, q0: np.ndarray, bounds: PoseBounds,
                                          kept_poses: dict) -> None:
    p, d = kept_poses["p"], kept_poses["d"]
    base = sh.BasePlacement()
    lift = robot.frame(q0, robot.lift_frame, base)[:3, 3]
    assert not bounds.out_of_reach(p, d).any() and not bounds.out_of_reach(p, d, lift).any()
    clear = kept_poses["ground"] >= -coll.GROUND_TOLERANCE
    assert not bounds.below_ground(p[clear], d[clear]).any()
    stable = kept_poses["margin"] >= DETOUR_MARGIN
    assert stable.sum() > 50
    assert not bounds.unstable(p[stable], q0, base, DETOUR_MARGIN).any()
    # and the tests are not empty: they exclude poses the random ones miss, and some of those of failing ones
    assert bounds.below_ground(p[~clear], d[~clear]).any()
    assert bounds.unstable(p[~stable], q0, base, DETOUR_MARGIN).mean() > 0.1


def test_ground_bound_is_tight_for_a_flat_head(bounds: PoseBounds) -> None:
    """A horizontal head at height h: its box's lowest corner, for the best roll (flat), is h - half its height."""
    half = float(np.abs(bounds.tip_points[:, 2]).max())
    d = np.array([[1.0, 0.0, 0.0]])
    assert not bounds.below_ground(np.array([[0, 0, half]]), d)[0]
    assert bounds.below_ground(np.array([[0, 0, half - 0.005]]), d)[0]


def _sample(mask: np.ndarray, count: int, seed: int) -> np.ndarray:
    idx = np.flatnonzero(mask)
    return np.random.default_rng(seed).choice(idx, min(count, len(idx)), replace=False)


@pytest.mark.parametrize("count", [pytest.param(2, id="ci"), pytest.param(40, id="many", marks=pytest.mark.slow)])
def test_pruned_poses_fail_the_full_solves(robot: sh.SnakeRobot, bounds: PoseBounds, q0: np.ndarray,
                                           count: int) -> None:
    """Poses that only the stability or only the ground test excludes (not the reach test, which the solve itself
    checks first) are not solved by the planner's whole-body solve with the base kept; the classes (height,
    direction) excluded for any base are not solved with the base moved either."""
    grid = reach.reach_grid(robot, 0.1, 12)
    lift = robot.frame(q0, robot.lift_frame, sh.BasePlacement())[:3, 3]
    P = grid.poses().reshape(-1, 3)
    D = np.tile(grid.directions, (len(grid.centers), 1))
    near = reach._near(grid, lift[:2], bounds.joint_reach + robot.head_link_length).reshape(-1)
    far = bounds.out_of_reach(P, D, lift)
    unstable = near & ~far & bounds.unstable(P, q0, sh.BasePlacement(), DETOUR_MARGIN)
    low = near & ~far & bounds.below_ground(P, D) & ~unstable
    recipe = reach.RobotRecipe.of(robot)
    for which, seed in ((unstable, 0), (low, 1)):
        picks = _sample(which, count, seed)
        assert len(picks)
        results = reach.kept_task(recipe, "rotated", 1, [(P[i], D[i]) for i in picks])
        assert not any(ok for ok, *_ in results)
    # with the base moved: a far target of an excluded height and direction
    anybase = bounds.below_ground(P, D) | bounds.out_of_reach(P, D)
    picks = _sample(anybase & ~near, max(1, count // 4), 2)
    shifted = [(P[i] + np.array([1.5, 0.0, 0.0]), D[i]) for i in picks]
    assert not any(ok for ok, *_ in (reach.relocation_task(recipe, "rotated", 1, [pose])[0] for pose in shifted))
