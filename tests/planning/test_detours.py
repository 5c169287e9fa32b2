"""The detours of a move whose straight path is not safe (``planning.waypoints.Waypoints._joint_path``): the staged
screen and the bounded search of the fallback give the very path of the plain search (every configuration of
every detour checked, every detour's margins computed), on moves that take a detour and on moves that have none."""
from __future__ import annotations

import numpy as np
import pytest

import snakehead
from snakehead.planning import start_state
from snakehead.planning import waypoints as wp
from snakehead.solve.head_controller import HeadController


def plain_joint_path(way, qa, qb, n):
    """The search before it was staged and bounded (main d9ea809), as the reference: every configuration of every
    detour checked, every detour's margins computed (its fallback the first of the near-equal largest, as the
    staged search's: the plain argmax picked among paths equal but for round-off)."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    straight = wp.split_steps(qa + s * (qb - qa))
    if way.path_feasible(straight):
        return straight, "joint space"
    movable = np.arange(way.robot.lift_joints.start, way.robot.parts.head.stop)
    rng = np.random.default_rng(wp.DETOUR_SEED)
    W = np.tile(0.5 * (qa + qb), (wp.DETOUR_TRIALS, 1))
    W[:, movable] += rng.normal(0.0, wp.DETOUR_SPREAD, (wp.DETOUR_TRIALS, len(movable)))
    W = np.clip(W, way.robot.lower, way.robot.upper)
    paths = np.concatenate([qa + s[None] * (W[:, None] - qa), W[:, None] + s[None, 1:] * (qb - W[:, None])], axis=1)
    length = np.abs(np.diff(paths, axis=1)).sum(axis=(1, 2))
    order = np.argsort(length, kind="stable")
    for batch in np.array_split(order, max(1, len(order) // wp.DETOUR_BATCH)):
        flat = wp.densify(paths[batch]).reshape(-1, qa.size)
        ok = way.feasible(flat).reshape(len(batch), -1).all(axis=1)
        for k in batch[ok]:
            path = wp.split_steps(paths[k])
            if way.path_feasible(path):
                return path, "joint space via a stable detour"
    flat = wp.densify(paths).reshape(-1, qa.size)
    worst = way.static_margins(flat).reshape(len(W), -1).min(axis=1)
    return wp.split_steps(paths[steadiest(worst)]), "joint space (no stable detour found)"


def steadiest(worst):
    """The first path whose smallest margin is within MARGIN_TIE of the largest (argmax, but for round-off)."""
    return int(np.flatnonzero(worst >= worst.max() - wp.MARGIN_TIE)[0])


@pytest.fixture(scope="module")
def controller():
    return HeadController(snakehead.SnakeRobot.default(), method="free_roll", seed=1)


def moves(controller, count: int, seed: int, safe_end: bool = False):
    """From the bending state to random poses of the lifting joints (many unsafe: into the ground, unstable; with
    ``safe_end`` only poses that are themselves safe, near the initial state: most then have a safe detour)."""
    robot = controller.robot
    qa = start_state.bending_state(controller)
    way = wp.Waypoints(robot, snakehead.BasePlacement())
    rng = np.random.default_rng(seed)
    lift = np.arange(robot.lift_joints.start, robot.n_joints)
    made = 0
    while made < count:
        qb = qa.copy()
        if safe_end:
            qb[lift] = controller.q_initial[lift] + rng.normal(0.0, 0.5, len(lift))
            if not way.feasible(qb[None])[0]:
                continue
        else:
            qb[lift] = rng.uniform(robot.lower[lift], robot.upper[lift]) * 0.6
        made += 1
        yield qa, qb


def test_the_staged_search_finds_the_plain_searchs_path(controller):
    methods = set()
    for qa, qb in [*moves(controller, 3, seed=2), *moves(controller, 5, seed=3, safe_end=True)]:
        way = wp.Waypoints(controller.robot, snakehead.BasePlacement())
        path, method = way._joint_path(qa, qb, 12)
        want, want_method = plain_joint_path(way, qa, qb, 12)
        assert method == want_method
        np.testing.assert_array_equal(path, want)
        methods.add(method)
    # both the screen's and the fallback's answers were compared
    assert {"joint space via a stable detour", "joint space (no stable detour found)"} <= methods, methods


def test_the_steadiest_detour_is_the_largest_smallest_margin_first_of_equals(controller):
    """The bounded search against every path's margins, also when all paths share their smallest margin (ties go
    to the first path)."""
    robot = controller.robot
    way = wp.Waypoints(robot, snakehead.BasePlacement())
    rng = np.random.default_rng(4)
    for qa, qb in moves(controller, 3, seed=5):
        W = qa + rng.normal(0.0, 0.4, (40, robot.n_joints)) * (np.arange(robot.n_joints) >= robot.lift_joints.start)
        s = np.linspace(0.0, 1.0, 6)[:, None]
        paths = np.concatenate([qa + s[None] * (W[:, None] - qa), W[:, None] + s[None, 1:] * (qb - W[:, None])], 1)
        dense = wp.densify(paths)
        worst = way.static_margins(dense.reshape(-1, robot.n_joints)).reshape(len(W), -1).min(axis=1)
        assert way._steadiest(dense, 5) == steadiest(worst)
        tied = dense.copy()
        tied[:, -1] = dense[0, -1]  # one end shared exactly
        tied_worst = way.static_margins(tied.reshape(-1, robot.n_joints)).reshape(len(W), -1).min(axis=1)
        assert way._steadiest(tied, 5) == steadiest(tied_worst)


def test_the_screen_is_every_configurations_check(controller):
    robot = controller.robot
    way = wp.Waypoints(robot, snakehead.BasePlacement())
    for qa, qb in moves(controller, 2, seed=7):
        W = qa + np.random.default_rng(1).normal(0.0, 0.4, (32, robot.n_joints)) * (
            np.arange(robot.n_joints) >= robot.lift_joints.start)
        s = np.linspace(0.0, 1.0, 12)[:, None]
        paths = np.concatenate([qa + s[None] * (W[:, None] - qa), W[:, None] + s[None, 1:] * (qb - W[:, None])], 1)
        dense = wp.densify(paths)
        every = way.feasible(dense.reshape(-1, robot.n_joints)).reshape(len(W), -1).all(axis=1)
        np.testing.assert_array_equal(way._screened(dense, 11), every)
