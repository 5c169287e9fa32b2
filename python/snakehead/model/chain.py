"""`Chain`: a serial chain of a URDF between two named links, with its kinematics (C++ core)."""
from __future__ import annotations

import os

import numpy as np
import numpy.typing as npt

from .. import _core
from .._errors import InputError, InputTypeError
from .._validate import finite_array, joint_vector

__all__ = ["Chain", "check_utf8"]


def check_utf8(text: str, name: str) -> None:
    """InputError naming ``name`` for a str that is not valid UTF-8 (lone surrogates): the core takes UTF-8, and
    pybind11's conversion of such a str fails with an "incompatible function arguments" TypeError that names no
    argument."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise InputError(f"{name} is not valid text: {exc.reason} at position {exc.start}") from None


class Chain:
    """An immutable kinematic chain from ``base`` to ``tip``.

    Joint vectors are 1-D float64 arrays in chain order (rad for revolute, m for prismatic joints);
    poses are 4x4 homogeneous transforms in the base link's frame. Fixed joints are folded into the
    moving segments, but every link on the path (fixed ones included) has a frame in ``fk_all``.
    """

    def __init__(self, model: _core.ChainModel, urdf: str | None = None) -> None:
        if not isinstance(model, _core.ChainModel):
            raise InputTypeError("model must be a snakehead._core.ChainModel (use Chain.from_urdf), got "
                                 f"{type(model).__name__}")
        self._model = model
        #: The URDF the chain was read from (a path or the XML), when known: lets workers rebuild it.
        self.urdf = urdf

    @classmethod
    def from_urdf(cls, urdf: str | os.PathLike, base: str, tip: str) -> "Chain":
        """Parse ``urdf`` (a path, or an XML string starting with ``<``) and take the chain base -> tip.

        Raises ValueError for a missing file, a path that is not a regular file (a directory, a FIFO,
        /dev/zero) or a text larger than 8 MiB, elements nested more than 100 levels deep, malformed XML
        (with urdfdom's own message, which is never printed), unknown links, a base that is not an ancestor
        of the tip, invalid joint data (e.g. lower limit > upper limit), or invalid link bodies (a malformed
        number, a negative mass, an inertia that is not positive semidefinite, a box of size <= 0),
        naming the link and the element. TypeError when an argument is not a str (or a path).
        """
        if isinstance(urdf, os.PathLike):
            urdf = os.fspath(urdf)
        if not isinstance(urdf, str):
            raise InputTypeError(f"urdf must be a path or an XML string, got {type(urdf).__name__}")
        if not isinstance(base, str) or not isinstance(tip, str):
            raise InputTypeError("base and tip must be link names (str)")
        for name, text in (("urdf", urdf), ("base", base), ("tip", tip)):
            check_utf8(text, name)
        return cls(_core.ChainModel.from_urdf(urdf, base, tip), urdf)

    # --- description -------------------------------------------------------------------------
    @property
    def model(self) -> _core.ChainModel:
        """The C++ model (shared, immutable)."""
        return self._model

    @property
    def base(self) -> str:
        return self._model.base

    @property
    def tip(self) -> str:
        return self._model.tip

    @property
    def n_joints(self) -> int:
        return self._model.n_joints

    @property
    def joint_names(self) -> list[str]:
        return self._model.joint_names

    @property
    def joint_types(self) -> list[str]:
        return self._model.joint_types

    @property
    def lower(self) -> np.ndarray:
        """Lower joint limits, shape (n,); -inf for continuous joints."""
        return self._model.lower

    @property
    def upper(self) -> np.ndarray:
        return self._model.upper

    @property
    def link_names(self) -> list[str]:
        """Every link from base to tip inclusive; the rows of ``fk_all``."""
        return self._model.link_names

    @property
    def reach(self) -> float:
        """Sum of the distances between consecutive joints and to the tip (m): no point is farther."""
        return self._model.reach

    @property
    def hash(self) -> str:
        """Digest of the chain's kinematics; maps record it to know which chain they belong to."""
        return self._model.hash

    @property
    def body_hash(self) -> str:
        """Digest of the links' bodies (masses, centres of mass, inertias, collision shapes), which ``hash``
        leaves out: together they cover everything the chain holds."""
        return self._model.body_hash

    @property
    def total_mass(self) -> float:
        """Sum of the link masses on the chain (kg). 0 for a URDF without ``<inertial>``: whatever needs a
        centre of mass must refuse such a chain."""
        return self._model.total_mass

    def link_index(self, name: str) -> int:
        try:
            return self.link_names.index(name)
        except ValueError:
            raise InputError(f"link {name!r} is not on the chain {self.base!r} -> {self.tip!r}") from None

    # --- kinematics --------------------------------------------------------------------------
    def fk(self, q: npt.ArrayLike) -> np.ndarray:
        """Pose of the tip in the base frame, (4, 4)."""
        return self._model.fk(joint_vector(q, self.n_joints))

    def fk_all(self, q: npt.ArrayLike) -> np.ndarray:
        """Poses of every link of ``link_names`` in the base frame, (n_links, 4, 4)."""
        return self._model.fk_all(joint_vector(q, self.n_joints))

    def fk_all_many(self, qs: npt.ArrayLike, origin: npt.ArrayLike | None = None) -> np.ndarray:
        """``fk_all`` for many configurations: qs (T, n) -> (T, n_links, 4, 4); with ``origin`` (the pose (4, 4) of
        the chain's base frame) in origin's frame: origin @ fk_all(q), multiplied in the core."""
        qs = finite_array(qs, "qs", (None, self.n_joints))
        if origin is not None:
            origin = finite_array(origin, "origin", (4, 4))
        return self._model.fk_all_many(np.ascontiguousarray(qs), origin)

    def jacobian(self, q: npt.ArrayLike) -> np.ndarray:
        """Geometric Jacobian of the tip, (6, n): rows (v, omega) in the base frame, point at the tip."""
        return self._model.jacobian(joint_vector(q, self.n_joints))

    def random_configuration(self, rng: np.random.Generator | None = None) -> np.ndarray:
        """Uniform within the limits (continuous joints in [-pi, pi])."""
        rng = np.random.default_rng() if rng is None else rng
        lo = np.where(np.isfinite(self.lower), self.lower, -np.pi)
        hi = np.where(np.isfinite(self.upper), self.upper, np.pi)
        return rng.uniform(lo, hi)

    def __repr__(self) -> str:
        return f"Chain({self.base!r} -> {self.tip!r}, {self.n_joints} joints)"
