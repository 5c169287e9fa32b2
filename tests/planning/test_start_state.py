"""The bending state's search (``planning.start_state.ground_curl``): the fast search finds the very curl of the
exhaustive one (every curl's margin from the robot's kinematics) on many base shapes of several robots, and its
parts equal independent computations (the centre of mass of every curl, the margins inside the base's polygon)."""
from __future__ import annotations

import numpy as np
import pytest
from conftest import generated_specs

import snakehead
from snakehead._errors import Infeasible
from snakehead.dynamics import stability
from snakehead.model.generate import snake_urdf
from snakehead.model.robot_file import write_robot_file
from snakehead.planning import start_state as ss

SPECS = generated_specs()  # long20 (a 2-joint neck beginning with a yaw joint), pitchy (pitch first, heavy)


@pytest.fixture(scope="module", params=["default", *sorted(SPECS)])
def robot(request, tmp_path_factory):
    if request.param == "default":
        return snakehead.SnakeRobot.default()
    spec, frames = SPECS[request.param]
    folder = tmp_path_factory.mktemp(request.param)
    (folder / "r.urdf").write_text(snake_urdf(spec))
    return snakehead.SnakeRobot.from_file(write_robot_file(folder / "r.toml", urdf=folder / "r.urdf", **frames))


def base_shapes(robot, count: int, seed: int) -> list[np.ndarray]:
    """Random flat base shapes: the yaw joints before the neck's first lifting joint within +-1.2 rad."""
    rng = np.random.default_rng(seed)
    start = robot.lift_joints.start
    yaw = np.array(robot.joint_kinds[:start]) == "yaw"
    shapes = []
    for _ in range(count):
        q = np.zeros(robot.n_joints)
        q[:start][yaw] = rng.uniform(np.maximum(robot.lower[:start], -1.2), np.minimum(robot.upper[:start], 1.2))[yaw]
        shapes.append(q)
    return shapes


def curl_or_none(search, robot, q):
    try:
        return search(robot, q)
    except Infeasible:
        return None


def test_the_fast_curl_is_the_exhaustive_curl_on_many_shapes(robot):
    found = 0
    for q in base_shapes(robot, 12, seed=3):
        fast, full = curl_or_none(ss.ground_curl, robot, q), curl_or_none(ss.ground_curl_exhaustive, robot, q)
        assert (fast is None) == (full is None)
        if fast is not None:
            np.testing.assert_array_equal(fast, full)
            found += 1
    assert found >= 3  # the comparison covers shapes that have a curl, not only shapes that have none


def test_the_curls_centres_of_mass_are_the_robots(robot):
    """Every curl's centre of mass composed joint by joint equals the one from every link's frame."""
    q, yaw, values = ss._curl_grid(robot, base_shapes(robot, 1, seed=5)[0])
    com = ss._curl_com(robot, q, yaw, values)
    assert len(com) == values.shape[1] ** len(yaw)
    rows = np.random.default_rng(0).choice(len(com), min(len(com), 400), replace=False)
    exact = stability.center_of_mass(robot, ss._curl_configurations(q, yaw, values, rows))[:, :2]
    np.testing.assert_allclose(com[rows], exact, rtol=0, atol=ss.CURL_MARGIN_SLACK / 100)


def test_the_curl_configurations_are_the_grid_in_order(robot):
    q, yaw, values = ss._curl_grid(robot, np.zeros(robot.n_joints))
    p, k = values.shape[1], len(yaw)
    qs = ss._curl_configurations(q, yaw, values, np.arange(p ** k))
    grid = np.stack(np.meshgrid(*values, indexing="ij"), -1).reshape(-1, k)  # the first joint the slowest
    np.testing.assert_array_equal(qs[:, yaw], grid)
    others = np.setdiff1d(np.arange(robot.n_joints), yaw)
    np.testing.assert_array_equal(qs[:, others], np.broadcast_to(q[others], (len(qs), len(others))))


def test_line_margins_are_the_polygon_margins_inside_and_not_positive_outside():
    rng = np.random.default_rng(1)
    pts = rng.normal(size=(9, 2))
    hull = pts[stability.hull_indices(pts)]
    xy = rng.uniform(-3, 3, (2000, 2))
    fast = ss._line_margins(hull, xy)
    exact = stability.polygon_margin_many(np.broadcast_to(pts, (len(xy), 9, 2)), np.ones((len(xy), 9), bool), xy)
    inside = exact > 0
    assert 100 < inside.sum() < len(xy) - 100
    np.testing.assert_allclose(fast[inside], exact[inside], rtol=0, atol=1e-12)
    assert (fast[~inside] <= 1e-12).all()


def test_a_straight_base_has_no_curl_by_either_search():
    robot = snakehead.SnakeRobot.default()
    for search in (ss.ground_curl, ss.ground_curl_exhaustive):
        with pytest.raises(Infeasible, match="no curl of the neck and head"):
            search(robot, np.zeros(robot.n_joints))


@pytest.fixture(scope="module")
def reu(tmp_path_factory):
    from snakehead.samples import published
    from snakehead.solve.head_controller import HeadController

    robot = snakehead.SnakeRobot.from_file(published.write_robot("reu", tmp_path_factory.mktemp("reu") / "reu"))
    return HeadController(robot, method="free_roll", seed=1)


def test_a_shape_whose_lift_ends_unsafe_is_no_base_to_choose(reu):
    """On the published reu snake the initial state's neck and head over a flatter base arc (half its angles) are
    statically stable by less than DETOUR_MARGIN: the curl is stable, but the plan could not lift from it (it went
    straight from the curl on the ground to the target, 45 mm into the ground: bench/targets.py --generated
    published:reu, place 12). The base's choice skips such shapes; the initial shape is fine."""
    from snakehead.collision import path_proof as path_check
    from snakehead.margins import DETOUR_MARGIN
    from snakehead.planning import base_choice
    from snakehead.planning.waypoints import Waypoints

    start = reu.robot.lift_joints.start
    flat = reu.q_initial.copy()
    flat[:start] *= 0.5
    ss.bending_state(reu, flat)  # a stable curl
    lifted = base_choice.shape_of(reu.robot, flat, reu.q_initial)
    way = Waypoints(reu.robot, snakehead.BasePlacement(0.7, -0.6, 2.8))  # independent: the checks one by one
    ground, self_, _ = path_check.sample_clearances(reu.robot, lifted[None], way.base, made=way.checker)
    assert ground[0] >= 0.0 and self_[0] > 0.0 and 0.0 < way.static_margins(lifted[None])[0] < DETOUR_MARGIN
    assert not ss.lift_ends_safe(reu, flat) and not base_choice.has_curl(reu, flat)
    assert ss.lift_ends_safe(reu, reu.q_initial) and base_choice.has_curl(reu, reu.q_initial)


def test_a_composition_that_disagrees_with_the_kinematics_falls_back_to_the_exhaustive_search(monkeypatch):
    """The fast centres of mass are checked against the robot's own at the curls ranked and at a spread of all;
    were they wrong (a chain the composition does not model), the exhaustive search answers."""
    robot = snakehead.SnakeRobot.default()
    q = base_shapes(robot, 1, seed=11)[0]
    want = ss.ground_curl_exhaustive(robot, q)
    composed = ss._curl_com
    calls = []
    monkeypatch.setattr(ss, "_curl_com", lambda *a: composed(*a)[::-1].copy())  # every curl's mass misplaced
    monkeypatch.setattr(ss, "ground_curl_exhaustive", lambda *a: calls.append(1) or want)
    np.testing.assert_array_equal(ss.ground_curl(robot, q), want)
    assert calls == [1]
