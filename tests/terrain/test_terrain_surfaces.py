"""The terrain surfaces against independent computations: a plane's closed form, a heightfield's triangles by hand,
a mesh's heights and normals by barycentric coordinates on each triangle in numpy, its signed distances against
trimesh's closest points on triangles and a box's closed form; the same answers from many threads; flat ground is z = 0."""
from __future__ import annotations

import pickle
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from snakehead._errors import InputError
from snakehead.terrain import (
    FlatGround,
    HeightfieldTerrain,
    MeshTerrain,
    PlaneTerrain,
    StepsTerrain,
    egg_crate,
)

trimesh = pytest.importorskip("trimesh")

SETTINGS = settings(derandomize=True, deadline=None, database=None, max_examples=50)
coordinate = st.floats(-3.0, 3.0, allow_nan=False)


def mesh_heights_by_hand(vertices: np.ndarray, faces: np.ndarray, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The highest surface z over each point and that triangle's upward unit normal, by barycentric coordinates of
    the point in each triangle's projection (NaN where no triangle is over it)."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    normals = np.cross(b - a, c - a)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    normals *= np.where(normals[:, 2:] < 0, -1.0, 1.0)
    z = np.full(len(xy), np.nan)
    n = np.full((len(xy), 3), np.nan)
    for k, (x, y) in enumerate(xy):
        with np.errstate(divide="ignore", invalid="ignore"):
            u = ((x - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (y - a[:, 1])) / det
            v = ((b[:, 0] - a[:, 0]) * (y - a[:, 1]) - (x - a[:, 0]) * (b[:, 1] - a[:, 1])) / det
        inside = (det != 0) & (u >= -1e-12) & (v >= -1e-12) & (u + v <= 1 + 1e-12)
        if inside.any():
            heights = a[:, 2] + u * (b[:, 2] - a[:, 2]) + v * (c[:, 2] - a[:, 2])
            best = np.flatnonzero(inside)[np.argmax(heights[inside])]
            z[k], n[k] = heights[best], normals[best]
    return z, n


def bumpy_mesh(seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """An irregular open surface: a jittered grid of 12 x 10 points, its z random, triangulated up."""
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.linspace(-1, 1, 12), np.linspace(-1, 1, 10), indexing="ij")
    x = x + rng.uniform(-0.03, 0.03, x.shape)
    y = y + rng.uniform(-0.03, 0.03, y.shape)
    z = rng.uniform(-0.1, 0.1, x.shape)
    vertices = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    faces = []
    for i in range(11):
        for j in range(9):
            p = i * 10 + j
            faces += [[p, p + 10, p + 11], [p, p + 11, p + 1]]
    return vertices, np.array(faces)


def test_flat_ground_is_z_zero():
    g = FlatGround()
    rng = np.random.default_rng(1)
    p = rng.uniform(-5, 5, (100, 3))
    assert np.array_equal(g.height(p[:, :2]), np.zeros(100))
    assert np.array_equal(g.signed_distance(p), p[:, 2])
    assert np.array_equal(g.normal(p[:, :2]), np.tile([0.0, 0.0, 1.0], (100, 1)))
    assert g == FlatGround()


@SETTINGS
@given(st.floats(-40, 40), st.floats(-40, 40), coordinate, coordinate, coordinate)
def test_a_plane_is_its_closed_form(roll, pitch, x, y, z):
    point = np.array([0.3, -0.2, 0.1])
    plane = PlaneTerrain.from_roll_pitch(roll, pitch, point)
    n = plane.unit_normal
    assert np.isclose(np.linalg.norm(n), 1.0) and n[2] > 0
    h = plane.height([x, y])
    assert np.isclose(n @ (np.array([x, y, h]) - point), 0.0, atol=1e-12)
    assert np.isclose(plane.signed_distance([x, y, z]), n @ (np.array([x, y, z]) - point), atol=1e-12)
    assert np.allclose(plane.normal([x, y]), n)


def test_plane_normal_of_roll_and_pitch():
    assert np.allclose(PlaneTerrain.from_roll_pitch(0, 5).height([1.0, 0.0]), -np.tan(np.radians(5)))
    assert np.allclose(PlaneTerrain.from_roll_pitch(5, 0).height([0.0, 1.0]), np.tan(np.radians(5)))
    with pytest.raises(InputError):
        PlaneTerrain(np.array([1.0, 0.0, 0.0]), np.zeros(3))


def heightfield_by_hand(h: np.ndarray, extent: np.ndarray, origin: np.ndarray, x: float, y: float) -> float:
    """The height of the cell's triangle under (x, y): split along (i, j)-(i+1, j+1), linear on each half."""
    nx, ny = h.shape
    s = (x - origin[0]) / extent[0] * (nx - 1)
    t = (y - origin[1]) / extent[1] * (ny - 1)
    if not (0 <= s <= nx - 1 and 0 <= t <= ny - 1):
        return float("nan")
    i, j = min(int(s), nx - 2), min(int(t), ny - 2)
    u, v = s - i, t - j
    z00, z10, z01, z11 = h[i, j], h[i + 1, j], h[i, j + 1], h[i + 1, j + 1]
    if u >= v:  # the triangle (0,0) (1,0) (1,1)
        return origin[2] + z00 + u * (z10 - z00) + v * (z11 - z10)
    return origin[2] + z00 + v * (z01 - z00) + u * (z11 - z01)


@SETTINGS
@given(st.floats(-1.2, 1.2), st.floats(-0.7, 0.7))
def test_a_heightfield_is_its_triangles(x, y):
    h = np.random.default_rng(2).uniform(-0.2, 0.2, (6, 4))
    extent, origin = np.array([2.0, 1.2]), np.array([-1.0, -0.6, 0.05])
    terrain = HeightfieldTerrain(h, extent, origin)
    expected = heightfield_by_hand(h, extent, origin, x, y)
    got = terrain.height([x, y])
    assert (np.isnan(got) and np.isnan(expected)) or np.isclose(got, expected, atol=1e-12)
    if np.isfinite(expected):  # the normal is perpendicular to the facet: the heights around agree with it
        n = terrain.normal([x, y])
        assert np.isclose(np.linalg.norm(n), 1.0) and n[2] > 0


def test_a_heightfield_is_the_mesh_of_its_triangles():
    terrain = egg_crate(0.05, 0.5, extent=(1.0, 1.0), spacing=0.1)
    as_mesh = MeshTerrain(terrain.core.vertices, terrain.core.faces)
    rng = np.random.default_rng(3)
    xy = rng.uniform(-0.49, 0.49, (500, 2))
    assert np.allclose(terrain.height(xy), as_mesh.height(xy), atol=1e-12)
    assert np.allclose(terrain.normal(xy), as_mesh.normal(xy), atol=1e-9)
    p = np.column_stack([xy, rng.uniform(-0.2, 0.2, 500)])
    assert np.allclose(terrain.signed_distance(p), as_mesh.signed_distance(p), atol=1e-12)


def test_mesh_heights_and_normals_by_hand():
    vertices, faces = bumpy_mesh()
    terrain = MeshTerrain(vertices, faces)
    xy = np.random.default_rng(4).uniform(-1.2, 1.2, (400, 2))
    z, n = mesh_heights_by_hand(vertices, faces, xy)
    got = terrain.height(xy)
    assert np.array_equal(np.isnan(got), np.isnan(z))
    assert np.allclose(got[~np.isnan(z)], z[~np.isnan(z)], atol=1e-12)
    assert np.allclose(terrain.normal(xy)[~np.isnan(z)], n[~np.isnan(z)], atol=1e-9)


def trimesh_distances(vertices: np.ndarray, faces: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The distance of each point to its closest point on the mesh by trimesh's closest point on each triangle
    (``trimesh.triangles.closest_point``, over every point-triangle pair: the mesh's tree needs rtree)."""
    triangles = vertices[faces]
    pairs = np.repeat(points, len(triangles), axis=0)
    closest = trimesh.triangles.closest_point(np.tile(triangles, (len(points), 1, 1)), pairs)
    return np.linalg.norm(closest - pairs, axis=1).reshape(len(points), len(triangles)).min(axis=1)


def test_mesh_signed_distance_against_trimesh():
    vertices, faces = bumpy_mesh(7)
    terrain = MeshTerrain(vertices, faces)
    rng = np.random.default_rng(8)
    points = np.column_stack([rng.uniform(-1.3, 1.3, (300, 2)), rng.uniform(-0.4, 0.4, 300)])
    got = terrain.signed_distance(points)
    assert np.allclose(np.abs(got), trimesh_distances(vertices, faces, points), atol=1e-9)
    inside = ~np.isnan(terrain.height(points[:, :2]))
    above = points[inside, 2] >= terrain.height(points[inside, :2])
    assert np.array_equal(got[inside] >= 0, above)  # an upward surface: positive above it


def test_a_closed_mesh_is_positive_outside():
    box = trimesh.creation.box((1.0, 1.0, 1.0))  # normals out, as an STL holds it (each triangle its own vertices)
    vertices = np.asarray(box.vertices)[np.asarray(box.faces)].reshape(-1, 3)
    terrain = MeshTerrain(vertices, np.arange(len(vertices)).reshape(-1, 3))
    points = np.random.default_rng(9).uniform(-1.0, 1.0, (400, 3))
    q = np.abs(points) - 0.5
    expected = np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)  # the box's closed form
    assert np.allclose(terrain.signed_distance(points), expected, atol=1e-9)


def test_a_staircase():
    stairs = StepsTerrain(0.1, 0.3, 3, heading_deg=90.0, start=np.array([0.0, 1.0, 0.2]))
    xy = np.array([[0.0, 0.5], [0.0, 1.1], [0.5, 1.4], [0.0, 1.7], [0.0, 2.85], [0.0, 2.95]])
    assert np.allclose(stairs.height(xy), [0.2, 0.3, 0.4, 0.5, 0.5, np.nan], equal_nan=True)
    assert np.allclose(stairs.signed_distance([[0.0, 0.95, 0.25], [0.0, 1.1, 0.25]]), [0.05, -0.05])
    down = StepsTerrain(-0.1, 0.3, 2)
    assert np.allclose(down.height([[-0.5, 0.0], [0.1, 0.0], [0.5, 0.0]]), [0.0, -0.1, -0.2])
    assert np.isclose(down.signed_distance([0.05, 0.0, -0.05]), 0.05)  # in front of the riser down


def test_spheres_and_capsules():
    plane = PlaneTerrain.from_roll_pitch(0.0, 10.0)
    a = np.array([[0.0, 0.0, 0.5], [1.0, 0.0, 0.0]])
    b = np.array([[0.5, 0.0, 0.5], [1.0, 0.0, -0.5]])
    expected = np.minimum(plane.signed_distance(a), plane.signed_distance(b)) - 0.05
    assert np.allclose(plane.capsule_clearance(a, b, 0.05), expected, atol=1e-12)
    assert np.allclose(plane.sphere_clearance(a, [0.1, 0.2]), plane.signed_distance(a) - [0.1, 0.2], atol=1e-12)
    stairs = StepsTerrain(0.1, 0.3, 2)
    # A capsule lying across the first riser, clear of it: its distance is the riser's top edge's (0, 0.1).
    got = stairs.capsule_clearance([-0.2, 0.0, 0.15], [0.2, 0.0, 0.15], 0.01)
    assert np.isclose(got, 0.05 - 0.01)
    with pytest.raises(InputError, match="b must have the shape of a"):
        stairs.capsule_clearance(np.zeros((2, 3)), np.zeros((3, 3)), 0.1)


def test_many_threads_give_the_same_answers():
    vertices, faces = bumpy_mesh(10)
    terrains = [MeshTerrain(vertices, faces), egg_crate(0.05, 0.5, extent=(2.0, 2.0), spacing=0.05)]
    points = np.random.default_rng(11).uniform(-1.1, 1.1, (20000, 3))
    for terrain in terrains:
        expected = (terrain.height(points[:, :2]), terrain.signed_distance(points))
        with ThreadPoolExecutor(8) as pool:
            results = list(pool.map(lambda _: (terrain.height(points[:, :2]), terrain.signed_distance(points)),
                                    range(16)))
        for h, d in results:
            assert np.array_equal(h, expected[0], equal_nan=True)
            assert np.array_equal(d, expected[1])


def test_terrains_pickle_by_value():
    for terrain in (FlatGround(), PlaneTerrain.from_roll_pitch(3, 4), egg_crate(0.05, 0.5, spacing=0.1),
                    StepsTerrain(0.1, 0.3, 2), MeshTerrain(*bumpy_mesh())):
        again = pickle.loads(pickle.dumps(terrain))
        p = np.random.default_rng(12).uniform(-1, 1, (50, 3))
        assert np.array_equal(again.signed_distance(p), terrain.signed_distance(p))


def test_queries_take_any_leading_shape():
    g = egg_crate(0.05, 0.5, spacing=0.1)
    xy = np.zeros((2, 3, 2))
    assert g.height(xy).shape == (2, 3)
    assert g.normal(xy).shape == (2, 3, 3)
    assert g.signed_distance(np.zeros((4, 3))).shape == (4,)
    with pytest.raises(InputError, match="xy must have shape"):
        g.height(np.zeros((3, 3)))


@pytest.mark.parametrize("make", [
    lambda: HeightfieldTerrain(np.zeros(3), np.ones(2)),
    lambda: HeightfieldTerrain(np.array([[0.0, np.nan], [0.0, 0.0]]), np.ones(2)),
    lambda: HeightfieldTerrain(np.zeros((2, 2)), np.array([1.0, 0.0])),
    lambda: MeshTerrain(np.zeros((3, 3)), np.zeros((0, 3), int)),
    lambda: MeshTerrain(np.eye(3), np.array([[0, 1, 5]])),
    lambda: MeshTerrain(np.zeros((3, 3)), np.array([[0, 1, 2]])),
    lambda: StepsTerrain(0.0, 0.3),
    lambda: StepsTerrain(0.1, -0.3),
    lambda: PlaneTerrain(np.zeros(3), np.zeros(3)),
])
def test_bad_terrains_are_input_errors(make):
    with pytest.raises(InputError):
        make()
