"""snakehead._core's convex-shape kernel (ShapeSet, shape_*) against independent implementations, on random poses of
every pair of kinds: coal's signed distances apart, and in penetration a depth computed from the shapes' support
functions alone (tests/minkowski_reference.py); plus its bad input and pickling."""

import pickle

import coal
import numpy as np
import pytest
from minkowski_reference import Shape, signed_distance

from snakehead import _core
from snakehead._errors import InputError

KINDS = ["box", "cylinder", "sphere", "convex"]
BLOB = np.random.default_rng(0).uniform(-0.04, 0.04, size=(12, 3))


def random_poses(rng, n, spread):
    """n random rigid 4x4 poses (uniform rotations, translations in a cube of half side `spread`)."""
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    poses = np.tile(np.eye(4), (n, 1, 1))
    poses[:, :3, :3] = np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], 1)
    poses[:, :3, 3] = rng.uniform(-spread, spread, size=(n, 3))
    return poses


def one_of_each(rng):
    """A ShapeSet of one shape of every kind, shape i on frame i, each with a random origin."""
    origins = random_poses(rng, 4, 0.03)
    sizes = np.array([[0.08, 0.05, 0.04], [0.025, 0.09, 0.0], [0.03, 0.0, 0.0], [0.0, 0.0, 0.0]])
    return _core.ShapeSet(KINDS, np.arange(4), origins, sizes, [None, None, None, BLOB]), origins, sizes


def coal_geometry(kind, size):
    if kind == "box":
        return coal.Box(*size)
    if kind == "cylinder":
        return coal.Cylinder(size[0], size[1])
    if kind == "sphere":
        return coal.Sphere(size[0])
    points = coal.StdVec_Vec3s()
    for p in BLOB:
        points.append(p)
    return coal.Convex.convexHull(points, False, None)


def coal_distance(geom_a, pose_a, geom_b, pose_b):
    to_coal = lambda p: coal.Transform3s(p[:3, :3].copy(), p[:3, 3].copy())  # noqa: E731
    request = coal.DistanceRequest()
    request.gjk_tolerance = request.epa_tolerance = 1e-10  # its default 1e-6 leaves errors of ~1e-6 m
    return coal.distance(geom_a, to_coal(pose_a), geom_b, to_coal(pose_b), request, coal.DistanceResult())


# Where coal 3.0.3's EPA is wrong in penetration, by the independent computation (tests/minkowski_reference.py,
# certified to 1e-7 m) and by coal itself: moving the second shape by the independent depth (+1 um) along its
# direction leaves the two 1 um apart by coal's own GJK. (sample, kind a, kind b): coal's depth, the true depth.
COAL_EPA_WRONG = {
    (44, "convex", "cylinder"): (0.04114, 0.01190),  # the "open disagreement" of before: coal 2.9 cm too deep
    (53, "cylinder", "cylinder"): (0.04878, 0.03977),
}


def independent_distance(kind_a, size_a, pose_a, kind_b, size_b, pose_b):
    """The signed distance by the branch and bound over directions of tests/minkowski_reference.py."""
    shape = lambda kind, size, pose: Shape(kind, size, pose, BLOB if kind == "convex" else None)  # noqa: E731
    found = signed_distance(shape(kind_a, size_a, pose_a), shape(kind_b, size_b, pose_b), tolerance=1e-7)
    assert found.upper - found.lower <= 1.001e-7  # refined to the end (not stopped by its budget of cells)
    return found


@pytest.mark.parametrize("regime", ["apart", "penetrating"])
def test_pair_distances_match_references_for_every_pair_of_kinds(regime):
    """Every pair of kinds on 60 random poses. Apart, against coal (its GJK; checked against brute force). In
    penetration, against an independent computation of the depth (the Minkowski difference's support function
    minimised over directions, certified to 1e-7 m; tests/minkowski_reference.py), which coal's depths confirm
    wherever no cylinder is involved (on cylinders coal's EPA is wrong on the cases of COAL_EPA_WRONG and gives up
    on a few more). Every pair is compared; the mismatches are listed together."""
    rng = np.random.default_rng(1)
    shapes, origins, sizes = one_of_each(rng)
    T = 60
    frames_a = random_poses(rng, T * 4, 0.08).reshape(T, 4, 4, 4)
    frames_b = random_poses(rng, T * 4, 0.08).reshape(T, 4, 4, 4)
    pairs = np.array([[i, j] for i in range(4) for j in range(4)])
    ours = _core.shape_pair_distances(frames_a, shapes, frames_b, shapes, pairs)
    geoms = [coal_geometry(k, s) for k, s in zip(KINDS, sizes)]
    compared, mismatches = 0, []
    for t in range(T):
        for p, (i, j) in enumerate(pairs):
            pose_a, pose_b = frames_a[t, i] @ origins[i], frames_b[t, j] @ origins[j]
            case = (t, KINDS[i], KINDS[j])
            theirs = coal_distance(geoms[i], pose_a, geoms[j], pose_b)
            coal_failed = abs(theirs) > 1.0  # coal's EPA gave up (it reports -DBL_MAX)
            if (regime == "apart") != (not coal_failed and theirs > 1e-4):
                continue
            curved = "cylinder" in case
            if regime == "apart":
                # libccd's GJK stops up to ~2e-6 m long on a cylinder (checked against brute force: coal is right)
                reference, tolerance = theirs, 5e-6 if curved else 1e-6
            else:
                independent = independent_distance(KINDS[i], sizes[i], pose_a, KINDS[j], sizes[j], pose_b)
                reference = independent.signed
                if not curved and not abs(theirs - reference) <= 1e-6:  # the reference against a second one
                    mismatches.append(f"{case}: coal {theirs:+.7f}, the independent depth {reference:+.7f}")
                # ours: closed forms, and libccd's EPA on polytopes, to ~1e-9 m; libccd's EPA on a cylinder stops
                # short, up to ~2e-5 m too shallow (1.75e-5 measured here)
                tolerance = 3e-5 if curved else 1e-6
            compared += 1
            if not abs(ours[t, p] - reference) <= tolerance:
                mismatches.append(f"{case}: ours {ours[t, p]:+.7f}, reference {reference:+.7f}, coal {theirs:+.7f}")
    assert not mismatches, f"{len(mismatches)} of {compared} pairs differ:\n" + "\n".join(mismatches)
    assert compared > 150  # the regime was tried


def test_coal_epa_is_wrong_on_the_named_cases():
    """The cases of COAL_EPA_WRONG, among them the convex-cylinder penetration that ours and coal disagreed on
    (-0.0119 against -0.0411 m): the independent depth is ours (to its 3e-5 m); and coal's own GJK shows its
    depth too deep, since a translation of the independent depth (+1 um) along its direction leaves the shapes
    1 um apart. (A coal whose EPA is mended there passes too.)"""
    rng = np.random.default_rng(1)
    shapes, origins, sizes = one_of_each(rng)
    T = 60
    frames_a = random_poses(rng, T * 4, 0.08).reshape(T, 4, 4, 4)
    frames_b = random_poses(rng, T * 4, 0.08).reshape(T, 4, 4, 4)
    geoms = [coal_geometry(k, s) for k, s in zip(KINDS, sizes)]
    for (t, kind_a, kind_b), (coal_depth, depth) in COAL_EPA_WRONG.items():
        i, j = KINDS.index(kind_a), KINDS.index(kind_b)
        pose_a, pose_b = frames_a[t, i] @ origins[i], frames_b[t, j] @ origins[j]
        independent = independent_distance(kind_a, sizes[i], pose_a, kind_b, sizes[j], pose_b)
        assert -independent.signed == pytest.approx(depth, abs=1e-5)
        ours = _core.shape_pair_distances(frames_a[t:t + 1], shapes, frames_b[t:t + 1], shapes, np.array([[i, j]]))
        assert ours[0, 0] == pytest.approx(independent.signed, abs=3e-5)
        theirs = coal_distance(geoms[i], pose_a, geoms[j], pose_b)
        assert theirs == pytest.approx(-coal_depth, abs=1e-5) or theirs == pytest.approx(-depth, abs=1e-5)
        moved = pose_b.copy()
        moved[:3, 3] += (1e-6 - independent.signed) * independent.direction  # the projections on it overlap by that
        assert coal_distance(geoms[i], pose_a, geoms[j], moved) == pytest.approx(1e-6, abs=2e-7)


def test_min_distances_broadcast_and_cutoff():
    rng = np.random.default_rng(2)
    shapes, _, _ = one_of_each(rng)
    frames = random_poses(rng, 20 * 4, 0.1).reshape(20, 4, 4, 4)
    world = frames[:1]
    pairs = np.array([[0, 1], [2, 3], [1, 2], [3, 0]])
    every = _core.shape_pair_distances(frames, shapes, world, shapes, pairs)
    assert every.shape == (20, 4)
    np.testing.assert_allclose(_core.shape_pair_min_distances(frames, shapes, world, shapes, pairs), every.min(axis=1),
                               atol=1e-12)
    bounded = _core.shape_pair_distances(frames, shapes, world, shapes, pairs, cutoff=-1.0)
    assert np.all(bounded <= every + 1e-12)  # the bound everywhere: a lower bound
    assert np.all(np.isinf(_core.shape_pair_min_distances(frames, shapes, world, shapes, np.zeros((0, 2), int))))


def test_lowest_z_and_points():
    rng = np.random.default_rng(3)
    shapes, origins, sizes = one_of_each(rng)
    frames = random_poses(rng, 10 * 4, 0.2).reshape(10, 4, 4, 4)
    z = _core.shape_lowest_z(frames, shapes, np.arange(4))
    points = _core.shape_lowest_points(frames, shapes, np.arange(4), max_points=6)
    assert z.shape == (10, 4) and points.shape == (10, 4, 6, 3)
    np.testing.assert_allclose(points[:, :, 0, 2], z, atol=1e-12)  # the lowest candidate is the lowest point
    assert np.all(np.diff(points[..., 2], axis=2) >= 0)
    # the convex shape's lowest point is its lowest hull vertex
    world = frames[:, 3] @ origins[3]
    hull = np.c_[shapes.hull_vertices(3), np.ones(len(shapes.hull_vertices(3)))]
    np.testing.assert_allclose(z[:, 3], (hull @ world[:, 2, :].T).min(axis=0), atol=1e-12)


def test_properties_hull_and_pickle():
    shapes, origins, sizes = one_of_each(np.random.default_rng(4))
    assert shapes.size == 4 and shapes.kinds == KINDS
    np.testing.assert_array_equal(shapes.frames, np.arange(4))
    np.testing.assert_allclose(shapes.bounding_radii[:3], [np.linalg.norm(sizes[0]) / 2, np.hypot(0.025, 0.045), 0.03])
    vertices, faces = shapes.hull_vertices(3), shapes.hull_faces(3)
    assert faces.shape[1] == 3 and faces.max() < len(vertices)
    assert {tuple(v) for v in vertices} <= {tuple(v) for v in BLOB}
    with pytest.raises(ValueError, match="not convex"):
        shapes.hull_faces(0)
    again = pickle.loads(pickle.dumps(shapes))
    assert again.kinds == shapes.kinds
    frames = random_poses(np.random.default_rng(5), 5 * 4, 0.1).reshape(5, 4, 4, 4)
    pairs = np.array([[0, 3], [1, 2]])
    np.testing.assert_array_equal(_core.shape_pair_distances(frames, again, frames, again, pairs),
                                  _core.shape_pair_distances(frames, shapes, frames, shapes, pairs))


def test_bad_input_is_value_error():
    eye = np.eye(4)[None]
    ok = dict(kinds=["box"], frames=np.array([0]), origins=eye, sizes=np.array([[0.1, 0.1, 0.1]]), vertices=[None])
    _core.ShapeSet(**ok)
    bad = [
        (dict(kinds=["cone"]), "unknown kind 'cone'"),
        (dict(sizes=np.array([[0.1, -0.1, 0.1]])), r"shape 0: size \(box extents.*must be > 0"),
        (dict(sizes=np.array([[0.1, np.nan, 0.1]])), "shape 0: size must be finite"),
        (dict(sizes=np.array([0.1, 0.1, 0.1])), r"sizes must have shape \(S, 3\)"),
        (dict(origins=np.eye(4)), r"origins must have shape \(S, 4, 4\)"),
        (dict(origins=np.array([[[1, 0.5, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]])),
         "shape 0: origin's rotation must be orthonormal and right-handed"),
        (dict(frames=np.array([-1])), "frames must be >= 0"),
        (dict(frames=np.array([0, 1])), r"frames must have shape \(S,\) like kinds"),
        (dict(vertices=[np.zeros((4, 3))]), "shape 0 is not convex: its vertices must be None"),
        (dict(kinds=["convex"], vertices=[np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]])]),
         "shape 0: its vertices span no volume"),
        (dict(kinds=["convex"], vertices=[None]), r"shape 0 is convex: its vertices must have shape \(V, 3\)"),
        (dict(kinds=["convex"], vertices=[np.zeros((4, 2))]), r"shape 0 is convex: its vertices must have shape \(V, 3\)"),
    ]
    for change, match in bad:
        with pytest.raises(InputError, match="ShapeSet: " + match):
            _core.ShapeSet(**{**ok, **change})
    shapes = _core.ShapeSet(**ok)
    frames = np.tile(np.eye(4), (3, 1, 1, 1))
    with pytest.raises(InputError, match=r"shape_lowest_z: frames must have shape \(T, L, 4, 4\)"):
        _core.shape_lowest_z(frames[:, :, :3], shapes, np.array([0]))
    with pytest.raises(InputError, match="lowest_z: shape index 1 is outside the set of 1 shapes"):
        _core.shape_lowest_z(frames, shapes, np.array([1]))
    with pytest.raises(TypeError, match="incompatible function arguments"):  # pybind11's own: owners must be ints
        _core.shape_lowest_z(frames, shapes, np.array([0.0]))
    with pytest.raises(InputError, match="shape_lowest_points: max_points must be >= 1"):
        _core.shape_lowest_points(frames, shapes, np.array([0]), max_points=0)
    with pytest.raises(InputError, match="pair_distances: sample counts 3 and 2 do not broadcast"):
        _core.shape_pair_distances(frames, shapes, frames[:2], shapes, np.array([[0, 0]]))
    with pytest.raises(InputError, match=r"shape_pair_distances: pairs must have shape \(P, 2\)"):
        _core.shape_pair_distances(frames, shapes, frames, shapes, np.array([0, 0]))
    with pytest.raises(InputError, match="pair_min_distances: cutoff must not be NaN"):
        _core.shape_pair_min_distances(frames, shapes, frames, shapes, np.array([[0, 0]]), cutoff=np.nan)
    nan = frames.copy()
    nan[1, 0, 0, 3] = np.nan
    with pytest.raises(InputError, match="pair_min_distances: frames must be finite"):
        _core.shape_pair_min_distances(nan, shapes, frames, shapes, np.array([[0, 0]]))


def test_shapes_of_is_the_shapes_on_the_frames_and_remembered() -> None:
    """ShapeSet.shapes_of against np.isin over the shapes' frames, for random frame lists, asked again and again
    (the remembered answer) and past the number it keeps."""
    from snakehead.geometry import shapes as sh_shapes
    from snakehead.model.robot import SnakeRobot

    g = SnakeRobot.default().geometry
    rng = np.random.default_rng(5)
    lists = [rng.choice(g.n_frames, size=rng.integers(0, g.n_frames + 1), replace=False)
             for _ in range(sh_shapes.SHAPES_OF_KEPT + 20)]
    for _ in range(2):
        for frames in lists:
            want = np.flatnonzero(np.isin([s.frame for s in g.shapes], frames))
            got = g.shapes_of(frames)
            np.testing.assert_array_equal(got, want)
            assert not got.flags.writeable
            assert len(g._shapes_on) <= sh_shapes.SHAPES_OF_KEPT
    np.testing.assert_array_equal(g.shapes_of(list(lists[0])), g.shapes_of(lists[0]))  # a list as an array
