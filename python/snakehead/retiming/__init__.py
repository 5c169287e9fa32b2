"""Time-optimal retiming of a whole-body path (TOPP-RA in the C++ core) under the robot's joint limits, torques,
friction and the ZMP in the support polygon: :func:`retime`.

Its modules, one concept each: :mod:`.timing` (:func:`retime`, :class:`RetimedTrajectory`), :mod:`.retiming_limits`
(:class:`RetimingLimits` and their defaults), :mod:`.joint_path` (the path q(s) through the waypoints),
:mod:`.path_dynamics` (Newton-Euler along it in TOPP-RA's form), the constraints (:mod:`.joint_constraints`: joint
velocity, acceleration and torque; :mod:`.stability_constraint`: the ZMP in the :mod:`.support_polygon`, friction,
the ground pushing), :mod:`.topp_ra` (the canonical rows and the solve in the core), :mod:`.gridpoints` (what the
solve needs at each gridpoint), :mod:`.grid_refinement` (probing between gridpoints), :mod:`.rest_to_rest` (one
piece timed), :mod:`.timeline` (the motion as a function of time) and :mod:`.limit_check` (a sampled trajectory
against the limits)."""
from .timing import RetimedTrajectory, RetimingLimits, retime

__all__ = ["retime", "RetimedTrajectory", "RetimingLimits"]
