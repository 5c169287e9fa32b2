"""Chain FK and Jacobian against KDL, pinocchio and finite differences; bad input."""
import threading

import numpy as np
import pinocchio as pin
import pytest
from conftest import head6_robot

import snakehead
from snakehead import Chain, SnakeRobot

SNAKE = str(snakehead.default_urdf_path())
CHAINS = [
    (SNAKE, "link_0", "head_tip"),
    (SNAKE, "neck_end", "head_tip"),
    (SNAKE, "link_10", "head_tip"),
    ("MIXED", "world", "tool"),
    ("MIXED", "base", "d"),
]


def resolve(urdf, mixed_urdf):
    return mixed_urdf if urdf == "MIXED" else urdf


def pin_q(model: pin.Model, names: list[str], q: np.ndarray) -> np.ndarray:
    """Our joint vector as pinocchio's configuration (continuous joints are (cos, sin) there)."""
    qp = pin.neutral(model)
    for name, value in zip(names, q):
        j = model.joints[model.getJointId(name)]
        if j.nq == 2:
            qp[j.idx_q : j.idx_q + 2] = np.cos(value), np.sin(value)
        else:
            qp[j.idx_q] = value
    return qp


@pytest.mark.parametrize("urdf,base,tip", CHAINS)
def test_fk_and_jacobian_match_kdl_and_pinocchio(urdf, base, tip, mixed_urdf):
    urdf = resolve(urdf, mixed_urdf)
    chain = Chain.from_urdf(urdf, base, tip)
    model = pin.buildModelFromUrdf(urdf)
    data = model.createData()
    fb, ft = model.getFrameId(base), model.getFrameId(tip)
    cols = [model.joints[model.getJointId(n)].idx_v for n in chain.joint_names]
    rng = np.random.default_rng(7)
    for _ in range(1000):
        q = chain.random_configuration(rng)
        T = chain.fk(q)
        J = chain.jacobian(q)
        np.testing.assert_allclose(T, chain.model.kdl_fk(q), atol=1e-10, rtol=0)
        np.testing.assert_allclose(J, chain.model.kdl_jacobian(q), atol=1e-10, rtol=0)
        qp = pin_q(model, chain.joint_names, q)
        pin.computeJointJacobians(model, data, qp)
        pin.updateFramePlacements(model, data)
        oMb, oMt = data.oMf[fb], data.oMf[ft]
        np.testing.assert_allclose(T, (oMb.inverse() * oMt).homogeneous, atol=1e-10, rtol=0)
        Jw = pin.getFrameJacobian(model, data, ft, pin.LOCAL_WORLD_ALIGNED)[:, cols]
        Rb = oMb.rotation
        Jb = np.vstack([Rb.T @ Jw[:3], Rb.T @ Jw[3:]])
        # For a continuous joint pinocchio's velocity is the angle rate too; columns compare directly.
        np.testing.assert_allclose(J, Jb, atol=1e-10, rtol=0)


@pytest.mark.parametrize("urdf,base,tip", CHAINS)
def test_jacobian_matches_central_differences(urdf, base, tip, mixed_urdf):
    chain = Chain.from_urdf(resolve(urdf, mixed_urdf), base, tip)
    rng = np.random.default_rng(3)
    h = 1e-6
    for _ in range(20):
        q = chain.random_configuration(rng)
        J = chain.jacobian(q)
        R = chain.fk(q)[:3, :3]
        for i in range(chain.n_joints):
            dq = np.zeros(chain.n_joints)
            dq[i] = h
            Tp, Tm = chain.fk(q + dq), chain.fk(q - dq)
            v = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
            W = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ R.T  # skew(omega)
            w = np.array([W[2, 1], W[0, 2], W[1, 0]])
            np.testing.assert_allclose(J[:3, i], v, atol=1e-7)
            np.testing.assert_allclose(J[3:, i], w, atol=1e-7)


def test_default_robot_straight_head_tip_at_1384():
    robot = SnakeRobot.default()
    T = robot.body.fk(np.zeros(16))
    np.testing.assert_allclose(T[:3, 3], [1.384, 0, 0], atol=1e-12)
    np.testing.assert_allclose(T[:3, :3], np.eye(3), atol=1e-12)


def test_default_robot_parts_and_frames():
    robot = SnakeRobot.default()
    assert robot.n_joints == 16
    assert robot.body.joint_names == [f"joint_{i}" for i in range(1, 17)]
    names = robot.link_names
    assert names[0] == "link_0" and names[-1] == "head_tip"
    assert {"base_end", "neck_end"} <= set(names)
    assert [robot.body.joint_names[i] for i in range(16)[robot.parts.base]] == [f"joint_{i}" for i in range(1, 8)]
    assert [robot.body.joint_names[i] for i in range(16)[robot.parts.neck]] == ["joint_8", "joint_9"]
    assert robot.head_chain.n_joints == 7 and head6_robot().head_chain.n_joints == 6
    np.testing.assert_allclose(robot.lower, -np.pi / 2)
    np.testing.assert_allclose(robot.upper, np.pi / 2)
    assert robot.total_mass == pytest.approx(3.2, abs=1e-9)
    # Straight on the ground: P0 (base_end) and B0 (neck_end) at the ends of link_7 and link_9.
    F = robot.frames(np.zeros(16))

    def x(n):
        return F[names.index(n)][0, 3]

    assert x("base_end") == pytest.approx(0.0405 + 7 * 0.0865)
    assert x("neck_end") == pytest.approx(0.0405 + 9 * 0.0865)
    assert F[0][2, 3] == pytest.approx(0.0215)  # body axis height on the ground
    # The head chain's FK is the whole body's, seen from neck_end.
    q = robot.body.random_configuration(np.random.default_rng(0))
    F = robot.body.fk_all(q)
    rel = np.linalg.inv(F[names.index("neck_end")]) @ F[-1]
    np.testing.assert_allclose(robot.head_chain.fk(q[robot.parts.head]), rel, atol=1e-12)


def test_fk_all_many_equals_fk_all():
    robot = SnakeRobot.default()
    rng = np.random.default_rng(1)
    qs = np.array([robot.body.random_configuration(rng) for _ in range(5)])
    many = robot.body.fk_all_many(qs)
    for k in range(5):
        np.testing.assert_array_equal(many[k], robot.body.fk_all(qs[k]))
    # into a given origin frame (multiplied in the core): origin @ fk_all, and a bad origin is a ValueError
    origin = np.eye(4)
    origin[:3, :3] = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    origin[:3, 3] = [0.3, -0.2, 0.05]
    moved = robot.body.fk_all_many(qs, origin)
    for k in range(5):
        np.testing.assert_allclose(moved[k], origin @ robot.body.fk_all(qs[k]), atol=1e-14)
    with pytest.raises(ValueError, match="origin"):
        robot.body.fk_all_many(qs, np.eye(3))
    with pytest.raises(ValueError, match="origin"):
        robot.body.fk_all_many(qs, np.full((4, 4), np.nan))


def test_urdf_as_string_and_pathlike(tmp_path):
    xml = open(SNAKE).read()
    a = Chain.from_urdf(xml, "neck_end", "head_tip")
    p = tmp_path / "s.urdf"
    p.write_text(xml)
    b = Chain.from_urdf(p, "neck_end", "head_tip")
    assert a.hash == b.hash
    assert a.n_joints == 7


BAD_URDF = [
    ("/no/such/file.urdf", "cannot read URDF file"),
    ("<robot name='x'><link name='a'/>", "malformed URDF"),
    ("<robot name='x'><link name='a'/><link name='a'/></robot>", "malformed URDF"),
]


@pytest.mark.parametrize("urdf,message", BAD_URDF)
def test_bad_urdf_raises_value_error(urdf, message):
    with pytest.raises(ValueError, match=message):
        Chain.from_urdf(urdf, "a", "b")


@pytest.mark.parametrize(
    "base,tip,message",
    [
        ("link_0", "nope", "unknown tip link 'nope'"),
        ("nope", "head_tip", "unknown base link 'nope'"),
        ("head_tip", "link_0", "not an ancestor"),
        ("link_3", "link_3", "same link"),
    ],
)
def test_bad_links_raise_value_error(base, tip, message):
    with pytest.raises(ValueError, match=message):
        Chain.from_urdf(SNAKE, base, tip)


def test_bad_limits_raise_value_error():
    xml = (
        "<robot name='r'><link name='a'/><link name='b'/>"
        "<joint name='j' type='prismatic'><parent link='a'/><child link='b'/><axis xyz='1 0 0'/>"
        "<limit lower='0.5' upper='0.1' effort='1' velocity='1'/></joint></robot>"
    )
    with pytest.raises(ValueError, match="lower limit > upper limit"):
        Chain.from_urdf(xml, "a", "b")


@pytest.mark.parametrize(
    "q,message",
    [
        (np.zeros(15), r"shape \(15,\)"),
        (np.zeros((16, 1)), "shape"),
        (np.r_[np.zeros(15), np.nan], "NaN or inf"),
        (np.r_[np.zeros(15), np.inf], "NaN or inf"),
        (["a"] * 16, "must be numbers, got text"),
    ],
)
def test_bad_configuration_raises_value_error(q, message):
    chain = SnakeRobot.default().body
    for f in (chain.fk, chain.fk_all, chain.jacobian):
        with pytest.raises(TypeError if "text" in message else ValueError, match=message):
            f(q)


def test_core_checks_configuration_too():
    """The C++ layer rejects bad q by itself (no reliance on the Python checks)."""
    model = SnakeRobot.default().body.model
    with pytest.raises(ValueError, match="has 3 entries"):
        model.fk(np.zeros(3))
    with pytest.raises(ValueError, match="not finite"):
        model.jacobian(np.full(16, np.nan))
    with pytest.raises(ValueError, match="columns"):
        model.fk_all_many(np.zeros((4, 3)))


def test_fk_from_many_threads():
    chain = SnakeRobot.default().body
    rng = np.random.default_rng(5)
    qs = [chain.random_configuration(rng) for _ in range(200)]
    expected = [chain.model.kdl_fk(q) for q in qs]
    errors = []

    def work():
        for q, T in zip(qs, expected):
            if np.abs(chain.fk(q) - T).max() > 1e-12:
                errors.append(q)

    threads = [threading.Thread(target=work) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
