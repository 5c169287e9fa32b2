"""Mesh obstacles in scene files (their convex hulls) against the same obstacle as a box; support polygons of
cylinder snakes against scipy's hull of their bottom lines (closed form)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull

import snakehead
from snakehead._errors import InputError
from snakehead.collision import body_collisions as coll
from snakehead.dynamics import stability
from snakehead.geometry.obstacles import BoxObstacle, MeshObstacle
from snakehead.ground_contact import GROUND_TOLERANCE
from snakehead.samples import published
from snakehead.scenes import load_scene


def scene_with_a_mesh(folder: Path, mesh: str, position: str) -> Path:
    """A scene file with one target and one mesh obstacle (``position``: its TOML value and any further lines)."""
    path = folder / "scene.toml"
    path.write_text(f'''
[[targets]]
name = "t"
position = [0.15, 0.51, 0.40]
direction = [0.0, 1.0, 0.0]

[[obstacles]]
kind = "mesh"
file = "{mesh}"
position = {position}
''')
    return path


def test_a_mesh_obstacle_in_a_scene_file_is_its_box(tmp_path: Path) -> None:
    trimesh.creation.box(extents=(0.2, 0.3, 0.25)).export(tmp_path / "rock.stl")
    scene = load_scene(scene_with_a_mesh(tmp_path, "rock.stl", "[0.9, 0.3, 0.125]\nyaw = 0.4"))
    (rock,) = scene.obstacles
    assert isinstance(rock, MeshObstacle) and len(rock.vertices) == 8
    box = BoxObstacle.from_yaw([0.9, 0.3, 0.125], [0.2, 0.3, 0.25], 0.4)
    robot = snakehead.SnakeRobot.default()
    rng = np.random.default_rng(0)
    qs = np.array([robot.random_configuration(rng) for _ in range(40)])
    as_mesh = coll.collision_check(robot, qs, [rock], exact_within=np.inf).link_distance
    as_box = coll.collision_check(robot, qs, [box], exact_within=np.inf).link_distance
    np.testing.assert_allclose(as_mesh, as_box, atol=1e-6)
    # the hull's plane distance is exact inside and where a face is closest
    assert rock.distance_to_points(np.array([[0.9, 0.3, 0.125]]))[0] == pytest.approx(-0.1, abs=1e-6)  # STL: float32


def test_a_scene_mesh_that_is_missing_is_an_input_error(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="nothing.stl"):
        load_scene(scene_with_a_mesh(tmp_path, "nothing.stl", "[0.9, 0.3, 0.0]"))


def test_cylinder_support_polygon_is_the_hull_of_the_bottom_lines(tmp_path: Path) -> None:
    """On the SEA-style snake (cylinders along z behind a rotated root) in its initial state, the base's footprint
    is the convex hull of its cylinders' bottom lines: each cylinder lying on its side touches the ground along
    c - r e_z +- (L / 2) a, with a its horizontal axis (closed form; scipy's hull)."""
    robot = snakehead.SnakeRobot.from_file(published.write_robot("sea", tmp_path / "sea"))
    from snakehead.backbone.initial import initial_configuration

    q = initial_configuration(robot)
    F = robot.frames(q)
    ends = []
    for s in robot.geometry.shapes:
        if s.frame not in set(robot.base_links.tolist()):
            continue
        B = F[s.frame] @ s.origin
        if s.kind == "cylinder":
            a, c = B[:3, 2], B[:3, 3]
            assert abs(a[2]) < 1e-9  # lying on its side
            for sign in (-1.0, 1.0):
                ends.append(c + sign * s.size[1] / 2 * a - s.size[0] * np.array([0.0, 0.0, 1.0]))
        else:  # the tail, a faceted mesh: its hull's vertices within the contact tolerance of the ground
            v = s.vertices @ B[:3, :3].T + B[:3, 3]
            ends.extend(v[v[:, 2] <= GROUND_TOLERANCE])
    ends = np.array(ends)
    assert np.abs(ends[:, 2]).max() <= GROUND_TOLERANCE  # on the ground
    hull = ends[ConvexHull(ends[:, :2]).vertices, :2]
    poly = stability.support_polygon(robot, q, contact="footprint")
    assert len(poly) == len(hull)
    for v in hull:
        assert np.min(np.linalg.norm(poly - v, axis=1)) < 1e-9


def test_shapes_and_mesh_obstacles_reject_bad_input(tmp_path: Path) -> None:
    from snakehead.geometry.shapes import Shape, ShapeSet

    with pytest.raises(ValueError, match="kind"):
        Shape("cone", 0, np.eye(4), np.ones(3))
    with pytest.raises(ValueError, match="frame"):
        ShapeSet((Shape("box", 3, np.eye(4), np.ones(3)),), 2)
    with pytest.raises(InputError, match=r"shape 0: size \(box extents.*must be > 0"):
        ShapeSet((Shape("box", 0, np.eye(4), -np.ones(3)),), 1)  # the core checks sizes
    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(tmp_path / "rock.stl")
    with pytest.raises(ValueError, match="scale"):
        MeshObstacle.load(tmp_path / "rock.stl", [0, 0, 0], scale=[1, 0, 1])
    with pytest.raises(ValueError, match="does not exist"):
        MeshObstacle.load(tmp_path / "none.stl", [0, 0, 0])
