"""Stability of the body (paper Section 3.1, Eqs. 23-40): centre of mass, support polygon, momenta, ZMP; and the
joint torques of a snake lying on the ground (Newton-Euler, :mod:`.inverse_dynamics`)."""
from .inverse_dynamics import carried_weights, inverse_dynamics, momentum_rates, newton_euler
from .stability import (
                        DynamicStability,
                        center_of_mass,
                        dynamic_stability,
                        momenta,
                        static_margin,
                        support_polygon,
                        support_polygons,
                        zmp,
)

__all__ = ["DynamicStability", "center_of_mass", "dynamic_stability", "momenta", "static_margin",
           "support_polygon", "support_polygons", "zmp", "inverse_dynamics", "newton_euler", "momentum_rates",
           "carried_weights"]
