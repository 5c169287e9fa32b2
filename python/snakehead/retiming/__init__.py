"""Time-optimal retiming of a whole-body path (TOPP-RA in the C++ core) under the robot's joint limits, torques,
friction and the ZMP in the support polygon: :func:`retime`."""
from .timing import RetimedTrajectory, RetimingLimits, retime

__all__ = ["retime", "RetimedTrajectory", "RetimingLimits"]
