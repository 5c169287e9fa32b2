"""Obstacles (one model for planning and simulation) and collisions of the body's boxes with the ground, with
itself and with obstacles."""
from .collision import (GROUND_TOLERANCE, CollisionReport, collision_check, ground_clearance, self_clearance)
from .obstacles import BoxObstacle, WallWithHole

__all__ = ["BoxObstacle", "WallWithHole", "GROUND_TOLERANCE", "CollisionReport", "collision_check",
           "ground_clearance", "self_clearance"]
