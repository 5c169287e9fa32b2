"""The one geometry layer of the robot and the scene: convex shapes on frames (:mod:`.shapes`: boxes, cylinders,
spheres, mesh hulls; distances on FCL in the C++ core), obstacles (one model for planning and simulation) and the
body's collisions with the ground, with itself and with obstacles."""
from .collision import (GROUND_TOLERANCE, CollisionReport, collision_check, ground_clearance, obstacle_shapes,
                        self_clearance)
from .obstacles import BoxObstacle, MeshObstacle, WallWithHole
from .shapes import Shape, ShapeSet, shape_mesh

__all__ = ["BoxObstacle", "MeshObstacle", "WallWithHole", "GROUND_TOLERANCE", "CollisionReport", "collision_check",
           "ground_clearance", "obstacle_shapes", "self_clearance", "Shape", "ShapeSet", "shape_mesh"]
