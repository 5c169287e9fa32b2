"""HeadController: the segmented head control of Section 3.3 on the default robot and its shipped map."""
import numpy as np
import pytest
from conftest import head6_robot

from snakehead import SnakeRobot
from snakehead.dynamics import stability
from snakehead.scenes import paper_scene
from snakehead.solve.head_controller import HeadController


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


@pytest.fixture(scope="module", params=["free_roll", "rotated"])
def controller(request, robot):
    return HeadController(robot, method=request.param, seed=2)


def check_solution(robot, sol, position, direction):
    """Independent checks: whole-body FK of the returned joints, the limits, the static verdict."""
    T = robot.head_pose(sol.q, sol.base)
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    assert np.linalg.norm(T[:3, 3] - position) <= 1e-4  # 0.1 mm
    assert np.degrees(np.arccos(np.clip(T[:3, 0] @ d, -1, 1))) <= 0.05
    np.testing.assert_allclose(T, sol.head_frame, atol=1e-12)
    assert np.all(sol.q >= robot.lower - 1e-12) and np.all(sol.q <= robot.upper + 1e-12)
    margin = stability.static_margin(robot, sol.q, sol.base)
    assert sol.static_margin_m == pytest.approx(margin, abs=1e-12)
    assert sol.static_stable == (margin > 0)


SPHERES = paper_scene("spheres").targets
SPHERE_1, SPHERE_2 = SPHERES[0].position, SPHERES[2].position
SPHERE_DIRECTION = SPHERES[0].direction
HOLE = paper_scene("hole").obstacles[0]


@pytest.mark.parametrize("position,direction", [
    (SPHERE_1, SPHERE_DIRECTION), (SPHERE_2, SPHERE_DIRECTION), (HOLE.centre, HOLE.normal),
])
def test_paper_targets(controller, robot, position, direction):
    sol = controller.solve(position, direction)
    assert sol.success, sol.message
    check_solution(robot, sol, position, direction)
    np.testing.assert_array_equal(sol.q[robot.parts.base], controller.q_initial[robot.parts.base])
    assert set(sol.timings) >= {"neck", "head", "check", "total"}
    # Eq. 20's geometry for the goal the neck was given
    g = sol.neck_goal
    assert np.linalg.norm(g.G0 - g.P_d) == pytest.approx(controller.Lc)
    np.testing.assert_allclose(g.G0, position)


def test_random_reachable_targets_are_verified_by_fk(robot):
    controller = HeadController(robot, method="free_roll", seed=5)
    rng = np.random.default_rng(3)
    solved = 0
    for _ in range(30):
        q = controller.q_initial.copy()
        sl = slice(robot.parts.neck.start, robot.parts.head.stop)
        q[sl] = rng.uniform(robot.lower[sl], robot.upper[sl])
        T = robot.head_pose(q)
        sol = controller.solve(T[:3, 3], T[:3, 0])
        if sol.success:
            solved += 1
            check_solution(robot, sol, T[:3, 3], T[:3, 0])
        else:
            assert sol.message
    assert solved > 0


def test_keeps_closest_to_previous_joints(robot):
    controller = HeadController(robot, method="rotated", n_frames=12, seed=1)
    first = controller.solve(SPHERE_2, SPHERE_DIRECTION)
    moved = controller.solve(SPHERE_2 + [0.0, -0.01, 0.0], SPHERE_DIRECTION, q_prev=first.q)
    assert moved.success
    cands = moved.head.candidates
    dists = [np.linalg.norm(q - first.q[robot.parts.head]) for _, q in cands]
    assert np.linalg.norm(moved.q[robot.parts.head] - first.q[robot.parts.head]) == pytest.approx(min(dists))


def test_unreachable_target_fails_with_a_reason(robot):
    controller = HeadController(robot, method="free_roll", timeout=0.002, seed=0)
    sol = controller.solve([0.0, 0.4, 3.0], [0, 1, 0])  # 3 m up: beyond the whole body
    assert not sol.success
    assert "no planar base move" in sol.message and "no solution" in sol.message


@pytest.mark.parametrize("seed, calls", [(0, 1), (None, 3)])
def test_free_roll_calls_the_ik_again_only_when_unseeded(robot, seed, calls):
    """A seeded head IK would run the same seeded restarts again (one call, the whole budget, is enough); an
    unseeded one searches anew from each start (FREE_ROLL_ATTEMPTS calls for a target it does not reach)."""
    controller = HeadController(robot, method="free_roll", timeout=0.002, seed=seed)
    sol = controller.solve([0.0, 0.4, 3.0], [0, 1, 0], allow_base_move=False)  # beyond the whole body
    assert not sol.success and sol.head is not None
    assert sol.head.tried == calls


def test_accept_hook_filters_solutions(robot):
    controller = HeadController(robot, method="rotated", n_frames=6, seed=0)
    sol = controller.solve(SPHERE_2, SPHERE_DIRECTION, accept=lambda q, base: False)
    assert not sol.success and "acceptance" in sol.message
    low = controller.solve(SPHERE_2, SPHERE_DIRECTION, accept=lambda q, base: q[12] > 0)
    if low.success:
        assert low.q[12] > 0


@pytest.mark.parametrize("kwargs,message", [
    (dict(method="nope"), "method"),
    (dict(n_frames=0), "n_frames"),
    (dict(timeout=0.0), "timeout"),
    (dict(slack=-1.0), "slack"),
    (dict(base_configuration=np.zeros(3)), "shape"),
])
def test_bad_construction(robot, kwargs, message):
    with pytest.raises(ValueError, match=message):
        HeadController(robot, **kwargs)


def test_map_of_another_chain_is_rejected(robot):
    from snakehead.kinematics import reachability as workspace

    with pytest.raises(ValueError, match="another head chain"):
        HeadController(robot, workspace_map=workspace.map_for(head6_robot()))


@pytest.mark.parametrize("position,direction,message", [
    ([0.1, 0.5, 0.3], [0, 0, 0], "zero length"),
    ([0.1, np.nan, 0.3], [0, 1, 0], "NaN"),
    ([0.1, 0.5], [0, 1, 0], "shape"),
    ([0.1, 0.5, 0.3], [0, 1, np.inf], "NaN or inf"),
])
def test_bad_solve_input(robot, position, direction, message):
    controller = HeadController(robot, method="free_roll")
    with pytest.raises(ValueError, match=message):
        controller.solve(position, direction)
    with pytest.raises(ValueError, match="shape"):
        controller.solve([0.1, 0.5, 0.3], [0, 1, 0], q_prev=np.zeros(5))


def test_solution_figure(robot, tmp_path):
    from snakehead.viz import body, save

    controller = HeadController(robot, method="free_roll", seed=0)
    sol = controller.solve(SPHERE_2, SPHERE_DIRECTION)
    path = save(body.plot_head_solution(robot, sol), tmp_path / "solution.png")
    assert path.exists() and path.stat().st_size > 20_000
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
