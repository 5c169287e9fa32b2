"""Hostile and broken input at the Python boundary (issue 14, findings 3-9; the native ones are in
test_hostile_native.py): robots without mass, names that are not data, writes that fail half-way, damaged and
inconsistent maps, durations and sizes without end, states outside their ranges, and numbers of the wrong kind.

Cases that hung, allocated without bound or could open files run in a subprocess with a timeout (and an address
space limit), so that a hang or a crash fails the test instead of ending the run.
"""
from __future__ import annotations

import errno
import functools
import io
import os
import re
import resource
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import numpy as np
import pytest

import snakehead
from snakehead import InputError, SnakeRobot, default_urdf_path, sim
from snakehead._files import atomic_open, write_text_atomic
from snakehead.kinematics import reachability as ws
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.model.robot_file import read_robot_file, write_robot_file
from snakehead.scenes import Scene, Target, load_scene
from snakehead.solve import neck as nk

URDF = default_urdf_path()
MAP = URDF.with_name("snake16_head7.npz")
SPHERE_1 = ([-0.0405, 0.5443, 0.3], [0.0, 1.0, 0.0])  # the paper's first sphere (Section 4.1)


def python(code: str, timeout: float = 300, **kw) -> subprocess.CompletedProcess:
    """Runs ``code`` in a fresh interpreter; a crash shows as a negative return code, a hang as a timeout."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=timeout, **kw)


def without_inertial(urdf: str, links: list[str] | None = None) -> str:
    """``urdf`` with the <inertial> of ``links`` removed (all of them when None)."""
    if links is None:
        return re.sub(r"<inertial>.*?</inertial>", "", urdf, flags=re.S)
    for name in links:
        start = urdf.index(f'<link name="{name}">')
        end = urdf.index("</link>", start)
        urdf = urdf[:start] + re.sub(r"<inertial>.*?</inertial>", "", urdf[start:end], flags=re.S) + urdf[end:]
    return urdf


@pytest.fixture(scope="module")
def controller():
    return _CONTROLLER()


@functools.cache
def _CONTROLLER() -> snakehead.HeadController:
    """One controller for the module (made on first use)."""
    return snakehead.HeadController(method="free_roll", seed=1)


# --- finding 3: robots without mass -------------------------------------------------------------------------
def test_a_robot_without_mass_is_refused_at_every_entry(tmp_path):
    """A URDF without <inertial> gave a NaN centre of mass and a misleading error later; each way in refuses it."""
    urdf = tmp_path / "massless.urdf"
    urdf.write_text(without_inertial(URDF.read_text()))
    robot_file = write_robot_file(tmp_path / "massless.toml", urdf=urdf, base_end="base_end", neck_end="neck_end",
                                  head_tip="head_tip")
    (tmp_path / "scene.toml").write_text('robot = "massless.toml"\n[[targets]]\nname = "a"\n'
                                         'position = [-0.0405, 0.5443, 0.3]\ndirection = [0.0, 1.0, 0.0]\n')
    frames = dict(base_end="base_end", neck_end="neck_end", head_tip="head_tip")
    for make in (lambda: SnakeRobot.from_urdf(urdf, **frames), lambda: SnakeRobot.from_urdf(urdf.read_text(), **frames),
                 lambda: SnakeRobot.from_file(robot_file), lambda: snakehead.plan(tmp_path / "scene.toml"),
                 lambda: snakehead.plan([SPHERE_1], robot=SnakeRobot.from_file(robot_file))):
        with pytest.raises(ValueError, match=r"the robot has no mass \(no <inertial> on its links\)"):
            make()
    assert snakehead.Chain.from_urdf(urdf, "link_0", "head_tip").total_mass == 0.0  # a chain may be massless


def test_a_moving_link_without_mass_is_named_by_the_simulation():
    """MuJoCo needs a mass on every moving link: its own message ("mass and inertia of moving bodies must be larger
    than mjMINVAL", two lines) named a body id; the robot's link and joint are named instead."""
    whole = snake_urdf(SnakeSpec(n_joints=8, markers={"p0": 3, "b0": 4}))
    urdf = without_inertial(whole, ["link_6"])
    robot = SnakeRobot.from_urdf(urdf, base_end="p0", neck_end="b0", head_tip="head_tip")
    assert robot.total_mass > 0  # the robot as a whole has mass: stability works, the simulation cannot
    message = r"link 'link_6' is moved by joint 'joint_6' but has no mass and inertia in the URDF"
    with pytest.raises(ValueError, match=message):
        sim.build_model(robot)
    with pytest.raises(ValueError, match=message):
        sim.simulate_trajectory(robot, [0.0, 0.1], np.zeros((2, robot.n_joints)), settle=0.01)
    # a massless link fixed to a massive one is fine (MuJoCo welds them): the markers p0, b0, head_tip are
    whole = SnakeRobot.from_urdf(whole, base_end="p0", neck_end="b0", head_tip="head_tip")
    assert [whole.masses[whole.link_index(k)] for k in ("p0", "b0", "head_tip")] == [0.0, 0.0, 0.0]
    assert sim.build_model(whole).model.nbody == len(whole.link_names) + 1


# --- finding 4: names are data ----------------------------------------------------------------------------
def test_names_cannot_add_elements_or_open_files(tmp_path):
    """Link and joint names were written into the MJCF unescaped: a name could add elements, including an
    <include file=...> that MuJoCo opens. Here the names include a file that would add a body, and a FIFO that
    would block whoever opens it (so an open shows as a timeout); the model, built and compiled, and its MJCF text
    read back by MuJoCo, hold exactly the robot's elements."""
    inject = tmp_path / "inject.xml"
    inject.write_text('<mujoco><worldbody><body name="INJECTED"><geom size="1"/></body></worldbody></mujoco>')
    fifo = tmp_path / "block.xml"
    os.mkfifo(fifo)
    hostile = f'"/><include file="{inject}"/><include file="{fifo}"/><body name="x&amp;<'
    r = python(f"""
        import mujoco
        from snakehead import SnakeRobot, sim
        from snakehead.model.generate import SnakeSpec, snake_urdf
        hostile = {hostile!r}
        spec = SnakeSpec(n_joints=8, link_prefix="l" + hostile, joint_prefix="j" + hostile,
                         tip_name="tip" + hostile, markers={{"p0" + hostile: 3, "b0" + hostile: 4}})
        robot = SnakeRobot.from_urdf(snake_urdf(spec), base_end="p0" + hostile, neck_end="b0" + hostile,
                                     head_tip="tip" + hostile)
        s = sim.build_model(robot)
        again = mujoco.MjModel.from_xml_string(s.spec.to_xml())
        for m in (s.model, again):
            names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) for b in range(m.nbody)]
            print(m.nbody, m.njnt, m.ngeom, m.nu, "INJECTED" in names, names[1:] == robot.link_names)
        """, timeout=120)
    assert r.returncode == 0, r.stderr[-3000:]
    lines = r.stdout.split("\n")[:2]
    # 12 frames + the world; 8 hinges + the free joint; 9 boxes + the floor; 8 actuators
    assert lines == ["13 9 10 8 False True"] * 2, r.stdout


def test_scene_names_cannot_name_files_outside_the_output_folder(tmp_path):
    """A scene's name names its output files (NAME_trajectory.csv ...): "../x" wrote outside --out."""
    for name in ("../escaped", "a/b", "..", "", "tab\there", "x" * 101):
        with pytest.raises(ValueError, match="scene's name"):
            Scene(name=name, targets=(Target("a", *SPHERE_1),))
    with pytest.raises(TypeError, match="scene's name must be a str"):
        Scene(name=3, targets=(Target("a", *SPHERE_1),))
    scene = tmp_path / "scene.toml"
    scene.write_text('name = "../escaped"\n[[targets]]\nname = "a"\nposition = [-0.0405, 0.5443, 0.3]\n'
                     'direction = [0.0, 1.0, 0.0]\n')
    with pytest.raises(ValueError, match=r"scene file .*: a scene's name '../escaped' holds '/'"):
        load_scene(scene)
    # where a field is, said once (it was "scene, targets[0]: scene, targets[0]: position must ...")
    scene.write_text('[[targets]]\nname = "a"\nposition = [0.0, 0.5]\ndirection = [0.0, 1.0, 0.0]\n')
    with pytest.raises(ValueError, match=r"targets\[0\]: position must be a list of 3 numbers, got \[0.0, 0.5\]$"):
        load_scene(scene)
    r = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--scene", str(scene), "--out",
                        str(tmp_path / "out"), "--no-sim", "--fast"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.toml"]  # no "escaped_..." beside it, no out


def test_names_are_shown_as_they_are_in_the_outputs(tmp_path):
    """A "$" in a scene's or a target's name made matplotlib parse it as math: the figures failed (exit 3)."""
    scene = tmp_path / "dollars.toml"
    scene.write_text('description = "costs $\\\\frac{$"\n[[targets]]\nname = "$\\\\sqrt{$"\n'
                     'position = [-0.0405, 0.5443, 0.3]\ndirection = [0.0, 1.0, 0.0]\n')
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--scene", str(scene), "--out", str(out),
                        "--no-sim", "--fast"], capture_output=True, text=True, timeout=600)
    assert r.returncode in (0, 1), r.stderr[-2000:]
    assert (out / "dollars_snapshots.png").stat().st_size > 0 and (out / "dollars.gif").stat().st_size > 0
    assert "<title>snakehead: costs $\\frac{$</title>" in (out / "dollars.html").read_text()


def test_robot_files_keep_names_as_data(tmp_path):
    """Frame names with quotes, backslashes or newlines were written into the TOML unescaped."""
    names = dict(base_end='p0"\nmap = "evil', neck_end="b0\\\u007f\x00", head_tip="tip\u2603\t")
    path = write_robot_file(tmp_path / "r.toml", urdf=URDF, **names)
    back = read_robot_file(path)
    assert (back.base_end, back.neck_end, back.head_tip) == tuple(names.values()) and back.map is None


# --- finding 5: no half-written file ------------------------------------------------------------------------
WRITERS = """
    import os, sys, json, resource
    import numpy as np
    import snakehead
    from snakehead.app import report as rep
    from snakehead.app.pipeline import Progress, Settings, run_scenes
    from snakehead.kinematics import workspace
    from snakehead.model.robot_file import write_robot_file
    from snakehead.scenes import Scene
    from snakehead.viz import animation, body, save, viewer
    work, out, limit = sys.argv[1], sys.argv[2], int(sys.argv[3])
    controller = snakehead.HeadController(method="free_roll", seed=1)
    scene = Scene.from_targets([([-0.0405, 0.5443, 0.3], [0.0, 1.0, 0.0])], name="t")
    run_scenes([scene], work, controller=controller, settings=Settings(simulate=False, figures=False),
               progress=Progress(quiet=True))
    report = json.load(open(os.path.join(work, "report.json")))
    plan = snakehead.plan(scene, controller=controller)
    figure, gif = body.plot_snapshots(plan, n_panels=3), animation.animate(plan, max_frames=3)
    scene_data = viewer.viewer_scene(plan, title="t")
    page = viewer.html_page(scene_data)
    m = workspace.load(snakehead.default_urdf_path().with_name("snake16_head7.npz"))
    writers = {
        "report.json": lambda p: rep.write_json(report, p),
        "summary.md": lambda p: rep.write_summary(report, p),
        "t_trajectory.csv": lambda p: rep.write_trajectory_csv(plan, p, plan.robot.joint_names),
        "t_snapshots.png": lambda p: save(figure, p),
        "t.gif": lambda p: save(gif, p),
        "t_viewer.npz": lambda p: viewer.save_viewer_scene(scene_data, p),
        "t.html": lambda p: viewer.write_html(scene_data, p),
        "robot.toml": lambda p: write_robot_file(p, urdf=snakehead.default_urdf_path(), base_end="base_end",
                                                 neck_end="neck_end", head_tip="head_tip"),
        "map.npz": lambda p: workspace.save(m, p),
    }
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))  # every output is larger: each write fails
    for name, write in writers.items():
        try:
            write(os.path.join(out, name))
            print(name, "written")
        except Exception as exc:
            print(name, type(exc).__name__, "File too large" in str(exc))
"""
OUTPUTS = ["report.json", "summary.md", "t_trajectory.csv", "t_snapshots.png", "t.gif", "t_viewer.npz", "t.html",
           "robot.toml", "map.npz"]


def test_a_failed_write_leaves_the_old_file_and_no_partial_one(tmp_path):
    """Saving over a file and failing (disk full, a file-size limit) destroyed the old file and left a truncated
    one: a CSV cut mid-row looked like a shorter motion. Every writer of the package, with a 64-byte file-size
    limit in a subprocess, fails with an error and leaves the old file as it was and nothing beside it."""
    work, out = tmp_path / "work", tmp_path / "out"
    work.mkdir()
    out.mkdir()
    for name in OUTPUTS:
        (out / name).write_bytes(b"old\n")
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(WRITERS), str(work), str(out), "64"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    results = dict(line.split(" ", 1) for line in r.stdout.splitlines())
    assert sorted(results) == sorted(OUTPUTS), r.stdout
    for name in OUTPUTS:
        # every writer says which file it could not write: an InputError (the output's place is the user's)
        assert results[name] == "InputError True", (name, results[name])
        assert (out / name).read_bytes() == b"old\n", name
    assert sorted(p.name for p in out.iterdir()) == sorted(OUTPUTS)  # no temporary file left


def test_the_command_line_on_a_full_disk_keeps_the_old_outputs(tmp_path):
    old = {"report.json": b"{}\n", "target_trajectory.csv": b"time_s\n0.000000\n"}
    for name, content in old.items():
        (tmp_path / name).write_bytes(content)
    r = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--position", *map(str, SPHERE_1[0]),
                        "--direction", *map(str, SPHERE_1[1]), "--out", str(tmp_path), "--no-sim", "--fast"],
                       capture_output=True, text=True, timeout=600,
                       preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096)))
    assert r.returncode == 2, r.stderr[-2000:]
    last = r.stderr.strip().splitlines()[-1]
    assert last.startswith("snakehead plan: error: ") and "File too large" in last and "Traceback" not in r.stderr
    for name, content in old.items():
        assert (tmp_path / name).read_bytes() == content
    assert not [p.name for p in tmp_path.iterdir() if p.name.endswith(".part")]


@pytest.mark.parametrize("failing", ["write", "fsync", "replace"])
def test_atomic_writes_fail_cleanly_wherever_they_fail(tmp_path, monkeypatch, failing):
    """Disk full in the middle of the data, at the flush to disk, or at the rename: the old file stays."""
    target = tmp_path / "file.txt"
    target.write_text("old")

    def boom(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    if failing == "fsync":
        monkeypatch.setattr(os, "fsync", boom)
    elif failing == "replace":
        monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(InputError, match="cannot write .*No space left"):
        if failing == "write":
            with atomic_open(target) as f:
                f.write("new " * 1000)
                boom()
        else:
            write_text_atomic(target, "new")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["file.txt"]


# --- finding 6: damaged and inconsistent maps -----------------------------------------------------------------
def _map_arrays() -> dict[str, np.ndarray]:
    with np.load(MAP) as z:
        return {k: z[k] for k in z.files}


def _write_map(path: Path, arrays: dict) -> Path:
    np.savez(path, **arrays)
    return path


def _declaring(raw: bytes, size: int) -> bytes:
    """A zip archive whose central directory declares ``size`` bytes for its first member (a zip bomb's claim)."""
    at = raw.index(b"PK\x01\x02")  # central directory file header; uncompressed size at offset 24
    return raw[:at + 24] + size.to_bytes(4, "little") + raw[at + 28:]


def test_damaged_map_files_are_value_errors(tmp_path):
    """Empty, truncated or corrupted .npz files raised EOFError, BadZipFile or KeyError (the CLI: a traceback, exit 1)."""
    raw = MAP.read_bytes()
    cut = raw.index(b"indices.npy")
    damaged = {"empty": b"", "half": raw[:len(raw) // 2], "no_end": raw[:-22], "a_byte": raw[:1],
               "not_zip": b"\x93NUMPY" + bytes(100), "flipped": raw[:cut + 200] + bytes([raw[cut + 200] ^ 0xFF]) +
               raw[cut + 201:], "bomb": _declaring(raw, 0xF000_0000)}
    for name, data in damaged.items():
        path = tmp_path / f"{name}.npz"
        path.write_bytes(data)
        with pytest.raises(ValueError, match=re.escape(f"cannot read the map {str(path)!r}")):
            ws.load(path)
    # no pickles, and nothing that is not a .npy array
    arrays = _map_arrays()
    for extra in ({"evil": np.array([{"a": 1}], dtype=object)},):
        buf = io.BytesIO()
        np.savez(buf, **arrays, **extra)
        (tmp_path / "pickle.npz").write_bytes(buf.getvalue())
        with pytest.raises(ValueError, match="Python objects"):
            ws.load(tmp_path / "pickle.npz")
    with zipfile.ZipFile(tmp_path / "text.npz", "w") as z:
        z.writestr("readme.txt", "hello")
    with pytest.raises(ValueError, match="not a .npy array"):
        ws.load(tmp_path / "text.npz")


def test_a_zip_bomb_is_refused_before_it_is_unpacked(tmp_path, monkeypatch):
    """A 2.9 MB map drove loading past 4 GiB. Here 200 MB of zeros compressed to 0.2 MB, with the limit lowered to
    64 MB: refused from the archive's directory, before anything is unpacked or allocated."""
    path = tmp_path / "bomb.npz"
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (25_000_000,)})
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("centers.npy", header.getvalue() + bytes(200_000_000))
    assert path.stat().st_size < 1_000_000
    monkeypatch.setattr(ws.map_io, "MAX_MAP_BYTES", 64 << 20)
    with pytest.raises(ValueError, match="would unpack to 200000128 bytes, more than the 67108864 allowed"):
        ws.load(path)
    # a header that claims more than its member holds is refused before the array is allocated
    from snakehead._files import read_npz

    liar = tmp_path / "liar.npz"
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (10**12,)})
    with zipfile.ZipFile(liar, "w") as z:
        z.writestr("centers.npy", header.getvalue() + bytes(8))
    with pytest.raises(ValueError, match=r"declares \(1000000000000,\) of float64"):
        read_npz(liar, "the map", max_bytes=1 << 20)


def _indices(a, value):
    a["indices"] = a["indices"].copy()
    a["indices"][0] = value


def _flip_bit(a):
    a["reached"] = a["reached"].copy()
    a["reached"][0, 0] ^= 1


def _duplicate_ids(a):
    a["voxel_ids"] = a["voxel_ids"].copy()
    a["voxel_ids"][1] = a["voxel_ids"][0]


INCONSISTENT = [
    ("indices of 250 %", lambda a: _indices(a, 250.0), r"indices must be within \[0, 100\]"),
    ("indices of -25 %", lambda a: _indices(a, -25.0), r"indices must be within \[0, 100\]"),
    ("indices not solved/tried", lambda a: _indices(a, 55.0), "indices disagree with 100 \\* solved / tried"),
    ("NaN voxel size", lambda a: a.update(voxel_size=np.float64("nan")), "voxel_size must be a positive finite"),
    ("zero voxel size", lambda a: a.update(voxel_size=np.float64(0.0)), "voxel_size must be a positive finite"),
    ("duplicate voxel ids", _duplicate_ids, r"voxel_ids holds duplicates"),
    ("ids beyond the grid", lambda a: a.update(voxel_ids=a["voxel_ids"] + 10**6), "voxel_ids must increase"),
    ("centres moved", lambda a: a.update(centers=a["centers"] + 0.01), "centers are not the centres"),
    ("shapes that disagree", lambda a: a.update(centers=a["centers"][:-1]), "centers has shape"),
    ("solved beyond tried", lambda a: a.update(solved=a["solved"] * 100), r"solved must be within \[0, tried"),
    ("tried as text", lambda a: a.update(tried=np.array("20")), "tried must be one int value"),
    ("base as a number", lambda a: a.update(base=np.int64(3)), "base must be one text value"),
    ("grid_shape not a cube", lambda a: a.update(grid_shape=np.array([23, 23, 24])), "grid_shape must be"),
    ("approach axis y", lambda a: a.update(approach_axis=np.array("y")), "approach_axis must be 'x' or 'z'"),
    ("a missing key", lambda a: a.pop("solved"), "solved is missing"),
    ("NaN centres", lambda a: a.update(centers=np.full_like(a["centers"], np.nan)), "centers holds NaN"),
    ("a foreign format", lambda a: a.update(format=np.array("other")), "is not a snakehead reachability map"),
    # the second format's per-direction results and hull
    ("a direction's bit flipped", _flip_bit, r"reached \(the per-direction results\) disagree with the solved"),
    ("bits for too few directions", lambda a: a.update(reached=a["reached"][:, :2]),
     r"reached must be uint8 of shape \(\d+, 3\)"),
    ("bits as numbers", lambda a: a.update(reached=a["reached"].astype(float)), "reached must be uint8"),
    ("sphere directions missing a row", lambda a: a.update(sphere_directions=a["sphere_directions"][1:]),
     r"sphere_directions must be \(20, 3\) finite numbers"),
    ("an unknown hull", lambda a: a.update(hull=np.array("concave")), "hull must be 'convex' or 'boundary'"),
    ("a NaN shrink", lambda a: a.update(shrink=np.float64("nan")), r"shrink must be within \[0, 1\]"),
]


@pytest.mark.parametrize("change, message", [(c, m) for _, c, m in INCONSISTENT], ids=[i for i, _, _ in INCONSISTENT])
def test_inconsistent_maps_are_refused_naming_the_field(tmp_path, change, message):
    """Inconsistent maps loaded without a word (G0 moved, index_at returned 0)."""
    arrays = _map_arrays()
    ws.load(_write_map(tmp_path / "good.npz", arrays))
    change(arrays)
    with pytest.raises(ValueError, match=message):
        ws.load(_write_map(tmp_path / "bad.npz", arrays))


@pytest.mark.parametrize("options", [dict(), dict(rolls=3, any_roll=False), dict(free_roll=True, rolls=0),
                                     dict(hull="convex", approach_axis="z"), dict(shard="1/2")],
                         ids=["default", "every_roll", "free_roll", "convex_z", "shard"])
def test_maps_as_the_sweep_writes_them_load(tmp_path, options):
    """The validation accepts every map the C++ writer makes (format 2: per-direction bits, rolls counted each or
    any, free roll, either hull, shards and their merge), and the first format's maps (tests/data)."""
    chain = snakehead.Chain.from_urdf(URDF, "neck_end", "head_tip")
    kw = dict(voxel=0.2, directions=6, rolls=2, timeout=1e-4, cloud_samples=2000, seed=3, progress=False, threads=1)
    m = ws.compute(chain, **{**kw, **options})
    ws.save(m, tmp_path / "m.npz")
    back = ws.load(tmp_path / "m.npz")
    assert back.tried == m.tried and np.array_equal(back.voxel_ids, m.voxel_ids)
    assert np.array_equal(back.solved, m.solved) and np.array_equal(back.reached, m.reached)
    if "shard" in options:  # the other shard, the merge, saved and read again
        other = ws.compute(chain, **{**kw, "shard": "0/2"})
        whole = ws.merge([m, other])
        ws.save(whole, tmp_path / "whole.npz")
        assert np.array_equal(ws.load(tmp_path / "whole.npz").solved, whole.solved)
    assert ws.load(Path(__file__).resolve().parents[1] / "data" / "map_format1.npz").lacks == ("reached",)


# --- finding 7: durations and sizes without end -------------------------------------------------------------
def test_durations_and_sizes_have_limits():
    """simulate(control_dt=1e300) never returned; a slow plan (speed=1e-9) asked for 5.7 TiB. In a subprocess with 4 GiB of address
    space and a timeout: each is a ValueError at once, naming the argument or the count it would give."""
    r = python("""
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (4 << 30, resource.RLIM_INFINITY))
        import numpy as np, snakehead
        from snakehead import sim
        from snakehead.locomotion import gaits
        from snakehead.trajectory import interpolation
        from snakehead.scenes import Scene, Target
        robot = snakehead.SnakeRobot.default()
        q = np.zeros((2, robot.n_joints))
        sphere = ([-0.0405, 0.5443, 0.3], [0.0, 1.0, 0.0])
        line = Scene(name="s", targets=(Target("a", *sphere), Target("b", [0.0, 0.5, 0.3], [0, 1, 0],
                                                                      approach="line", step_m=1e-300)))
        calls = [
            lambda: sim.simulate_trajectory(robot, [0, 1], q, control_dt=1e300),
            lambda: sim.simulate_trajectory(robot, [0, 1], q, control_dt=1e-300, timestep=1e-300),
            lambda: sim.simulate_trajectory(robot, [0, 1], q, hold=1e300),
            lambda: sim.simulate_trajectory(robot, [0, 1e12], q),
            lambda: snakehead.plan([sphere], timing={"dt": 1e300}),
            lambda: snakehead.plan([sphere], timing={"grid_step": 1e-300}),
            lambda: snakehead.plan(line),
            lambda: Target("a", *sphere, hold_s=1e300),
            lambda: interpolation.sample_times(0.0, 1e300),
            lambda: gaits.make_gait("rolling").trajectory(robot, 1e300),
        ]
        for call in calls:
            try:
                call()
                print("accepted")
            except Exception as exc:
                print(type(exc).__name__, exc)
        """, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    lines = r.stdout.splitlines()
    expected = ["InputError control_dt must be at most 1 s, got 1e+300",
                "InputError the simulated motion (t[-1] - t[0] + hold): 1 s in steps of 1e-300 s is 1e+300 samples",
                "InputError hold must be at most 86400 s, got 1e+300",
                "InputError the simulated motion (t[-1] - t[0] + hold): 1e+12 s in steps of 0.002 s",
                "InputError timing has no option 'dt'; its options are velocity_limit, acceleration_limit, "
                "torque_limit, zmp_margin, friction",
                "InputError timing has no option 'grid_step'",
                "InputError target 'b': the line from 'a' is 0.06002 m long; at step_m = 1e-300 m that is 6e+298 poses",
                "InputError target 'a' hold_s must be at most 86400 s",
                "InputError the trajectory (t1 - t0): 1e+300 s in steps of 0.002 s is 5e+302 samples; at most 1000000",
                "InputError a run of 1e+300 cycles of the rolling gait must be at most 86400 s"]
    assert len(lines) == len(expected), r.stdout
    for line, start in zip(lines, expected):
        assert line.startswith(start), (line, start)


# --- finding 8: states outside their ranges -------------------------------------------------------------------
def test_q_prev_outside_the_joint_limits_is_refused(controller):
    """HeadController.solve(q_prev=...) with joints outside their limits returned success=True with those joints."""
    robot = controller.robot
    q = controller.q_initial.copy()
    assert controller.solve(*SPHERE_1, q_prev=q).success
    q[2] = robot.upper[2] + 0.5
    with pytest.raises(ValueError, match=r"q_prev\[2\] = 2.07\d+ is outside the joint limits \[-1.5708, 1.5708\]"):
        controller.solve(*SPHERE_1, q_prev=q)
    with pytest.raises(ValueError, match="base_configuration"):
        snakehead.HeadController(controller.robot, controller.map, base_configuration=np.full(robot.n_joints, 3.0))


def test_the_neck_takes_rigid_frames_only(controller):
    """A scaled or sheared P0 frame was accepted by the neck solver and distorted Eq. 22."""
    robot = controller.robot
    P0 = robot.frame(controller.q_initial, robot.lift_frame)
    goal = nk.neck_goal(P0[:3, 3], SPHERE_1[0], controller.Lc)
    nk.solve_neck(robot.lift_chain, P0, goal)
    scaled, sheared = P0.copy(), P0.copy()
    scaled[:3, :3] *= 2.0
    sheared[0, 1] += 0.3
    for frame in (scaled, sheared):
        with pytest.raises(ValueError, match="P0_frame rotation is not a rotation"):
            nk.solve_neck(robot.lift_chain, frame, goal)
    with pytest.raises(TypeError, match="goal must be a NeckGoal"):
        nk.solve_neck(robot.lift_chain, P0, "goal")
    with pytest.raises(ValueError, match="P0_local rotation is not a rotation"):
        nk.base_move_into_range(SPHERE_1[0], scaled, snakehead.BasePlacement(), 0.1, 0.2, 0.05, 0.02)


def test_histogram_bins_must_be_numbers_in_order():
    """NaN bins passed the increasing-edges test and gave negative counts."""
    m = ws.load(MAP)
    counts, pct = m.histogram()
    assert counts.sum() == len(m) and np.all(counts >= 0)
    for bins in ([0, float("nan"), 100], [0, 50, float("inf")], [0, 60, 50, 100], [5]):
        with pytest.raises(ValueError, match="bins"):
            m.histogram(bins)
    with pytest.raises(TypeError, match="bins must be numbers"):
        m.histogram("0 50 100")


# --- finding 9: numbers of the wrong kind, errors that say what was wrong ---------------------------------------
@pytest.mark.parametrize("call, error, message", [
    (lambda: snakehead.TracIK(URDF, "neck_end", "head_tip", timeout=10**400), ValueError,
     "timeout is too large for a float"),
    (lambda: snakehead.TracIK(URDF, "neck_end", "head_tip", timeout="1"), TypeError,
     "timeout must be a real number, got str '1'"),
    (lambda: snakehead.TracIK(URDF, "neck_end", "head_tip", timeout=True), TypeError,
     "timeout must be a real number, got bool True"),
    (lambda: snakehead.HeadController(timeout=[0.1]), TypeError, "timeout must be a real number, got list"),
    (lambda: snakehead.HeadController(n_frames=2.5), TypeError, "n_frames must be an integer, got float"),
    (lambda: snakehead.HeadController(workspace_map="map.npz"), TypeError, "workspace_map must be a ReachabilityMap"),
    (lambda: snakehead.plan([SPHERE_1], timing={"velocity_limit": "fast"}), TypeError,
     "velocity_limit must be a number or an array of 16 numbers, got str"),
    (lambda: snakehead.plan([SPHERE_1], timing={"friction": None}), TypeError, "friction must be a real number"),
    (lambda: snakehead.BasePlacement(x="1"), TypeError, "must be numbers, got text"),
    (lambda: snakehead.BasePlacement(yaw=None), TypeError, "must be numbers, got None"),
    (lambda: Target("a", [0, 0, "1"], [1, 0, 0]), TypeError, "position must be numbers"),
    (lambda: Target("a", *SPHERE_1, hold_s=True), TypeError, "hold_s must be a real number, got bool"),
    (lambda: SnakeRobot.default().frames([True] * 16), TypeError, "q must be numbers, got booleans"),
    (lambda: sim.simulate_trajectory(SnakeRobot.default(), [0, 1], np.zeros((2, 16)), settle="0.3"), TypeError,
     "settle must be a real number"),
    (lambda: ws.load(3), TypeError, "must be a path"),
    # found by test_properties.py: pybind11's "incompatible function arguments" for a lone surrogate; numpy
    # dropped the imaginary part with a warning only; Python's own "'NoneType' object is not iterable"; method,
    # seed and a truthy "False" ignored beside a controller
    (lambda: SnakeRobot.from_urdf("\ud800" + URDF.read_text(), base_end="base_end", neck_end="neck_end",
                                  head_tip="head_tip"), ValueError, "urdf is not valid text: surrogates not allowed"),
    (lambda: Target("a", [1j, 0, 0], [1, 0, 0]), TypeError, "position must be real numbers, got complex128"),
    (lambda: snakehead.plan([SPHERE_1], obstacles=None), TypeError,
     "obstacles must be a sequence, got NoneType None"),
    (lambda: snakehead.plan(3), TypeError, "targets must be a sequence, got int 3"),
    (lambda: snakehead.plan([SPHERE_1], controller=_CONTROLLER(), seed=-1), ValueError, "seed must be between 0"),
    (lambda: snakehead.plan([SPHERE_1], controller=_CONTROLLER(), method="fast"), ValueError,
     "method must be 'rotated' or 'free_roll', got 'fast'"),
    (lambda: snakehead.plan([SPHERE_1], controller=_CONTROLLER(), allow_relocation="False"), TypeError,
     "allow_relocation must be True or False, got str 'False'"),
    (lambda: snakehead.plan([SPHERE_1], timing={"dt": 1.0}), ValueError, "timing has no option 'dt'"),
])
def test_wrong_kinds_of_numbers_are_type_errors(call, error, message):
    """timeout=10**400 raised OverflowError; "1" and True were accepted as 1 s; None became NaN."""
    with pytest.raises(error, match=re.escape(message)):
        call()


def test_huge_finite_directions_are_normalised_not_zeroed():
    """Hypothesis found it: a direction of (1e300, 1e300, 1e300) is finite, but its norm overflowed to inf, so it
    became the zero vector (a silent wrong answer). Directions are scaled before they are normalised."""
    from snakehead._validate import position_direction_pairs, unit_vector3
    from snakehead.scenes.scene import scene_from_dict

    expected = np.full(3, 1.0 / np.sqrt(3.0))
    np.testing.assert_allclose(unit_vector3([1e300, 1e300, 1e300], "direction"), expected, rtol=1e-15)
    _, d, _ = position_direction_pairs([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]], [[1e300, 0.0, 1e300], [0.0, 3.0, 4.0]])
    np.testing.assert_allclose(d, [[2 ** -0.5, 0.0, 2 ** -0.5], [0.0, 0.6, 0.8]], rtol=1e-15)
    scene = scene_from_dict({"name": "huge", "targets": [{"name": "a", "position": [0.0, 0.5, 0.3],
                                                           "direction": [1e300, 1e300, 1e300]}]})
    np.testing.assert_allclose(scene.targets[0].direction, expected, rtol=1e-15)
    with pytest.raises(ValueError, match="zero length"):
        unit_vector3([0.0, 0.0, 0.0], "direction")
