"""The poses a sweep tries at a voxel (Algorithm 1): points spread evenly over the voxel's inscribed sphere (a
Fibonacci lattice), and at each point a frame whose approach axis runs from the sphere's centre to the point, rolled
about that axis. Both are the C++ core's, so that a map's directions are the sweep's."""
from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from ... import _core
from ..._errors import InputError
from ..._validate import finite_array
from .sweep_options import MAX_DIRECTIONS, checked_count


def fibonacci_directions(n: int) -> np.ndarray:
    """n unit vectors spread evenly over the sphere (the sweep's Fibonacci lattice), (n, 3)."""
    return _core.fibonacci_directions(checked_count("n (directions)", n, 1, MAX_DIRECTIONS))


def approach_frame(point: npt.ArrayLike, direction: npt.ArrayLike, roll: float = 0.0, axis: str = "x") -> np.ndarray:
    """The sweep's frame at ``point`` whose ``axis`` ('x' or 'z') is ``direction``, rolled by ``roll`` rad, (4, 4)."""
    p = finite_array(point, "point", (3,))
    d = finite_array(direction, "direction", (3,))
    if not math.isfinite(float(roll)):
        raise InputError("roll must be finite")
    return _core.approach_frame(p, d, float(roll), axis)


__all__ = ["fibonacci_directions", "approach_frame"]
