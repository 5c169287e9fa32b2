"""The one geometry layer of the robot and the scene: convex shapes on frames (:mod:`.shapes`: boxes, cylinders,
spheres, mesh hulls; distances on FCL in the C++ core), mesh files read into hulls (:mod:`.meshes`) and obstacles
(:mod:`.obstacles`: one model for planning and simulation). The body's collisions are :mod:`snakehead.collision`'s."""
from .. import _moved
from .obstacles import BoxObstacle, MeshObstacle, WallWithHole
from .shapes import Shape, ShapeSet, shape_mesh

__all__ = ["BoxObstacle", "MeshObstacle", "WallWithHole", "Shape", "ShapeSet", "shape_mesh"]

__getattr__ = _moved.moved_names(__name__, {
    name: "snakehead.collision" for name in ("GROUND_TOLERANCE", "CollisionReport", "collision_check",
                                             "ground_clearance", "obstacle_shapes", "self_clearance")})
