"""Stability of the body (paper Section 3.1, Eqs. 23-40): centre of mass, support polygon, momenta, ZMP; and the
joint torques of a snake lying on the ground (Newton-Euler, :mod:`.inverse_dynamics`). Off the flat floor: contacts at
many heights and their contact wrench cone (:mod:`.contact_set`), the static-equilibrium region of the CoM
(:mod:`.equilibrium_region`) and dynamic balance in the cone (:mod:`.wrench_balance`)."""
from .contact_set import ContactSet, contact_wrench_cone, contact_wrench_span, flat_contacts, friction_cone_generators
from .equilibrium_region import EquilibriumRegion, region_margin, static_equilibrium_lp, static_equilibrium_region
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
from .wrench_balance import (
    cwc_margin,
    gravito_inertial_wrench,
    gravito_inertial_wrenches,
    is_balanced_lp,
    zmp_on_plane,
    zmp_support_area,
)

__all__ = ["DynamicStability", "center_of_mass", "dynamic_stability", "momenta", "static_margin",
           "support_polygon", "support_polygons", "zmp", "inverse_dynamics", "newton_euler", "momentum_rates",
           "carried_weights", "ContactSet", "contact_wrench_cone", "contact_wrench_span", "flat_contacts",
           "friction_cone_generators", "EquilibriumRegion", "static_equilibrium_region", "region_margin",
           "static_equilibrium_lp", "cwc_margin", "gravito_inertial_wrench", "gravito_inertial_wrenches",
           "is_balanced_lp", "zmp_on_plane", "zmp_support_area"]
