"""The body's collisions: with the ground, with itself and with obstacles (:mod:`.body_collisions`), and proofs that
a path or a timed motion stays clear between its samples (:mod:`.path_proof`, in C++ batches)."""
from .body_collisions import (
                              GROUND_TOLERANCE,
                              CollisionReport,
                              collision_check,
                              ground_clearance,
                              obstacle_shapes,
                              self_clearance,
)

__all__ = ["GROUND_TOLERANCE", "CollisionReport", "collision_check", "ground_clearance", "obstacle_shapes",
           "self_clearance"]
