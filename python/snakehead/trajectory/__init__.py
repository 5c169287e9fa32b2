"""Motion between states (paper Section 3.2): multi-segment joint-space interpolation sampled at the 2 ms control
period (:mod:`.interpolation`) and the whole-body Cartesian interpolation of Eqs. 41-44 (:mod:`.cartesian`)."""
from .cartesian import CartesianInterpolation, cartesian_interpolation, cartesian_trajectory
from .interpolation import CONTROL_PERIOD, JointTrajectory, MonotoneQuintic, joint_interpolation, joint_trajectory

__all__ = ["CONTROL_PERIOD", "JointTrajectory", "MonotoneQuintic", "joint_interpolation", "joint_trajectory",
           "CartesianInterpolation", "cartesian_interpolation", "cartesian_trajectory"]
