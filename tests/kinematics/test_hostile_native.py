"""Hostile and broken input at the native boundary (issue 14): what Python and the command line see of the
C++ core's checks on durations, sizes, robot descriptions, urdfdom's messages, exceptions and files.

Cases that crashed the interpreter (SIGSEGV) or hung before the fixes run in a subprocess with a timeout, so
that a crash or a hang fails the test instead of ending the run.
"""
from __future__ import annotations

import os
import resource
import shutil
import stat
import subprocess
import sys
import sysconfig
import textwrap
from pathlib import Path

import numpy as np
import pytest

from snakehead import Chain, TracIK, _core, default_urdf_path, limits
from snakehead.kinematics import reachability as ws

URDF = default_urdf_path()
MAX_TIMEOUT_S = limits.MAX_TIMEOUT_S  # the core's (include/snakehead/limits.hpp)
MAX_DEPTH = limits.MAX_URDF_DEPTH
MAX_URDF_BYTES = limits.MAX_URDF_BYTES
SMALL = dict(voxel=0.2, directions=2, rolls=1, cloud_samples=200, timeout=1e-3)


def python(code: str, timeout: float = 120, **kw) -> subprocess.CompletedProcess:
    """Runs ``code`` in a fresh interpreter; a crash shows as a negative return code, a hang as a timeout."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=timeout, **kw)


def workspace_gen() -> str:
    """The workspace_gen installed with this interpreter's snakehead (PATH may lead to another install)."""
    exe = Path(sysconfig.get_path("scripts")) / "workspace_gen"
    found = str(exe) if exe.exists() else shutil.which("workspace_gen")
    assert found, "workspace_gen is not installed (the wheel installs it)"
    return found


def gen(out, *extra: str, urdf=URDF, base="link_10", tip="head_tip", **kw) -> subprocess.CompletedProcess:
    args = [workspace_gen(), "--urdf", str(urdf), "--base", base, "--tip", tip, "--out", str(out), "--voxel", "0.2",
            "--directions", "2", "--rolls", "1", "--cloud-samples", "200", "--quiet", *extra]
    return subprocess.run(args, capture_output=True, text=True, **{"timeout": 120, **kw})


def one_error_line(stderr: str) -> str:
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert len(lines) == 1, stderr
    return lines[0]


def two_links(link_b: str) -> str:
    return ("<?xml version='1.0'?><robot name='r'><link name='a'/>" + link_b +
            "<joint name='j' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 1'/>"
            "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>")


@pytest.fixture(scope="module")
def head():
    return Chain.from_urdf(URDF, "neck_end", "head_tip")


# --- durations ----------------------------------------------------------------------------------------------
def test_huge_timeouts_are_rejected_not_silently_failing(head):
    """A finite timeout of 1e10 s overflowed the clock deadline: every call gave up at once."""
    q_target = np.full(head.n_joints, 0.3)
    target = head.fk(q_target)
    for timeout in (1e10, 1e19, 1e300):
        with pytest.raises(ValueError, match="timeout must be at most 86400"):
            TracIK.from_chain(head, timeout=timeout)
        with pytest.raises(ValueError, match="timeout"):
            TracIK.from_chain(head).ik_ex(target, np.zeros(head.n_joints), timeout=timeout)
        with pytest.raises(ValueError, match="timeout"):
            _core.kdl_nr_jl_ik(head.model, target, np.zeros(head.n_joints), timeout)
        with pytest.raises(ValueError, match="timeout must be at most 86400"):
            ws.compute(head, progress=False, **{**SMALL, "timeout": timeout})
    # The longest allowed budget still solves (Speed returns at the first solution), seeded or not.
    for seed in (None, 5):
        q = TracIK.from_chain(head, timeout=MAX_TIMEOUT_S, seed=seed).ik(target, np.zeros(head.n_joints))
        assert q is not None
        assert np.allclose(head.fk(q), target, atol=1e-4)


def test_workspace_cli_and_workspace_gen_refuse_a_huge_timeout(tmp_path):
    """``snakehead workspace --timeout 1e300`` wrote an all-zero map and exited 0."""
    out = tmp_path / "map.npz"
    r = subprocess.run([sys.executable, "-m", "snakehead", "workspace", "--out", str(out), "--timeout", "1e300",
                        "--voxel", "0.2", "--directions", "2", "--rolls", "1", "--quiet"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 2, r.stderr
    assert r.stderr.splitlines()[-1].startswith("snakehead workspace: error: timeout must be at most 86400")
    assert "Traceback" not in r.stderr
    assert not out.exists()
    r = gen(out, "--timeout", "1e300")
    assert r.returncode == 2
    assert "timeout must be at most 86400" in one_error_line(r.stderr)
    assert not out.exists()


def test_sizes_beyond_their_limits_name_the_field():
    """Sizes failed only at allocation (a voxel of 1e-9 m asked for 10^27 voxels), or ran for days. In a subprocess
    with 4 GiB of address space and a timeout, so that neither can take the machine down."""
    r = python("""
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (4 << 30, resource.RLIM_INFINITY))
        from snakehead import Chain, default_urdf_path
        from snakehead.kinematics import workspace as ws
        head = Chain.from_urdf(default_urdf_path(), "neck_end", "head_tip")
        small = dict(voxel=0.2, directions=2, rolls=1, cloud_samples=200, timeout=1e-3)
        for change in (dict(directions=10**6), dict(voxel=1e-9), dict(cloud_samples=2 * 10**9), dict(threads=10**5)):
            try:
                ws.compute(head, progress=False, **{**small, **change})
                print("accepted", change)
            except Exception as e:
                print(type(e).__name__, e)
        try:
            ws.fibonacci_directions(2 * 10**9)
        except Exception as e:
            print(type(e).__name__, e)
        """, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    lines = r.stdout.splitlines()
    assert len(lines) == 5, r.stdout
    # InputErrors (ValueErrors) naming the argument, raised in Python before the core is called
    assert lines[0].startswith("InputError directions must be between 1 and 4096"), lines[0]
    assert lines[1].startswith("InputError voxel size 1e-09 m is too small") and "at most 256" in lines[1], lines[1]
    assert lines[2].startswith("InputError cloud_samples must be between 100 and 10000000"), lines[2]
    assert lines[3].startswith("InputError threads must be between 0 and 256"), lines[3]
    assert lines[4].startswith("InputError n (directions) must be between 1 and 4096"), lines[4]


# --- robot descriptions ---------------------------------------------------------------------------------
def test_deeply_nested_urdf_is_a_value_error_not_a_crash(tmp_path):
    """40,000 nested elements (280 kB) made urdfdom's parser overflow the stack: SIGSEGV."""
    deep = tmp_path / "deep.urdf"
    deep.write_text('<robot name="r">' + "<a>" * 40000 + "</a>" * 40000 + "</robot>")
    r = python(f"""
        from snakehead import Chain
        for source in ({str(deep)!r}, open({str(deep)!r}).read()):
            try:
                Chain.from_urdf(source, "a", "b")
            except ValueError as e:
                print("ValueError:", e)
        """, timeout=60)
    assert r.returncode == 0, f"the interpreter died ({r.returncode}): {r.stderr[-2000:]}"
    assert r.stdout.count(f"nested more than {MAX_DEPTH} levels") == 2, r.stdout
    r = gen(tmp_path / "m.npz", urdf=deep, base="a", tip="b", timeout=60)
    assert r.returncode == 2
    assert "nested more than" in one_error_line(r.stderr)


def test_unbounded_or_blocking_paths_are_refused_at_once(tmp_path):
    """/dev/zero was read forever; a FIFO waited for a writer."""
    fifo = tmp_path / "robot.urdf"
    os.mkfifo(fifo)
    big = tmp_path / "big.urdf"
    with open(big, "wb") as f:  # sparse: no disk used
        f.truncate(MAX_URDF_BYTES + 1)
    r = python(f"""
        from snakehead import Chain
        for path in ("/dev/zero", {str(fifo)!r}, {str(tmp_path)!r}, {str(big)!r}, "{tmp_path}/x\\0.urdf"):
            try:
                Chain.from_urdf(path, "a", "b")
            except ValueError as e:
                print(e)
        """, timeout=60)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert len(lines) == 5, r.stdout
    assert "/dev/zero' is a character device" in lines[0]
    assert "is a FIFO" in lines[1]
    assert "is a directory" in lines[2]
    assert f"at most {MAX_URDF_BYTES}" in lines[3]
    assert "NUL" in lines[4]
    r = gen(tmp_path / "m.npz", urdf="/dev/zero", timeout=60)
    assert r.returncode == 2 and "character device" in one_error_line(r.stderr)
    # compute(executor=...) reads the URDF for its workers with the same checks.
    with pytest.raises(ValueError, match="character device"):
        ws.urdf_text(None, "/dev/zero")


def test_urdfdom_messages_are_the_error_and_never_printed(capfd):
    """The reason went to the C-level stderr; the exception said only 'urdfdom could not parse the document'."""
    no_limits = ("<robot name='r'><link name='a'/><link name='b'/><joint name='j1' type='revolute'>"
                 "<parent link='a'/><child link='b'/><axis xyz='0 0 1'/></joint></robot>")
    with pytest.raises(ValueError, match=r"Joint \[j1\] is of type REVOLUTE but it does not specify limits"):
        Chain.from_urdf(no_limits, "a", "b")
    with pytest.raises(ValueError, match="Error reading end tag"):
        Chain.from_urdf("<robot name='r'><link name='a'></robot>", "a", "b")
    # A successful parse that makes urdfdom warn (an undefined material) is quiet too.
    Chain.from_urdf(two_links("<link name='b'><visual><geometry><box size='1 1 1'/></geometry>"
                              "<material name='nowhere'/></visual></link>"), "a", "b")
    out, err = capfd.readouterr()
    assert out == "" and err == ""


@pytest.mark.parametrize("old, new, message", [
    ('<mass value="0.2"/>', '<mass value="0,2"/>', r"mass \[0,2\] is not a float.*Link \[link_1\]"),
    ('<mass value="0.2"/>', '<mass value="nan"/>', r"mass \[nan\] is not a float.*Link \[link_1\]"),
    ('<mass value="0.2"/>', '<mass value="-0.2"/>', r"link 'link_1' <inertial>: mass must be .* >= 0"),
    ('ixx="6.16333333333e-05"', 'ixx="-6.16333333333e-05"', r"link 'link_1' <inertial>: the inertia is not positive semidefinite"),
    ('<collision>\n      <origin xyz="0.04325 0 0" rpy="0 0 0"/>\n      <geometry><box size="0.0865 0.043 0.043"/>',
     '<collision>\n      <origin xyz="0.04325 0 0" rpy="0 0 0"/>\n      <geometry><box size="0.0865 0,043 0.043"/>',
     r"0,043.*collision element for Link \[link_1\]"),
    ('<collision>\n      <origin xyz="0.04325 0 0" rpy="0 0 0"/>\n      <geometry><box size="0.0865 0.043 0.043"/>',
     '<collision>\n      <origin xyz="0.04325 0 0" rpy="0 0 0"/>\n      <geometry><box size="0.0865 0 0.043"/>',
     r"link 'link_1' <collision>: a box size must be three positive numbers"),
])
def test_malformed_body_data_names_the_link(old, new, message):
    """urdfdom dropped a malformed <inertial> or <collision>: the link became massless (static margin 19.8 ->
    16.2 mm on the default robot) and nothing said so."""
    text = URDF.read_text()
    assert old in text, old
    broken = text.replace(old, new, 1)
    with pytest.raises(ValueError, match=message):
        Chain.from_urdf(broken, "link_0", "head_tip")


def test_hash_covers_kinematics_and_bodies_separately():
    body = Chain.from_urdf(URDF, "link_0", "head_tip")
    assert body.total_mass == pytest.approx(3.2)  # DESIGN.md: 0.2 kg per 0.0865 m of body
    # The shipped maps record the kinematic hash of their chains, unchanged.
    for name, (base, tip) in (("snake16_head7.npz", ("neck_end", "head_tip")), ("snake16_head6.npz", ("link_10", "head_tip"))):
        with np.load(URDF.parent / name) as z:
            assert Chain.from_urdf(URDF, base, tip).hash == str(z["chain_hash"])
    heavier = Chain.from_urdf(URDF.read_text().replace('<mass value="0.2"/>', '<mass value="0.25"/>', 1),
                              "link_0", "head_tip")
    assert heavier.hash == body.hash and heavier.body_hash != body.body_hash
    assert heavier.total_mass == pytest.approx(3.25)
    massless = Chain.from_urdf(two_links("<link name='b'/>"), "a", "b")
    assert massless.total_mass == 0.0


# --- the Python boundary of chain.py and ik.py ---------------------------------------------------------
def test_text_that_is_not_utf8_and_wrong_types_are_clear_errors(head):
    """Lone surrogates failed pybind11's conversion: "incompatible function arguments ... at 0x7f...". """
    for args in (("\udcff<robot/>", "a", "b"), (str(URDF), "link_\ud800", "head_tip"), (str(URDF), "link_0", "\udfff")):
        with pytest.raises(ValueError, match="not valid text") as info:
            Chain.from_urdf(*args)
        assert "incompatible function arguments" not in str(info.value)
    with pytest.raises(TypeError, match="ChainModel"):
        Chain("not a model")
    with pytest.raises(TypeError, match="link names"):
        TracIK(URDF, 1, "head_tip")


def test_no_runtime_error_from_the_core(head):
    """Every C++ exception is a ValueError or TypeError (or the Python exception a callback raised)."""
    options = _core.WorkspaceOptions()
    options.voxel_size, options.directions, options.rolls, options.cloud_samples = 0.2, 2, 1, 200

    def returns(value):
        return lambda done, total: value

    # A truthy result goes on (a str was "Unable to cast ... to C++ type 'bool'": RuntimeError).
    for value in ("yes", np.bool_(True), 1, None):
        _core.compute_reachability(head.model, options, returns(value))
    # A result whose truth is undefined: numpy's own ValueError, raised in the sweep's calling thread.
    with pytest.raises(ValueError, match="truth value"):
        _core.compute_reachability(head.model, options, returns(np.array([True, False])))

    def raises(done, total):
        raise KeyError("from the callback")

    with pytest.raises(KeyError, match="from the callback"):
        _core.compute_reachability(head.model, options, raises)
    with pytest.raises(_core.Cancelled, match="workspace sweep cancelled"):
        _core.compute_reachability(head.model, options, returns(False))
    assert not issubclass(_core.Cancelled, RuntimeError)


# --- files ----------------------------------------------------------------------------------------------
def _leftovers(directory: Path, keep: set[str]) -> list[str]:
    return sorted(p.name for p in directory.iterdir() if p.name not in keep)


def test_failed_map_writes_keep_the_old_file(tmp_path):
    """Saving over a map and failing (disk full, file-size limit) destroyed the old map and left a truncated one."""
    old = tmp_path / "map.npz"
    old.write_bytes(b"the old map")
    limit = 4096  # bytes: smaller than any map
    # workspace_gen (the C++ writer): exit 1 with one line, the old file as it was, no partial file.
    r = gen(old, "--voxel", "0.1", "--directions", "4",
            preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit)))
    assert r.returncode == 1, r.stderr
    assert "File too large" in one_error_line(r.stderr)
    assert old.read_bytes() == b"the old map"
    assert _leftovers(tmp_path, {"map.npz"}) == []
    # workspace.save (the same C++ writer, through the bindings): ValueError, the same guarantees.
    r = python(f"""
        import resource
        from snakehead.kinematics import workspace
        m = workspace.load({str(URDF.parent / "snake16_head6.npz")!r})
        resource.setrlimit(resource.RLIMIT_FSIZE, ({limit}, {limit}))
        try:
            workspace.save(m, {str(old)!r})
        except ValueError as e:
            print(e)
        """)
    assert r.returncode == 0, r.stderr
    assert "cannot write" in r.stdout and str(old) in r.stdout and "File too large" in r.stdout
    assert old.read_bytes() == b"the old map"
    assert _leftovers(tmp_path, {"map.npz"}) == []
    # Without the limit both replace the file, with the permissions a plain write would give.
    assert gen(old).returncode == 0
    assert np.load(old)["format"] == ws.FORMAT
    ws.save(ws.load(old), tmp_path / "copy.npz")
    assert (tmp_path / "copy.npz").stat().st_mode & 0o777 == 0o666 & ~_umask()
    assert _leftovers(tmp_path, {"map.npz", "copy.npz"}) == []


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_outputs_that_are_not_files_are_refused(tmp_path):
    """Renaming a map over a device (as root) replaced the device; opening a FIFO to check it blocked. Only
    files made here are used: never /dev/null itself."""
    fifo = tmp_path / "pipe.npz"
    os.mkfifo(fifo)
    outputs = [fifo]
    device = tmp_path / "null.npz"
    try:  # a copy of /dev/null's device node (root only)
        os.mknod(device, stat.S_IFCHR | 0o666, os.makedev(1, 3))
        outputs.append(device)
    except PermissionError:
        pass
    for out in outputs:
        r = gen(out, timeout=60)
        assert r.returncode == 2 and "not a regular file" in one_error_line(r.stderr)
        with pytest.raises(ValueError, match="not a regular file"):
            ws.save(ws.load(URDF.parent / "snake16_head6.npz"), out)
        mode = out.stat().st_mode
        assert stat.S_ISFIFO(mode) or stat.S_ISCHR(mode)
