"""Property-based fuzzing (Hypothesis) of the public API and the file formats (issue 14).

Hypothesis draws hostile inputs -- wrong types and shapes, NaN and inf, huge and tiny numbers, damaged URDFs,
robot files, scene files and map files, command lines -- and each case runs in a worker process, so that a crash
(the worker dies) or a hang (no answer within its time) fails the test with the input that caused it instead of
ending the run. The property, everywhere: a call returns a valid result or raises snakehead.InputError (or
snakehead.Infeasible: valid input without an answer) with a message, never another ValueError or TypeError (those
mean an internal step, not the input's check, refused); the command line exits 0, 1 or 2 (2 with one error line),
never 3 and never with a traceback.

Examples are bounded and drawn from a fixed seed (``derandomize``), so CI sees the same cases every run; set
SNAKEHEAD_FUZZ_EXAMPLES=N to draw N random cases per test instead (a longer search, e.g. N = 500).
"""
from __future__ import annotations

import contextlib
import io
import json
import multiprocessing
import os
import re
import shutil
import tempfile
import traceback
import warnings
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from snakehead import Infeasible, InputError, default_urdf_path
from snakehead.model.generate import SnakeSpec, snake_urdf

URDF = default_urdf_path()
DATA = Path(__file__).resolve().parents[1] / "data"
SNAKE = snake_urdf(SnakeSpec(n_joints=8, markers={"p0": 3, "b0": 4}))  # a small robot: quick to parse and solve
SNAKE_FRAMES = {"base_end": "p0", "neck_end": "b0", "head_tip": "head_tip"}
CALL_TIMEOUT_S = 120.0  # a case that has not returned by then hangs (the slowest valid case takes ~10 s)

_EXAMPLES = int(os.environ.get("SNAKEHEAD_FUZZ_EXAMPLES", "0"))


def fuzz(examples: int) -> Any:
    """Hypothesis settings: ``examples`` cases from a fixed seed, or SNAKEHEAD_FUZZ_EXAMPLES random ones."""
    return settings(max_examples=_EXAMPLES or examples, derandomize=not _EXAMPLES, deadline=None, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much], print_blob=False)


# ------------------------------------------------------------------------------------------------------------
# the worker: one process that runs the cases; the test process only draws them and judges the outcomes
# ------------------------------------------------------------------------------------------------------------
def _serve(conn: Any, folder: str) -> None:
    """The worker's loop: receives (name, args), answers ("ok", summary) or ("error", type name, message). Files
    go in ``folder``."""
    os.environ["MPLBACKEND"] = "Agg"
    _cache["folder"] = folder
    warnings.simplefilter("error", np.exceptions.ComplexWarning)  # an imaginary part dropped: a silent wrong input
    while True:
        try:
            name, args = conn.recv()
        except EOFError:
            return
        try:
            answer: tuple = ("ok", CALLS[name](*args))
        except (InputError, Infeasible) as exc:
            answer = ("error", type(exc).__name__, str(exc))
        except BaseException as exc:  # anything else is a finding: report it with where it came from
            answer = ("unexpected", type(exc).__name__, str(exc), traceback.format_exc(limit=-4))
        conn.send(answer)


class Worker:
    """A spawned interpreter that runs cases by name; restarted after a crash or a hang."""

    def __init__(self) -> None:
        self.process: Any = None
        self.folder: str | None = None

    def start(self) -> None:
        context = multiprocessing.get_context("spawn")  # a fresh interpreter: nothing inherited from pytest's
        self.conn, child = context.Pipe()
        self.folder = self.folder or tempfile.mkdtemp(prefix="snakehead-fuzz-")
        self.process = context.Process(target=_serve, args=(child, self.folder), daemon=True)
        self.process.start()
        child.close()

    def stop(self) -> None:
        if self.process is not None:
            self.process.kill()
            self.process.join()
            self.process = None

    def close(self) -> None:
        self.stop()
        if self.folder is not None:
            shutil.rmtree(self.folder, ignore_errors=True)
            self.folder = None

    def call(self, name: str, *args: Any) -> tuple:
        if self.process is None or not self.process.is_alive():
            self.start()
        self.conn.send((name, args))
        if not self.conn.poll(CALL_TIMEOUT_S):
            self.stop()
            raise AssertionError(f"{name}{_shown(args)} hung (no answer in {CALL_TIMEOUT_S:g} s)")
        try:
            return self.conn.recv()
        except EOFError:
            self.process.join()
            code = self.process.exitcode
            self.process = None
            raise AssertionError(f"{name}{_shown(args)} crashed the interpreter (exit code {code})") from None


def _shown(args: tuple) -> str:
    text = repr(args)
    return text if len(text) < 600 else text[:600] + "..."


WORKER = Worker()


@pytest.fixture(scope="module", autouse=True)
def _worker():
    yield
    WORKER.close()


#: Words of errors that do not say what was wrong with the input: pybind11's and C++'s, and Python's own about
#: an operation on a value of the wrong type deep inside (the input's name is not in them).
NOISE = (r"incompatible function arguments", r"Invoked with", r"_core\.\w+ object at 0x", r"Traceback", r"std::",
         r"^'\w+' object is not", r"object has no attribute", r"unsupported operand", r"not supported between",
         r"takes \d+ positional", r"got an unexpected keyword")


def _gist(message: str) -> str:
    """The first words of an error, paths left out: what the statistics count."""
    return " ".join(re.sub(r"'/[^']*'", "PATH", message).split()[:6])[:60]


def expect_valid_or_clear_error(name: str, *args: Any, must_fail: bool = False) -> tuple:
    """Runs case ``name`` in the worker; asserts it returned or raised InputError/Infeasible with a clear message
    (never pybind11's "incompatible function arguments", an address, or another exception type). Returns the
    answer."""
    answer = WORKER.call(name, *args)
    # what the cases came to (pytest --hypothesis-show-statistics): a suite whose cases all fail the same way
    # tests little
    event("accepted" if answer[0] == "ok" else f"{answer[1]}: {_gist(str(answer[2]))}")
    if answer[0] == "unexpected":
        raise AssertionError(f"{name}{_shown(args)} raised {answer[1]}: {answer[2]}\n{answer[3]}")
    if answer[0] == "error":
        kind, message = answer[1], answer[2]
        assert message.strip(), f"{name}{_shown(args)} raised {kind} without a message"
        for noise in NOISE:
            assert not re.search(noise, message), f"{name}{_shown(args)}: {kind}: {message}"
    elif must_fail:
        raise AssertionError(f"{name}{_shown(args)} accepted an input it must refuse: {answer[1]!r}")
    return answer


# ------------------------------------------------------------------------------------------------------------
# the cases, as the worker runs them (each returns a small summary, after checking what it can of the result)
# ------------------------------------------------------------------------------------------------------------
_cache: dict[str, Any] = {}


def _controller() -> Any:
    if "controller" not in _cache:
        import snakehead

        _cache["controller"] = snakehead.HeadController(method="free_roll", seed=1, timeout=0.002)
    return _cache["controller"]


def _in_folder(files: dict[str, bytes | str]) -> Path:
    """A folder (emptied: one case at a time) in the worker's temporary folder, holding ``files``."""
    folder = Path(_cache["folder"]) / "case"
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir()
    for name, content in files.items():
        (folder / name).write_bytes(content.encode("utf-8", "surrogatepass") if isinstance(content, str)
                                    else content)
    return folder


def _robot_from_urdf(text: str, frames: dict) -> tuple:
    from snakehead import SnakeRobot

    robot = SnakeRobot.from_urdf(text, **frames)
    F = robot.frames(np.zeros(robot.n_joints))
    assert np.all(np.isfinite(F)) and np.isfinite(robot.total_mass) and robot.total_mass > 0
    return robot.n_joints, robot.total_mass


def _robot_from_file(toml: str, urdf: str) -> tuple:
    from snakehead import SnakeRobot

    folder = _in_folder({"robot.toml": toml, "snake.urdf": urdf})
    robot = SnakeRobot.from_file(folder / "robot.toml")
    assert np.isfinite(robot.total_mass) and robot.total_mass > 0
    return robot.n_joints, robot.parts.base_end, robot.parts.neck_end, robot.parts.head_tip


def _robot_from_xacro(text: str) -> tuple:
    """The xacro style's robot file with its .xacro text replaced by ``text``."""
    from snakehead import SnakeRobot
    from snakehead.samples.published import write_robot

    folder = Path(_cache["folder"]) / "case"
    shutil.rmtree(folder, ignore_errors=True)
    robot_file = write_robot("xacro", folder)
    (folder / "reu_snake.urdf.xacro").write_text(text, encoding="utf-8", errors="surrogatepass")
    robot = SnakeRobot.from_file(robot_file)
    return robot.n_joints, robot.parts.head_tip


def _mesh_obstacle(name: str, data: bytes) -> tuple:
    """A mesh obstacle from the file ``name`` holding ``data``; what it promises: finite convex pieces."""
    from snakehead import MeshObstacle

    obstacle = MeshObstacle.load(_in_folder({name: data}) / name, position=[1.0, 0.0, 0.0])
    vertices = obstacle.world_vertices
    assert len(vertices) >= 4 and np.all(np.isfinite(vertices))
    return len(vertices), len(obstacle.shapes())


def _load_map(data: bytes) -> tuple:
    from snakehead import load_map

    m = load_map(_in_folder({"m.npz": data}) / "m.npz")
    # what a loaded map promises: indices in [0, 100] from its counts, its voxels inside its grid
    assert np.all((m.indices >= 0) & (m.indices <= 100)) and np.all(np.isfinite(m.centers))
    assert len(m.centers) == len(m.voxel_ids) == len(m.solved) and m.tried >= 1
    if len(m):
        assert m.index_at(m.centers[0]) == pytest.approx(m.indices[0])
    return len(m), m.tried


def _load_scene(text: str) -> tuple:
    from snakehead.scenes import load_scene

    scene = load_scene(_in_folder({"scene.toml": text}) / "scene.toml")
    return _check_scene(scene)


def _scene_from_dict(data: dict) -> tuple:
    from snakehead.scenes.scene import scene_from_dict

    return _check_scene(scene_from_dict(data))


def _check_scene(scene: Any) -> tuple:
    for t in scene.targets:
        assert np.all(np.isfinite(t.position)) and abs(np.linalg.norm(t.direction) - 1) < 1e-9
        assert np.isfinite(t.hold_s) and t.hold_s >= 0
    return scene.name, len(scene.targets), len(scene.obstacles)


def _trac_ik(options: dict, pose: Any, q_init: Any) -> Any:
    import snakehead

    ik = snakehead.TracIK(URDF, "neck_end", "head_tip", **options)
    q = ik.ik(pose, q_init)
    if q is not None:  # a solution is within the limits and at the pose (within the position tolerances)
        assert np.all((q >= ik.lower - 1e-9) & (q <= ik.upper + 1e-9))
        # each axis within its bound plus epsilon (the docstring of snakehead.kinematics.ik)
        per_axis = np.abs(np.asarray(ik.bounds, float)[:3]) + ik.epsilon
        assert np.linalg.norm(ik.fk(q)[:3, 3] - np.asarray(pose, float)[:3, 3]) <= np.linalg.norm(per_axis) + 1e-9
    return None if q is None else q.tolist()


def _controller_new(options: dict) -> str:
    import snakehead

    c = snakehead.HeadController(**options)
    return type(c).__name__


def _controller_solve(position: Any, direction: Any, q_prev: Any) -> tuple:
    c = _controller()
    s = c.solve(position, direction, q_prev=q_prev)
    if s.success:  # a success is within the limits and at the target (by the whole body's FK); stable, or says not
        robot = c.robot
        assert np.all((s.q >= robot.lower - 1e-9) & (s.q <= robot.upper + 1e-9))
        achieved = robot.frame(s.q, "head_tip", s.base)
        assert np.linalg.norm(achieved[:3, 3] - np.asarray(position, float)) < 0.01
        assert s.static_stable or "outside the support polygon" in s.message
    return bool(s.success), float(s.position_error_m)


def _plan(targets: Any, options: dict) -> tuple:
    import snakehead

    options = {"controller": _controller(), **options}
    if options["controller"] is None and options.get("robot") is None:
        options["controller"] = _controller()
    p = snakehead.plan(targets, **options)
    assert np.all(np.isfinite(p.q)) and np.all(np.diff(p.t) > 0)
    assert p.success or p.failure  # an unsuccessful plan says why
    return bool(p.success), len(p.t)


def _frames(q: Any) -> tuple:
    F = _controller().robot.frames(q)
    assert np.all(np.isfinite(F))
    return F.shape


def _cli(argv: list) -> tuple:
    from snakehead.app import cli

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = cli.main(argv)
        except SystemExit as exc:  # argparse's errors
            code = exc.code if isinstance(exc.code, int) else 2
    return code, err.getvalue()


CALLS = {"robot_from_urdf": _robot_from_urdf, "robot_from_file": _robot_from_file, "load_map": _load_map,
         "robot_from_xacro": _robot_from_xacro, "mesh_obstacle": _mesh_obstacle,
         "load_scene": _load_scene, "scene_from_dict": _scene_from_dict, "trac_ik": _trac_ik,
         "controller_new": _controller_new, "controller_solve": _controller_solve, "plan": _plan,
         "frames": _frames, "cli": _cli}


# ------------------------------------------------------------------------------------------------------------
# strategies
# ------------------------------------------------------------------------------------------------------------
#: numbers as text that are not plain finite numbers, or are at the edges of what a field takes
HOSTILE_NUMBERS = ["nan", "inf", "-inf", "-1", "0", "-0", "1e300", "1e-300", "1e400", "", "abc", "0,2", "0x10",
                   "1_0", "\u0661", " 1", "2.5", "9" * 40, "-1e-9"]
#: text that breaks the syntax or the meaning of a document where it is put
HOSTILE_TEXT = ['"', "'", "<", ">", "&", "&amp;", "]]>", "<!--", "\x00", "\x7f", "\ud800", "\n", "[", "]", "{", "=",
                "\\", "\u2603", "<link/>", '<joint name="x" type="revolute"/>', "<a>" * 3000 + "</a>" * 3000,
                '<!DOCTYPE r [<!ENTITY e "x">]>', "&e;", "\nx = " + "[" * 3000 + "]" * 3000 + "\n",
                "\n[" + "a." * 2000 + "b]\n", "$\\frac{$"]

hostile_scalars = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-(10**30), max_value=10**30), st.integers(10**300, 10**400),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=8), st.sampled_from(HOSTILE_NUMBERS),
    st.just(b"1"), st.just(1j), st.just(object()), st.just({}),
)


def _array(shape: Any, elements: Any = None) -> Any:
    if elements is None:
        elements = st.floats(allow_nan=True, allow_infinity=True)
    return hnp.arrays(np.float64, shape, elements=elements)


def vectors(n: int, valid: Any) -> Any:
    """``n``-vectors: valid ones (``valid``) half the time, else wrong lengths, shapes, types, NaN and inf."""
    return st.one_of(
        valid,
        _array(st.sampled_from([(n,), (n - 1,), (n + 1,), (1, n), (n, 1), (0,), ()])),
        st.lists(hostile_scalars, min_size=n, max_size=n), st.lists(st.floats(), max_size=n + 2),
        hostile_scalars,
    )


def unit_vectors() -> Any:
    return st.builds(lambda a, b: np.array([np.cos(a) * np.cos(b), np.sin(a) * np.cos(b), np.sin(b)]),
                     st.floats(-np.pi, np.pi), st.floats(-1.5, 1.5))




def poses() -> Any:
    """4x4 arrays: rigid transforms, and matrices that only look like one (scaled, sheared, NaN, wrong shape)."""
    def rigid(v: np.ndarray) -> np.ndarray:
        from scipy.spatial.transform import Rotation

        T = np.eye(4)
        T[:3, :3] = Rotation.from_rotvec(v[:3]).as_matrix()
        T[:3, 3] = v[3:]
        return T

    valid = _array((6,), st.floats(-1, 1)).map(rigid)

    def damaged(args: tuple) -> np.ndarray:
        T, kind, x = args
        T = T.copy()
        if kind == "scale":
            T[:3, :3] *= x
        elif kind == "shear":
            T[0, 1] += x
        elif kind == "bottom":
            T[3, :3] = x
        else:
            T[1, 2] = x
        return T

    broken = st.tuples(valid, st.sampled_from(["scale", "shear", "bottom", "entry"]),
                       st.floats(allow_nan=True, allow_infinity=True)).map(damaged)
    return st.one_of(valid, broken, _array(st.sampled_from([(4, 4), (3, 4), (4,), (16,), (2, 4, 4)])),
                     hostile_scalars)


def _replace(text: str, start: int, end: int, new: str) -> str:
    return text[:start] + new + text[end:]


@st.composite
def mutated(draw: Any, text: str, fragments: list[str], numbers: list[str]) -> str:
    """``text`` with one to three edits: a number replaced, a span deleted, duplicated or replaced by a hostile
    fragment, a name swapped for another of the document's names, or the text cut short."""
    spots = [m.span() for m in re.finditer(r"-?\d+(?:\.\d+)?(?:e-?\d+)?", text)]
    names = sorted(set(re.findall(r'name\s*=\s*"([^"]*)"', text)))
    for _ in range(draw(st.integers(1, 3))):
        n = len(text)
        kind = draw(st.sampled_from(["number", "delete", "duplicate", "insert", "name", "cut", "bom"]))
        a = draw(st.integers(0, n))
        b = min(n, a + draw(st.integers(0, 200)))
        if kind == "number" and spots:
            s, e = draw(st.sampled_from(spots))
            if e <= n:
                text = _replace(text, s, e, draw(st.sampled_from(numbers)))
        elif kind == "delete":
            text = _replace(text, a, b, "")
        elif kind == "duplicate":
            text = _replace(text, a, a, text[a:b])
        elif kind == "insert":
            text = _replace(text, a, a, draw(st.sampled_from(fragments) | st.text(max_size=20)))
        elif kind == "name" and len(names) > 1:
            old, new = draw(st.sampled_from(names)), draw(st.sampled_from(names + ["", "x" * 300, "\u2603"]))
            text = text.replace(f'"{old}"', f'"{new}"', draw(st.integers(1, 3)))
        elif kind == "cut":
            text = text[:a]
        elif kind == "bom":  # a byte-order mark, as Windows editors write it: valid, and read as if absent
            text = "\ufeff" + text.removeprefix("\ufeff")
    return text


# ------------------------------------------------------------------------------------------------------------
# robots: URDF text and robot files
# ------------------------------------------------------------------------------------------------------------
@fuzz(60)
@given(text=mutated(SNAKE, HOSTILE_TEXT, HOSTILE_NUMBERS),
       frames=st.one_of(st.just(SNAKE_FRAMES), st.fixed_dictionaries(
           {k: st.sampled_from([v, "link_0", "head_tip", "", "nope", "\x00", "p0"]) for k, v in SNAKE_FRAMES.items()})))
def test_robots_from_damaged_urdfs(text, frames):
    expect_valid_or_clear_error("robot_from_urdf", text, frames)


def _xacro_text() -> str:
    from snakehead.samples.published import write_robot

    with tempfile.TemporaryDirectory() as folder:
        write_robot("xacro", folder)
        return (Path(folder) / "reu_snake.urdf.xacro").read_text(encoding="utf-8")


XACRO = _xacro_text()


@fuzz(25)
@given(text=mutated(XACRO, HOSTILE_TEXT + ["${", "${1/0}", "${n_modules * 10**6}", '<xacro:include filename="/dev/zero"/>',
                                            '<xacro:macro name="m"><xacro:m/></xacro:macro><xacro:m/>'],
                    HOSTILE_NUMBERS))
def test_damaged_xacro_files(text):
    """The xacro style's description damaged: xacro's own errors, recursion, huge or bad expressions, includes of
    what is not a file: each an InputError naming the file."""
    expect_valid_or_clear_error("robot_from_xacro", text)


def _mesh_bytes() -> dict[str, bytes]:
    from snakehead.samples.published import write_robot

    with tempfile.TemporaryDirectory() as folder:
        write_robot("mesh", folder)
        return {p.name: p.read_bytes() for p in sorted((Path(folder) / "meshes").iterdir())}


MESHES = _mesh_bytes()


@st.composite
def damaged_meshes(draw: Any) -> tuple[str, bytes]:
    """A mesh file of each kind (STL, OBJ, DAE) with bytes flipped, cut or repeated, or its text damaged."""
    name = draw(st.sampled_from(sorted(MESHES)))
    raw = bytearray(MESHES[name])
    kind = draw(st.sampled_from(["flip", "cut", "repeat", "empty", "text"]))
    at = draw(st.integers(0, len(raw) - 1))
    if kind == "flip":
        for i in draw(st.lists(st.integers(0, len(raw) - 1), min_size=1, max_size=8)):
            raw[i] ^= draw(st.integers(1, 255))
    elif kind == "cut":
        raw = raw[:at]
    elif kind == "repeat":
        raw = raw[:at] + raw[max(at - 64, 0):]
    elif kind == "empty":
        raw = bytearray()
    else:
        raw = bytearray(raw[:at] + draw(st.sampled_from(HOSTILE_TEXT + HOSTILE_NUMBERS)).encode("utf-8", "surrogatepass")
                        + raw[at:])
    return name, bytes(raw)


@fuzz(40)
@given(mesh=damaged_meshes())
def test_damaged_mesh_files(mesh):
    expect_valid_or_clear_error("mesh_obstacle", *mesh)


def test_the_xacro_and_mesh_properties_can_pass():
    assert WORKER.call("robot_from_xacro", XACRO)[0] == "ok"
    for name, data in MESHES.items():
        assert WORKER.call("mesh_obstacle", name, data)[0] == "ok", name


ROBOT_KEYS = ["urdf", "root", "base_end", "neck_end", "head_tip", "map"]
toml_values = st.one_of(st.text(max_size=12), st.sampled_from(["snake.urdf", "p0", "b0", "head_tip", "link_0",
                                                               "missing.npz", "/dev/zero", ".", "../x", "m.npz"]),
                        st.integers(-5, 5), st.floats(allow_nan=False, allow_infinity=False), st.booleans(),
                        st.lists(st.integers(0, 3), max_size=3))


@fuzz(40)
@given(edits=st.lists(st.tuples(st.sampled_from(ROBOT_KEYS + ["extra", ""]), st.booleans(), toml_values),
                      max_size=3),
       urdf=st.one_of(st.just(SNAKE), mutated(SNAKE, HOSTILE_TEXT, HOSTILE_NUMBERS)),
       damage=st.sampled_from([False, False, False, True]))
def test_robot_files(edits, urdf, damage):
    """The small robot's file with keys removed, added or of another value or type (JSON's quoting is TOML's for
    these values), its URDF damaged, and sometimes the TOML itself broken."""
    entries: dict = {"urdf": "snake.urdf", **SNAKE_FRAMES}
    for key, remove, value in edits:
        if remove:
            entries.pop(key, None)
        else:
            entries[key] = value
    toml = "".join(f"{json.dumps(k)} = {json.dumps(v)}\n" for k, v in entries.items())
    if damage:
        toml = toml.replace("=", "", 1) + '\n[x\n"'
    expect_valid_or_clear_error("robot_from_file", toml, urdf)


def test_a_complete_robot_file_loads():
    """The robot-file property can pass: a complete file of the small robot loads."""
    toml = "".join(f"{k} = {json.dumps(v)}\n" for k, v in {"urdf": "snake.urdf", **SNAKE_FRAMES}.items())
    assert WORKER.call("robot_from_file", toml, SNAKE) == ("ok", (8, "p0", "b0", "head_tip"))


# ------------------------------------------------------------------------------------------------------------
# maps
# ------------------------------------------------------------------------------------------------------------
MAP_FILES = [DATA / "map_format1.npz", URDF.with_name("snake16_head6.npz")]


@st.composite
def damaged_map_arrays(draw: Any) -> bytes:
    """A map file with one to three of its arrays replaced (another dtype, shape or values), removed, or added."""
    with np.load(draw(st.sampled_from(MAP_FILES))) as z:
        arrays = {k: z[k] for k in z.files}
    for _ in range(draw(st.integers(1, 3))):
        key = draw(st.sampled_from(sorted(arrays)))
        kind = draw(st.sampled_from(["values", "dtype", "shape", "remove", "scalar", "text"]))
        a = arrays[key]
        if kind == "values" and a.size and a.dtype.kind in "iubf":
            a = a.astype(float)
            flat = a.reshape(-1)
            flat[draw(st.integers(0, flat.size - 1))] = draw(st.floats(allow_nan=True, allow_infinity=True))
        elif kind == "dtype":
            dtype = draw(st.sampled_from(["f4", "i1", "u8", "U3", "b1", "c16"]))
            a = a.astype(dtype if a.dtype.kind != "U" else "U3", casting="unsafe")  # text casts to text only
        elif kind == "shape":
            a = a.reshape(-1)[: draw(st.integers(0, max(a.size - 1, 0)))]
        elif kind == "remove":
            arrays.pop(key)
            continue
        elif kind == "scalar":
            a = np.array(draw(st.one_of(st.integers(-(2**63), 2**63 - 1), st.floats(), st.text(max_size=5),
                                        st.booleans())))
        else:
            a = np.array(draw(st.text(max_size=30)))
        arrays[key] = a
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


@st.composite
def damaged_map_bytes(draw: Any) -> bytes:
    """A map file's bytes flipped, cut, or repeated; or a valid archive of foreign members."""
    raw = bytearray(draw(st.sampled_from(MAP_FILES)).read_bytes())
    kind = draw(st.sampled_from(["flip", "cut", "repeat", "foreign"]))
    at = draw(st.integers(0, len(raw) - 1))
    if kind == "flip":
        for i in draw(st.lists(st.integers(0, len(raw) - 1), min_size=1, max_size=8)):
            raw[i] ^= draw(st.integers(1, 255))
        return bytes(raw)
    if kind == "cut":
        return bytes(raw[:at])
    if kind == "repeat":
        return bytes(raw[:at] + raw[at - 64 if at >= 64 else 0:])
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z, warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # duplicate member names are part of the damage
        for name, data in draw(st.lists(st.tuples(st.sampled_from(["format.npy", "centers.npy", "x.txt", "../a",
                                                                   "indices"]),
                                                  st.binary(max_size=64)), max_size=3)):
            z.writestr(name, data)
    return buf.getvalue()


@fuzz(80)
@given(data=st.one_of(damaged_map_arrays(), damaged_map_bytes()))
def test_damaged_maps(data):
    expect_valid_or_clear_error("load_map", data)


def test_the_map_property_can_pass():
    for path in MAP_FILES:
        assert WORKER.call("load_map", path.read_bytes())[0] == "ok"


# ------------------------------------------------------------------------------------------------------------
# scenes
# ------------------------------------------------------------------------------------------------------------
SCENE = """name = "fuzz"
description = "a target and a box"
base = [0.0, 0.0, 0.0]

[[targets]]
name = "a"
position = [-0.0405, 0.5443, 0.3]
direction = [0.0, 1.0, 0.0]
hold_s = 1.0

[[obstacles]]
kind = "box"
centre = [0.5, -0.5, 0.1]
size = [0.2, 0.2, 0.2]
yaw = 0.3
"""
json_values = st.recursive(
    st.one_of(st.none(), st.booleans(), st.floats(), st.integers(-(10**20), 10**20), st.text(max_size=6)),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=3),
    max_leaves=8)
SCENE_TABLE = {"name": "fuzz", "base": {"x": 0.0, "y": 0.0, "yaw": 0.0},
               "targets": [{"name": "a", "position": [-0.0405, 0.5443, 0.3], "direction": [0.0, 1.0, 0.0]},
                           {"name": "b", "position": [0.0, 0.5, 0.3], "direction": [0.0, 1.0, 0.0], "hold_s": 0.5,
                            "approach": "line", "step_m": 0.01}],
               "obstacles": [{"kind": "box", "centre": [0.5, -0.5, 0.1], "size": [0.2, 0.2, 0.2], "yaw": 0.3},
                             {"kind": "wall_with_hole", "hole_centre": [0.2, 0.5, 0.4], "normal": [0.0, 1.0, 0.0],
                              "size": [0.7, 0.58, 0.01], "hole_diameter": 0.07}]}
scene_values = st.one_of(json_values, st.sampled_from(HOSTILE_NUMBERS), st.sampled_from(
    [[0.1, 0.2], [0.1, 0.2, 0.3, 0.4], [float("nan")] * 3, [1e300] * 3, [0, 0, 0], "line", "free", "box", -1.0,
     1e300, 0.0]))


@st.composite
def edited_scene_tables(draw: Any) -> dict:
    """The valid scene above with one to three keys removed or given another value: at the top, in a target, in
    an obstacle or in the base."""
    data = json.loads(json.dumps(SCENE_TABLE))
    for _ in range(draw(st.integers(1, 3))):
        where = draw(st.sampled_from(["top", "targets", "obstacles", "base"]))
        table = data
        if where != "top":
            inner = data.get(where)
            if isinstance(inner, list) and inner and isinstance(inner[0], dict):
                table = inner[draw(st.integers(0, len(inner) - 1))]
            elif isinstance(inner, dict):
                table = inner
        key = draw(st.sampled_from(sorted(table) + ["extra"]))
        if draw(st.booleans()):
            table.pop(key, None)
        else:
            table[key] = draw(scene_values)
    return data


@fuzz(80)
@given(data=edited_scene_tables())
def test_scenes_from_tables(data):
    """Scene files as TOML gives them to scene_from_dict: keys missing, of another type or out of range."""
    expect_valid_or_clear_error("scene_from_dict", data)


def test_the_scene_property_can_pass():
    assert WORKER.call("scene_from_dict", SCENE_TABLE) == ("ok", ("fuzz", 2, 2))


@fuzz(40)
@given(text=mutated(SCENE, HOSTILE_TEXT, HOSTILE_NUMBERS))
def test_damaged_scene_files(text):
    expect_valid_or_clear_error("load_scene", text)


# ------------------------------------------------------------------------------------------------------------
# the solvers: TracIK, HeadController, plan
# ------------------------------------------------------------------------------------------------------------
ik_options = st.fixed_dictionaries({}, optional={
    "timeout": st.one_of(st.floats(1e-4, 0.01), hostile_scalars), "epsilon": st.one_of(st.just(1e-5), hostile_scalars),
    "solve_type": st.sampled_from(["Speed", "Distance", "Manip1", "Manip2", "speed", ""]) | hostile_scalars,
    "seed": st.one_of(st.integers(0, 2**64), st.integers(-5, -1), hostile_scalars),
    "bounds": vectors(6, st.just([1e-3] * 6))})


@fuzz(60)
@given(options=ik_options, pose=poses(), q_init=st.one_of(st.none(), vectors(7, _array((7,), st.floats(-1, 1)))))
def test_trac_ik(options, pose, q_init):
    answer = expect_valid_or_clear_error("trac_ik", options, pose, q_init)
    if answer[0] == "ok" and isinstance(pose, np.ndarray) and pose.shape == (4, 4):
        R = pose[:3, :3]  # a pose that is not a rigid transform must be refused, not solved to something else
        assert np.all(np.isfinite(pose)) and np.allclose(R @ R.T, np.eye(3), atol=1e-6)
        assert np.allclose(pose[3], [0, 0, 0, 1])


@fuzz(40)
@given(hostile=st.sampled_from(["none", "position", "direction", "q_prev"]), data=st.data())
def test_head_controller_solve(hostile, data):
    """One argument hostile at a time (or none: then a success keeps the joints within their limits)."""
    valid = {"position": _array((3,), st.floats(-0.6, 0.6)), "direction": unit_vectors(),
             "q_prev": st.none() | _array((16,), st.floats(-1.5, 1.5))}
    args = {k: data.draw(vectors(16 if k == "q_prev" else 3, v) if k == hostile else v, label=k)
            for k, v in valid.items()}
    answer = expect_valid_or_clear_error("controller_solve", args["position"], args["direction"], args["q_prev"])
    q_prev = args["q_prev"]
    if answer[0] == "ok" and isinstance(q_prev, np.ndarray):  # a q_prev outside the limits is refused
        assert np.all(np.abs(q_prev) <= np.pi / 2 + 1e-9)


@fuzz(25)
@given(options=st.fixed_dictionaries({}, optional={
    "method": st.sampled_from(["rotated", "free_roll", "x"]) | hostile_scalars, "n_frames": hostile_scalars,
    "timeout": hostile_scalars, "epsilon": hostile_scalars, "seed": hostile_scalars, "slack": hostile_scalars,
    "base_configuration": vectors(16, _array((16,), st.floats(-3, 3))), "allow_base_move": hostile_scalars,
    "workspace_map": hostile_scalars, "base_pose": hostile_scalars}))
def test_head_controller_options(options):
    assume(options)  # the default controller is the other tests' subject
    expect_valid_or_clear_error("controller_new", options)


@fuzz(40)
@given(q=vectors(16, _array((16,), st.floats(-3, 3))))
def test_robot_frames(q):
    expect_valid_or_clear_error("frames", q)


PLAN_OPTIONS = {
    "timing": st.dictionaries(st.sampled_from(["velocity_limit", "acceleration_limit", "torque_limit", "zmp_margin",
                                               "friction", "dt", "hold_s"]), hostile_scalars, min_size=1,
                              max_size=2) | hostile_scalars,
    # values that are valid (a seed, a flag, None for a default) would only plan again: left out
    "seed": hostile_scalars.filter(lambda x: x is not None and not (type(x) is int and 0 <= x < 2**64)),
    "method": hostile_scalars, "allow_relocation": hostile_scalars.filter(lambda x: not isinstance(x, bool)),
    "obstacles": hostile_scalars | st.lists(hostile_scalars, min_size=1, max_size=2),
    "base": hostile_scalars.filter(lambda x: x is not None), "robot": hostile_scalars.filter(lambda x: x is not None),
    "controller": hostile_scalars.filter(lambda x: x is not None)}


@fuzz(10)
@given(hostile=st.sampled_from(["position", "direction", "targets", *PLAN_OPTIONS]), data=st.data())
def test_plan(hostile, data):
    """One argument hostile at a time; the few hostile values that are valid (a seed, a friction) plan for real."""
    position, direction = [-0.0405, 0.5443, 0.3], [0.0, 1.0, 0.0]
    if hostile == "position":
        position = data.draw(vectors(3, st.nothing()), label="position")
    elif hostile == "direction":
        direction = data.draw(vectors(3, st.nothing()), label="direction")
    targets: Any = [(position, direction)]
    if hostile == "targets":
        targets = data.draw(hostile_scalars | st.lists(hostile_scalars, max_size=2), label="targets")
    options = {hostile: data.draw(PLAN_OPTIONS[hostile], label=hostile)} if hostile in PLAN_OPTIONS else {}
    if "robot" in options:  # the worker passes its controller; a robot beside it is refused before it is looked at
        options = {"robot": options["robot"], "controller": None}
    answer = expect_valid_or_clear_error("plan", targets, options)
    event(f"{hostile} {'accepted' if answer[0] == 'ok' else 'refused'}")
    if answer[0] == "ok":  # then the target was a pair of finite 3-vectors (the worker checked the plan)
        assert hostile != "targets"
        for v in (position, direction):
            assert np.shape(v) == (3,) and np.all(np.isfinite(np.asarray(v, dtype=float)))


# ------------------------------------------------------------------------------------------------------------
# the command line
# ------------------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Paths that are not what an option wants: missing, a directory, a FIFO, a device, garbage, empty."""
    folder = tmp_path_factory.mktemp("cli")
    (folder / "garbage.toml").write_bytes(b"\x00\xff[[[")
    (folder / "empty.npz").write_bytes(b"")
    (folder / "emptydir").mkdir()
    os.mkfifo(folder / "fifo")
    return {"folder": folder, "paths": [str(folder / "missing"), str(folder / "emptydir"), str(folder / "fifo"),
                                        "/dev/zero", str(folder / "garbage.toml"), str(folder / "empty.npz"), "",
                                        str(folder / "a\x00b")]}


def _argv(draw: Any, files: dict) -> list[str]:
    paths, out = files["paths"], str(files["folder"] / "out")
    bad = st.sampled_from(HOSTILE_NUMBERS + paths)
    command = draw(st.sampled_from(["info", "plan", "workspace", "view", "demo"]))
    if command == "info":
        return ["info", "--robot", draw(st.sampled_from(paths))]
    if command == "view":
        return ["view", draw(st.sampled_from(paths)), "--port", draw(st.sampled_from(["8080", *HOSTILE_NUMBERS]))]
    if command == "workspace":  # cheap when valid: a coarse grid, few directions, a short budget
        options = {"--out": out + ".npz", "--voxel": "0.3", "--directions": "2", "--rolls": "1", "--timeout": "1e-4",
                   "--seed": "1", "--threads": "1", "--shard": "0/2"}
        hostile = draw(st.sampled_from([None, *options]))  # one option hostile at a time, or none
        if hostile is not None:
            options[hostile] = draw(bad | st.sampled_from(["1/1", "2/2", "0/0", "a/b", "1e9", "100000"]))
        return ["workspace", "--quiet", *[x for kv in options.items() for x in kv]]
    # plan and demo: at least one value is bad (a valid plan takes seconds; test_cli.py runs those)
    argv = [command, "--out", out, "--no-sim", "--fast"]
    if command == "plan":
        argv += ["--position", *[draw(st.sampled_from(["0.1", "0.5", "0.3"]) | bad) for _ in range(3)],
                 "--direction", *[draw(st.sampled_from(["0", "1"]) | bad) for _ in range(3)]]
    argv += ["--seed", draw(st.sampled_from(["1"]) | bad), "--map", draw(st.sampled_from(paths))]
    return argv


@fuzz(60)
@given(data=st.data())
def test_command_lines(files, data):
    """Exit 0, 1 or 2, never 3 (a bug) and never a traceback; 2 with one error line last on stderr."""
    argv = _argv(data.draw, files)
    answer = WORKER.call("cli", argv)
    assert answer[0] == "ok", (argv, answer)
    code, err = answer[1]
    event(f"exit {code}: {' '.join(err.strip().splitlines()[-1].split()[:5]) if err.strip() else ''}"[:60])
    assert code in (0, 1, 2), (argv, code, err)
    assert "Traceback" not in err, (argv, err)
    if code == 2:
        last = err.strip().splitlines()[-1]
        assert re.match(r"snakehead( \w+)?: error: \S", last), (argv, err)


def test_the_worker_reports_crashes_and_hangs():
    """The harness can fail: a worker killed by a signal is a crash, a call that does not return is a hang."""
    global CALL_TIMEOUT_S
    with pytest.raises(AssertionError, match=r"crashed the interpreter \(exit code -11\)"):
        WORKER.call("crash")
    timeout, CALL_TIMEOUT_S = CALL_TIMEOUT_S, 1.0
    try:
        with pytest.raises(AssertionError, match="hung"):
            WORKER.call("hang")
    finally:
        CALL_TIMEOUT_S = timeout
    assert WORKER.call("frames", np.zeros(16))[0] == "ok"  # a new worker after both


def _crash() -> None:
    import signal

    os.kill(os.getpid(), signal.SIGSEGV)


def _hang() -> None:
    import time

    time.sleep(60)


CALLS.update(crash=_crash, hang=_hang)
