"""The plans' caches a HeadController owns (``plan_cache_of(controller)``): bounded maps, entries equal to what they
cache (recomputed without the cache), and plans that do not depend on what is kept."""
import gc
import threading
import weakref

import numpy as np
import pytest

import snakehead
from snakehead.planning import start_state
from snakehead.planning.plan_cache import KEPT_LIFTS, KeptMap, PlanCache, plan_cache_of, shape_key
from snakehead.solve.head_controller import HeadController


@pytest.fixture(scope="module")
def controller():
    return HeadController(snakehead.SnakeRobot.default(), method="free_roll", seed=1)


def test_a_kept_map_never_holds_more_than_its_bound():
    kept: KeptMap[int, int] = KeptMap(3)
    sizes = []
    for k in range(10):
        assert kept.put(k, 10 * k) == 10 * k
        sizes.append(len(kept))
        assert kept.get(k) == 10 * k  # the newest entry is always there
    assert max(sizes) == 3 and sizes[:4] == [1, 2, 3, 1]
    kept.put(9, 0)  # a key already kept is replaced, nothing else forgotten
    assert len(kept) == sizes[-1] and kept.get(9) == 0
    kept.clear()
    assert len(kept) == 0 and kept.get(9) is None and 9 not in kept


def test_a_kept_map_from_many_threads_stays_bounded():
    kept: KeptMap[int, int] = KeptMap(5)

    def fill(offset):
        for k in range(2000):
            kept.put(offset + k, k)
            assert len(kept) <= 5

    threads = [threading.Thread(target=fill, args=(10000 * i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert 1 <= len(kept) <= 5


def test_shape_key_is_the_base_joints_rounded():
    q = np.array([0.1, 0.2 + 1e-14, 0.3, 9.0])
    assert shape_key(q, 3) == q[:3].tobytes()
    assert shape_key(q, 3, 12) == np.round(q[:3], 12).tobytes() == shape_key(np.array([0.1, 0.2, 0.3, -1.0]), 3, 12)
    assert shape_key(q, 3) != shape_key(np.array([0.1, 0.2, 0.3, 9.0]), 3)


def test_each_controller_has_one_plan_cache_gone_with_it(controller):
    assert isinstance(plan_cache_of(controller), PlanCache)
    assert plan_cache_of(controller) is plan_cache_of(controller)
    other = HeadController(controller.robot, method="free_roll", seed=1)
    kept = weakref.ref(plan_cache_of(other))
    assert kept() is not plan_cache_of(controller)
    del other
    gc.collect()
    assert kept() is None  # the planner's cache does not keep a controller (or itself) alive


def test_bending_states_are_kept_per_base_shape_and_equal_the_uncached_curl(controller):
    robot = controller.robot
    plan_cache_of(controller).clear()
    q = start_state.bending_state(controller)
    np.testing.assert_array_equal(q, start_state.ground_curl(robot, controller.q_initial))  # independent: uncached
    assert len(plan_cache_of(controller).bending_states) == 1
    q[:] = 99.0  # a copy: the kept state is not changed through it
    np.testing.assert_array_equal(start_state.bending_state(controller),
                                  start_state.ground_curl(robot, controller.q_initial))
    assert len(plan_cache_of(controller).bending_states) == 1
    # the same base shape with the neck and head moved is the same entry
    moved = controller.q_initial.copy()
    moved[robot.lift_joints.start:] += 0.1
    start_state.bending_state(controller, moved)
    assert len(plan_cache_of(controller).bending_states) == 1


def test_a_plan_fills_the_lift_caches_and_plans_the_same_from_them(controller):
    """A plan from a kept lift (path and timing) equals the plan of the same controller with its caches emptied."""
    robot = controller.robot
    H = robot.head_pose(controller.q_initial)
    target = [(H[:3, 3] + [0.0, 0.0, -0.05], H[:3, 0])]
    plan_cache_of(controller).clear()
    first = snakehead.plan(target, controller=controller)
    cache = plan_cache_of(controller)
    assert len(cache.lift_paths) == 1 and len(cache.timed_lifts) == 1 and len(cache.bending_states) == 1
    assert len(cache.lift_paths) <= KEPT_LIFTS
    again = snakehead.plan(target, controller=controller)  # from the kept lift
    assert len(cache.lift_paths) == 1 and len(cache.timed_lifts) == 1
    np.testing.assert_array_equal(again.q, first.q)
    np.testing.assert_array_equal(again.t, first.t)
    assert [s[0] for s in again.states] == [s[0] for s in first.states]


def test_a_scene_with_obstacles_keeps_no_lift_path(controller):
    """With obstacles the lift is checked again every time: its path is not kept."""
    robot = controller.robot
    H = robot.head_pose(controller.q_initial)
    far = snakehead.geometry.BoxObstacle(centre=[H[0, 3], H[1, 3] + 1.5, 0.2], size=[0.1, 0.1, 0.4])
    plan_cache_of(controller).clear()
    snakehead.plan([(H[:3, 3] + [0.0, 0.0, -0.05], H[:3, 0])], controller=controller, obstacles=[far])
    assert len(plan_cache_of(controller).lift_paths) == 0
