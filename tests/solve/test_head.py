"""Head part: frames from a direction, the paper's rotated frames (Fig. 9) and the free-roll method."""
import numpy as np
import pytest

from snakehead import SnakeRobot, TracIK
from snakehead.solve import head


@pytest.fixture(scope="module")
def chain():
    return SnakeRobot.default().head_chain


@pytest.fixture(scope="module")
def ik(chain):
    return TracIK.from_chain(chain, timeout=0.005, epsilon=1e-6, seed=3)


def test_frame_from_direction():
    rng = np.random.default_rng(0)
    for d in list(rng.normal(size=(50, 3))) + [np.array([0, 0, 1.0]), np.array([0, 0, -2.0])]:
        T = head.frame_from_direction([1, 2, 3], d)
        R = T[:3, :3]
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)
        np.testing.assert_allclose(R[:, 0], d / np.linalg.norm(d), atol=1e-12)
        np.testing.assert_allclose(T[:3, 3], [1, 2, 3])
        if abs(d[2]) / np.linalg.norm(d) < 0.999:
            assert R[2, 1] == pytest.approx(0.0, abs=1e-12)  # y horizontal: z as close to up as can be


def test_roll_about_x_keeps_origin_and_x_axis():
    T = head.frame_from_direction([0.1, 0.2, 0.3], [1, 1, 0])
    for a in np.linspace(0, 2 * np.pi, 7):
        Tr = head.roll_about_x(T, a)
        np.testing.assert_allclose(Tr[:3, 3], T[:3, 3])
        np.testing.assert_allclose(Tr[:3, 0], T[:3, 0], atol=1e-12)
        assert np.arccos(np.clip(Tr[:3, 1] @ T[:3, 1], -1, 1)) == pytest.approx(abs(np.arctan2(np.sin(a), np.cos(a))), abs=1e-7)


def reachable_targets(chain, k, seed=1):
    rng = np.random.default_rng(seed)
    return [chain.fk(chain.random_configuration(rng)) for _ in range(k)]


def test_rotated_frames_reaches_position_and_direction(ik, chain):
    for T in reachable_targets(chain, 8):
        res = head.rotated_frames(ik, T, n_frames=8)
        assert res.success and res.solved >= 1 and res.tried == 8
        F = chain.fk(res.q)  # independent check by FK
        assert np.linalg.norm(F[:3, 3] - T[:3, 3]) < 1e-5
        assert np.degrees(np.arccos(np.clip(F[:3, 0] @ T[:3, 0], -1, 1))) < 1e-3
        assert np.all(res.q >= chain.lower - 1e-12) and np.all(res.q <= chain.upper + 1e-12)
        # the kept candidate is the one whose frame is least rolled from the desired one
        rolls = [abs(np.arctan2(np.sin(a), np.cos(a))) for a, _ in res.candidates]
        assert abs(np.radians(res.roll_deg)) == pytest.approx(min(rolls), abs=1e-4)


def test_rotated_frames_keeps_closest_to_previous(ik, chain):
    for T in reachable_targets(chain, 5, seed=2):
        q_prev = chain.random_configuration(np.random.default_rng(4))
        res = head.rotated_frames(ik, T, n_frames=10, q_prev=q_prev)
        assert res.success
        dists = [np.linalg.norm(q - q_prev) for _, q in res.candidates]
        assert np.linalg.norm(res.q - q_prev) == pytest.approx(min(dists))


def test_free_roll_reaches_position_and_direction(ik, chain):
    for T in reachable_targets(chain, 10, seed=5):
        res = head.free_roll(ik, head.roll_about_x(T, 1.0), q_init=np.zeros(7), attempts=3)
        assert res.success
        F = chain.fk(res.q)
        assert np.linalg.norm(F[:3, 3] - T[:3, 3]) < 1e-5
        assert np.degrees(np.arccos(np.clip(F[:3, 0] @ T[:3, 0], -1, 1))) < 1e-3


def test_unreachable_target_fails_cleanly(ik):
    T = head.frame_from_direction([2.0, 0.0, 0.0], [1, 0, 0])  # 2 m away; the head reaches 0.565 m
    for res in (head.rotated_frames(ik, T, 4), head.free_roll(ik, T)):
        assert not res.success and res.q is None and res.solved == 0


@pytest.mark.parametrize(
    "call,message",
    [
        (lambda ik: head.frame_from_direction([0, 0, 0], [0, 0, 0]), "zero length"),
        (lambda ik: head.frame_from_direction([0, 0, np.nan], [1, 0, 0]), "NaN"),
        (lambda ik: head.frame_from_direction([0, 0], [1, 0, 0]), "shape"),
        (lambda ik: head.rotated_frames(ik, np.eye(4), n_frames=0), "n_frames"),
        (lambda ik: head.rotated_frames(ik, np.eye(3)), "shape"),
        (lambda ik: head.free_roll(ik, np.diag([1, 1, 2, 1.0])), "not a rotation"),
        (lambda ik: head.free_roll(ik, np.eye(4), q_init=np.zeros(3)), "shape"),
    ],
)
def test_bad_input(ik, call, message):
    with pytest.raises(ValueError, match=message):
        call(ik)


def test_angle_between_against_closed_form():
    assert head.angle_between_deg([1, 0, 0], [0, 2, 0]) == pytest.approx(90.0)
    assert head.angle_between_deg([1, 1, 0], [1, 0, 0]) == pytest.approx(45.0)
    assert head.angle_between_deg([0, 0, 3], [0, 0, -1]) == pytest.approx(180.0)


def test_rotated_frames_accept_filters_candidates(ik, chain):
    T = reachable_targets(chain, 1, seed=9)[0]
    every = head.rotated_frames(ik, T, n_frames=8)
    assert every.solved >= 2
    keep = lambda q: q[0] >= every.q[0]  # noqa: E731  (rejects some solutions, keeps the unfiltered choice)
    some = head.rotated_frames(ik, T, n_frames=8, accept=keep)
    assert some.solved == every.solved  # solutions found, before the test
    assert all(keep(q) for _, q in some.candidates)
    none = head.rotated_frames(ik, T, n_frames=8, accept=lambda q: False)
    assert not none.success and none.solved == every.solved and none.candidates == []


@pytest.mark.parametrize("a,b,message", [([0, 0, 0], [1, 0, 0], "zero length"), ([1, 0], [1, 0, 0], "shape"),
                                          ([np.nan, 0, 1], [1, 0, 0], "NaN")])
def test_angle_between_bad_input(a, b, message):
    with pytest.raises(ValueError, match=message):
        head.angle_between_deg(a, b)
