"""What the planner keeps from one plan for the next with the same :class:`~snakehead.solve.HeadController`
(:class:`PlanCache`, :func:`plan_cache_of`): the start states of the base shapes it has planned from, and the lift of the head from them, as a
checked path and as a timed motion, and the lift's part of the plan's ZMP check.

Every entry is a function of the controller's robot (fixed for the controller's life) and of the key, never of
where the base lies (the checks and the retiming are the same at every placement on the flat ground; the ZMP
check's part, in world coordinates, has the placement in its key), so an entry
stays valid as long as the controller does; what each key must hold for that is said with each field. Each map
holds at most a bounded number of entries and is emptied when full (the plans of a session use a few base shapes;
recomputing an entry gives the same value). The maps may be read and written from several threads planning with
one controller: a lookup is one ``get``, and ``put`` is serialised.
"""
from __future__ import annotations

import threading
import weakref
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Generic, TypeVar

import numpy as np

if TYPE_CHECKING:
    from ..dynamics.stability import KeptSamples
    from ..retiming.timing import RetimedTrajectory
    from ..solve.head_controller import HeadController

#: Lifts (checked paths, timed motions) a controller keeps: one per base shape planned from.
KEPT_LIFTS = 16
#: Base shapes whose bending state (or whose lack of one) a controller keeps.
KEPT_SHAPES = 256

K = TypeVar("K")
V = TypeVar("V")


class KeptMap(Generic[K, V]):
    """A map of at most ``most`` entries, emptied when a new entry would make it larger (the entries are cheap to
    recompute and few are in use at once: no order to keep)."""

    def __init__(self, most: int) -> None:
        self.most = int(most)
        self._items: dict[K, V] = {}
        self._lock = threading.Lock()

    def get(self, key: K) -> V | None:
        """The value kept for ``key``, None when there is none (one lookup: another thread may empty the map)."""
        return self._items.get(key)

    def put(self, key: K, value: V) -> V:
        """Keep ``value`` for ``key`` (emptying the map first when it is full); returns ``value``."""
        with self._lock:
            if key not in self._items and len(self._items) >= self.most:
                self._items.clear()
            self._items[key] = value
        return value

    def __contains__(self, key: object) -> bool:
        return key in self._items

    def __len__(self) -> int:
        return len(self._items)

    def clear(self) -> None:
        with self._lock:
            self._items.clear()


def shape_key(q: np.ndarray, lift_start: int, decimals: int | None = None) -> bytes:
    """The key of the base's flat shape of configuration ``q``: its joints before the neck's first lifting joint
    (``robot.lift_joints.start``), rounded to ``decimals`` (None: exact)."""
    shape = np.asarray(q, float)[:lift_start]
    return (shape if decimals is None else np.round(shape, decimals)).tobytes()


@dataclass
class PlanCache:
    """The plans' caches of one :class:`~snakehead.solve.HeadController` (:func:`plan_cache_of`).

    bending_states: base shape (:func:`shape_key`, exact) -> the bending state (n,) rad from that shape
        (:func:`~snakehead.planning.start_state.bending_state`); handed out as copies.
    shapes_without_curl: base shapes (:func:`shape_key` rounded to 1e-12 rad) that hold no stable curl of the neck
        and head (:func:`~snakehead.planning.start_state.bending_state` raised ``Infeasible``) or whose lift from it
        ends in no safe state (:func:`~snakehead.planning.start_state.lift_ends_safe`): the base's choice skips them
        (``planning.base_choice.has_curl``).
    lift_paths: (bending state, initial state with that base shape), both rounded to 1e-9 rad as bytes -> (the
        checked path of the lift between them (K, n) rad, the method that made it) (``Waypoints.move``). Kept for
        scenes without obstacles only (with them the lift is checked again).
    timed_lifts: (the lift's waypoints rounded to 1e-9 rad as bytes, ``repr`` of the sorted retiming options) ->
        the lift retimed (``retiming.timing.retime``). Invalid when the retiming's defaults change (the options given
        are in the key, the defaults are not): call :meth:`clear` then.
    checked_lifts: timed_lifts' key (any placement: KeptSamples moves it) -> the lift's part of the plan's ZMP check
        (``dynamics.stability.KeptSamples``, filled by the first plan's check; the core takes it over only when the
        motion begins with the very samples it was made from; at another placement of the base on the ground it
        moves the kept momenta, CoM and polygons there, the same to ~1e-15 m).
    """

    bending_states: KeptMap[bytes, np.ndarray] = field(default_factory=lambda: KeptMap(KEPT_SHAPES))
    shapes_without_curl: KeptMap[bytes, bool] = field(default_factory=lambda: KeptMap(KEPT_SHAPES))
    lift_paths: KeptMap[tuple[bytes, bytes], tuple[np.ndarray, str]] = field(
        default_factory=lambda: KeptMap(KEPT_LIFTS))
    timed_lifts: KeptMap[tuple[bytes, str], RetimedTrajectory] = field(default_factory=lambda: KeptMap(KEPT_LIFTS))
    checked_lifts: KeptMap[tuple[bytes, str], KeptSamples] = field(default_factory=lambda: KeptMap(KEPT_LIFTS))

    def clear(self) -> None:
        """Forget every entry."""
        for kept in (self.bending_states, self.shapes_without_curl, self.lift_paths, self.timed_lifts,
                     self.checked_lifts):
            kept.clear()


_CACHES: "weakref.WeakKeyDictionary[HeadController, PlanCache]" = weakref.WeakKeyDictionary()
_CACHES_LOCK = threading.Lock()


def plan_cache_of(controller: HeadController) -> PlanCache:
    """The :class:`PlanCache` of ``controller``: made at its first plan, gone with it (the controller is the key
    of a weak map, so the solve layer need not know what the planner keeps)."""
    with _CACHES_LOCK:
        cache = _CACHES.get(controller)
        if cache is None:
            cache = _CACHES[controller] = PlanCache()
    return cache


__all__ = ["PlanCache", "KeptMap", "shape_key", "plan_cache_of", "KEPT_LIFTS", "KEPT_SHAPES"]
