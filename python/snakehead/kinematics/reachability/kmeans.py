"""k-means++ clustering (Lloyd's iterations, several seeded starts) in numpy, for the dexterous workspace's clusters
(Eqs. 16-17; :meth:`snakehead.kinematics.reachability.reachability_map.ReachabilityMap.clusters`).

It follows scikit-learn's ``KMeans(init="k-means++", n_init, random_state)`` step for step -- the same draws from
``numpy.random.RandomState(random_state)`` for the greedy k-means++ seeding (2 + log k candidates per centre), the
same Lloyd's iterations with the same stopping rule (labels unchanged, or the centres' squared shift within
``tol`` times the data's mean variance), the best start by inertia -- so that it gives scikit-learn's clusters
(tested against it) without importing it (scikit-learn is slow to import, and every ``snakehead demo`` clusters a
map).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..._errors import InputError

#: scikit-learn's defaults, which the map's clusters were made with.
MAX_ITER = 300
TOL = 1e-4


@dataclass(frozen=True)
class KMeansResult:
    """``centers`` (k, d), ``labels`` (n,) the cluster of each point, ``inertia`` the sum of squared distances of
    the points to their centres."""

    centers: np.ndarray
    labels: np.ndarray
    inertia: float


def kmeans(points: npt.ArrayLike, k: int, *, n_init: int = 10, random_state: int = 0, max_iter: int = MAX_ITER,
           tol: float = TOL) -> KMeansResult:
    """k-means++ with Lloyd's iterations from ``n_init`` seeded starts; the start of least inertia."""
    X = np.array(points, dtype=float)
    if X.ndim != 2 or len(X) < k or k < 1:
        raise InputError(f"points must be (n, d) with n >= k = {k}, got shape {X.shape}")
    mean = X.mean(axis=0)
    X -= mean  # as scikit-learn: distances of centred data are more accurate
    sq_norms = np.einsum("ij,ij->i", X, X)
    rng = np.random.RandomState(random_state)
    threshold = float(np.mean(np.var(X, axis=0))) * tol
    best: KMeansResult | None = None
    for _ in range(n_init):
        run = _lloyd(X, _plus_plus(X, k, sq_norms, rng), max_iter, threshold)
        if best is None or (run.inertia < best.inertia and not _same_clustering(run.labels, best.labels, k)):
            best = run
    assert best is not None  # n_init >= 1
    return KMeansResult(best.centers + mean, best.labels, best.inertia)


def _squared_distances(A: np.ndarray, X: np.ndarray, sq_norms: np.ndarray) -> np.ndarray:
    """(len(A), len(X)) squared distances by |a|^2 - 2 a.x + |x|^2, clipped at 0 (scikit-learn's formula)."""
    d = np.einsum("ij,ij->i", A, A)[:, None] - 2.0 * (A @ X.T) + sq_norms[None, :]
    return np.maximum(d, 0.0, out=d)


def _plus_plus(X: np.ndarray, k: int, sq_norms: np.ndarray, rng: np.random.RandomState) -> np.ndarray:
    """Greedy k-means++ seeding: each next centre the best of 2 + log(k) candidates drawn in proportion to the
    squared distance to the nearest centre so far."""
    n = len(X)
    trials = 2 + int(np.log(k))
    weight = np.ones(n)
    centers = np.empty((k, X.shape[1]))
    centers[0] = X[rng.choice(n, p=weight / weight.sum())]
    closest = _squared_distances(centers[:1], X, sq_norms)[0]
    potential = closest @ weight
    for c in range(1, k):
        draws = rng.uniform(size=trials) * potential
        ids = np.minimum(np.searchsorted(np.cumsum(weight * closest), draws), n - 1)
        candidates = np.minimum(closest, _squared_distances(X[ids], X, sq_norms))
        pots = candidates @ weight
        best = int(np.argmin(pots))
        potential, closest = pots[best], candidates[best]
        centers[c] = X[ids[best]]
    return centers


def _assign(X: np.ndarray, centers: np.ndarray) -> np.ndarray:
    """The nearest centre of each point."""
    d = np.einsum("ij,ij->i", centers, centers)[None, :] - 2.0 * (X @ centers.T)
    return np.argmin(d, axis=1)


def _update(X: np.ndarray, labels: np.ndarray, old: np.ndarray) -> np.ndarray:
    """Each cluster's mean (summed in point order, times 1/count); an empty cluster takes the point farthest from
    its own centre (scikit-learn's relocation)."""
    k = len(old)
    sums = np.zeros_like(old)
    np.add.at(sums, labels, X)
    counts = np.bincount(labels, minlength=k).astype(float)
    empty = np.flatnonzero(counts == 0)
    if len(empty):
        far = ((X - old[labels]) ** 2).sum(axis=1)
        if far.max() > 0:
            for cluster, i in zip(empty, np.argsort(-far, kind="stable")[: len(empty)]):
                sums[labels[i]] -= X[i]
                counts[labels[i]] -= 1.0
                sums[cluster] = X[i]
                counts[cluster] = 1.0
    filled = counts > 0
    sums[filled] *= (1.0 / counts[filled])[:, None]
    sums[~filled] = old[~filled]
    return sums


def _lloyd(X: np.ndarray, centers: np.ndarray, max_iter: int, tol: float) -> KMeansResult:
    """Lloyd's iterations until the labels stop changing or the centres' squared shift is within ``tol``; the
    labels are then those of the final centres."""
    labels_old = np.full(len(X), -1)
    strict = False
    for _ in range(max_iter):
        labels = _assign(X, centers)
        new = _update(X, labels, centers)
        shift = float(((new - centers) ** 2).sum())
        centers = new
        if np.array_equal(labels, labels_old):
            strict = True
            break
        if shift <= tol:
            break
        labels_old = labels
    if not strict:
        labels = _assign(X, centers)
    inertia = float(((X - centers[labels]) ** 2).sum())
    return KMeansResult(centers, labels, inertia)


def _same_clustering(a: np.ndarray, b: np.ndarray, k: int) -> bool:
    """Whether two labellings are the same partition (up to renaming the clusters)."""
    mapping = np.full(k, -1)
    for x, y in zip(a, b):
        if mapping[x] == -1:
            mapping[x] = y
        elif mapping[x] != y:
            return False
    return True


__all__ = ["KMeansResult", "kmeans"]
