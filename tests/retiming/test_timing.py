"""Time-optimal retiming (retiming.timing): a lift of the head retimed on two robots keeps every limit and the ZMP
inside at every 2 ms sample (checked independently by stability.dynamic_stability), is faster than the fixed
speed and cannot be sped up by 5 %, tracks in MuJoCo; the linear ZMP rows and the momentum-rate coefficients
against direct computations; holds, stops and bad input."""
import numpy as np
import pytest

import snakehead
from snakehead._errors import Infeasible
from snakehead.collision import body_collisions as coll
from snakehead.dynamics import stability
from snakehead.dynamics.inverse_dynamics import inverse_dynamics
from snakehead.kinematics import reachability as ws
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.planning import start_state
from snakehead.retiming import grid_refinement, limit_check, timing
from snakehead.trajectory.interpolation import MonotoneQuintic

GENERATED = SnakeSpec(n_joints=14, module_length=0.08, section=0.045, mass_per_module=0.22, first_axis="yaw",
                      markers={"p0": 7, "b0": 9}, tip_name="tip", name="gen14")
#: The fixed speed the planner used before retiming (rad/s of the fastest joint) and its shortest move (s).
FIXED_SPEED, FIXED_MIN_MOVE = 0.12, 2.0
#: Share over a limit the 2 ms samples may show (TOPP-RA keeps the limits at its gridpoints; retime refines the
#: grid until the samples between them keep them too).
LIMIT_TOLERANCE = 1e-3


def feasible(robot, qs, margin=0.02):
    """Statically stable with ``margin`` m (ground polygon), nothing below the ground, no self-contact."""
    still = np.zeros_like(qs)
    m = stability.dynamic_stability(robot, np.arange(len(qs), dtype=float), qs, None, still, contact="ground").margin
    clear = coll.ground_clearance(robot, qs)[:, robot.lifted_links].min(axis=1)
    return (m >= margin) & (clear >= -coll.GROUND_TOLERANCE) & (coll.self_clearance(robot, qs) > 0)


def stable_lift(robot, controller, n=16, trials=64, seed=3):
    """Waypoints lifting the head from the bending state to the initial state: the straight joint path when it is
    feasible, else the shortest of seeded two-piece paths through a midpoint with the neck and head perturbed."""
    qa, qb = start_state.bending_state(controller), controller.q_initial
    s = np.linspace(0.0, 1.0, n)[:, None]
    straight = qa + s * (qb - qa)
    if feasible(robot, straight).all():
        return straight
    rng = np.random.default_rng(seed)
    up = np.arange(robot.parts.neck.start, robot.n_joints)
    mids = np.tile(0.5 * (qa + qb), (trials, 1))
    mids[:, up] += rng.normal(0.0, 0.4, (trials, len(up)))
    mids = np.clip(mids, robot.lower, robot.upper)
    paths = np.concatenate([qa + s[None] * (mids[:, None] - qa), mids[:, None] + s[None, 1:] * (qb - mids[:, None])],
                           axis=1)
    ok = feasible(robot, paths.reshape(-1, robot.n_joints)).reshape(trials, -1).all(axis=1)
    assert ok.any(), "no feasible lift"
    length = np.abs(np.diff(paths, axis=1)).sum(axis=(1, 2))
    return paths[int(np.argmin(np.where(ok, length, np.inf)))]


def fixed_speed_duration(waypoints) -> float:
    """The planner's timing before retiming: each step at the fixed speed, a move at least FIXED_MIN_MOVE s."""
    steps = np.abs(np.diff(waypoints, axis=0)).max(axis=1) / FIXED_SPEED
    return float(np.maximum(steps, FIXED_MIN_MOVE / len(steps)).sum())


@pytest.fixture(scope="module", params=["default", "gen14"])
def lift(request):
    if request.param == "default":
        robot = snakehead.SnakeRobot.default()
        controller = snakehead.HeadController(robot)
    else:
        robot = snakehead.SnakeRobot.from_urdf(snake_urdf(GENERATED), base_end="p0", neck_end="b0", head_tip="tip")
        coarse = ws.compute(robot, progress=False, voxel=2 * ws.default_map_options(robot)["voxel"], directions=6,
                            rolls=1)
        controller = snakehead.HeadController(robot, coarse, method="free_roll", seed=1)
    waypoints = stable_lift(robot, controller)
    return request.param, robot, waypoints, timing.retime(robot, waypoints)


def test_retimed_lift_keeps_every_limit_at_every_sample(lift):
    name, robot, W, traj = lift
    limits = traj.limits
    assert np.allclose(limits.velocity, timing.VELOCITY_SHARE * robot.velocity_limit)
    assert np.allclose(limits.torque, timing.TORQUE_SHARE * robot.effort)
    # the samples: every 2 ms (the last step to the end shorter), through the waypoints, at rest at both ends,
    # within the joint limits
    assert np.allclose(np.diff(traj.t)[:-1], 0.002, atol=1e-9) and 0 < traj.t[-1] - traj.t[-2] <= 0.002 + 1e-12
    assert np.isclose(traj.duration, traj.t[-1]) and np.allclose(traj.q[[0, -1]], W[[0, -1]])
    assert np.allclose(traj.qd[[0, -1]], 0.0, atol=1e-6)
    assert np.all(traj.q >= robot.lower - 1e-9) and np.all(traj.q <= robot.upper + 1e-9)
    at = traj.spline(traj.waypoint_times)
    assert np.abs(at - W).max() < 1e-9 and np.all(np.diff(traj.waypoint_times) > 0)
    # qd and qdd are the derivatives of q (central differences of the samples)
    fd = np.gradient(traj.q, traj.t, axis=0)
    assert np.abs(fd - traj.qd)[1:-1].max() < 0.01 * np.abs(traj.qd).max()
    # every limit, by direct computation at the samples
    assert (np.abs(traj.qd) / limits.velocity).max() <= 1 + LIMIT_TOLERANCE
    assert (np.abs(traj.qdd) / limits.acceleration).max() <= 1 + LIMIT_TOLERANCE
    tau = inverse_dynamics(robot, traj.q, traj.qd, traj.qdd)
    assert (np.abs(tau) / limits.torque).max() <= 1 + LIMIT_TOLERANCE
    assert traj.check.within(LIMIT_TOLERANCE), traj.check
    assert traj.check.friction_ratio <= 1 + LIMIT_TOLERANCE
    # the ZMP inside the ground support polygon at every sample: the independent computation (momenta by
    # Eqs. 25-31, their rates by finite differences of the samples, polygons by stability)
    dyn = stability.dynamic_stability(robot, traj.t, traj.q, None, traj.qd, contact="ground")
    assert dyn.stable, dyn.min_margin
    required = timing.required_margins(timing.Support.of(robot, traj.q, snakehead.BasePlacement(),
                                                         limits.zmp_margin).static, limits.zmp_margin)
    assert np.all(dyn.margin >= required - 5e-4), (dyn.margin - required).min()
    # something binds most of the time: a time-optimal motion runs at a limit
    assert max(traj.check.binding.values()) > 0.5, traj.check.binding


def test_retimed_lift_is_faster_and_time_optimal(lift):
    name, robot, W, traj = lift
    assert traj.duration < 0.5 * fixed_speed_duration(W)
    # 5 % faster (time scaled by 0.95) breaks a limit: velocities / 0.95, accelerations / 0.95^2
    k = 0.95
    faster = timing.check_limits(robot, traj.q, traj.qd / k, traj.qdd / k ** 2, None, traj.limits)
    assert not faster.within(0.02, 1e-4), faster


def test_timeline_samples_every_order_at_once_as_one_at_a_time(lift):
    """retime samples q, qd, qdd in one pass (``sample``): the values of the motion's ``spline(t, nu)``."""
    _, _, _, traj = lift
    t = np.r_[-0.1, np.linspace(0.0, traj.duration, 777), traj.duration + 0.1]
    together = traj.spline.sample(t)
    for nu in (0, 1, 2):
        np.testing.assert_array_equal(together[nu], traj.spline(t, nu))
    np.testing.assert_array_equal(traj.spline.sample(t, (2,))[0], together[2])
    np.testing.assert_array_equal(traj.qd[1:-1], traj.spline(traj.t, 1)[1:-1])
    # times in any order: each one's value, whatever the others (the pieces are looked up in time order)
    shuffled = np.random.default_rng(0).permutation(t)
    for nu in (0, 1, 2):
        np.testing.assert_array_equal(traj.spline(shuffled, nu), [traj.spline(x, nu)[0] for x in shuffled])
    with pytest.raises(ValueError, match="t .*NaN"):
        traj.spline(np.r_[0.0, np.nan])


def test_end_only_sample_is_the_full_samplings_last(lift):
    """``sample=False`` (for a caller that samples the spline itself) keeps the last sample only: bit for bit the
    full sampling's, the same timeline and waypoint times."""
    _, robot, W, traj = lift
    end = timing.retime(robot, W, sample=False, check_samples=False)
    assert end.t.shape == (1,) and end.q.shape == (1, robot.n_joints)
    for a, b in ((end.t, traj.t), (end.q, traj.q), (end.qd, traj.qd), (end.qdd, traj.qdd)):
        np.testing.assert_array_equal(a, b[-1:])
    np.testing.assert_array_equal(end.waypoint_times, traj.waypoint_times)
    t = np.linspace(0.0, traj.duration, 101)
    np.testing.assert_array_equal(end.spline(t, 1), traj.spline(t, 1))


def test_stage_keys_match_exactly_equal_stages():
    """The refinement's memory of stages probed within the limits: a stage matches only one with the same four
    numbers (a bit apart is another stage)."""
    s, x = np.array([0.0, 0.1, 0.3, 0.4]), np.array([0.0, 0.25, 0.5, 0.0])
    keys = grid_refinement.stage_keys(s, x)
    assert keys.shape == (3,)
    s2 = np.array([0.0, 0.1, 0.2, 0.3, 0.4])
    x2 = np.array([0.0, 0.25, 0.4, 0.5, np.nextafter(0.0, 1.0)])
    assert np.isin(grid_refinement.stage_keys(s2, x2), keys).tolist() == [True, False, False, False]
    assert np.isin(keys, grid_refinement.stage_keys(s, x.copy())).all()
    assert not np.isin(keys, grid_refinement.stage_keys(np.zeros(0), np.zeros(0))).any()


def test_timing_does_not_depend_on_the_placement(lift):
    """The planner times a lift once per base shape: at another placement the same waypoints get the same motion,
    and that motion keeps the ZMP inside there too (checked by stability in the world frame of that placement)."""
    name, robot, W, traj = lift
    moved = snakehead.BasePlacement(0.7, -1.3, 2.4)
    again = timing.retime(robot, W, moved)
    assert again.q.shape == traj.q.shape and np.abs(again.q - traj.q).max() < 1e-9
    assert np.abs(again.waypoint_times - traj.waypoint_times).max() < 1e-9
    dyn = stability.dynamic_stability(robot, again.t, again.q, moved, again.qd, contact="ground")
    assert dyn.stable and dyn.min_margin > 0.5 * traj.limits.zmp_margin, dyn.min_margin
    assert np.abs(dyn.zmp - stability.dynamic_stability(robot, traj.t, traj.q, None, traj.qd, contact="ground").zmp
                  @ np.array([[np.cos(2.4), np.sin(2.4)], [-np.sin(2.4), np.cos(2.4)]]) - [0.7, -1.3]).max() < 1e-6


def test_retimed_lift_tracks_in_mujoco(lift):
    pytest.importorskip("mujoco")
    from snakehead.sim import compare, simulate_trajectory

    name, robot, W, traj = lift
    result = simulate_trajectory(robot, traj.t, traj.q, hold=0.3)
    metrics = compare(robot, traj.t, traj.q, result, targets=[float(traj.waypoint_times[-1])])
    assert metrics["position_error_m"] < 2e-3, metrics
    assert metrics["direction_error_deg"] < 1.0, metrics
    assert metrics["zmp_inside"], metrics
    assert metrics["base_slide_m"] < 2e-3, metrics


def test_stability_rows_are_the_zmp_and_friction_conditions():
    """F w <= g row by row is the ZMP of Eqs. 39-40 keeping its margin inside each polygon edge (times the normal
    force), the friction polygon and the ground pushing."""
    robot = snakehead.SnakeRobot.default()
    base = snakehead.BasePlacement(0.2, -0.1, 0.5)
    q = np.array([snakehead.HeadController(robot).q_initial, np.zeros(robot.n_joints)])
    limits = timing.resolve_limits(robot, zmp_margin=0.004, friction=0.3)
    support = timing.Support.of(robot, q, base, limits.zmp_margin)
    F, g = timing.stability_rows(robot, support, limits)
    E = support.offset.shape[1]
    rng = np.random.default_rng(5)
    Mg = robot.total_mass * stability.GRAVITY
    com = stability.center_of_mass(robot, q, base)
    for _ in range(50):
        w = rng.normal(0.0, 2.0, 6)
        lhs = F @ w - g  # (2, rows)
        N = Mg + w[2]
        zmp = np.column_stack([(Mg * com[:, 0] - w[4]) / N, (Mg * com[:, 1] + w[3]) / N])
        inside_by = (support.normal * zmp[:, None, :]).sum(-1) - support.offset - support.required[:, None]
        assert np.allclose(lhs[:, :E], -N * inside_by)
        side = 2 * np.pi * np.arange(timing.FRICTION_SIDES) / timing.FRICTION_SIDES
        apothem = limits.friction * np.cos(np.pi / timing.FRICTION_SIDES) * N
        assert np.allclose(lhs[:, E:-1], np.cos(side) * w[0] + np.sin(side) * w[1] - apothem)
        assert np.allclose(lhs[:, -1], -w[2] - (1 - timing.MIN_NORMAL_SHARE) * Mg)
    # the polygons are stability.support_polygon's (contact="ground"), edge by edge
    for k in range(len(q)):
        poly = stability.support_polygon(robot, q[k], base, contact="ground")
        e = np.roll(poly, -1, axis=0) - poly
        n = np.column_stack([-e[:, 1], e[:, 0]]) / np.linalg.norm(e, axis=1)[:, None]
        pairs = np.c_[support.normal[k], support.offset[k]]
        for nk, dk in zip(n, (n * poly).sum(1)):
            assert np.min(np.abs(pairs - np.r_[nk, dk]).max(axis=1)) < 1e-9


def test_momentum_rate_coefficients_against_finite_differences():
    """w = a s'' + b s'^2 along a path q(s) timed by s(t): finite differences of the momenta of Eqs. 25-31."""
    robot = snakehead.SnakeRobot.default()
    rng = np.random.default_rng(7)
    W = np.array([robot.random_configuration(rng) * 0.6 for _ in range(5)])
    knots = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(W, axis=0), axis=1))]
    path = MonotoneQuintic(knots, W)
    t = np.linspace(0.0, 2.0, 8001)
    s = knots[-1] * (t / 2.0) ** 2 * (3 - t)  # s(0) = 0, s(2) = S
    sd = knots[-1] * (6 * t - 3 * t ** 2) / 4.0
    sdd = knots[-1] * (6 - 6 * t) / 4.0
    q, dq, ddq = path(s, 0), path(s, 1), path(s, 2)
    P, L = stability.momenta_from_velocities(robot, q, dq * sd[:, None])
    w = np.hstack([np.gradient(P, t, axis=0), np.gradient(L, t, axis=0)])
    a, b = timing.momentum_rate_coefficients(robot, q[::50], dq[::50], ddq[::50])
    model = a * sdd[::50, None] + b * sd[::50, None] ** 2
    inner = slice(1, -1)
    assert np.abs(model - w[::50])[inner].max() < 1e-3 * np.abs(w).max()


def test_holds_stops_and_waypoint_times():
    robot = snakehead.SnakeRobot.default()
    q0 = snakehead.HeadController(robot).q_initial
    head = np.arange(robot.parts.head.start, robot.n_joints)
    W = np.tile(q0, (6, 1))
    W[1, head] += 0.05
    W[2, head] += 0.1  # 2 -> 3 a hold of 0.7 s
    W[3, head] += 0.1
    W[4, head] += 0.05  # a stop at 4
    traj = timing.retime(robot, W, hold_s=[9.0, 9.0, 0.7, 9.0, 9.0], stops=[4])
    T = traj.waypoint_times
    assert np.isclose(T[3] - T[2], 0.7)
    pause = (traj.t > T[2] + 1e-6) & (traj.t < T[3] - 1e-6)
    assert pause.any() and np.allclose(traj.q[pause], W[2]) and np.allclose(traj.qd[pause], 0.0)
    at_stop = int(np.argmin(np.abs(traj.t - T[4])))
    assert np.abs(traj.qd[at_stop]).max() < 0.02 * np.abs(traj.qd).max()
    assert np.isclose(T[-1], traj.duration)
    # a waypoint that is all holds is a pause
    still = timing.retime(robot, np.tile(q0, (3, 1)), hold_s=0.5)
    assert np.isclose(still.duration, 1.0) and np.allclose(still.q, q0) and np.allclose(still.qd, 0.0)


def test_bad_input():
    robot = snakehead.SnakeRobot.default()
    q0 = snakehead.HeadController(robot).q_initial
    q1 = q0.copy()
    q1[robot.lift_joints.start] += 0.1
    W = np.array([q0, q1])
    cases = [
        (dict(waypoints=np.zeros((2, 15))), ValueError, "shape"),
        (dict(waypoints=q0[None]), ValueError, "at least two"),
        (dict(waypoints=np.array([q0, np.full(16, np.nan)])), ValueError, "NaN"),
        (dict(waypoints=np.array([q0, q0 + 3.0])), ValueError, "outside its limits"),
        (dict(velocity_limit=-1.0), ValueError, "velocity_limit"),
        (dict(acceleration_limit=np.ones(3)), ValueError, "acceleration_limit"),
        (dict(acceleration_limit=None), ValueError, "acceleration_limit"),
        (dict(torque_limit="ten"), (TypeError, ValueError), "torque_limit"),
        (dict(zmp_margin=-0.001), ValueError, "zmp_margin"),
        (dict(friction=0.0), ValueError, "friction"),
        (dict(dt=0.0), ValueError, "dt"),
        (dict(hold_s=[1.0, 2.0]), ValueError, "hold_s"),
        (dict(stops=[5]), ValueError, "stop"),
        (dict(stops=["1"]), TypeError, "stops"),
        (dict(interpolation="linear"), ValueError, "interpolation"),
        (dict(base="here"), TypeError, "base"),
        (dict(check_samples="yes"), TypeError, "check_samples"),
        (dict(sample=1), TypeError, "sample"),
        (dict(sample=False), ValueError, "check_samples=True needs sample=True"),
    ]
    for kw, error, match in cases:
        args = dict(waypoints=W)
        args.update(kw)
        with pytest.raises(error, match=match):
            timing.retime(robot, args.pop("waypoints"), **args)
    with pytest.raises(TypeError, match="robot"):
        timing.retime("snake", W)
    # paths no timing can follow, with the reason
    with pytest.raises(Infeasible, match="torque limit"):
        timing.retime(robot, W, torque_limit=0.5)
    flat = np.zeros(robot.n_joints)
    tipping = flat.copy()
    tipping[robot.lift_joints.start] = -1.2 * robot.joint_signs[robot.lift_joints.start]  # the whole front up
    with pytest.raises(Infeasible, match="outside the support polygon"):
        timing.retime(robot, np.array([flat, tipping]), torque_limit=100.0)


def test_spline_path_and_its_overshoot():
    """The not-a-knot cubic (toppra's own path) keeps the limits too where it stays inside the joint limits, and is
    refused with the reason where it overshoots one."""
    robot = snakehead.SnakeRobot.default()
    q0 = snakehead.HeadController(robot).q_initial
    head = np.arange(robot.parts.head.start, robot.n_joints)
    W = np.tile(q0, (4, 1))
    W[1, head] -= 0.05
    W[2, head] -= 0.08
    W[3, head] -= 0.12
    for interpolation in timing.INTERPOLATIONS:
        traj = timing.retime(robot, W, interpolation=interpolation)
        assert traj.check.within(LIMIT_TOLERANCE), (interpolation, traj.check)
        assert np.abs(traj.spline(traj.waypoint_times) - W).max() < 1e-9
    j = head[-1]  # the head link's joint: the CoM hardly moves
    W[:, j] = [robot.upper[j] - 0.3, robot.upper[j], robot.upper[j] - 0.05, robot.upper[j] - 0.3]
    with pytest.raises(Infeasible, match="overshoots a joint limit"):
        timing.retime(robot, W, interpolation="spline")
    assert timing.retime(robot, W).q[:, j].max() <= robot.upper[j] + 1e-12  # the monotone path never does


def test_a_path_that_turns_back_rests_at_the_turn():
    """Every joint reverses at the middle waypoint: the path stands still there (a cusp); the motion rests there."""
    robot = snakehead.SnakeRobot.default()
    q0 = snakehead.HeadController(robot).q_initial
    q1 = q0.copy()
    q1[robot.parts.head] -= 0.1
    traj = timing.retime(robot, np.array([q0, q1, q0]))
    k = int(np.argmin(np.abs(traj.t - traj.waypoint_times[1])))
    assert np.abs(traj.qd[k]).max() < 1e-9 and np.abs(traj.q[k] - q1).max() < 1e-9
    assert traj.check.within(LIMIT_TOLERANCE), traj.check


def test_required_zmp_margin_closed_form():
    """The ZMP keeps ZMP_MARGIN where the CoM leaves ZMP_DYNAMIC_ROOM more room, else the larger of half the CoM's
    margin and the CoM's margin less that room (a CoM 8.4 mm inside needs 5 mm, not 4.2: the plan's own check)."""
    m, room = timing.ZMP_MARGIN, timing.ZMP_DYNAMIC_ROOM
    static = np.array([0.02, 0.0084, 0.006, 0.004, 0.0])
    expected = [m, m, max(0.003, 0.006 - room), max(0.002, 0.004 - room), 0.0]
    np.testing.assert_allclose(timing.required_margins(static, m), expected, atol=1e-15)


def test_limit_ratios_are_the_numpy_formulas_to_the_bit():
    """``_ratios`` (the core's ``limit_ratios``) against the formulas written in numpy here: each sample's largest
    |qd| / limit, |qdd| / limit, |tau| / limit, the friction used and the ZMP's signed distance inside its polygon
    (Eqs. 39-40), equal bit for bit, with samples where the ground would have to pull (no ZMP: -inf, friction inf).
    Bad shapes are refused."""
    from snakehead import _core
    from snakehead.dynamics.inverse_dynamics import InverseDynamics
    from snakehead.model.physics import GRAVITY

    robot = snakehead.SnakeRobot.default()
    rng = np.random.default_rng(21)
    N, n, E = 400, robot.n_joints, 6
    qd, qdd, tau = (rng.normal(size=(N, n)) for _ in range(3))
    Pdot, Ldot, com = rng.normal(size=(N, 3)), rng.normal(size=(N, 3)), rng.normal(size=(N, 3)) * 0.1
    Mg = robot.total_mass * GRAVITY
    Pdot[::7, 2] = -2 * Mg  # the ground would have to pull
    angle = rng.uniform(0, 2 * np.pi, (N, E))
    normal = np.stack([np.cos(angle), np.sin(angle)], axis=-1)
    offset = rng.normal(size=(N, E)) * 0.1
    support = timing.Support(normal, offset, com, rng.uniform(0.01, 0.05, N), rng.uniform(0.005, 0.01, N),
                             np.tile([0.0, 0.0, -Mg], (N, 1)))
    limits = timing.resolve_limits(robot)
    got = limit_check.limit_ratios(robot, snakehead.BasePlacement(), limits, support, np.zeros((N, n)), qd, qdd,
                         dyn=InverseDynamics(tau, Pdot, Ldot))
    force = Mg + Pdot[:, 2]
    up = force > 0
    safe = np.where(up, force, 1.0)
    zmp = np.column_stack([(Mg * com[:, 0] - Ldot[:, 1]) / safe, (Mg * com[:, 1] + Ldot[:, 0]) / safe])
    margin = np.where(up, ((normal * zmp[:, None, :]).sum(-1) - offset).min(axis=1), -np.inf)
    want = {"velocity": (np.abs(qd) / limits.velocity).max(axis=1),
            "acceleration": (np.abs(qdd) / limits.acceleration).max(axis=1),
            "torque": (np.abs(tau) / limits.torque).max(axis=1),
            "friction": np.where(up, np.hypot(Pdot[:, 0], Pdot[:, 1]) / (limits.friction * safe), np.inf),
            "zmp_margin": margin, "zmp_slack": margin - support.required}
    assert set(got) == set(want) and not up.all()
    for key in want:
        np.testing.assert_array_equal(got[key], want[key], err_msg=key)
    args = [qd, qdd, tau, Pdot, Ldot, com, normal, offset, limits.velocity, limits.acceleration, limits.torque]
    for k, bad in [(1, qdd[:, :3]), (3, Pdot[:, :2]), (7, offset[:-1]), (8, limits.velocity[:3])]:
        with pytest.raises(ValueError, match="limit_ratios"):
            _core.limit_ratios(*(bad if i == k else a for i, a in enumerate(args)), Mg, limits.friction)
