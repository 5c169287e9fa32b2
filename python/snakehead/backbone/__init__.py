"""Backbone curves and their discretisation into joint angles (paper Section 2.1, Eqs. 1-9) and the initial
configuration of Section 3.3 (1) (Fig. 14).

* :mod:`.curves` -- :class:`SpaceCurve` (Eqs. 3-7) and :func:`cubic_bezier`.
* :mod:`.discretize` -- Eqs. 3-6 on a snake with yaw and pitch joints (:func:`curve_joint_angles`).
* :mod:`.base_arc` -- the base's plane arc (Eqs. 1, 2, 8, 9) and its optimised central angle.
* :mod:`.initial` -- the base arc joined G1 to the neck-and-head Bezier: :func:`initial_configuration`.
"""
from .base_arc import (
                       CHORD_MODES,
                       ArcOptimum,
                       PlaneArc,
                       arc_angle_limit,
                       arc_area_maximum,
                       arc_joint_angles,
                       arc_segment_area,
                       base_arc,
                       exact_chord_radius,
                       optimize_base_arc,
                       polygon_area,
)
from .curves import SpaceCurve, cubic_bezier
from .discretize import curve_joint_angles, discretize, joint_intervals
from .initial import InitialBackbone, UpCurveShape, initial_backbone, initial_configuration, up_curve, up_length

__all__ = ["SpaceCurve", "cubic_bezier", "curve_joint_angles", "discretize", "joint_intervals", "PlaneArc",
           "CHORD_MODES", "ArcOptimum", "arc_angle_limit", "arc_area_maximum", "arc_joint_angles", "arc_segment_area",
           "base_arc", "exact_chord_radius", "optimize_base_arc", "polygon_area", "InitialBackbone",
           "UpCurveShape", "initial_backbone", "initial_configuration", "up_curve", "up_length"]
