"""snakehead reach: the whole body's stable reachability map, checked against full plans, its file, its kind."""
from __future__ import annotations

import numpy as np
import pytest
from conftest import plan_agrees

import snakehead as sh
from snakehead.app import cli
from snakehead.kinematics import reachability as ws
from snakehead.planning import whole_body_reach as reach

VOXEL, DIRECTIONS = 0.6, 2  # a tiny grid: 5 x 5 voxels x 2 layers, 2 directions


@pytest.fixture(scope="module")
def robot() -> sh.SnakeRobot:
    return sh.SnakeRobot.default()


@pytest.fixture(scope="module")
def body_map(robot: sh.SnakeRobot, tmp_path_factory: pytest.TempPathFactory) -> ws.ReachabilityMap:
    m = reach.compute_reach(robot, voxel=VOXEL, directions=DIRECTIONS)
    path = tmp_path_factory.mktemp("reach") / "reach.npz"
    m.save(path)
    return m


def test_reached_poses_are_planned(robot: sh.SnakeRobot, body_map: ws.ReachabilityMap) -> None:
    bits = body_map.reached_units()
    yes, no = np.argwhere(bits), np.argwhere(~bits)
    assert len(yes) and len(no)  # the grid holds both
    rng = np.random.default_rng(0)
    pairs = np.concatenate([yes[rng.choice(len(yes), 2, replace=False)], no[rng.choice(len(no), 1, replace=False)]])
    assert all(plan_agrees(robot, body_map, pairs))


@pytest.mark.slow  # every reached pose of the tiny grid planned in full (~2 min)
def test_every_reached_pose_is_planned(robot: sh.SnakeRobot, body_map: ws.ReachabilityMap) -> None:
    yes = np.argwhere(body_map.reached_units())
    agree = plan_agrees(robot, body_map, yes)
    assert np.mean(agree) >= 0.98


def test_witnesses_reach_the_pose(robot: sh.SnakeRobot, body_map: ws.ReachabilityMap) -> None:
    """The base of a reached pose is a real witness: the whole-body solve with that base kept reaches the pose."""
    from snakehead.solve.head_controller import HeadController
    from snakehead.solve.whole_body import solve_checked_target

    bits = body_map.reached_units()
    v, k = np.argwhere(bits)[-1]
    d = body_map.sphere_directions[k]
    p = body_map.centers[v] + 0.5 * body_map.voxel_size * d
    x, y, yaw = body_map.base_placements[v, k]
    base = sh.BasePlacement(float(x), float(y), float(yaw))
    c = HeadController(robot, base_pose=base)
    q = c.q_initial.copy()
    q[:robot.lift_joints.start] = body_map.base_joints[v, k]
    sol = solve_checked_target(c, p, d, q_prev=q, base=base, allow_base_move=False, problem=c.body_problem)
    assert sol.success
    assert np.all(np.isnan(body_map.base_placements[~bits]))


def test_map_round_trips_and_answers(body_map: ws.ReachabilityMap) -> None:
    again = sh.load_map(body_map.path)
    assert again.kind == ws.KIND_WHOLE_BODY and again.same_map_as(body_map)
    np.testing.assert_array_equal(again.base_placements, body_map.base_placements)
    np.testing.assert_array_equal(again.base_joints, body_map.base_joints)
    bits = again.reached_units()
    dirs = again.sphere_directions
    pos = (again.centers[:, None, :] + 0.5 * again.voxel_size * dirs[None]).reshape(-1, 3)
    answered = again.reachable(pos, np.tile(dirs, (len(again), 1)), interpolate=False)
    np.testing.assert_array_equal(answered, bits.reshape(-1))


def test_head_and_body_maps_refuse_each_other(robot: sh.SnakeRobot, body_map: ws.ReachabilityMap,
                                              ) -> None:
    head_map = sh.load_map(robot.map_path)
    with pytest.raises(sh.InputError, match="whole-body stable reachability map"):
        ws.require_map(body_map, robot, what="workspace_map")
    with pytest.raises(sh.InputError, match="head map"):
        ws.require_map(head_map, robot, kind=ws.KIND_WHOLE_BODY)
    with pytest.raises(sh.InputError, match="workspace_map .* is a whole-body stable reachability map"):
        sh.HeadController(robot, workspace_map=body_map)
    with pytest.raises(sh.InputError, match="the reach map .* is a head map"):
        reach.check_reach(head_map, robot, 2)
    assert ws.require_map(body_map, robot, kind=ws.KIND_WHOLE_BODY) is body_map


def test_options_checked_before_work(robot: sh.SnakeRobot) -> None:
    for voxel, directions, match in ((0.001, 12, "voxel must be within"), (5.0, 12, "voxel must be within"),
                                     (float("nan"), 12, "voxel must be within"),
                                     (0.1, 0, "directions must be between 1 and 64, got 0"),
                                     (0.1, 1000, "directions must be between 1 and 64, got 1000")):
        with pytest.raises(sh.InputError, match=match):
            reach.check_options(robot, voxel, directions)
    with pytest.raises(sh.InputTypeError, match="directions must be an integer, got float 2.5"):
        reach.check_options(robot, 0.1, 2.5)


def test_cli_exit_codes(tmp_path: object, monkeypatch: pytest.MonkeyPatch, body_map: ws.ReachabilityMap) -> None:
    assert cli.main(["reach", "--voxel", "0.001", "--out", str(tmp_path)]) == 2
    with pytest.raises(SystemExit, match="^2$") as exc:  # argparse's usage error
        cli.main(["reach", "--workers", "2", "--scheduler", "tcp://x:1", "--out", str(tmp_path)])
    assert exc.value.code == 2

    def broken(*args: object, **kwargs: object) -> None:
        raise RuntimeError("a bug")

    monkeypatch.setattr(reach, "compute_reach", broken)
    assert cli.main(["reach", "--voxel", "0.6", "--directions", "2", "--out", str(tmp_path)]) == 3
    monkeypatch.setattr(reach, "compute_reach", lambda *a, **k: body_map)
    assert cli.main(["reach", "--voxel", "0.6", "--directions", "2", "--quiet", "--out", str(tmp_path)]) == 0
    assert sh.load_map(tmp_path / "reach.npz").same_map_as(body_map)  # type: ignore[operator]
