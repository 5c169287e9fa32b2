"""Real collision shapes in the simulation and the figures: a snake whose modules are cylinders (along the link
frames' x, or along their z so that the body frame is turned in the root's), with two shapes on one link, a sphere
head and a mesh (an STL box, used as its convex hull). The MuJoCo model has one geom per shape of the same kind,
size and place; lying at rest on the ground, MuJoCo's floor contacts are where ``robot.lowest_points`` says; the
estimator and the figures see every shape."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh  # noqa: E402

from snakehead import BasePlacement, SnakeRobot, sim  # noqa: E402
from snakehead.closed_loop.estimate import BodyPoseEstimator  # noqa: E402

L = 0.08  # module length (m)
R = 0.02  # cylinder and sphere radius (m): the body axis lies R above the ground
MESH = (0.06, 0.036, 0.04)  # the STL box's extents (m): its bottom face on the ground with the cylinders
N_JOINTS = 6


def _rpy_along(axis: str) -> str:
    """rpy that turns a URDF cylinder (its z) along the link frame's ``axis``; and the body direction vector."""
    return {"x": "0 1.5707963267948966 0", "z": "0 0 0"}[axis]


def _urdf(axis: str, mesh_path: str) -> str:
    """Links link_0 .. link_6 along the link frames' ``axis``; yaw and pitch joints alternating."""
    along = {"x": np.array([1.0, 0, 0]), "z": np.array([0, 0, 1.0])}[axis]
    yaw_axis = {"x": "0 0 1", "z": "1 0 0"}[axis]  # "up" of the body
    pitch_axis = "0 1 0"
    mesh_rpy = {"x": "0 0 0", "z": "0 -1.5707963267948966 0"}[axis]  # the box's x along the body, its z up

    def xyz(s: float) -> str:
        return " ".join(f"{v:.10g}" for v in s * along)

    inertia = '<inertial><mass value="0.1"/><origin xyz="{}"/><inertia ixx="4e-5" iyy="6e-5" izz="6e-5" ixy="0" ' \
              'ixz="0" iyz="0"/></inertial>'
    parts = ['<?xml version="1.0"?>', '<robot name="shapes">']
    for i in range(N_JOINTS + 1):
        shapes = []
        if i == N_JOINTS:  # the head: a sphere in the middle of the link
            shapes.append(f'<collision><origin xyz="{xyz(L / 2)}"/><geometry><sphere radius="{R}"/></geometry>'
                          '</collision>')
        elif i == 3:  # a mesh module: an STL box (its hull)
            shapes.append(f'<collision><origin xyz="{xyz(L / 2)}" rpy="{mesh_rpy}"/><geometry><mesh '
                          f'filename="{mesh_path}"/></geometry></collision>')
        else:
            shapes.append(f'<collision><origin xyz="{xyz(L / 2)}" rpy="{_rpy_along(axis)}"/><geometry><cylinder '
                          f'radius="{R}" length="{0.9 * L}"/></geometry></collision>')
            if i == 1:  # a second shape on the same link: a sphere at its distal end
                shapes.append(f'<collision><origin xyz="{xyz(0.95 * L)}"/><geometry><sphere radius="{R}"/>'
                              '</geometry></collision>')
        parts.append(f'<link name="link_{i}">{inertia.format(xyz(L / 2))}{"".join(shapes)}</link>')
    markers = {2: "p0", 4: "b0", N_JOINTS: "nose"}  # on the chain: link -> marker (fixed) -> next joint
    for i, name in markers.items():
        parts.append(f'<link name="{name}"/><joint name="{name}_fixed" type="fixed"><parent link="link_{i}"/>'
                     f'<child link="{name}"/><origin xyz="{xyz(L)}"/></joint>')
    for j in range(1, N_JOINTS + 1):
        a = yaw_axis if j % 2 else pitch_axis
        parent, offset = (markers[j - 1], 0.0) if j - 1 in markers else (f"link_{j - 1}", L)
        parts.append(f'<joint name="joint_{j}" type="revolute"><parent link="{parent}"/><child link="link_{j}"/>'
                     f'<origin xyz="{xyz(offset)}"/><axis xyz="{a}"/><limit lower="-1.57" upper="1.57" effort="5" '
                     'velocity="3"/></joint>')
    parts.append("</robot>")
    return "\n".join(parts)


@pytest.fixture(scope="module", params=["x", "z"])
def robot(request, tmp_path_factory) -> SnakeRobot:
    folder = tmp_path_factory.mktemp(f"shapes_{request.param}")
    mesh = folder / "box.stl"
    trimesh.creation.box(extents=MESH).export(mesh)
    urdf = folder / "snake.urdf"
    urdf.write_text(_urdf(request.param, str(mesh)))
    return SnakeRobot.from_urdf(urdf, base_end="p0", neck_end="b0", head_tip="nose")


def test_the_robot_has_every_kind_of_shape(robot):
    kinds = [s.kind for s in robot.geometry.shapes]
    assert sorted(set(kinds)) == ["convex", "cylinder", "sphere"]
    assert kinds.count("cylinder") == N_JOINTS - 1 and kinds.count("sphere") == 2 and kinds.count("convex") == 1
    assert robot.body_axis_height == pytest.approx(R, abs=1e-9)


def test_the_geoms_are_the_shapes(mujoco, robot):
    """One geom per shape on its link's body: same type, MuJoCo's size (half length of a box or cylinder), same
    pose in the world; a mesh geom's vertices are the hull's."""
    s = sim.build_model(robot)
    m = s.model
    shapes = robot.geometry.shapes
    assert len(s.robot_geoms) == len(shapes) and sorted(s.shape_geoms.tolist()) == sorted(s.robot_geoms.tolist())
    d = mujoco.MjData(m)
    rng = np.random.default_rng(3)
    q = 0.5 * robot.random_configuration(rng)
    base = BasePlacement(0.3, -0.2, 0.7)
    s.set_state(d, q, base)
    F = robot.frames(q, base)
    types = {"box": mujoco.mjtGeom.mjGEOM_BOX, "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
             "sphere": mujoco.mjtGeom.mjGEOM_SPHERE, "convex": mujoco.mjtGeom.mjGEOM_MESH}
    for k, (shape, g) in enumerate(zip(shapes, s.shape_geoms)):
        assert m.geom_type[g] == types[shape.kind], k
        assert m.geom_bodyid[g] == s.body_ids[shape.frame], k
        W = F[shape.frame] @ shape.origin  # the shape's frame in the world
        if shape.kind == "cylinder":
            np.testing.assert_allclose(m.geom_size[g][:2], (shape.size[0], shape.size[1] / 2), atol=1e-12)
            np.testing.assert_allclose(d.geom_xpos[g], W[:3, 3], atol=1e-9)
            np.testing.assert_allclose(d.geom_xmat[g].reshape(3, 3)[:, 2], W[:3, 2], atol=1e-9)  # the axis
        elif shape.kind == "sphere":
            assert m.geom_size[g][0] == pytest.approx(shape.size[0], abs=1e-12)
            np.testing.assert_allclose(d.geom_xpos[g], W[:3, 3], atol=1e-9)
        else:
            mid = m.geom_dataid[g]
            start, count = m.mesh_vertadr[mid], m.mesh_vertnum[mid]
            local = m.mesh_vert[start:start + count]
            world = local @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g]
            hull = shape.vertices @ W[:3, :3].T + W[:3, 3]
            assert count == 8
            gaps = np.linalg.norm(world[:, None] - hull[None], axis=2).min(axis=1)
            assert gaps.max() < 1e-6


def test_floor_contacts_at_rest_are_the_lowest_points(mujoco, robot):
    """Lying straight on the ground at the body-axis height (0.1 mm into it, so that every touching shape makes
    contact), MuJoCo's floor contacts lie where robot.lowest_points says, within 1 mm, and every shape that touches
    the ground has one."""
    s = sim.build_model(robot)
    d = mujoco.MjData(s.model)
    base = BasePlacement(0.2, 0.1, 0.4)
    q = np.zeros(robot.n_joints)
    s.set_state(d, q, base, lift=-1e-4)
    F = robot.frames(q, base)
    F[..., 2, 3] -= 1e-4
    points, links = robot.lowest_points(F[None])
    points = points[0]
    contacts = [d.contact[i] for i in range(d.ncon) if s.floor_geom in (d.contact[i].geom1, d.contact[i].geom2)]
    assert contacts
    touched = set()
    for c in contacts:
        g = c.geom2 if c.geom1 == s.floor_geom else c.geom1
        k = int(np.flatnonzero(s.shape_geoms == g)[0])
        touched.add(k)
        frame = robot.geometry.shapes[k].frame
        near = np.linalg.norm(points[links == frame] - np.asarray(c.pos), axis=1).min()
        assert near < 1e-3, (k, robot.geometry.shapes[k].kind, near)
    assert touched == set(range(len(robot.geometry.shapes)))  # every shape rests on the ground (its bottom at R)


def test_the_estimator_places_the_body_frame(robot):
    """reset() takes the body frame's placement (BasePlacement's): the root frame is robot.root_pose of it, and
    the estimate's base is the placement."""
    base = BasePlacement(0.4, -0.3, 1.1)
    q = np.zeros(robot.n_joints)
    F = robot.frames(q, base)
    est = BodyPoseEstimator(robot)
    R_imu = F[est.imu_index, :3, :3]
    pose = est.reset(q, R_imu, (base.x, base.y), body_yaw=base.yaw)
    np.testing.assert_allclose(pose.root, robot.root_pose(base), atol=1e-9)
    b = pose.base
    assert (b.x, b.y, b.yaw) == pytest.approx((base.x, base.y, base.yaw), abs=1e-9)
    assert pose.tilt_deg == pytest.approx(0.0, abs=1e-6)


def test_the_figures_draw_every_shape(robot):
    """The body's collection has each shape's polygons: a cylinder's sides and two caps, a sphere's bands and
    caps, the STL box's six faces; the footprints are one per shape; the viewer has a mesh per kind and one for
    the hull."""
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from snakehead.viz import body, viewer

    n = body.FIGURE_SEGMENTS
    per_kind = {"cylinder": n + 2, "sphere": 2 * n + (n // 2 - 2) * n, "convex": 6}
    expected = sum(per_kind[s.kind] for s in robot.geometry.shapes)
    F = robot.frames(np.zeros(robot.n_joints), BasePlacement(0.1, 0.0, 0.3))
    fig = Figure()
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    drawn = body.draw_body(ax, robot, F)
    assert isinstance(drawn, Poly3DCollection) and len(drawn.get_facecolor()) == expected
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()  # projected: one path per polygon
    assert len(drawn.get_paths()) == expected
    faces, colors = body.body_faces(robot, F)
    assert len(faces) == len(colors) == expected
    # every polygon's corners lie on its shape's surface: within the shapes' mesh vertices' bounds
    allv = np.concatenate(faces)
    assert allv[:, 2].min() == pytest.approx(F[0, 2, 3] - R, abs=1e-9)
    foot = body.shape_footprints(robot, F)
    assert len(foot) == len(robot.geometry.shapes)
    meshes = viewer.robot_meshes(robot)
    assert len(meshes["mesh_vertex_starts"]) - 1 == 3  # unit cylinder, unit sphere, the hull
    kinds = [s.kind for s in robot.geometry.shapes]
    hull = meshes["shape_mesh"][kinds.index("convex")]
    v = meshes["mesh_vertices"][meshes["mesh_vertex_starts"][hull]:meshes["mesh_vertex_starts"][hull + 1]]
    np.testing.assert_allclose(np.sort(np.abs(v).max(axis=0)), np.sort(np.array(MESH) / 2), atol=1e-9)
