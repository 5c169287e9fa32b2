"""The MuJoCo plant (an optional extra: ``pip install snakehead[sim]``): the robot's model built with MjSpec
(:mod:`.mjcf`), PD control with gravity compensation at the 2 ms control period (:mod:`.tracking`) and what it
records (:mod:`.measurements`: momenta, ground contacts, ZMP), the servos' gains and torque limits (:mod:`.gains`),
the robot's own senses (:mod:`.sensors`), and a plan simulated and compared with itself as the paper does in
Section 4 (:mod:`.simulate_plan`, :mod:`.compare`).
"""
from .. import _moved
from . import gains
from .compare import compare, zmp_margins
from .mjcf import SimModel, build_model, build_spec, obstacle_boxes
from .simulate_plan import PlanSimulation, simulate
from .tracking import SimResult, SimState, simulate_trajectory

__all__ = ["simulate", "PlanSimulation", "simulate_trajectory", "SimResult", "SimState", "compare", "zmp_margins",
           "SimModel", "build_spec", "build_model", "obstacle_boxes", "gains"]

__getattr__ = _moved.moved_names(__name__, {
    name: "snakehead.closed_loop" for name in ("GaitSimulator", "GaitRun", "BodyPose", "BodyPoseEstimator", "pose_error")})
