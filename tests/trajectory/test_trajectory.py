"""Trajectories (Section 3.2): the joint-space spline, the Cartesian interpolation of Eqs. 41-44 against
closed forms and brute force, ground clearance, box and wall collisions against brute force; bad input."""
import numpy as np
import pytest
from scipy.optimize import lsq_linear
from scipy.spatial.transform import Rotation

from snakehead import BasePlacement, SnakeRobot
from snakehead._errors import Infeasible, InputTypeError
from snakehead.collision import body_collisions as coll
from snakehead.geometry import obstacles as obs
from snakehead.geometry.shapes import Shape, ShapeSet, pair_distances
from snakehead.trajectory import cartesian as cart
from snakehead.trajectory import interpolation as interp


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


def lift_motion(robot):
    """The paper's Fig. 11 / Fig. 13 situation: the neck and head lie curled on the ground beside a base
    bent in an arc (State 1), and end raised with the head bent forward and down (State 2)."""
    q_start = np.zeros(robot.n_joints)
    q_start[0:7:2] = 0.65  # base arc: yaw joints 1, 3, 5, 7
    q_end = q_start.copy()
    q_start[8:16:2] = 0.5  # neck and head curled on the ground: yaw joints 9, 11, 13, 15
    q_end[7] = -1.5  # joint 8 (pitch) raises the neck
    q_end[8] = 1.5  # joint 9 (yaw) turns the head
    q_end[[9, 11, 13, 15]] = [0.5, 0.5, 0.4, 0.3]  # head pitch joints bend it forward and down
    return q_start, q_end


# ---------------------------------------------------------------- joint-space interpolation
def test_joint_interpolation_through_waypoints_smooth_and_at_rest():
    rng = np.random.default_rng(0)
    times = np.array([0.0, 1.3, 2.0, 4.1, 5.0])
    wps = rng.uniform(-1, 1, (5, 16))
    traj = interp.joint_trajectory(times, wps, dt=0.002)
    t, q = interp.joint_interpolation(times, wps, dt=0.002)
    np.testing.assert_array_equal(t, traj.t)
    np.testing.assert_array_equal(q, traj.q)
    # 2 ms samples from the first to the last time
    assert t[0] == 0.0 and t[-1] == 5.0 and np.allclose(np.diff(t), 0.002)
    # through every waypoint (they fall on samples here)
    for tk, wk in zip(times, wps):
        k = int(round(tk / 0.002))
        np.testing.assert_allclose(q[k], wk, atol=1e-12)
    np.testing.assert_array_equal(q[0], wps[0])
    np.testing.assert_array_equal(q[-1], wps[-1])
    # velocities and accelerations: at rest at both ends, and they are the derivatives of the samples
    assert np.abs(traj.qd[[0, -1]]).max() == 0 and np.abs(traj.qdd[[0, -1]]).max() == 0
    assert np.abs(traj.spline(times[[0, -1]], 1)).max() < 1e-9 and np.abs(traj.spline(times[[0, -1]], 2)).max() < 1e-9
    np.testing.assert_allclose(np.gradient(q, t, axis=0)[1:-1], traj.qd[1:-1], atol=1e-4)
    np.testing.assert_allclose(np.gradient(traj.qd, t, axis=0)[1:-1], traj.qdd[1:-1], atol=2e-3)
    # velocity and acceleration continuous across the interior waypoints: left and right limits agree
    for tk in times[1:-1]:
        for nu in (0, 1, 2):
            left, right = traj.spline(tk - 1e-9, nu), traj.spline(tk + 1e-9, nu)
            np.testing.assert_allclose(left, right, atol=1e-5)
    # and along the samples: the acceleration changes by at most max|jerk| dt per sample (no jumps)
    jerk = np.abs(traj.spline(np.linspace(0, 5, 20001), 3)).max(axis=0)
    assert np.all(np.abs(np.diff(traj.qdd, axis=0)).max(axis=0) <= jerk * 0.002 * 1.01)


def test_two_waypoints_give_minimum_jerk_quintic():
    t, q = interp.joint_interpolation([0.0, 2.0], [np.zeros(3), np.array([1.0, -2.0, 0.5])], dt=0.01)
    s = t / 2.0
    ref = (10 * s**3 - 15 * s**4 + 6 * s**5)[:, None] * np.array([1.0, -2.0, 0.5])
    np.testing.assert_allclose(q, ref, atol=1e-12)


def test_duration_not_a_multiple_of_dt_ends_exactly():
    t, q = interp.joint_interpolation([0.0, 0.0105], [[0.0], [1.0]], dt=0.002)
    assert t[-1] == 0.0105 and q[-1, 0] == 1.0 and np.all(np.diff(t) > 0)


def test_joint_limits_overshoot_is_reported():
    wps = np.array([[0.0], [1.5], [1.5], [0.0]])
    with pytest.raises(Infeasible, match="overshoots the upper limit"):
        interp.joint_trajectory([0, 1, 1.2, 2.0], wps, lower=[-1.55], upper=[1.55])


def test_joint_interpolation_bad_input():
    wps = np.zeros((3, 16))
    with pytest.raises(ValueError, match="increase"):
        interp.joint_interpolation([0, 2, 1], wps)
    with pytest.raises(ValueError, match="increase"):
        interp.joint_interpolation([0, 1, 1], wps)
    with pytest.raises(ValueError, match="shape"):
        interp.joint_interpolation([0, 1, 2], np.zeros((4, 16)))
    with pytest.raises(ValueError, match="shape"):
        interp.joint_interpolation([[0, 1, 2]], wps)
    with pytest.raises(ValueError, match="at least two"):
        interp.joint_interpolation([0.0], wps[:1])
    with pytest.raises(ValueError, match="NaN"):
        interp.joint_interpolation([0, np.nan, 2], wps)
    bad = wps.copy()
    bad[1, 3] = np.inf
    with pytest.raises(ValueError, match="NaN or inf"):
        interp.joint_interpolation([0, 1, 2], bad)
    for dt in (0.0, -0.002, np.nan):
        with pytest.raises(ValueError, match="dt"):
            interp.joint_interpolation([0, 1, 2], wps, dt=dt)


# ---------------------------------------------------------------- Eqs. 41-44
def test_cartesian_interpolation_ends_base_and_points(robot):
    q0, q1 = lift_motion(robot)
    q0 = q0.copy()
    q0[0:7:2] = 0.5  # the base moves too
    base = BasePlacement(0.2, -0.1, 0.4)
    res = cart.cartesian_interpolation(robot, q0, q1, 50, base, full_output=True)
    q = res.q
    assert q.shape == (50, 16)
    np.testing.assert_array_equal(q[0], q0)
    np.testing.assert_array_equal(q[-1], q1)
    # base joints: linear in joint space
    s = np.linspace(0, 1, 50)
    np.testing.assert_allclose(q[:, :7], (1 - s)[:, None] * q0[:7] + s[:, None] * q1[:7], atol=1e-15)
    # Eq. 41: interpolated points are linear between the end configurations' joint positions
    F0, F1 = robot.frames(q0, base), robot.frames(q1, base)
    names = robot.link_names
    idx = [names.index(n) for n in ["link_8", "link_9", *[f"link_{i}" for i in range(10, 17)], "head_tip"]]
    np.testing.assert_allclose(res.points[0], F0[idx, :3, 3], atol=1e-15)
    np.testing.assert_allclose(res.points[-1], F1[idx, :3, 3], atol=1e-15)
    np.testing.assert_allclose(res.points[17], (1 - s[17]) * F0[idx, :3, 3] + s[17] * F1[idx, :3, 3], atol=1e-15)
    # the deviation report is the distance between recovered and interpolated joint positions
    Fk = robot.frames(q[17], base)
    assert res.deviation[17] == pytest.approx(np.linalg.norm(Fk[idx, :3, 3] - res.points[17], axis=1).max())
    assert res.deviation[0] < 1e-12 and res.deviation[-1] < 1e-12
    assert res.max_deviation == pytest.approx(res.deviation.max())
    np.testing.assert_array_equal(cart.cartesian_interpolation(robot, q0, q1, 50, base), q)


def test_cartesian_interpolation_of_a_still_robot_is_still(robot):
    q0, _ = lift_motion(robot)
    q0 = q0.copy()
    q0[[7, 9]] = -0.4, 0.3  # raised a little, so that every link has a well-defined angle
    res = cart.cartesian_interpolation(robot, q0, q0, 10, full_output=True)
    np.testing.assert_allclose(res.q, np.tile(q0, (10, 1)), atol=1e-12)
    assert res.max_deviation < 1e-12


def test_recovered_angles_reproduce_the_start_without_snapping(robot):
    # samples next to the ends converge to the ends as n grows: the recovery inverts FK at t_j = 0 and 1
    q0, q1 = lift_motion(robot)
    steps = []
    for n in (50, 200, 800):
        q = cart.cartesian_interpolation(robot, q0, q1, n)
        steps.append(max(np.abs(q[1] - q[0]).max(), np.abs(q[-1] - q[-2]).max()))
    assert steps[0] > steps[1] > steps[2] and steps[2] < 0.005


def test_eq42_literal_and_brute_force_projection(robot):
    """Eq. 42-43 as printed (yaw joints: theta = pi/2 - arccos(T_y . l_p/|l_p|)), the pitch analogue, and a
    brute-force maximisation of the projected alignment, against joint_angle_towards."""
    rng = np.random.default_rng(4)
    R0 = Rotation.random(200, random_state=rng).as_matrix()
    l = rng.normal(size=(200, 3))
    l /= np.linalg.norm(l, axis=1, keepdims=True)
    x = np.array([1.0, 0.0, 0.0])
    for axis in (np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0])):
        theta, ok = cart.joint_angle_towards(R0, axis, x, l)
        assert ok.all()
        Tx, Ty, Tz = R0[:, :, 0], R0[:, :, 1], R0[:, :, 2]
        a = R0 @ axis
        lp = l - np.sum(l * a, 1, keepdims=True) * a  # Eq. 43
        lp /= np.linalg.norm(lp, axis=1, keepdims=True)
        front = np.sum(Tx * lp, 1) > 0  # Eq. 42 covers |theta| <= 90 deg
        other = Ty if axis[2] == 1 else -Tz  # the D-H y-axis of the joint: z_DH x x
        literal = np.pi / 2 - np.arccos(np.clip(np.sum(other * lp, 1), -1, 1))
        np.testing.assert_allclose(theta[front], literal[front], atol=1e-9)
        # brute force: the rotation about the axis that brings the link closest to l
        grid = np.linspace(-np.pi, np.pi, 20001)
        for k in range(0, 200, 20):
            rots = Rotation.from_rotvec(grid[:, None] * axis).as_matrix()  # (G, 3, 3) in the joint frame
            dirs = R0[k] @ (rots @ x).T  # (3, G)
            best = grid[np.argmax(l[k] @ dirs)]
            assert abs(np.angle(np.exp(1j * (best - theta[k])))) < 1e-3


def test_recovered_links_point_along_the_segments(robot):
    """Each recovered (unclipped) link lies in the plane spanned by its joint axis and its segment."""
    q0, q1 = lift_motion(robot)
    q1 = q1.copy()
    q1[[9, 11, 13, 15]] = 0.2
    res = cart.cartesian_interpolation(robot, q0, q1, 40, full_output=True)
    F = robot.frames_many(res.q)
    model = robot.body.model
    names = robot.link_names
    idx = [names.index(n) for n in ["link_8", "link_9", *[f"link_{i}" for i in range(10, 17)], "head_tip"]]
    for i, j in enumerate(range(7, 16)):
        frame = F[:, model.joint_child_links[j]]
        a = frame[:, :3, :3] @ model.joint_axes[j]
        link = F[:, idx[i + 1], :3, 3] - F[:, idx[i], :3, 3]
        seg = res.points[:, i + 1] - res.points[:, i]
        normal = np.cross(a, seg)
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        off_plane = np.abs(np.sum(normal * link, 1)) / np.linalg.norm(link, axis=1)
        ok = ~res.clipped[:, i]
        assert off_plane[ok].max() < 1e-9
        assert np.all(np.sum(link * seg, 1)[ok] > 0)  # pointing forward along the segment


def test_rigid_rotation_directions_exact_positions_shrink(robot):
    """Raising a straight neck and head rigidly by joint 8: every segment keeps the links' direction, so the
    recovered angles are the linear ones and the direction error is 0; the positions stray by the chord's
    shortening, |tip - interpolated tip| = L (1 - cos(a s)) ... in closed form below."""
    q0 = np.zeros(16)
    q1 = q0.copy()
    q1[7] = -1.0
    res = cart.cartesian_interpolation(robot, q0, q1, 21, full_output=True)
    s = res.s
    # the straight line from joint 8 rotates rigidly about it; interpolated points lie on the chords
    np.testing.assert_allclose(res.q[:, 7], -np.arctan2(np.sin(1.0) * s, 1 - s + s * np.cos(1.0)), atol=1e-12)
    np.testing.assert_allclose(res.q[:, 8:], 0.0, atol=1e-12)
    assert res.direction_error.max() < 1e-9
    L = 1.384 - 0.646  # joint 8 to the head tip
    chord = np.hypot(1 - s + s * np.cos(1.0), s * np.sin(1.0))  # interpolated tip distance / L
    np.testing.assert_allclose(res.deviation, L * (1 - chord), atol=1e-12)


def test_aim_at_points_tracks_the_interpolated_points(robot):
    q0, q1 = lift_motion(robot)
    seg = cart.cartesian_interpolation(robot, q0, q1, 60, full_output=True)
    pts = cart.cartesian_interpolation(robot, q0, q1, 60, aim="points", full_output=True)
    np.testing.assert_array_equal(pts.q[[0, -1]], np.stack([q0, q1]))
    assert pts.max_deviation < seg.max_deviation  # aiming at the points keeps closer to them
    # each unclipped link lies in the plane of its joint axis and the line from its actual joint to the next point
    F = robot.frames_many(pts.q)
    model = robot.body.model
    for i, j in enumerate(range(7, 16)):
        a = F[:, model.joint_child_links[j], :3, :3] @ model.joint_axes[j]
        want = pts.points[:, i + 1] - pts.actual[:, i]
        link = pts.actual[:, i + 1] - pts.actual[:, i]
        normal = np.cross(a, want)
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        ok = ~pts.clipped[:, i]
        assert (np.abs(np.sum(normal * link, 1)) / np.linalg.norm(link, axis=1))[ok].max() < 1e-9


def test_cartesian_interpolation_clears_the_ground_where_joint_space_does_not(robot):
    """Fig. 11 vs Fig. 13: the head hits the ground under joint interpolation, not under Eqs. 41-44."""
    q0, q1 = lift_motion(robot)
    n = 200
    links = robot.lifted_links
    # the ends themselves: lying on the ground (touching, clearance 0) and raised clear of it
    c_end = coll.ground_clearance(robot, np.stack([q0, q1]))[:, links]
    assert abs(c_end[0].min()) < 1e-12 and c_end[1].min() > 0.01
    q_joint = q0 + (q1 - q0) * np.linspace(0, 1, n)[:, None]
    joint_clear = coll.ground_clearance(robot, q_joint)[:, links].min(axis=1)
    assert joint_clear.min() < -0.04  # 4 cm into the ground
    assert coll.below_ground(robot, q_joint).any()
    # at the start the neck and head lie on the ground: touching, not below it
    assert coll.touching_ground(robot, q0)[0, links].all() and not coll.below_ground(robot, q0).any()
    assert not coll.touching_ground(robot, q1).any()
    q_cart = cart.cartesian_interpolation(robot, q0, q1, n)
    cart_clear = coll.ground_clearance(robot, q_cart)[:, links].min(axis=1)
    assert cart_clear.min() > -coll.GROUND_TOLERANCE
    assert not coll.below_ground(robot, q_cart).any()
    # the base stays on the ground throughout
    base_links = [robot.link_names.index(f"link_{i}") for i in range(8)]
    np.testing.assert_allclose(coll.ground_clearance(robot, q_cart)[:, base_links], 0.0, atol=1e-12)


def test_cartesian_interpolation_bad_input(robot):
    q = np.zeros(16)
    with pytest.raises(ValueError, match="n must be"):
        cart.cartesian_interpolation(robot, q, q, 1)
    with pytest.raises(ValueError, match="n must be"):
        cart.cartesian_interpolation(robot, q, q, 2.5)
    with pytest.raises(ValueError, match="shape"):
        cart.cartesian_interpolation(robot, q[:15], q, 5)
    with pytest.raises(ValueError, match="NaN"):
        cart.cartesian_interpolation(robot, q, np.full(16, np.nan), 5)
    with pytest.raises(ValueError, match="aim"):
        cart.cartesian_interpolation(robot, q, q, 5, aim="sideways")


# ---------------------------------------------------------------- ground clearance
def test_ground_clearance_closed_form(robot):
    q = np.zeros(16)
    c = coll.ground_clearance(robot, q)
    shaped = np.isin(np.arange(len(robot.link_names)), robot.shaped_links)
    np.testing.assert_allclose(c[0, shaped], 0.0, atol=1e-15)
    assert np.all(np.isinf(c[0, ~shaped]))
    # raise the neck by theta with joint 8 (pitch): link_8's lowest corner is its distal bottom edge... no:
    # rotating up about the joint, the proximal bottom corner goes to z = 0.0215 - 0.0215 cos(theta) and the
    # distal bottom corner higher, so the lowest point of link_8 is h/2 (1 - cos theta) above the ground
    th = 0.6
    q[7] = -th
    c = coll.ground_clearance(robot, q)[0]
    k = robot.link_names.index("link_8")
    assert c[k] == pytest.approx(0.0215 * (1 - np.cos(th)), abs=1e-12)
    # and the head, bent down by 2 theta at joint 10 after the 2-link neck, dips this far
    q[9] = 2 * th
    c = coll.ground_clearance(robot, q)[0]
    k10 = robot.link_names.index("link_10")
    z_joint = 0.0215 + 2 * 0.0865 * np.sin(th)  # height of joint 10 (link_8, link_9 both at angle theta)
    # link_10 points down at angle theta; its lowest corner is the distal bottom one
    ref = z_joint - 0.0865 * np.sin(th) - 0.0215 * np.cos(th)
    assert c[k10] == pytest.approx(ref, abs=1e-12)
    # a batch gives the same rows
    np.testing.assert_allclose(coll.ground_clearance(robot, np.stack([q, q]))[1], c, atol=0)


def test_ground_clearance_bad_input(robot):
    with pytest.raises(ValueError, match="shape"):
        coll.ground_clearance(robot, np.zeros((3, 15)))
    with pytest.raises(ValueError, match="NaN"):
        coll.ground_clearance(robot, np.full((3, 16), np.nan))
    with pytest.raises(InputTypeError, match="base must be a BasePlacement or None, got str"):
        coll.ground_clearance(robot, np.zeros(16), base="origin")


# ---------------------------------------------------------------- obstacles
def random_boxes(rng, n):
    c = rng.normal(scale=0.25, size=(n, 3))
    R = Rotation.random(n, random_state=rng).as_matrix()
    h = rng.uniform(0.02, 0.2, (n, 3))
    return c, R, h


def brute_box_distance(ca, Ra, ha, cb, Rb, hb):
    """min |(ca + Ra u) - (cb + Rb v)| over |u| <= ha, |v| <= hb: bounded linear least squares (BVLS)."""
    A = np.hstack([Ra, -Rb])
    r = lsq_linear(A, cb - ca, bounds=(-np.r_[ha, hb], np.r_[ha, hb]), method="bvls", tol=1e-14)
    return np.linalg.norm(A @ r.x - (cb - ca))


def box_shapes(c, R, h):
    """Boxes (centres (n, 3), rotations (n, 3, 3), half extents (n, 3)) as a shape set: one box per frame, and the
    frames (1, n, 4, 4) that place them."""
    n = len(c)
    frames = np.tile(np.eye(4), (1, n, 1, 1))
    frames[0, :, :3, :3], frames[0, :, :3, 3] = R, c
    return frames, ShapeSet(tuple(Shape("box", k, np.eye(4), 2 * h[k]) for k in range(n)), n)


def test_box_box_distance_against_optimisation():
    """The geometry layer's signed distance of boxes (FCL's GJK apart, the separating-axis depth overlapping)
    against bounded least squares (apart) and a shared point (overlapping)."""
    rng = np.random.default_rng(0)
    Fa, A = box_shapes(*random_boxes(rng, 200))
    Fb, B = box_shapes(*random_boxes(rng, 200))
    pairs = np.stack([np.arange(200), np.arange(200)], axis=1)
    d = pair_distances(Fa, A, Fb, B, pairs)[0]
    n_apart = 0
    for k in range(200):
        ca, Ra, ha = Fa[0, k, :3, 3], Fa[0, k, :3, :3], A.shapes[k].size / 2
        cb, Rb, hb = Fb[0, k, :3, 3], Fb[0, k, :3, :3], B.shapes[k].size / 2
        ref = brute_box_distance(ca, Ra, ha, cb, Rb, hb)
        if d[k] > 0:
            n_apart += 1
            assert d[k] == pytest.approx(ref, abs=1e-7)
        else:
            assert ref < 1e-9  # they do intersect
    assert n_apart > 30 and 200 - n_apart > 5  # both cases were exercised


def test_box_box_penetration_depth_closed_form():
    # two axis-aligned unit cubes overlapping by 0.1 along x: depth 0.1
    I = np.eye(3)
    h = np.full((2, 3), 0.5)
    for other, expected in (([0.9, 0.2, 0], -0.1), ([1.3, 0.0, 0], 0.3), ([1.5, 1.5, 1.5], np.sqrt(3) * 0.5)):
        F, S = box_shapes(np.array([[0.0, 0, 0], other]), np.stack([I, I]), h)
        assert pair_distances(F, S, F, S, np.array([[0, 1]]))[0, 0] == pytest.approx(expected, abs=1e-9)


def wall_solid_contains(wall, p):
    loc = (p - wall.centre) @ wall.rotation
    rel = loc[..., :2] - wall.hole_offset
    in_slab = np.all(np.abs(rel) <= wall.size[:2] / 2, -1) & (np.abs(loc[..., 2]) <= wall.size[2] / 2)
    return in_slab & (np.linalg.norm(loc[..., :2], axis=-1) > wall.hole_diameter / 2)


def test_box_wall_collision_against_dense_sampling():
    """Boxes against a wall's convex pieces (its hole an inscribed polygon) against points sampled in the boxes:
    a sampled point in the solid means a collision; a collision without one is a sliver (the polygon's safe side)."""
    rng = np.random.default_rng(1)
    wall = obs.WallWithHole([0.2, 0.5, 0.4], [0, 1, 0], (0.7, 0.58, 0.01), 0.07)
    n = 200
    # link-sized boxes near the hole, randomly placed and turned
    c = wall.centre + rng.normal(scale=[0.04, 0.05, 0.04], size=(n, 3))
    R = Rotation.random(n, random_state=rng).as_matrix()
    R[: n // 2] = Rotation.from_euler("z", rng.normal(90, 8, (n // 2, 1)), degrees=True).as_matrix()  # along the axis
    h = np.array([0.0865, 0.043, 0.043]) / 2

    def collides(c, R):
        F, S = box_shapes(np.atleast_2d(c), np.reshape(R, (-1, 3, 3)), np.tile(h, (len(np.atleast_2d(c)), 1)))
        W, owner = coll.obstacle_shapes([wall])
        pairs = np.stack(np.meshgrid(np.arange(S.n_frames), np.arange(len(owner)), indexing="ij"), -1).reshape(-1, 2)
        d = pair_distances(F, S, np.eye(4)[None, None], W, pairs)[0].reshape(S.n_frames, -1)
        return d.min(axis=1) <= 0

    got = collides(c, R)
    g = np.linspace(-1, 1, 31)
    grid = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    n_hit = 0
    for k in range(n):
        pts = c[k] + (grid * h) @ R[k].T
        ref = wall_solid_contains(wall, pts).any()
        if ref:
            assert got[k]  # a sampled point inside the solid: it collides
        n_hit += got[k]
        if got[k] and not ref:  # the sampling may miss a sliver, or the polygon's corner: then the overlap is tiny
            r = wall.hole_diameter / 2
            assert wall.distance_to_points(pts).min() < 0.003 + r * (1 - np.cos(np.pi / obs.WALL_HOLE_SIDES))
    assert 20 < n_hit < n - 20
    # boxes passing straight through the middle of the hole do not collide; one beside it does
    Rx = np.column_stack([[0, 1, 0], [-1, 0, 0], [0, 0, 1]])
    assert not collides(wall.centre, Rx)[0]
    assert collides(wall.centre + [0.03, 0, 0], Rx)[0]
    assert not collides(wall.centre + [0.0, 0.2, 0], Rx)[0]  # in front of the wall


def test_wall_point_distance_closed_form():
    wall = obs.WallWithHole([0, 0, 0.4], [1, 0, 0], (0.6, 0.5, 0.02), 0.1)
    # wall axes: width along world -y or +y, height along z, normal along x
    assert wall.distance_to_points([0.0, 0.0, 0.4]) == pytest.approx(0.05)  # hole centre: to the rim
    assert wall.distance_to_points([0.11, 0.0, 0.4]) == pytest.approx(np.hypot(0.05, 0.1))  # in front of it
    assert wall.distance_to_points([0.11, 0.0, 0.6]) == pytest.approx(0.1)  # in front of the solid part
    assert wall.distance_to_points([0.0, 0.0, 0.6]) == 0.0  # inside the solid
    assert wall.distance_to_points([0.0, 0.0, 0.4 + 0.25 + 0.03]) == pytest.approx(0.03)  # above the wall


def test_collision_check_on_the_robot(robot):
    q0, q1 = lift_motion(robot)
    qs = cart.cartesian_interpolation(robot, q0, q1, 30)
    F = robot.frames(q1)
    tip = F[robot.link_names.index("head_tip"), :3, 3]
    box = obs.BoxObstacle(tip + [0.0, 0.0, 0.1], [0.1, 0.1, 0.05])  # 10 cm over the final head tip
    ground_box = obs.BoxObstacle([0, 0, -0.05], [5, 5, 0.1])  # the ground as a box: the base touches it
    rep = coll.collision_check(robot, qs, [box, ground_box], exact_within=np.inf)
    assert rep.link_distance.shape == (30, 17, 2)
    assert rep.collides.all()  # the base lies on the ground box
    assert not rep.link_collides[..., 0].any()
    d_box = rep.link_distance[..., 0].min(1)
    # the final pose's distance against coal's (another GJK than the core's FCL) over every link box: measured
    # 0.0470755 m, 5e-12 from coal's (it was checked as 0.075 +- 0.05: the box's bottom 7.5 cm above the tip, but the
    # nearest link corner is not under it)
    coal = pytest.importorskip("coal")
    final = robot.frames_many(qs[-1:])[0]
    to_coal = lambda M: coal.Transform3s(M[:3, :3].copy(), M[:3, 3].copy())  # noqa: E731
    request = coal.DistanceRequest()
    request.gjk_tolerance = 1e-10
    expected = min(coal.distance(coal.Box(*s.size), to_coal(final[s.frame] @ s.origin), coal.Box(0.1, 0.1, 0.05),
                                 coal.Transform3s(np.eye(3), tip + [0.0, 0.0, 0.1]), request, coal.DistanceResult())
                   for s in robot.geometry.shapes if s.kind == "box")
    assert d_box[-1] == pytest.approx(expected, abs=1e-9) and d_box.min() > 0
    # consistent with ground_clearance for the ground box (distance = clearance for boxes above it)
    clear = coll.ground_clearance(robot, qs)[:, rep.links]
    np.testing.assert_allclose(np.maximum(rep.link_distance[..., 1], 0), np.maximum(clear, 0), atol=1e-12)
    # a wall: the distance to its convex pieces against points sampled on the links' shapes (an upper bound)
    wall = obs.WallWithHole([0.6, 0.4, 0.2], [1, 0, 0], (0.4, 0.3, 0.01), 0.07)  # beyond the body (x < 0.23)
    rep2 = coll.collision_check(robot, qs, wall, exact_within=1.0)
    assert not rep2.collides.any()
    sampled = wall.distance_to_points(robot.hull_points(robot.frames_many(qs)).reshape(len(qs), -1, 3)).min(axis=1)
    slab = coll.collision_check(robot, qs, wall.slab(), exact_within=np.inf).distance  # the wall without its hole
    assert np.all(rep2.distance <= sampled + 1e-9) and np.all(rep2.distance >= slab - 1e-9)
    # with the default band, distances beyond it are lower bounds above it; inside it they are exact
    rep3 = coll.collision_check(robot, qs, [box, ground_box], exact_within=0.05)
    exact3 = rep.link_distance
    band = exact3 <= 0.05
    np.testing.assert_array_equal(rep3.link_distance[band], exact3[band])
    assert np.all(rep3.link_distance[~band] > 0.05) and np.all(rep3.link_distance[~band] <= exact3[~band] + 1e-12)


def test_obstacle_bad_input(robot):
    with pytest.raises(ValueError, match="size"):
        obs.BoxObstacle([0, 0, 0], [1, -1, 1])
    with pytest.raises(ValueError, match="rotation"):
        obs.BoxObstacle([0, 0, 0], [1, 1, 1], np.ones((3, 3)))
    with pytest.raises(ValueError, match="NaN"):
        obs.BoxObstacle([0, np.nan, 0], [1, 1, 1])
    with pytest.raises(ValueError, match="zero length"):
        obs.WallWithHole([0, 0, 0], [0, 0, 0], (1, 1, 0.01), 0.1)
    with pytest.raises(ValueError, match="inside the wall"):
        obs.WallWithHole([0, 0, 0], [1, 0, 0], (0.1, 0.1, 0.01), 0.2)
    with pytest.raises(ValueError, match="hole_diameter"):
        obs.WallWithHole([0, 0, 0], [1, 0, 0], (1, 1, 0.01), -0.1)
    with pytest.raises(ValueError, match="no obstacles"):
        coll.collision_check(robot, np.zeros((2, 16)), [])
    with pytest.raises(InputTypeError, match="obstacles must be BoxObstacle, WallWithHole, MeshObstacle, got str"):
        coll.collision_check(robot, np.zeros((2, 16)), ["a wall"])
    with pytest.raises(ValueError, match="shape"):
        coll.collision_check(robot, np.zeros((2, 17)), obs.BoxObstacle([0, 0, 1], [1, 1, 1]))


def test_cartesian_trajectory_is_timed_min_jerk(robot):
    q0, q1 = lift_motion(robot)
    traj = cart.cartesian_trajectory(robot, q0, q1, duration=2.0, dt=0.002)
    assert traj.t[0] == 0 and traj.t[-1] == 2.0 and len(traj.t) == 1001
    s = interp.minimum_jerk(traj.t / 2.0)
    np.testing.assert_allclose(traj.q, cart.cartesian_interpolation(robot, q0, q1, s), atol=1e-12)
    np.testing.assert_array_equal(traj.q[[0, -1]], np.stack([q0, q1]))
    assert np.abs(traj.qd[[0, 1, -2, -1]]).max() < 1e-3  # at rest at both ends
    # explicit parameters must run from 0 to 1
    with pytest.raises(ValueError, match="from exactly 0"):
        cart.cartesian_interpolation(robot, q0, q1, np.array([0.0, 0.5, 0.9]))
    with pytest.raises(ValueError, match="non-decreasing"):
        cart.cartesian_interpolation(robot, q0, q1, np.array([0.0, 0.6, 0.5, 1.0]))
    with pytest.raises(ValueError, match="duration"):
        cart.cartesian_trajectory(robot, q0, q1, duration=0.0)


def stable_lift_motion(robot):
    """A lift of the head that stays dynamically stable (default robot): the base curled in a tight arc, the neck
    and head curled on the ground inside it, lifted to stand over the arc (found by maximising the static margin
    of the raised configuration)."""
    q_start = np.zeros(robot.n_joints)
    q_start[0:7:2] = 0.9
    q_end = q_start.copy()
    q_start[8:16:2] = 0.9
    q_end[7:] = [-1.57, 0.266, -0.285, 0.451, -0.173, -0.021, 0.322, 0.051, 0.027]
    return q_start, q_end


def test_figures_are_written(robot, tmp_path):
    """Figs. 11/13 for the lift of lift_motion; Figs. 18-20 for the stable lift timed over 2 s."""
    from snakehead.dynamics import stability
    from snakehead.viz import body, save
    from snakehead.viz import dynamics_figures as dynamics

    fig = body.plot_interpolation_comparison(robot, *lift_motion(robot))
    # the clearance panel: joint space goes into the ground (Fig. 11), Eqs. 41-44 do not (Fig. 13)
    joint_space, cartesian = fig.axes[2].get_lines()[:2]
    assert joint_space.get_ydata().min() < -5 and cartesian.get_ydata().min() > -coll.GROUND_TOLERANCE * 1000
    traj = cart.cartesian_trajectory(robot, *stable_lift_motion(robot), 2.0)
    P, L = stability.momenta(robot, traj.t, traj.q)
    figs = {"fig11_13_interpolation": fig, "fig18_19_momenta": dynamics.plot_momenta(traj.t, P, L),
            "fig20_zmp": dynamics.plot_zmp(robot, traj.t, traj.q, contact="endpoints")}
    for name, f in figs.items():
        p = save(f, tmp_path / f"{name}.png")
        assert p.stat().st_size > 20_000
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ------------------------------------------------------------------------------------------------
# the monotone multi-segment quintic
# ------------------------------------------------------------------------------------------------
def test_monotone_quintic_passes_waypoints_without_overshoot():
    from snakehead.trajectory.interpolation import MonotoneQuintic

    rng = np.random.default_rng(11)
    times = np.cumsum(rng.uniform(0.2, 2.0, 12))
    way = rng.uniform(-1.5, 1.5, (12, 4))
    way[3:6, 1] = 1.5707963  # a run of waypoints on a limit: the C4 spline overshoots there
    f = MonotoneQuintic(times, way)
    np.testing.assert_allclose(f(times), way, atol=1e-12)
    t = np.linspace(times[0], times[-1], 20001)
    q = f(t)
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    lo = np.minimum(way[k], way[k + 1])
    hi = np.maximum(way[k], way[k + 1])
    assert np.all(q >= lo - 1e-12) and np.all(q <= hi + 1e-12)
    assert q[:, 1].max() <= 1.5707963 + 1e-12


def test_monotone_quintic_derivatives_are_continuous_and_match_differences():
    from snakehead.trajectory.interpolation import MonotoneQuintic

    rng = np.random.default_rng(12)
    times = np.cumsum(rng.uniform(0.5, 1.5, 8))
    way = rng.normal(size=(8, 3))
    f = MonotoneQuintic(times, way)
    h = 1e-6
    for nu in (1, 2):
        # across every interior knot, the left and right limits agree (C2)
        np.testing.assert_allclose(f(times[1:-1] - 1e-9, nu), f(times[1:-1] + 1e-9, nu), atol=1e-5)
    t = np.linspace(times[0] + 0.01, times[-1] - 0.01, 50)
    np.testing.assert_allclose(f(t, 1), (f(t + h) - f(t - h)) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(f(t, 2), (f(t + h, 1) - f(t - h, 1)) / (2 * h), atol=1e-5)
    np.testing.assert_allclose(f(times[[0, -1]], 1), 0.0, atol=1e-12)  # at rest at both ends
    np.testing.assert_allclose(f(times[[0, -1]], 2), 0.0, atol=1e-12)


def test_monotone_quintic_piecewise_polynomial_equals_the_hermite_basis():
    """The per-segment coefficients (scipy's PPoly) give the quintic Hermite basis's values and derivatives (written out
    here, as the class documents them), and ``derivatives`` gives what three calls give."""
    from snakehead.trajectory.interpolation import MonotoneQuintic

    rng = np.random.default_rng(13)
    times = np.cumsum(rng.uniform(0.05, 2.0, 15))
    way = rng.normal(size=(15, 5))
    f = MonotoneQuintic(times, way)
    t = np.r_[rng.uniform(times[0] - 0.5, times[-1] + 0.5, 3000), times]
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    h = (times[k + 1] - times[k])[:, None]
    s = (t - times[k])[:, None] / h
    p0, p1, v0, v1 = way[k], way[k + 1], f.v[k], f.v[k + 1]
    basis = [(1 - 10 * s**3 + 15 * s**4 - 6 * s**5) * p0 + h * (s - 6 * s**3 + 8 * s**4 - 3 * s**5) * v0
             + (10 * s**3 - 15 * s**4 + 6 * s**5) * p1 + h * (-4 * s**3 + 7 * s**4 - 3 * s**5) * v1,
             (-30 * s**2 + 60 * s**3 - 30 * s**4) * (p0 - p1) / h + (1 - 18 * s**2 + 32 * s**3 - 15 * s**4) * v0
             + (-12 * s**2 + 28 * s**3 - 15 * s**4) * v1,
             (-60 * s + 180 * s**2 - 120 * s**3) * (p0 - p1) / h**2 + (-36 * s + 96 * s**2 - 60 * s**3) * v0 / h
             + (-24 * s + 84 * s**2 - 60 * s**3) * v1 / h]
    together = f.derivatives(t)
    for nu in (0, 1, 2):
        scale = np.abs(basis[nu]).max()
        np.testing.assert_allclose(f(t, nu), basis[nu], atol=1e-12 * scale, rtol=0)
        np.testing.assert_array_equal(together[nu], f(t, nu))
    np.testing.assert_array_equal(f.derivatives(t, (2, 0))[0], together[2])
    with pytest.raises(ValueError, match="orders must be 0, 1 or 2"):
        f.derivatives(t, (3,))


def test_monotone_quintic_values_are_scipys_ppoly_to_the_bit():
    """The core's evaluation (``_core.evaluate_piecewise_polynomial``) gives what scipy's PPoly gives from the same
    coefficients, bit for bit: inside, on every knot, and extrapolated on both sides; for random piecewise polynomials
    of every degree too. Bad input is refused by name."""
    from scipy.interpolate import PPoly

    from snakehead import _core
    from snakehead.trajectory.interpolation import MonotoneQuintic

    rng = np.random.default_rng(14)
    times = np.cumsum(rng.uniform(0.01, 2.0, 30))
    way = rng.normal(size=(30, 16))
    f = MonotoneQuintic(times, way)
    t = np.r_[rng.uniform(times[0] - 1.0, times[-1] + 1.0, 40000), times, np.nextafter(times, np.inf)]
    for nu, got in zip((0, 1, 2), f.derivatives(t)):
        np.testing.assert_array_equal(got, f.pieces[nu](t))
    for k in range(1, 8):
        x = np.cumsum(rng.uniform(1e-3, 1.0, 12))
        c = rng.normal(size=(k, 11, 3)) * 10.0 ** rng.uniform(-4, 4, (k, 1, 1))
        points = rng.uniform(x[0] - 2, x[-1] + 2, 500)
        np.testing.assert_array_equal(_core.evaluate_piecewise_polynomial(c, x, points), PPoly(c, x)(points))
    c, x = rng.normal(size=(6, 4, 2)), np.arange(5.0)
    for args, match in [((c[0], x, t), "shape"), ((c, x[:-1], t), "breaks"), ((c, x[::-1], t), "increase"),
                        ((c, x, np.array([0.5, np.nan])), "finite"), ((c, x, t[None]), "points")]:
        with pytest.raises(ValueError, match=match):
            _core.evaluate_piecewise_polynomial(*args)
    with pytest.raises(ValueError, match="finite"):
        f(np.array([1.0, np.inf]))


def test_joint_trajectory_monotone_method_and_bad_method():
    times = np.array([0.0, 1.0, 2.0])
    way = np.array([[0.0], [1.0], [1.0]])
    traj = interp.joint_trajectory(times, way, method="monotone")
    assert traj.q.max() <= 1.0 + 1e-12
    with pytest.raises(ValueError, match="method"):
        interp.joint_trajectory(times, way, method="cubic")


def test_sample_times_never_adds_a_sample_a_hair_after_the_last():
    for t1 in (1.0, 1.0 + 1e-9, 1.0 + 5e-7, 1.0 + 2e-6, 36.000000013):
        t = interp.sample_times(0.0, t1)
        assert t[0] == 0.0 and t[-1] == t1
        d = np.diff(t)
        assert d.min() > 1e-6 and d.max() <= 0.002 + 1e-6
