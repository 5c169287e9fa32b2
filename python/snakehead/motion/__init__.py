"""Whole-body motion (paper Section 3.2): joint-space interpolation at the 2 ms control period, the Cartesian
interpolation of Eqs. 41-44, the time-optimal retiming under the robot's limits and the ZMP (:func:`retime`), the
planner that strings states, paths and checks together, and the gaits that move the body over the ground
(:mod:`.gaits`: rolling, sidewinding, turning in place)."""
from .cartesian import CartesianInterpolation, cartesian_interpolation, cartesian_trajectory
from .gaits import GAITS, Gait, Wave, make_gait, virtual_chassis
from .interpolation import CONTROL_PERIOD, JointTrajectory, MonotoneQuintic, joint_interpolation, joint_trajectory
from .timing import RetimedTrajectory, RetimingLimits, retime

__all__ = ["CONTROL_PERIOD", "JointTrajectory", "MonotoneQuintic", "joint_interpolation", "joint_trajectory",
           "CartesianInterpolation", "cartesian_interpolation", "cartesian_trajectory", "GAITS", "Gait", "Wave",
           "make_gait", "virtual_chassis", "retime", "RetimedTrajectory", "RetimingLimits"]
