"""What counts as touching the ground, each tolerance defined once (tests/package/test_shared_numbers.py).

The planner's ground (the support polygon, the clearance checks, the whole-body solve's ground links) is exact: a
link lies at height 0, and a millimetre separates touching from lifted. A body that is simulated or measured rocks
and sinks into soft contacts by more, so the sliding model and the pose estimator allow a few millimetres.
"""
from __future__ import annotations

__all__ = ["GROUND_TOLERANCE", "RESTING_TOLERANCE"]

#: m: a collision shape within this height of the ground touches it, and the points of a link's shapes within this
#: of its lowest make its contact patch; a shape lower than this below the ground is driven into it.
GROUND_TOLERANCE = 1e-3
#: m: a link whose bottom is within this height of the lowest rests on the ground, where the body is simulated or
#: measured (the quasi-static sliding model, the pose estimator).
RESTING_TOLERANCE = 3e-3
