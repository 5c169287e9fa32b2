"""What a reachability map answers: reachable poses (vectorised), inverse reachability of the head's base frame,
and base placements on the ground, on the default robot and on a generated snake. Checked against the map's
own samples, against TRAC-IK and against the robot's forward kinematics."""
from __future__ import annotations

import numpy as np
import pytest

from snakehead import SnakeRobot, TracIK
from snakehead.backbone.initial import initial_configuration
from snakehead.kinematics import base_placement as bp
from snakehead.kinematics import reachability as ws
from snakehead.kinematics.reachability import map_queries as mq
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.model.robot_file import write_robot_file

SMALL = dict(voxel=0.1, directions=12, rolls=4, cloud_samples=5000, seed=3, timeout=5e-4)
FREE_ROLL = [0.0, 0.0, 0.0, np.inf, 0.0, 0.0]  # the head's roll about its x-axis left free


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


@pytest.fixture(scope="module")
def small(robot):
    return ws.compute(robot, progress=False, **SMALL)


def samples(m):
    """Every pose the map tried: (M * N, 3) points, (M * N, 3) directions, (M * N,) reached."""
    d = m.sphere_directions
    points = (m.centers[:, None, :] + 0.5 * m.voxel_size * d[None]).reshape(-1, 3)
    return points, np.tile(d, (len(m), 1)), mq.direction_bits(m).reshape(-1)


def frames_at(points, directions):
    return np.array([ws.approach_frame(p, d) for p, d in zip(points, directions)])


# --- reachable ----------------------------------------------------------------------------------------------
def test_reachable_answers_the_maps_own_samples(small):
    points, dirs, bits = samples(small)
    assert 0.2 < bits.mean() < 0.8
    np.testing.assert_array_equal(small.reachable(points, dirs, interpolate=False), bits)
    # Slightly off the samples (less than half the spacing of positions and directions): the same answers.
    rng = np.random.default_rng(1)
    jitter = rng.uniform(-0.2, 0.2, points.shape) * small.voxel_size
    tilt = dirs + 0.1 * rng.normal(size=dirs.shape)
    near = np.argmax((tilt / np.linalg.norm(tilt, axis=1, keepdims=True)) @ small.sphere_directions.T, axis=1)
    same = near == np.tile(np.arange(len(small.sphere_directions)), len(small))
    np.testing.assert_array_equal(small.reachable(points + jitter, tilt * 3.0, interpolate=False)[same], bits[same])
    # One pose in, one bool out; directions need not be unit.
    k = int(np.argmax(bits))
    assert small.reachable(points[k], 2.5 * dirs[k], interpolate=False) is True
    assert isinstance(small.reachable(points[k], dirs[k]), bool)
    # Outside the map's voxels nothing is reachable.
    for interpolate in (False, True):
        assert not small.reachable([[5.0, 0.0, 0.0], [0.0, -3.0, 1.0]], [[1.0, 0, 0], [0, 0, 1.0]],
                                   interpolate=interpolate).any()


def test_interpolated_reachability(small):
    points, dirs, bits = samples(small)
    score = mq.reachability(small, points, dirs)
    assert score.shape == bits.shape and score.min() >= 0.0 and score.max() <= 1.0
    # At the samples the blend leans on the sample itself: it mostly agrees with it.
    agree = np.mean(small.reachable(points, dirs) == bits)
    assert agree > 0.85
    assert np.mean(score[bits]) > 0.6 > 0.4 > np.mean(score[~bits])


def test_reachable_agrees_with_trac_ik(robot, small):
    # The map's bits come from IK with a short budget; TRAC-IK with a long one, on each of the map's rolled
    # frames, solves one for the poses marked reached and almost never for the others: an independent check.
    points, dirs, bits = samples(small)
    rng = np.random.default_rng(7)
    ik = TracIK.from_chain(robot.head_chain, timeout=0.02, seed=5)
    rolls = 2 * np.pi * np.arange(SMALL["rolls"]) / SMALL["rolls"]

    def any_roll(picked):
        frames = np.array([ws.approach_frame(points[i], dirs[i], r) for i in picked for r in rolls])
        return ik.ik_many(frames)[1].reshape(len(picked), len(rolls)).any(axis=1)

    assert any_roll(rng.choice(np.nonzero(bits)[0], 60, replace=False)).mean() >= 0.95
    assert any_roll(rng.choice(np.nonzero(~bits)[0], 60, replace=False)).mean() <= 0.1


@pytest.mark.parametrize("positions, directions, error, match", [
    ([0.1, 0.0], [1.0, 0.0, 0.0], ValueError, "shape"),
    ([[0.1, 0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]], ValueError, "shape"),
    ([[0.1, 0.0, 0.0]] * 2, [[1.0, 0.0, 0.0]] * 3, ValueError, "one direction per position"),
    ([np.nan, 0.0, 0.0], [1.0, 0.0, 0.0], ValueError, "NaN"),
    ([0.1, 0.0, 0.0], [np.inf, 0.0, 0.0], ValueError, "NaN or inf"),
    ([0.1, 0.0, 0.0], [0.0, 0.0, 0.0], ValueError, "zero length"),
    ([[0.1, 0.0, 0.0]] * 2, [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]], ValueError, "direction 1 has zero length"),
    ("here", [1.0, 0.0, 0.0], TypeError, "positions must be numbers, got str"),  # text is the wrong type
])
def test_queries_reject_bad_input(small, positions, directions, error, match):
    with pytest.raises(error, match=match):
        small.reachable(positions, directions)
    with pytest.raises(error, match=match):
        mq.reachability(small, positions, directions)


# --- inverse reachability -------------------------------------------------------------------------------------
def test_inverse_gives_base_frames_that_see_the_target_as_a_reached_sample(robot, small):
    target, direction = np.array([0.3, -0.2, 0.4]), np.array([0.0, 0.6, 0.8])
    c = small.inverse(target, direction, rolls=6, limit=50)
    assert len(c) == 300 and np.all(np.diff(c.index) <= 0)
    bits = mq.direction_bits(small)
    assert np.all(bits[c.voxels, c.directions])
    np.testing.assert_allclose(c.index, small.indices[c.voxels])
    for T, v, k in zip(c.poses, c.voxels, c.directions):
        R = T[:3, :3]
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)
        seen = np.linalg.solve(T, np.r_[target, 1.0])[:3]  # the target in the base frame
        np.testing.assert_allclose(seen, small.centers[v] + 0.5 * small.voxel_size * small.sphere_directions[k],
                                   atol=1e-12)
        np.testing.assert_allclose(R.T @ direction, small.sphere_directions[k], atol=1e-12)
    # The turns about the target direction differ by 60 degrees and keep the target where it is.
    assert sorted(set(np.round(np.degrees(c.turns), 6))) == [0.0, 60.0, 120.0, 180.0, 240.0, 300.0]
    # From the best base frames, TRAC-IK puts the head on the target (roll free).
    ik = TracIK.from_chain(robot.head_chain, timeout=0.02, bounds=FREE_ROLL, seed=2)
    local = np.array([np.linalg.solve(T, ws.approach_frame(target, direction)) for T in c.poses[:30]])
    _, ok = ik.ik_many(local)
    assert ok.mean() >= 0.9
    # min_index keeps the voxels of at least that index.
    best = small.inverse(target, direction, min_index=80.0, limit=None)
    assert len(best) > 0 and best.index.min() >= 80.0


@pytest.mark.parametrize("kw, match", [
    (dict(position=[[0.1, 0, 0]] * 2, direction=[[1.0, 0, 0]] * 2), "one target"),
    (dict(position=[0.1, 0, 0], direction=[0.0, 0, 0]), "zero length"),
    (dict(position=[np.nan, 0, 0], direction=[1.0, 0, 0]), "NaN"),
    (dict(position=[0.1, 0, 0], direction=[1.0, 0, 0], rolls=0), "rolls"),
    (dict(position=[0.1, 0, 0], direction=[1.0, 0, 0], limit=0), "limit"),
    (dict(position=[0.1, 0, 0], direction=[1.0, 0, 0], min_index=np.nan), "min_index"),
])
def test_inverse_rejects_bad_input(small, kw, match):
    position, direction = kw.pop("position"), kw.pop("direction")
    with pytest.raises(ValueError, match=match):
        small.inverse(position, direction, **kw)


# --- base placements ------------------------------------------------------------------------------------------
def check_placements(robot, m, position, direction, c, q_base):
    """Each placement, by the robot's own kinematics, puts B0 where the map reaches the target."""
    assert len(c) > 0 and np.all(np.diff(c.index) <= 0)
    ik = TracIK.from_chain(robot.head_chain, timeout=0.02, bounds=FREE_ROLL, seed=3)
    local = []
    for base, neck_q, a, d in zip(c.placements(), c.neck_q, c.target_in_b0, c.direction_in_b0):
        q = q_base.copy()
        q[robot.parts.neck] = neck_q
        B0 = robot.frame(q, robot.parts.neck_end, base)
        np.testing.assert_allclose(np.linalg.solve(B0, np.r_[position, 1.0])[:3], a, atol=1e-9)
        np.testing.assert_allclose(B0[:3, :3].T @ direction, d, atol=1e-9)
        local.append(np.linalg.solve(B0, ws.approach_frame(position, direction)))
    assert np.all(m.reachable(c.target_in_b0, c.direction_in_b0, interpolate=False))  # the samples they come from
    _, ok = ik.ik_many(np.array(local))
    return ok.mean()


def test_base_placements_of_the_default_robot(robot, small):
    position, direction = np.array([1.0, 0.3, 0.3]), np.array([0.0, 1.0, 0.0])
    c = bp.base_placements(robot, small, position, direction, limit=15)
    assert check_placements(robot, small, position, direction, c, initial_configuration(robot)) >= 0.8
    assert c.index[0] == small.indices.max() or c.index[0] >= 80
    with pytest.raises(ValueError, match="zero length"):
        bp.base_placements(robot, small, position, [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="base_configuration"):
        bp.base_placements(robot, small, position, direction, base_configuration=np.zeros(3))
    with pytest.raises(ValueError, match="samples"):
        bp.base_placements(robot, small, position, direction, neck_samples=0)
    with pytest.raises(ValueError, match="yaw_samples"):
        bp.base_placements(robot, small, position, direction, yaw_samples=0)
    # A target no placement reaches (far above the robot): no candidate, not an error.
    assert len(bp.base_placements(robot, small, [0.0, 0.0, 5.0], direction)) == 0


def test_base_placements_of_another_snake(tmp_path):
    # 13 joints starting with a pitch joint, 10 cm modules, 6 cm section, a 1-joint neck and a 6-DOF head named
    # by link frames.
    spec = SnakeSpec(n_joints=13, module_length=0.1, section=0.06, mass_per_module=0.3, first_axis="pitch",
                     link_prefix="seg", joint_prefix="j", tip_name="nose", name="other")
    (tmp_path / "other.urdf").write_text(snake_urdf(spec))
    robot = SnakeRobot.from_file(write_robot_file(tmp_path / "other.toml", urdf=tmp_path / "other.urdf",
                                                  base_end="seg6", neck_end="seg7", head_tip="nose"))
    m = ws.compute(robot, progress=False, voxel=0.12, directions=12, rolls=4, cloud_samples=5000, timeout=5e-4)
    q_base = initial_configuration(robot)
    B0 = robot.frame(q_base, robot.parts.neck_end)
    position = B0[:3, :3] @ np.array([0.25, 0.1, 0.1]) + B0[:3, 3] + np.array([0.3, 0.2, 0.0])
    direction = np.array([0.3, 1.0, 0.2])
    c = bp.base_placements(robot, m, position, direction, base_configuration=q_base, limit=10)
    assert check_placements(robot, m, position, direction / np.linalg.norm(direction), c, q_base) >= 0.7
