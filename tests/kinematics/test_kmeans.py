"""The numpy k-means++ of the dexterous workspace's clusters (snakehead.kinematics.reachability.kmeans) against scikit-learn's
KMeans (the test-only reference it replaces): the same partition and centres on the default map's dexterous voxels
and on random clustered and unclustered point sets."""
from __future__ import annotations

import numpy as np
import pytest

from snakehead import InputError
from snakehead.kinematics.reachability.kmeans import kmeans


def _sklearn_cluster():
    """scikit-learn's clustering, for the comparisons only (skipped without it, a failure in CI)."""
    return pytest.importorskip("sklearn.cluster")


def _same_partition(a: np.ndarray, b: np.ndarray) -> bool:
    pairs = set(zip(a.tolist(), b.tolist()))
    return len(pairs) == len(set(a.tolist())) == len(set(b.tolist()))


def _check_against_sklearn(points: np.ndarray, k: int, seed: int) -> None:
    ours = kmeans(points, k, n_init=10, random_state=seed)
    ref = _sklearn_cluster().KMeans(n_clusters=k, init="k-means++", n_init=10, random_state=seed).fit(points)
    assert _same_partition(ours.labels, ref.labels_)
    # the same clusters; which number each gets is not compared (it follows the seeding's draws, whose near-ties
    # scikit-learn's BLAS and ours may round apart, and scikit-learn is not pinned): the centres of the same clusters
    theirs = {a: b for a, b in zip(ours.labels.tolist(), ref.labels_.tolist())}
    np.testing.assert_allclose(ours.centers, ref.cluster_centers_[[theirs[c] for c in range(k)]], rtol=0, atol=1e-12)
    assert ours.inertia == pytest.approx(ref.inertia_, rel=1e-9)
    # the centres are the means of their clusters (Lloyd's fixed point)
    for c in range(k):
        np.testing.assert_allclose(ours.centers[c], points[ours.labels == c].mean(axis=0), atol=1e-12)


def test_the_default_maps_g0_is_scikit_learns() -> None:
    from snakehead.kinematics import reachability as workspace
    from snakehead.model.robot import SnakeRobot

    m = workspace.map_for(SnakeRobot.default(), progress=False)
    pts = m.dexterous(m.dexterous_threshold())
    _check_against_sklearn(pts, 3, 0)
    ref = _sklearn_cluster().KMeans(n_clusters=3, init="k-means++", n_init=10, random_state=0).fit(pts)
    sizes = np.bincount(ref.labels_, minlength=3)
    largest = ref.cluster_centers_[int(np.argmax(sizes))]
    np.testing.assert_allclose(m.center(), largest, rtol=0, atol=1e-12)


@pytest.mark.parametrize("seed", range(6))
def test_random_blobs_and_noise_agree_with_scikit_learn(seed: int) -> None:
    rng = np.random.default_rng(seed)
    k = int(rng.integers(2, 6))
    if seed % 2:  # clustered: blobs around k centres
        centres = rng.uniform(-1, 1, (k, 3))
        points = np.vstack([c + 0.1 * rng.standard_normal((int(rng.integers(5, 60)), 3)) for c in centres])
    else:  # no structure: many local optima, so the seeding and the choice among starts matter
        points = rng.uniform(-1, 1, (int(rng.integers(20, 300)), 3))
    _check_against_sklearn(points, k, seed)


def test_grid_points_with_ties_agree_with_scikit_learn() -> None:
    """Voxel centres: on an exact grid, mirror images of the best partition have the same inertia to the last bit
    or two, and which one wins depends on the rounding of the sums (numpy's against scikit-learn's BLAS): the same
    inertia and cluster sizes then; a grid jittered by a nanometre has one best partition, and it is the same."""
    g = np.arange(6) * 0.05
    points = np.stack(np.meshgrid(g, g, g[:3], indexing="ij"), axis=-1).reshape(-1, 3)
    rng = np.random.default_rng(0)
    for seed in range(3):
        ours = kmeans(points, 3, random_state=seed)
        ref = _sklearn_cluster().KMeans(n_clusters=3, init="k-means++", n_init=10, random_state=seed).fit(points)
        assert ours.inertia == pytest.approx(ref.inertia_, rel=1e-12)
        assert sorted(np.bincount(ours.labels)) == sorted(np.bincount(ref.labels_))
        _check_against_sklearn(points + 1e-9 * rng.standard_normal(points.shape), 3, seed)


def test_bad_input() -> None:
    with pytest.raises(InputError, match=r"points must be \(n, d\) with n >= k = 3, got shape \(2, 3\)"):
        kmeans(np.zeros((2, 3)), 3)
    with pytest.raises(InputError, match=r"points must be \(n, d\) with n >= k = 1, got shape \(5,\)"):
        kmeans(np.zeros(5), 1)
