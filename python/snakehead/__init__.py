"""snakehead: head control of snake robots by segmented kinematics.

The C++ core (``snakehead._core``) does kinematics, TRAC-IK, the workspace sweep and the hot loops; the subpackages
plan with it, one concept each, each importing only those listed after it:

* :mod:`snakehead.app` -- the pipeline and the command line; :mod:`snakehead.viz` -- figures and the 3-D viewer;
* :mod:`snakehead.samples` -- published-style robots and reachable target sets (tests, benchmarks, docs);
* :mod:`snakehead.closed_loop` -- the loop from any lying state on the robot's own senses;
* :mod:`snakehead.sim` -- the MuJoCo plant and the comparison with the plan;
* :mod:`snakehead.planning` -- :func:`plan`: targets -> a checked whole-body motion; :mod:`snakehead.locomotion`
  -- gaits and ground paths;
* :mod:`snakehead.retiming` -- time-optimal retiming (TOPP-RA); :mod:`snakehead.trajectory` -- joint and Cartesian
  interpolation (Eqs. 41-44);
* :mod:`snakehead.solve` -- the neck (Eqs. 18-22), the head, the :class:`HeadController`, the whole-body solve;
* :mod:`snakehead.kinematics` -- :class:`TracIK`, the head's reachability maps, base placement;
* :mod:`snakehead.backbone` -- backbone curves and the base arc (Eqs. 1-9), the initial configuration;
* :mod:`snakehead.scenes` -- scene files; :mod:`snakehead.dynamics` -- centre of mass, support polygon, momenta,
  ZMP (Eqs. 23-40); :mod:`snakehead.collision` -- the body against the ground, itself and obstacles;
* :mod:`snakehead.model` -- the robot (:class:`SnakeRobot`, :class:`Chain`, robot files);
  :mod:`snakehead.geometry` -- shapes, meshes and obstacles.

Start with ``SnakeRobot.default()``. The layers are drawn in ``docs/architecture.rst``.
"""
from . import _moved
from ._errors import Infeasible, InputError, InputTypeError, InternalError, MotionTooLong
from .geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole
from .kinematics.ik import TracIK
from .kinematics.reachability import compute as compute_map
from .kinematics.reachability import load as load_map
from .kinematics.reachability.reachability_map import ReachabilityMap
from .model.chain import Chain
from .model.robot import BasePlacement, RobotParts, SnakeRobot, default_robot_file, default_urdf_path
from .planning.plan_many import PlanError, plan_many
from .planning.plan_result import Plan, PlanProgress, TargetResult
from .planning.planner import plan
from .scenes.scene import Scene, Target, load_scene
from .sim.simulate_plan import PlanSimulation, simulate
from .solve.head_controller import HeadController, HeadSolution
from .threads import core_threads, set_core_threads

__all__ = ["Infeasible", "InputError", "InputTypeError", "InternalError", "MotionTooLong", "SnakeRobot", "BasePlacement", "RobotParts", "Chain", "TracIK", "HeadController", "HeadSolution",
           "ReachabilityMap", "compute_map", "load_map", "plan", "plan_many", "PlanError", "Plan", "PlanProgress", "TargetResult", "simulate",
           "PlanSimulation", "Scene", "Target", "load_scene", "BoxObstacle", "MeshObstacle", "WallWithHole", "default_robot_file",
           "default_urdf_path", "core_threads", "set_core_threads"]
_moved.install()  # old import paths (snakehead.motion.planner, ...) warn for one release

__version__ = "0.2.0"
