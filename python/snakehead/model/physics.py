"""The physical world the robots lie in, each number defined once: gravity and the friction of the ground.

The ZMP (:mod:`snakehead.dynamics.stability`, Eq. 38), inverse dynamics, the generated robots' efforts, the
retiming's friction constraint (:mod:`snakehead.retiming.timing`) and the MuJoCo model (:mod:`snakehead.sim`) read
them from here.
"""
from __future__ import annotations

#: Standard gravity (m/s^2); g in Eq. 38 is (0, 0, -GRAVITY).
GRAVITY = 9.80665
#: The ground's Coulomb (sliding) friction coefficient: the MuJoCo model's by default (``sim.build_spec``), of which
#: the retiming allows the base a share (``retiming.timing.FRICTION``).
GROUND_FRICTION = 0.8

__all__ = ["GRAVITY", "GROUND_FRICTION"]
