"""The dynamics check in MuJoCo (an optional extra: ``pip install snakehead[sim]``): the robot's model, PD control
with gravity compensation at the 2 ms control period, and the comparison with the plan (paper Section 4).

* :func:`simulate` -- a :class:`~snakehead.motion.plan_result.Plan` end to end (``snakehead.simulate``);
* :func:`simulate_trajectory` -- any joint trajectory; :func:`compare` -- a simulation against its plan;
* :func:`build_model` / :func:`build_spec` -- the MuJoCo model (built with MjSpec) of a robot and the scene's obstacles;
  :mod:`.gains` -- the servos' gains and torque limits, derived from each joint's load;
* :class:`GaitSimulator` -- gaits (:mod:`snakehead.motion.gaits`) run on the ground from any simulated state, with
  the body's pose estimated as the robot would (:mod:`.estimate`: joint angles + one link's IMU) and measured.
"""
from . import gains
from .compare import compare, zmp_margins
from .estimate import BodyPose, BodyPoseEstimator, pose_error
from .gaits import GaitRun, GaitSimulator, SimState
from .mjcf import SimModel, build_model, build_spec, obstacle_boxes
from .plan import PlanSimulation, simulate
from .tracking import SimResult, simulate_trajectory

__all__ = ["simulate", "PlanSimulation", "simulate_trajectory", "SimResult", "compare", "zmp_margins", "SimModel",
           "build_spec", "build_model", "obstacle_boxes", "gains", "GaitSimulator", "GaitRun", "SimState", "BodyPose",
           "BodyPoseEstimator", "pose_error"]
