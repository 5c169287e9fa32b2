"""The dynamics check in MuJoCo (an optional extra: ``pip install snakehead[sim]``): the robot's model, PD control
with gravity compensation at the 2 ms control period, and the comparison with the plan (paper Section 4).

* :func:`simulate` -- a :class:`~snakehead.motion.planner.Plan` end to end (``snakehead.simulate``);
* :func:`simulate_trajectory` -- any joint trajectory; :func:`compare` -- a simulation against its plan;
* :func:`build_model` / :func:`build_mjcf` -- the MuJoCo model of a robot and the scene's obstacles.
"""
from .compare import compare, zmp_margins
from .mjcf import SimModel, build_mjcf, build_model, obstacle_boxes
from .plan import PlanSimulation, simulate
from .tracking import SimResult, simulate_trajectory

__all__ = ["simulate", "PlanSimulation", "simulate_trajectory", "SimResult", "compare", "zmp_margins", "SimModel",
           "build_mjcf", "build_model", "obstacle_boxes"]
