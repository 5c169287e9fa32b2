"""The robot: a kinematic :class:`Chain` over the C++ model, and the :class:`SnakeRobot` that knows the body's
parts (base, neck, head) and everything derived from its URDF (built by :mod:`.robot_build`; the algorithms on it
in :mod:`.frames`, :mod:`.robot_geometry`, :mod:`.straight_body` and :mod:`.robot_parts`); robot files (TOML);
checks of its masses and inertias, and inertias recomputed from its collision shapes (:mod:`.mass_properties`);
where the base lies, on flat ground or in a slope's ground frame (:mod:`.placement`)."""
from .chain import Chain
from .placement import GroundFrame
from .robot import BasePlacement, RobotParts, SnakeRobot, default_urdf_path

__all__ = ["Chain", "SnakeRobot", "BasePlacement", "GroundFrame", "RobotParts", "default_urdf_path"]
