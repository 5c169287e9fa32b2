"""snakehead: head control of snake robots by segmented kinematics.

The C++ core (``snakehead._core``) does kinematics, TRAC-IK and the workspace sweep; the subpackages plan with it:

* :mod:`snakehead.model` -- the robot (:class:`SnakeRobot`, :class:`Chain`, robot files);
* :mod:`snakehead.kinematics` -- :class:`TracIK` and the head's reachability maps;
* :mod:`snakehead.backbone` -- backbone curves and the base arc (Eqs. 1-9), the initial configuration;
* :mod:`snakehead.control` -- the neck (Eqs. 18-22), the head, the :class:`HeadController`;
* :mod:`snakehead.dynamics` -- centre of mass, support polygon, momenta, ZMP (Eqs. 23-40);
* :mod:`snakehead.motion` -- joint and Cartesian interpolation (Eqs. 41-44), the planner;
* :mod:`snakehead.geometry` -- obstacles and collisions; :mod:`snakehead.scenes` -- scene files;
* :mod:`snakehead.sim` -- the dynamics check in MuJoCo; :mod:`snakehead.viz` -- figures; :mod:`snakehead.app` --
  the pipeline and the command line.

Start with ``SnakeRobot.default()``.
"""
from ._errors import Infeasible, InputError, InputTypeError, InternalError, MotionTooLong
from .control.controller import HeadController, HeadSolution
from .threads import core_threads, set_core_threads
from .geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole
from .kinematics.ik import TracIK
from .kinematics.workspace import ReachabilityMap
from .kinematics.workspace import compute as compute_map
from .kinematics.workspace import load as load_map
from .model.chain import Chain
from .model.robot import BasePlacement, RobotParts, SnakeRobot, default_robot_file, default_urdf_path
from .motion.plan_many import PlanError, plan_many
from .motion.plan_result import Plan, PlanProgress, TargetResult
from .motion.planner import plan
from .scenes.scene import Scene, Target, load_scene
from .sim.plan import PlanSimulation, simulate

__all__ = ["Infeasible", "InputError", "InputTypeError", "InternalError", "MotionTooLong", "SnakeRobot", "BasePlacement", "RobotParts", "Chain", "TracIK", "HeadController", "HeadSolution",
           "ReachabilityMap", "compute_map", "load_map", "plan", "plan_many", "PlanError", "Plan", "PlanProgress", "TargetResult", "simulate",
           "PlanSimulation", "Scene", "Target", "load_scene", "BoxObstacle", "MeshObstacle", "WallWithHole", "default_robot_file",
           "default_urdf_path", "core_threads", "set_core_threads"]
__version__ = "0.2.0"
