"""Joint torques of a snake lying on the ground (dynamics.inverse_dynamics): pinocchio's RNEA on the fixed-base
chain, the lifted-share rule written as a sum, the root's wrench against finite differences of the momenta."""
import numpy as np
import pytest

import snakehead
from snakehead.dynamics import stability
from snakehead.dynamics.inverse_dynamics import (
    carried_weights,
    inverse_dynamics,
    lift_shares,
    momentum_rates,
    newton_euler,
)
from snakehead.model.generate import SnakeSpec, snake_urdf

GENERATED = SnakeSpec(n_joints=11, module_length=0.11, section=0.05, mass_per_module=0.3, first_axis="pitch",
                      markers={"p0": 5, "b0": 6}, tip_name="tip", name="gen11")


@pytest.fixture(scope="module", params=["default", "gen11"])
def robot(request):
    if request.param == "default":
        return snakehead.SnakeRobot.default()
    return snakehead.SnakeRobot.from_urdf(snake_urdf(GENERATED), base_end="p0", neck_end="b0", head_tip="tip")


@pytest.fixture(scope="module")
def pin():
    """pinocchio, the independent Newton-Euler reference: the one test that compares with it needs it."""
    return pytest.importorskip("pinocchio")


def pin_model(pin, robot):
    src = robot.urdf
    model = pin.buildModelFromXML(src) if src.lstrip().startswith("<") else pin.buildModelFromUrdf(src)
    assert [model.names[i] for i in range(1, model.njoints)] == robot.joint_names
    return model


def random_states(robot, T, seed):
    rng = np.random.default_rng(seed)
    q = np.array([robot.random_configuration(rng) for _ in range(T)])
    return q, rng.normal(0, 1.5, q.shape), rng.normal(0, 3.0, q.shape)


def test_full_gravity_and_inertia_equal_pinocchio_rnea(pin, robot):
    model = pin_model(pin, robot)
    data = model.createData()
    q, qd, qdd = random_states(robot, 40, 1)
    base = snakehead.BasePlacement(0.3, -0.7, 1.1)  # a yaw of the root does not change gravity's direction in it
    for gravity, g in (("full", stability.GRAVITY), ("none", 0.0)):
        model.gravity.linear = np.array([0.0, 0.0, -g])
        expected = np.array([pin.rnea(model, data, a, b, c) for a, b, c in zip(q, qd, qdd)])
        tau = inverse_dynamics(robot, q, qd, qdd, base, gravity=gravity)
        assert np.abs(tau - expected).max() < 1e-9 * max(1.0, np.abs(expected).max())
    # one sample in, one out
    one = inverse_dynamics(robot, q[0], qd[0], qdd[0], base, gravity="none")
    assert one.shape == (robot.n_joints,) and np.allclose(one, tau[0])


def test_carried_gravity_is_the_lifted_share_sum(robot):
    """Each joint holds sum_i W_ji (c_i - p_j) x m_i g against gravity (the sum written out, W from
    carried_weights); the inertial terms add in full."""
    rng = np.random.default_rng(2)
    q = np.array([robot.random_configuration(rng) for _ in range(30)])
    q[:10, robot.joint_kinds.index("pitch")::2] *= 0.02  # some nearly flat: links on and near the ground
    q[:10] = np.clip(q[:10], robot.lower, robot.upper)
    base = snakehead.BasePlacement(0.1, 0.2, -0.4)
    F = robot.frames_many(q, base)
    W = carried_weights(robot, F)
    assert 0.0 < W.mean() < 1.0  # some links carried by the ground, some by the joints
    child = np.asarray(robot.body.model.joint_child_links)
    axes = np.einsum("tjik,jk->tji", F[:, child][..., :3, :3], np.asarray(robot.body.model.joint_axes))
    anchors = F[:, child][..., :3, 3]
    coms = np.einsum("tlij,lj->tli", F[..., :3, :3], robot.coms) + F[..., :3, 3]
    weight = robot.masses[:, None] * np.array([0.0, 0.0, -stability.GRAVITY])
    moment = np.cross(coms[:, None, :, :] - anchors[:, :, None, :], weight[None, None])
    expected = -np.einsum("tjl,tjlk,tjk->tj", W, moment, axes)
    zero = np.zeros_like(q)
    assert np.abs(inverse_dynamics(robot, q, zero, zero, base) - expected).max() < 1e-9
    qd, qdd = rng.normal(size=q.shape), rng.normal(size=q.shape)
    both = inverse_dynamics(robot, q, qd, qdd, base)
    assert np.allclose(both, expected + inverse_dynamics(robot, q, qd, qdd, base, gravity="none"), atol=1e-9)


def test_lying_flat_the_ground_carries_everything():
    robot = snakehead.SnakeRobot.default()
    flat = np.zeros((1, robot.n_joints))
    w = lift_shares(robot, robot.frames_many(flat))
    assert np.all(w[0, robot.shaped_links] == 0.0)
    assert np.abs(inverse_dynamics(robot, flat, flat, flat)).max() == 0.0
    # lift the head part about a pitch joint of the neck: the joints from there on carry it, the base joints not
    q = flat[0].copy()
    j = robot.lift_joints.start
    q[j] = -0.5 * robot.joint_signs[j]  # a pitch joint turning the distal body up
    tau = inverse_dynamics(robot, q, 0 * q, 0 * q)
    full = inverse_dynamics(robot, q, 0 * q, 0 * q, gravity="full")
    assert abs(tau[j]) > 0.5 and np.isclose(tau[j], full[j])
    assert np.abs(tau[:robot.parts.base.stop]).max() < 1e-12


def test_sim_uses_the_same_rule():
    from snakehead.sim import tracking

    assert tracking.carried_weights is carried_weights


def test_root_wrench_is_the_momentum_rate(robot):
    """The inertial wrench across the first joint (about the world origin) is dP/dt and dL/dt: finite differences in
    time of the momenta of Eqs. 25-31 along a smooth motion, and momentum_rates; whatever the gravity model."""
    base = snakehead.BasePlacement(-0.2, 0.4, 0.6)
    rng = np.random.default_rng(3)
    q0 = robot.random_configuration(rng) * 0.5
    amp, freq = rng.uniform(-0.4, 0.4, robot.n_joints), rng.uniform(0.5, 2.0, robot.n_joints)
    t = np.linspace(0.0, 1.0, 4001)
    q = q0 + amp * np.sin(freq * t[:, None])
    qd = amp * freq * np.cos(freq * t[:, None])
    qdd = -amp * freq ** 2 * np.sin(freq * t[:, None])
    P, L = stability.momenta_from_velocities(robot, q, qd, base)
    Pdot, Ldot = np.gradient(P, t, axis=0, edge_order=2), np.gradient(L, t, axis=0, edge_order=2)
    ne = newton_euler(robot, q, qd, qdd, base)
    inner = slice(10, -10)
    assert np.abs(ne.Pdot - Pdot)[inner].max() < 1e-5 * max(1.0, np.abs(Pdot).max())
    assert np.abs(ne.Ldot - Ldot)[inner].max() < 1e-5 * max(1.0, np.abs(Ldot).max())
    assert np.allclose(ne.tau, inverse_dynamics(robot, q, qd, qdd, base))
    Pr, Lr = momentum_rates(robot, q[::100], qd[::100], qdd[::100], base)
    assert np.abs(Pr - ne.Pdot[::100]).max() < 1e-7 and np.abs(Lr - ne.Ldot[::100]).max() < 1e-7


def test_bad_input():
    robot = snakehead.SnakeRobot.default()
    q = np.zeros(robot.n_joints)
    with pytest.raises(ValueError, match="gravity"):
        inverse_dynamics(robot, q, q, q, gravity="moon")
    with pytest.raises(ValueError, match="qd"):
        inverse_dynamics(robot, np.zeros((3, 16)), np.zeros((2, 16)), np.zeros((3, 16)))
    with pytest.raises(ValueError, match="q"):
        inverse_dynamics(robot, np.zeros(15), q, q)
    with pytest.raises(ValueError, match="NaN"):
        inverse_dynamics(robot, q, np.full(16, np.nan), q)
    with pytest.raises(TypeError, match="robot"):
        inverse_dynamics("snake", q, q, q)
    with pytest.raises(TypeError, match="base"):
        inverse_dynamics(robot, q, q, q, base=(0, 0, 0))
    with pytest.raises(ValueError, match="ramp"):
        inverse_dynamics(robot, q, q, q, ramp=0.0)


def test_core_passes_from_many_threads_and_bad_shapes():
    """The core's Newton-Euler and momenta release the GIL and keep no state: from 8 threads at once they give what
    one thread gives; arrays of the wrong shape are a ValueError from the binding, not a crash."""
    from concurrent.futures import ThreadPoolExecutor

    from snakehead import _core
    from snakehead.dynamics import stability

    robot = snakehead.SnakeRobot.default()
    rng = np.random.default_rng(11)
    q = np.array([robot.random_configuration(rng) for _ in range(400)])
    qd, qdd = rng.normal(size=q.shape), rng.normal(size=q.shape)
    expected = newton_euler(robot, q, qd, qdd)
    expected_P = stability.momenta_from_velocities(robot, q, qd)[0]

    def run(_):
        ne = newton_euler(robot, q, qd, qdd)
        return ne.tau, ne.Ldot, stability.momenta_from_velocities(robot, q, qd)[0]

    with ThreadPoolExecutor(8) as pool:
        for tau, Ldot, P in pool.map(run, range(16)):
            assert np.array_equal(tau, expected.tau) and np.array_equal(Ldot, expected.Ldot)
            assert np.array_equal(P, expected_P)
    model = robot.body.model
    frames = robot.frames_many(q[:3])
    args = (list(model.joint_child_links), model.joint_axes, robot.masses, robot.coms, robot.inertias)
    with pytest.raises(ValueError, match="qd"):
        _core.newton_euler(frames, qd[:2], qdd[:3], *args, None, np.zeros(3))
    with pytest.raises(ValueError, match="frames"):
        _core.momenta(frames[:, :, :3], qd[:3], *args)
    with pytest.raises(ValueError, match="child"):
        _core.newton_euler(frames, qd[:3], qdd[:3], [0] * robot.n_joints, *args[1:], None, np.zeros(3))


@pytest.fixture(scope="module")
def sea_robot(tmp_path_factory):
    """A snake written as published ones are: a rotated dummy root, modules along z of two links each, cylinders and
    a mesh tail (``snakehead.samples.published``, style "sea")."""
    from snakehead.samples import published

    return snakehead.SnakeRobot.from_file(published.write_robot("sea", tmp_path_factory.mktemp("sea")))


def test_pass_along_q_equals_the_pass_over_given_frames(robot):
    check_pass_along_q(robot)


def test_pass_along_q_on_a_published_snake(sea_robot):
    check_pass_along_q(sea_robot)


def check_pass_along_q(robot):
    """Without frames the core computes each sample's frames, lifted shares and CoM in place: the same torques and
    momentum rates as the pass over ``frames_many``'s frames with the lifted shares of ``lift_shares`` (numpy), and
    the CoM of ``stability.center_of_mass``; with links on, near and off the ground."""
    rng = np.random.default_rng(5)
    q = np.array([robot.random_configuration(rng) for _ in range(60)])
    q[:30, robot.joint_kinds.index("pitch")::2] *= 0.02  # nearly flat: shares strictly between 0 and 1
    q = np.clip(q, robot.lower, robot.upper)
    qd, qdd = rng.normal(size=q.shape), rng.normal(size=q.shape)
    base = snakehead.BasePlacement(0.4, -0.2, 0.7)
    frames = robot.frames_many(q, base)
    shares = lift_shares(robot, frames)
    assert np.any((shares > 0) & (shares < 1)), "the test needs links partly lifted"
    for gravity in ("carried", "full", "none"):
        along = newton_euler(robot, q, qd, qdd, base, gravity=gravity)
        given = newton_euler(robot, q, qd, qdd, base, gravity=gravity, frames=frames)
        scale = max(1.0, np.abs(given.tau).max())
        assert np.abs(along.tau - given.tau).max() < 1e-12 * scale
        np.testing.assert_allclose(along.Pdot, given.Pdot, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(along.Ldot, given.Ldot, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(along.com, stability.center_of_mass(robot, q, base), rtol=0, atol=1e-14)
        assert given.com is None
    one = newton_euler(robot, q[0], qd[0], qdd[0], base)
    assert one.com.shape == (3,) and np.allclose(one.tau, newton_euler(robot, q, qd, qdd, base).tau[0])


def test_pass_along_q_rejects_bad_shapes():
    from snakehead import _core

    robot = snakehead.SnakeRobot.default()
    model = robot.body.model
    q = np.zeros((3, robot.n_joints))
    args = (list(model.joint_child_links), model.joint_axes, robot.masses, robot.coms, robot.inertias)
    links, points = robot.distal_points
    links = [int(k) for k in links]
    origin = robot.root_pose(None)
    with pytest.raises(ValueError, match="qdd"):
        _core.newton_euler_along(model, origin, q, q, q[:2], *args, links, points, 0.005, np.zeros(3))
    with pytest.raises(ValueError, match="lift_points"):
        _core.newton_euler_along(model, origin, q, q, q, *args, links, points[:-1], 0.005, np.zeros(3))
    with pytest.raises(ValueError, match="lift_points are needed"):
        _core.newton_euler_along(model, origin, q, q, q, *args, links, None, 0.005, np.zeros(3))
    with pytest.raises(ValueError, match="ramp"):
        _core.newton_euler_along(model, origin, q, q, q, *args, links, points, 0.0, np.zeros(3))
    with pytest.raises(ValueError, match="lifted link"):
        _core.newton_euler_along(model, origin, q, q, q, *args, [999] + links[1:], points, 0.005, np.zeros(3))
