"""Stability of the body (paper Section 3.1, Eqs. 23-40): centre of mass, support polygon, momenta, ZMP."""
from .stability import (DynamicStability, center_of_mass, dynamic_stability, momenta, static_margin,
                        support_polygon, zmp)

__all__ = ["DynamicStability", "center_of_mass", "dynamic_stability", "momenta", "static_margin",
           "support_polygon", "zmp"]
