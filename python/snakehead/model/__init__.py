"""The robot: a kinematic :class:`Chain` over the C++ model, and the :class:`SnakeRobot` that knows the body's
parts (base, neck, head) and everything derived from its URDF; robot files (TOML); checks of its masses and
inertias, and inertias recomputed from its collision shapes (:mod:`.mass_properties`)."""
from .chain import Chain
from .robot import BasePlacement, RobotParts, SnakeRobot, default_urdf_path

__all__ = ["Chain", "SnakeRobot", "BasePlacement", "RobotParts", "default_urdf_path"]
