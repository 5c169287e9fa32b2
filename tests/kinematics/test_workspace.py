"""Reachability maps (Algorithm 1): the sweep through the bindings, the boundary, files (one writer; old files),
shards, Dask, workspace_gen, G0."""
from __future__ import annotations

import shutil
import subprocess
import sysconfig
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from conftest import SMALL_MAP, head6_robot

from snakehead import Chain, SnakeRobot, default_robot_file, sweep_defaults
from snakehead._errors import InputError, InputTypeError
from snakehead.kinematics import reachability as ws

SMALL = SMALL_MAP


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


@pytest.fixture(scope="module")
def small(small_map):
    return small_map


DATA = Path(__file__).resolve().parents[1] / "data"


def workspace_gen() -> str:
    """The workspace_gen installed with this interpreter's snakehead (PATH may lead to another install)."""
    exe = Path(sysconfig.get_path("scripts")) / "workspace_gen"
    found = str(exe) if exe.exists() else shutil.which("workspace_gen")
    assert found, "workspace_gen is not installed (the wheel installs it)"
    return found


def gen_args(robot, out, **kw):
    args = [workspace_gen(), "--urdf", str(robot.urdf), "--base", kw.pop("base", "neck_end"),
            "--tip", kw.pop("tip", "head_tip"), "--out", str(out), "--quiet"]
    for k, v in kw.items():
        args += [f"--{k.replace('_', '-')}", str(v)]
    return args


# --- geometry ---------------------------------------------------------------------------------------
def test_fibonacci_directions_unit_and_well_spread():
    for n in (1, 5, 20, 300):
        d = ws.fibonacci_directions(n)
        assert d.shape == (n, 3)
        np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12)
    d = ws.fibonacci_directions(300)
    # Evenly spread: centred, isotropic second moment, no two points much closer than an even
    # covering's spacing, and no spherical cap of the covering's size left empty.
    assert np.linalg.norm(d.mean(axis=0)) < 0.01
    np.testing.assert_allclose(d.T @ d / len(d), np.eye(3) / 3, atol=0.01)
    gaps = np.linalg.norm(d[:, None] - d[None], axis=2) + 10 * np.eye(len(d))
    spacing = np.sqrt(4 * np.pi / len(d))
    assert gaps.min() > 0.7 * spacing
    probes = np.random.default_rng(0).normal(size=(2000, 3))
    probes /= np.linalg.norm(probes, axis=1, keepdims=True)
    assert np.max(np.min(np.linalg.norm(probes[:, None] - d[None], axis=2), axis=1)) < 1.2 * spacing
    with pytest.raises(InputError, match=r"n \(directions\) must be between 1 and 4096, got 0"):
        ws.fibonacci_directions(0)


@pytest.mark.parametrize("axis, col", [("x", 0), ("z", 2)])
def test_approach_frame_axis_is_the_direction(axis, col):
    rng = np.random.default_rng(1)
    for _ in range(50):
        d, p, roll = rng.normal(size=3), rng.normal(size=3), rng.uniform(-4, 4)
        T = ws.approach_frame(p, d, roll, axis)
        R = T[:3, :3]
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)
        np.testing.assert_allclose(R[:, col], d / np.linalg.norm(d), atol=1e-12)
        np.testing.assert_allclose(T[:3, 3], p)
        np.testing.assert_allclose(T[3], [0, 0, 0, 1])
    with pytest.raises(InputError, match="approach direction must be a finite non-zero vector"):
        ws.approach_frame([0, 0, 0], [0, 0, 0])
    with pytest.raises(InputError, match="approach axis must be 'x' or 'z', got 'y'"):
        ws.approach_frame([0, 0, 0], [1, 0, 0], axis="y")


# --- the sweep ---------------------------------------------------------------------------------------
def test_voxel_out_of_reach_has_index_zero(robot):
    reach = robot.head_chain.reach
    far = [[0.0, 0.0, 2 * reach], [reach + 0.1, 0.0, 0.0], [-reach, -reach, 0.0]]
    np.testing.assert_array_equal(ws.evaluate(robot, far, voxel=0.1, directions=8), 0.0)


def test_small_map_indices_in_range(small, robot):
    d = small.indices
    assert len(small) > 50 and small.tried == 6
    assert d.min() >= 0.0 and d.max() <= 100.0 and d.max() > 0.0
    assert np.all(np.linalg.norm(small.centers, axis=1) <= robot.head_chain.reach)
    assert small.chain_hash == robot.head_chain.hash and (small.base, small.tip) == ("neck_end", "head_tip")
    # Centres are those of their grid ids.
    n = small.grid_shape[0]
    ijk = np.stack([small.voxel_ids // (n * n), (small.voxel_ids // n) % n, small.voxel_ids % n], axis=1)
    np.testing.assert_allclose(small.centers, small.grid_origin + (ijk + 0.5) * small.voxel_size, atol=1e-12)
    assert small.grid_size == pytest.approx(n * 0.15) and small.grid_size >= 2 * robot.head_chain.reach


def test_same_map_for_any_thread_count(robot, small):
    one = ws.compute(robot, progress=False, threads=1, **SMALL)
    three = ws.compute(robot, progress=False, threads=3, **SMALL)
    assert one.same_map_as(small) and three.same_map_as(small)
    assert one.stats["threads"] == 1 and three.stats["threads"] == 3


def test_shards_merge_exactly(robot, small):
    parts = [ws.compute(robot, progress=False, shard=(i, 3), **SMALL) for i in (2, 0, 1)]
    assert sum(len(p) for p in parts) == len(small)
    merged = ws.merge(parts)
    assert merged.same_map_as(small) and merged.shard == (0, 1)
    with pytest.raises(ValueError, match="3 shards"):
        ws.merge(parts[:2])
    with pytest.raises(ValueError, match="twice"):
        ws.merge([parts[0], parts[0], parts[1]])
    other = ws.compute(robot, progress=False, shard="1/3", **{**SMALL, "seed": 4})
    with pytest.raises(ValueError, match="different maps"):
        ws.merge([parts[0], parts[1], other])


def test_executor_shards_equal_one_process(robot, small):
    with ThreadPoolExecutor(2) as ex:
        m = ws.compute(robot, progress=False, executor=ex, shards=4, **SMALL)
    assert m.same_map_as(small)


def test_dask_local_cluster(robot, small):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            m = ws.compute(robot, progress=False, executor=client.get_executor(), shards=3, **SMALL)
    assert m.same_map_as(small)
    assert "shards=3" in m.command


def test_chain_with_executor_needs_its_urdf(robot, small):
    from snakehead import Chain

    chain = robot.head_chain  # made by Chain.from_urdf: it knows its URDF
    bare = Chain(chain.model)  # made from a model alone: it does not
    with ThreadPoolExecutor(1) as ex:
        with pytest.raises(ValueError, match="urdf="):
            ws.compute(bare, progress=False, executor=ex, **SMALL)
        m = ws.compute(bare, progress=False, executor=ex, shards=2, urdf=robot.urdf, **SMALL)
        assert m.same_map_as(small)
        assert ws.compute(chain, progress=False, executor=ex, shards=2, **SMALL).same_map_as(small)
        six = head6_robot().head_chain
        with pytest.raises(ValueError, match="different kinematics"):
            ws.compute(six, progress=False, executor=ex, urdf=_other_urdf(robot), **SMALL)


def _other_urdf(robot) -> str:
    # The same robot with the head link 1 cm longer: a different chain.
    text = Path(robot.urdf).read_text()
    return text.replace('<origin xyz="0.046 0 0"', '<origin xyz="0.056 0 0"', 1)


def test_progress_bar(robot, capsys):
    m = ws.compute(robot, progress=True, **SMALL)
    assert len(m) > 0
    assert "reachability" in capsys.readouterr().err


# --- files --------------------------------------------------------------------------------------------
def test_round_trip(small, tmp_path):
    path = tmp_path / "map.npz"
    small.save(path)
    back = ws.load(path)
    assert back.same_map_as(small)
    assert back.params == small.params and back.shard == small.shard and back.command == small.command
    z = np.load(path, allow_pickle=False)
    np.testing.assert_allclose(z["indices"], small.indices)
    assert str(z["approach_axis"]) == "x" and int(z["directions"]) == 6


def test_workspace_gen_output_reads_with_numpy(robot, small, tmp_path):
    out = tmp_path / "gen.npz"
    args = gen_args(robot, out, voxel=0.15, directions=6, rolls=2, cloud_samples=3000, seed=3, timeout=3e-4,
                    threads=2)
    subprocess.run(args, check=True, capture_output=True, text=True, timeout=120)
    z = np.load(out, allow_pickle=False)
    assert z["centers"].shape == (len(small), 3) and z["centers"].dtype == np.float64
    np.testing.assert_allclose(z["indices"], small.indices)
    assert str(z["chain_hash"]) == robot.head_chain.hash
    assert str(z["base"]) == "neck_end" and str(z["tip"]) == "head_tip"
    assert float(z["voxel_size"]) == 0.15 and int(z["rolls"]) == 2 and bool(z["any_roll"])
    assert list(z["shard"]) == [0, 1] and list(z["grid_shape"]) == [small.grid_shape[0]] * 3
    assert "--voxel 0.15" in str(z["command"])
    assert ws.load(out).same_map_as(small)
    # The same map written by Python's save: every array identical but the run's own records.
    py = tmp_path / "py.npz"
    small.save(py)
    zp = np.load(py, allow_pickle=False)
    assert sorted(zp.files) == sorted(z.files)
    for key in z.files:
        if key not in ("command", "seconds", "threads"):
            assert z[key].dtype == zp[key].dtype and np.array_equal(z[key], zp[key]), key
    # A shard from workspace_gen merges with shards from Python.
    gen_shard = tmp_path / "s0.npz"
    subprocess.run(gen_args(robot, gen_shard, voxel=0.15, directions=6, rolls=2, cloud_samples=3000, seed=3,
                            timeout=3e-4, shard="0/2"), check=True, timeout=120)
    assert list(np.load(gen_shard)["shard"]) == [0, 2]
    merged = ws.merge([ws.load(gen_shard), ws.compute(robot, progress=False, shard=(1, 2), **SMALL)])
    assert merged.same_map_as(small)


def test_map_reads_with_numpy_alone(small, tmp_path):
    path = tmp_path / "map.npz"
    small.save(path)
    z = np.load(path, allow_pickle=False)
    assert str(z["format"]) == ws.FORMAT and str(z["hull"]) == "boundary" and 0 < float(z["alpha"]) < 1
    # The per-direction bits: one per direction of each voxel, as many set as the voxel's solved count.
    bits = np.unpackbits(z["reached"], axis=1, count=int(z["tried"]), bitorder="little")
    np.testing.assert_array_equal(bits.sum(axis=1), z["solved"])
    np.testing.assert_allclose(100 * bits.mean(axis=1), z["indices"])
    np.testing.assert_allclose(z["sphere_directions"], ws.fibonacci_directions(6))


def test_old_map_loads_and_says_what_it_lacks(robot, tmp_path):
    # tests/data/map_format1.npz: written by the previous release's workspace_gen with SMALL's options.
    old = ws.load(DATA / "map_format1.npz")
    assert old.lacks == ("reached",) and old.reached is None and "lacks reached" in repr(old)
    assert old.params["hull"] == "convex" and old.params["shrink"] == 0.0
    assert old.tried == 6 and len(old) == old.hull_voxels > 50
    with pytest.raises(ValueError, match="no per-direction results"):
        old.reachable([0.2, 0.0, 0.0], [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="no per-direction results"):
        old.inverse([0.2, 0.0, 0.0], [1.0, 0.0, 0.0])
    # Written again (by the one writer) it stays what it was: a map without the bits.
    path = tmp_path / "again.npz"
    old.save(path)
    again = ws.load(path)
    assert again.same_map_as(old) and again.lacks == ("reached",) and "reached" not in np.load(path).files
    # The convex hull is unchanged: this release's convex map of the same options has the same voxels.
    convex = ws.compute(robot, progress=False, hull="convex", **SMALL)
    np.testing.assert_array_equal(convex.voxel_ids, old.voxel_ids)
    np.testing.assert_allclose(convex.centers, old.centers, rtol=0, atol=1e-15)
    assert convex.hull_voxels == old.hull_voxels and convex.stats["hull_facets"] == old.stats["hull_facets"]


def test_boundary_holds_the_deep_interior_and_leaves_empty_space_out(robot):
    # The paper's boundary(P) against the convex hull of the same cloud: fewer voxels, all among the hull's; every
    # voxel 0.1 m or more inside the hull where the cloud is dense is kept (the hull's interior also holds a few
    # voxels near the head's own base that the tip hardly reaches, which the boundary leaves out); none is kept that
    # no sample comes near: a point x of a tetrahedron (vertices v_i, samples) whose circumsphere (centre c,
    # radius rho <= alpha) holds it is within rho of a vertex, since x - c = sum l_i (v_i - c) with l_i >= 0 summing
    # to 1 gives (x - c).(v_i - c) >= |x - c|^2 for some i, so |x - v_i|^2 <= rho^2 - |x - c|^2.
    from scipy.spatial import cKDTree

    from snakehead import _core

    kw = dict(voxel=0.05, directions=1, rolls=1, cloud_samples=20000, seed=2, timeout=1e-4)
    boundary = ws.compute(robot, progress=False, **kw)
    convex = ws.compute(robot, progress=False, hull="convex", **kw)
    assert boundary.params["hull"] == "boundary" and convex.params["hull"] == "convex"
    assert set(boundary.voxel_ids) < set(convex.voxel_ids) and len(boundary) > 0.6 * len(convex)
    cloud = _core.sample_tip_positions(robot.head_chain.model, kw["cloud_samples"], kw["seed"])
    hull = _core.convex_hull(cloud)
    depth = -(convex.centers @ hull["normals"].T + hull["offsets"]).max(axis=1)  # distance inside the hull
    tree = cKDTree(cloud)
    dense = np.array([len(near) >= 10 for near in tree.query_ball_point(convex.centers, kw["voxel"])])
    deep = convex.voxel_ids[(depth >= 0.1) & dense]
    assert len(deep) > 1000 and set(deep) <= set(boundary.voxel_ids)
    alpha = boundary.stats["alpha"]
    assert 0 < alpha < 0.2 and convex.stats["alpha"] == np.inf
    gap = tree.query(convex.centers)[0]
    lonely = convex.voxel_ids[gap > alpha]
    assert len(lonely) > 0 and not set(lonely) & set(boundary.voxel_ids)
    # MATLAB's shrink factor: 1 is the tightest one-region boundary, 0 the hull of all tetrahedra.
    tight = _core.boundary(cloud, 1.0)
    loose = _core.boundary(cloud, 0.0)
    assert tight["regions"] == 1 and tight["alpha"] == tight["critical_alpha"] <= alpha <= loose["alpha"]
    assert tight["volume"] < _core.boundary(cloud, 0.5)["volume"] < loose["volume"] <= hull["volume"] + 1e-9


def test_load_rejects_foreign_files(tmp_path):
    np.savez(tmp_path / "other.npz", a=np.zeros(3))
    with pytest.raises(ValueError, match="not a snakehead"):
        ws.load(tmp_path / "other.npz")
    with pytest.raises(ValueError, match="cannot read"):
        ws.load(tmp_path / "missing.npz")


# --- bad input ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kw, match", [
    ({"voxel": 0.0}, "voxel"), ({"voxel": -0.05}, "voxel"), ({"voxel": float("nan")}, "voxel"),
    ({"directions": 0}, "directions"), ({"rolls": 0}, "rolls"), ({"timeout": 0.0}, "timeout"),
    ({"approach_axis": "y"}, "approach"), ({"shard": (3, 3)}, "shard"), ({"shard": "a/b"}, "shard"),
    ({"directions": 2.5}, "directions"), ({"seed": -1}, "seed"), ({"threads": -1}, "threads"),
    ({"hull": "concave"}, "hull"), ({"shrink": 1.5}, "shrink"), ({"shrink": "half"}, "shrink"),
])
def test_bad_arguments_are_value_errors(robot, kw, match):
    with pytest.raises(ValueError, match=match):
        ws.compute(robot, progress=False, **{**SMALL, **kw})


def test_bad_chain_and_output(robot, small, tmp_path):
    with pytest.raises(ValueError, match="no_such_link"):
        ws.compute(Chain.from_urdf(robot.urdf, "neck_end", "no_such_link"), progress=False, **SMALL)
    with pytest.raises(ValueError, match="expected a Chain"):
        ws.compute("neck_end", progress=False, **SMALL)
    # One joint: the tip moves on an arc, whose points span no volume (no hull).
    with pytest.raises(ValueError, match="no volume"):
        ws.compute(Chain.from_urdf(robot.urdf, "link_15", "head_tip"), progress=False, **{**SMALL, "voxel": 0.05})
    with pytest.raises(ValueError, match="cannot write"):
        small.save(tmp_path / "no-such-dir" / "map.npz")
    with pytest.raises(ValueError, match=".npz"):
        small.save(tmp_path / "map.txt")


@pytest.mark.parametrize("kw, message", [
    ({"voxel": 0}, "voxel size"), ({"voxel": -1}, "voxel size"), ({"directions": 0}, "directions"),
    ({"tip": "no_such_link"}, "no_such_link"), ({"base": "nope"}, "nope"), ({"shard": "2/2"}, "shard"),
    ({"approach_axis": "q"}, "approach"), ({"voxel": "abc"}, "expects a number"), ({"bogus": 1}, "unknown argument"),
    ({"hull": "concave"}, "hull"), ({"shrink": 2}, "shrink"), ({"hull": "convex", "shrink": 0.3}, "--shrink"),
])
def test_workspace_gen_bad_arguments_exit_nonzero(robot, tmp_path, kw, message):
    out = tmp_path / "m.npz"
    r = subprocess.run(gen_args(robot, out, **{"voxel": 0.2, "directions": 2, **kw}), capture_output=True, text=True,
                       timeout=60)
    assert r.returncode != 0
    assert message in r.stderr and "error" in r.stderr
    assert not out.exists()


def test_workspace_gen_unwritable_output_and_help(robot, tmp_path):
    r = subprocess.run(gen_args(robot, tmp_path / "missing-dir" / "m.npz", voxel=0.2, directions=2),
                       capture_output=True, text=True, timeout=60)
    assert r.returncode != 0 and "cannot write" in r.stderr
    r = subprocess.run([workspace_gen(), "--help"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and "--free-roll" in r.stdout and "--shard" in r.stdout
    # the defaults it prints are the core's own (the numbers the Python API reads, sweep_defaults)
    sd = sweep_defaults
    for flag, value in [("--voxel", sd.HEAD_VOXEL_M), ("--directions", sd.HEAD_DIRECTIONS), ("--rolls", sd.HEAD_ROLLS),
                        ("--timeout", sd.HEAD_TIMEOUT_S), ("--epsilon", sd.HEAD_EPSILON),
                        ("--cloud-samples", sd.HEAD_CLOUD_SAMPLES), ("--shrink", sd.HEAD_SHRINK),
                        ("--seed", sd.HEAD_SEED)]:
        line = next(x for x in r.stdout.splitlines() if x.strip().startswith(flag + " "))
        printed = line.split("(default ")[1].split(")")[0].split(",")[0]
        assert float(printed) == value, (flag, printed, value)
    r = subprocess.run([workspace_gen()], capture_output=True, text=True, timeout=60)
    assert r.returncode != 0 and "required" in r.stderr


# --- Table 2, the dexterous workspace, G0 ------------------------------------------------------------------
def synthetic(indices, centers=None) -> ws.ReachabilityMap:
    d = np.asarray(indices, dtype=float)
    n = len(d)
    c = np.zeros((n, 3)) if centers is None else np.asarray(centers, dtype=float)
    return ws.ReachabilityMap(
        centers=c, solved=np.round(d / 5).astype(np.int32), voxel_ids=np.arange(n, dtype=np.int64), tried=20,
        grid_origin=np.zeros(3), grid_size=1.0, grid_shape=(10, 10, 10), hull_voxels=n, chain_hash="x",
        base="b", tip="t", params={"voxel_size": 0.1, "directions": 20})


def test_histogram_uses_table2_bins():
    m = synthetic([0, 15, 20, 35, 40, 55, 60, 75, 80, 95, 100, 100])
    counts, pct = m.histogram()
    np.testing.assert_array_equal(counts, [2, 2, 2, 2, 4])  # [80, 100] is closed
    np.testing.assert_allclose(pct, 100 * np.array([2, 2, 2, 2, 4]) / 12)
    with pytest.raises(InputError, match="bins must be an increasing sequence of at least two edges"):
        m.histogram([0, 50, 20])


def test_clusters_and_center_on_known_blobs():
    rng = np.random.default_rng(5)
    means = np.array([[0.3, 0.0, 0.1], [0.0, 0.3, 0.2], [-0.2, -0.2, 0.3]])
    sizes = [40, 25, 15]
    pts = np.concatenate([m + 0.01 * rng.normal(size=(s, 3)) for m, s in zip(means, sizes)])
    # Dexterous blobs plus voxels of lower index that must be left out.
    centers = np.concatenate([pts, rng.uniform(-1, 1, size=(30, 3))])
    m = synthetic([100] * len(pts) + [50] * 30, centers)
    np.testing.assert_allclose(m.dexterous(), pts)
    c = m.clusters(k=3)
    np.testing.assert_array_equal(c.sizes, sizes)  # ordered by size
    for j, (mean, s) in enumerate(zip(means, sizes)):
        np.testing.assert_allclose(c.centroids[j], pts[sum(sizes[:j]):sum(sizes[:j]) + s].mean(axis=0), atol=1e-12)
    np.testing.assert_allclose(c.center, c.centroids[0])  # the largest cluster
    np.testing.assert_allclose(m.center(k=3), c.center)
    assert m.clusters(k=3, random_state=7).chosen == 0
    with pytest.raises(ValueError, match="at least"):
        synthetic([100, 100]).clusters(k=3)
    with pytest.raises(InputError, match="k must be a positive integer, got 0"):
        m.clusters(k=0)
    with pytest.raises(InputError, match=r"threshold must be within \[0, 100\], got 101"):
        m.dexterous(threshold=101)


def test_index_at(small):
    np.testing.assert_allclose(small.index_at(small.centers), small.indices)
    assert small.index_at([10.0, 0.0, 0.0])[0] == 0.0


# --- the shipped maps -------------------------------------------------------------------------------------
@pytest.mark.parametrize("robot_file", ["snake16.toml", "snake16_head6.toml"])
def test_shipped_maps(robot_file):
    robot = SnakeRobot.from_file(default_robot_file().with_name(robot_file))
    path = robot.map_path
    assert path.stat().st_size < 1_000_000
    m = ws.map_for(robot)
    assert m.path == path
    assert m.chain_hash == robot.head_chain.hash
    assert m.params["voxel_size"] == 0.05 and m.params["directions"] == 20 and m.params["rolls"] == 10
    assert m.params["hull"] == "boundary" and m.params["shrink"] == 0.5 and m.lacks == ()
    assert m.command.startswith("workspace_gen ") and "--voxel 0.05" in m.command
    assert len(m) == m.hull_voxels > 1000 and m.indices.max() <= 100
    readme = (default_robot_file().with_name("README.md")).read_text()
    assert m.command in readme


def test_shipped_poses_map(robot):
    path = default_robot_file().with_name("snake16_head7_poses.npz")
    assert path.stat().st_size < 1_000_000
    m = ws.load(path)
    assert m.chain_hash == robot.head_chain.hash and m.params["free_roll"] and m.params["directions"] == 60
    assert m.voxel_ids.tolist() == ws.map_for(robot).voxel_ids.tolist()  # the same boundary
    assert m.command in (default_robot_file().with_name("README.md")).read_text()


def test_shipped_head_map_g0(robot):
    m = ws.map_for(robot)
    c = m.clusters(k=3)
    assert len(c.points) >= 3 and np.all(np.isfinite(c.center))
    # G0 lies within the head's reach, among the voxels of high index.
    assert np.linalg.norm(c.center) < robot.head_chain.reach
    assert m.index_at(c.center)[0] >= 50


# --- figures ------------------------------------------------------------------------------------------------
def test_figures(small, tmp_path):
    from snakehead.viz import reachability_figures as wp
    from snakehead.viz import save

    figures = wp.map_figures(small, k=2)
    assert list(figures) == ["map", "dexterous", "clusters"]
    for name, fig in figures.items():
        p = save(fig, tmp_path / f"small_{name}.png")
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size > 10_000
    ax = wp.plot_section(small, axis="y", value=0.01).axes[0]
    h = small.voxel_size
    layer_y = small.grid_origin[1] + (np.floor((0.01 - small.grid_origin[1]) / h) + 0.5) * h  # the layer holding y
    assert len(ax.collections[0].get_array()) == np.sum(np.isclose(small.centers[:, 1], layer_y)) > 0
    with pytest.raises(InputError, match="axis must be 'x', 'y' or 'z', got 'w'"):
        wp.plot_section(small, axis="w")
    with pytest.raises(ValueError, match="outside"):
        wp.plot_section(small, axis="z", value=5.0)


def test_sweep_releases_the_gil(robot):
    # The progress callback runs about every 0.1 s in the sweep's calling thread; between two calls the
    # main thread must be able to run Python (it could not if the sweep held the GIL).
    import threading

    from snakehead import _core

    ticks = [0]
    seen = []
    done = threading.Event()
    o = ws.core_options(**{**SMALL, "voxel": 0.1}, any_roll=True, free_roll=False, approach_axis="x", epsilon=1e-5,
                        threads=1, shard=None)

    def run():
        _core.compute_reachability(robot.head_chain.model, o, lambda d, t: seen.append(ticks[0]) or True)
        done.set()

    t = threading.Thread(target=run)
    t.start()
    while not done.is_set():
        ticks[0] += 1
    t.join()
    assert len(seen) >= 3, "the sweep was too quick to tell"
    assert seen[-1] - seen[0] > 1000


def test_free_roll_and_z_approach(robot, small):
    free = ws.compute(robot, progress=False, free_roll=True, **SMALL)
    assert free.tried == SMALL["directions"] and free.params["free_roll"] and free.params["rolls"] == 0
    assert 0 <= free.indices.min() and free.indices.max() <= 100
    # A free roll relaxes the 2 fixed rolls: it reaches at least about as much.
    assert free.indices.mean() >= small.indices.mean() - 2.0
    each = ws.compute(robot, progress=False, any_roll=False, **SMALL)
    assert each.tried == SMALL["directions"] * SMALL["rolls"]
    # Counting every frame cannot reach more than counting a point when any of its frames is solved.
    assert each.indices.mean() <= small.indices.mean() + 2.0
    z = ws.compute(robot, progress=False, approach_axis="z", **SMALL)
    assert z.params["approach_axis"] == "z" and np.array_equal(z.voxel_ids, small.voxel_ids)
    assert not np.array_equal(z.solved, small.solved)


def test_bad_inputs_of_the_helpers(robot, small, tmp_path):
    with pytest.raises(ValueError, match="centers"):
        ws.evaluate(robot, [[np.nan, 0.0, 0.0]])
    with pytest.raises(ValueError, match="centers"):
        ws.evaluate(robot, [1.0, 2.0])
    with pytest.raises(InputError, match="voxel size must be a positive number of metres, got -1.0"):
        ws.evaluate(robot, [[0.1, 0.0, 0.0]], voxel=-1.0)
    with pytest.raises(InputError, match=r"points must be finite, shape \(3,\) or \(k, 3\)"):
        small.index_at([[np.inf, 0.0, 0.0]])
    with pytest.raises(InputTypeError, match="robot must be a SnakeRobot, got str"):
        ws.map_for("snake16")
    with pytest.raises(ValueError, match="at least one"):
        ws.merge([])
    with pytest.raises(ValueError, match="ReachabilityMap"):
        ws.merge(["map.npz"])
    with pytest.raises(ValueError, match="ReachabilityMap"):
        ws.save("map", tmp_path / "m.npz")
    with ThreadPoolExecutor(1) as ex:
        with pytest.raises(ValueError, match="not both"):
            ws.compute(robot, progress=False, executor=ex, shard=(0, 2), **SMALL)
        with pytest.raises(ValueError, match="shards"):
            ws.compute(robot, progress=False, executor=ex, shards=0, **SMALL)
    with pytest.raises(ValueError, match="executor"):
        ws.compute(robot, progress=False, shards=2, **SMALL)
    with pytest.raises(ValueError, match="Executor"):
        ws.compute(robot, progress=False, executor=object(), **SMALL)
