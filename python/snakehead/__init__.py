"""snakehead: head control of snake robots by segmented kinematics.

The C++ core (``snakehead._core``) does kinematics, TRAC-IK and the workspace sweep; the Python
modules plan with it. Start with ``SnakeRobot.default()``.
"""
from .chain import Chain
from .ik import TracIK
from .robot import BasePlacement, RobotParts, SnakeRobot, default_urdf_path

__all__ = ["Chain", "TracIK", "SnakeRobot", "BasePlacement", "RobotParts", "default_urdf_path"]
__version__ = "0.1.0"
