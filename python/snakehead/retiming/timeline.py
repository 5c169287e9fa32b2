"""The retimed motion as a function of time (:class:`Timeline`): rest-to-rest pieces along their paths, each stage
at its constant path acceleration, and pauses."""
from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from .._errors import InputError
from .._validate import finite_array
from .joint_path import PathFunction, path_derivatives

__all__ = ["Timeline"]


class Timeline:
    """The retimed motion as a function of time: rest-to-rest pieces along their paths, and pauses."""

    def __init__(self, n: int) -> None:
        self.n = n
        self.items: list[dict[str, Any]] = []
        self.end = 0.0

    def add_piece(self, f: PathFunction, s: np.ndarray, sd: np.ndarray) -> np.ndarray:
        """A piece along path f through gridpoints s (N,) at path speeds sd (N,), after what came before; returns
        the times (N,) s at its gridpoints."""
        ds = np.diff(s)
        mean = 0.5 * (sd[:-1] + sd[1:])
        dt = ds / mean  # constant path acceleration over each stage
        u = (sd[1:] ** 2 - sd[:-1] ** 2) / (2 * ds)
        t = self.end + np.r_[0.0, np.cumsum(dt)]
        self.items.append(dict(kind="piece", t=t, s=s, sd=sd, u=u, f=f))
        self.end = float(t[-1])
        return t

    def add_pause(self, q: np.ndarray, seconds: float) -> None:
        """A pause of ``seconds`` s at q (n,)."""
        self.items.append(dict(kind="pause", t=np.array([self.end, self.end + seconds]), q=q))
        self.end += seconds

    def __call__(self, t: npt.ArrayLike, nu: int = 0) -> np.ndarray:
        if nu not in (0, 1, 2):
            raise InputError("nu must be 0, 1 or 2")
        return self.sample(t, (nu,))[0]

    def sample(self, t: npt.ArrayLike, orders: tuple[int, ...] = (0, 1, 2)) -> list[np.ndarray]:
        """The motion's derivatives of the given ``orders`` (0, 1, 2: q, qd, qdd) at times t: a list of (N, n), the
        path evaluated once for all of them. Times before the motion take its first item, after it its last."""
        t = np.atleast_1d(finite_array(t, "t"))
        if np.any(np.diff(t) < 0):  # in time order, then back in the caller's
            order = np.argsort(t, kind="stable")
            result = self.sample(t[order], orders)
            for r in result:
                r[order] = r.copy()
            return result
        out = [np.zeros((len(t), self.n)) for _ in orders]
        path_orders = tuple(sorted(set(orders) | ({1} if 2 in orders else set())))  # qdd needs q'(s) too
        # item k holds the times in [start_k, start_k+1) (the last item also its end and after): one search for all
        starts = np.array([item["t"][0] for item in self.items[1:]])
        bounds = np.r_[0, np.searchsorted(t, starts, side="left"), len(t)]
        for item, lo, hi in zip(self.items, bounds[:-1], bounds[1:]):
            if hi <= lo:
                continue
            if item["kind"] == "pause":
                for o, nu in zip(out, orders):
                    if nu == 0:
                        o[lo:hi] = item["q"]
                continue
            for o, value in zip(out, _piece_values(item, t[lo:hi], orders, path_orders)):
                o[lo:hi] = value
        return out


def _piece_values(item: dict[str, Any], t: np.ndarray, orders: tuple[int, ...], path_orders: tuple[int, ...]
                  ) -> list[np.ndarray]:
    """The derivatives of the given ``orders`` at times t (N,) within a piece (an item of :class:`Timeline`): each
    stage at its constant path acceleration u, so qd = q' s' and qdd = q' u + q'' s'^2. ``path_orders``: the path's
    derivatives they need."""
    tt = item["t"]
    i = np.clip(np.searchsorted(tt, t, side="right") - 1, 0, len(tt) - 2)
    tau = np.clip(t - tt[i], 0.0, tt[i + 1] - tt[i])
    s = np.clip(item["s"][i] + item["sd"][i] * tau + 0.5 * item["u"][i] * tau ** 2, item["s"][i], item["s"][i + 1])
    sd = np.maximum(item["sd"][i] + item["u"][i] * tau, 0.0)
    d = dict(zip(path_orders, path_derivatives(item["f"], s, path_orders)))
    values = []
    for nu in orders:
        if nu == 0:
            values.append(d[0])
        elif nu == 1:
            values.append(d[1] * sd[:, None])
        else:
            values.append(d[1] * item["u"][i][:, None] + d[2] * (sd ** 2)[:, None])
    return values
