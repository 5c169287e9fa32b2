"""Input checks shared by every public function: numpy in, a clear ValueError out."""
from __future__ import annotations

from typing import Any

import numpy as np

import numpy.typing as npt

ORTHONORMAL_TOLERANCE = 1e-6


def finite_array(x: npt.ArrayLike, name: str, shape: tuple | None = None) -> np.ndarray:
    """``x`` as a float64 array; ValueError unless finite and (when given) of ``shape`` (None = any size)."""
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be an array of numbers: {exc}") from None
    if shape is not None:
        if a.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, a.shape)):
            want = "(" + ", ".join("any" if s is None else str(s) for s in shape) + ")"
            raise ValueError(f"{name} has shape {a.shape}; expected {want}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or inf")
    return a


def joint_vector(q: npt.ArrayLike, n: int, name: str = "q") -> np.ndarray:
    """A 1-D float64 vector of ``n`` finite joint values."""
    return finite_array(q, name, (n,))


def vector3(v: npt.ArrayLike, name: str) -> np.ndarray:
    return finite_array(v, name, (3,))


def unit_vector3(v: npt.ArrayLike, name: str) -> np.ndarray:
    a = vector3(v, name)
    norm = float(np.linalg.norm(a))
    if norm < 1e-12:
        raise ValueError(f"{name} has zero length; a direction is needed")
    return a / norm


def position_direction_pairs(positions: npt.ArrayLike, directions: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray, bool]:
    """Poses given as positions and directions, (3,) or (K, 3) each: (K, 3) positions, (K, 3) unit directions and
    whether one pose was given. ValueError for wrong shapes, NaN or inf, unequal counts or a zero direction."""
    p = finite_array(positions, "positions")
    d = finite_array(directions, "directions")
    single = p.ndim == 1 and d.ndim == 1
    p, d = np.atleast_2d(p), np.atleast_2d(d)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"positions must have shape (3,) or (K, 3), got {np.shape(positions)}")
    if d.ndim != 2 or d.shape[1] != 3:
        raise ValueError(f"directions must have shape (3,) or (K, 3), got {np.shape(directions)}")
    if len(p) != len(d):
        raise ValueError(f"{len(p)} positions but {len(d)} directions; give one direction per position")
    norm = np.linalg.norm(d, axis=1)
    if np.any(norm < 1e-12):
        raise ValueError(f"directions must be non-zero; direction {int(np.argmin(norm))} has zero length")
    return p, d / norm[:, None], single


def pose(T: npt.ArrayLike, name: str = "pose") -> np.ndarray:
    """A 4x4 homogeneous transform with an orthonormal, right-handed rotation."""
    a = finite_array(T, name, (4, 4))
    if not np.allclose(a[3], (0.0, 0.0, 0.0, 1.0), atol=1e-9):
        raise ValueError(f"{name} last row must be [0, 0, 0, 1], got {a[3].tolist()}")
    rotation_matrix(a[:3, :3], name + " rotation")
    return a


def rotation_matrix(R: npt.ArrayLike, name: str = "rotation") -> np.ndarray:
    a = finite_array(R, name, (3, 3))
    err = np.abs(a.T @ a - np.eye(3)).max()
    if err > ORTHONORMAL_TOLERANCE or np.linalg.det(a) < 0:
        raise ValueError(f"{name} is not a rotation (orthonormality error {err:.2e}, det {np.linalg.det(a):+.3f})")
    return a


def positive(x: npt.ArrayLike, name: str) -> float:
    """``x`` as a positive finite float; ValueError naming ``name`` otherwise."""
    v = finite_float(x, name)
    if v <= 0:
        raise ValueError(f"{name} must be a positive finite number, got {x!r}")
    return v


def finite_float(x: Any, name: str) -> float:
    """``x`` as a finite float; ValueError naming ``name`` otherwise."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {x!r}") from None
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {x!r}")
    return v
