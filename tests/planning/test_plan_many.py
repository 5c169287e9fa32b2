"""plan_many: the same plans as snakehead.plan one after the other, over a thread pool, a process pool and Dask."""
from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

import snakehead as sh
from snakehead.planning.plan_many import PlanError, RobotRecipe, plan_many

# two targets the base reaches as it lies, and one whose scene is refused by the planner (a plan error, a result)
SETS = [[((0.3, 0.5, 0.6), (0.4, 0.0, 0.92))], [((0.3, 0.45, 0.55), (0.5, 0.1, 0.8))]]


@pytest.fixture(scope="module")
def robot() -> sh.SnakeRobot:
    return sh.SnakeRobot.default()


@pytest.fixture(scope="module")
def serial(robot: sh.SnakeRobot) -> list:
    return [sh.plan(s, robot=robot) for s in SETS]


def _same(a: list, b: list, robot: sh.SnakeRobot) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.success == y.success
        assert y.robot is robot  # put back where the plan came back without it
        assert x.q.shape == y.q.shape
        np.testing.assert_allclose(x.q, y.q, atol=1e-9)
        np.testing.assert_allclose(x.t, y.t, atol=1e-12)


def test_serial_and_threads_equal_plan(robot: sh.SnakeRobot, serial: list) -> None:
    seen = []
    _same(serial, plan_many(SETS, robot=robot, progress=seen.append), robot)
    assert [r.index for r in seen] == [1, 2] and all(r.kind == "plan" and r.solved for r in seen)
    with ThreadPoolExecutor(2) as pool:
        _same(serial, plan_many(SETS, robot=robot, executor=pool), robot)


@pytest.mark.slow  # ~25 s: a spawned process imports snakehead and builds the robot and its controller
def test_process_pool_equals_plan(robot: sh.SnakeRobot, serial: list) -> None:
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        _same(serial[:1], plan_many(SETS[:1], robot=robot, executor=pool), robot)


def test_dask_equals_plan(robot: sh.SnakeRobot, serial: list) -> None:
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        _same(serial[:1], plan_many(SETS[:1], robot=robot, executor=client), robot)


def test_bad_arguments_before_any_work(robot: sh.SnakeRobot) -> None:
    with pytest.raises(sh.InputError, match=r"target_sets\[1\]"):
        plan_many([SETS[0], [((0, 0, 0.5), (0, 0, 0))]], robot=robot)  # a zero direction
    with pytest.raises(sh.InputError, match="no option 'speed'"):
        plan_many(SETS, speed=2)
    with pytest.raises(sh.InputError, match="method"):
        plan_many(SETS, method="fast")
    with pytest.raises(sh.InputTypeError, match="executor must be a concurrent.futures.Executor .*got object"):
        plan_many(SETS, executor=object())
    with pytest.raises(sh.InputTypeError, match="target_sets must be a sequence .*got str"):
        plan_many("scene.toml")
    with ThreadPoolExecutor(1) as pool, pytest.raises(sh.InputError, match="controller"):
        plan_many(SETS, executor=pool, controller=sh.HeadController(robot))


def test_plan_errors_are_results(robot: sh.SnakeRobot, monkeypatch: pytest.MonkeyPatch) -> None:
    from snakehead.planning import plan_many as pm

    def refuse(*args: object, **kwargs: object) -> None:
        raise sh.Infeasible("no curl")

    monkeypatch.setattr(pm, "plan", refuse)
    out = plan_many(SETS[:1], robot=robot)
    assert isinstance(out[0], PlanError) and not out[0].success and "Infeasible: no curl" == out[0].failure


def test_recipe_builds_the_same_robot(robot: sh.SnakeRobot) -> None:
    import pickle

    again = pickle.loads(pickle.dumps(RobotRecipe.of(robot))).build()
    assert again.body.hash == robot.body.hash and again.head_chain.hash == robot.head_chain.hash


def test_description_arguments_rebuild_the_robot(robot: sh.SnakeRobot) -> None:
    """The public accessor the recipe reads: a copy (changing it changes nothing) that builds the same robot."""
    args = robot.description_arguments
    args["urdf"] = "elsewhere.urdf"
    assert robot.description_arguments["urdf"] != "elsewhere.urdf"
    again = sh.SnakeRobot(**robot.description_arguments, **robot.user_frames, map_path=robot.map_path)
    assert again.body.hash == robot.body.hash and again.parts == robot.parts
