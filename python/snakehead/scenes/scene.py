"""Scenes: where the head must go (targets) and what is in the way (obstacles), as data.

A scene file is TOML::

    name = "spheres"                        # optional (default: the file's stem)
    description = "..."                     # optional
    robot = "my_snake.toml"                 # optional: a robot file, in the scene file's folder (or below it)
    base = { x = 0.0, y = 0.0, yaw = 0.0 }  # optional: where the base lies (m, m, rad)

    [[targets]]                             # in the order the head visits them
    name = "sphere 1"
    position = [-0.0405, 0.5443, 0.3]       # m, world (z up, ground at z = 0)
    direction = [0.0, 1.0, 0.0]             # the head's x-axis (any non-zero length)
    hold_s = 2.0                            # optional: how long the head stays there (s, default 0)
    approach = "free"                       # optional: "free" (a whole-body move, default) or "line" (the
                                            #   head moves along the straight line from the previous target,
                                            #   solved every step_m metres)
    step_m = 0.01                           # optional, for approach = "line" (m, default 0.01)
    via = false                             # optional: a pose passed through, not reported as a target
    sphere_diameter = 0.04                  # optional: draw the target as a sphere of this diameter (m)

    [[obstacles]]
    kind = "box"                            # centre (m), size (full extents, m), yaw (rad, optional)
    centre = [0.5, 0.2, 0.1]
    size = [0.2, 0.2, 0.2]

    [[obstacles]]
    kind = "wall_with_hole"                 # standing on the ground, the hole on its vertical centre line
    hole_centre = [0.2, 0.5, 0.4]
    normal = [0.0, 1.0, 0.0]                # the hole's axis (horizontal)
    size = [0.7, 0.58, 0.01]                # width, height, thickness (m)
    hole_diameter = 0.07

    [[obstacles]]
    kind = "mesh"                           # a mesh file's convex hull (STL, OBJ, DAE...; a path inside the
    file = "rock.stl"                       #   scene file's folder), its origin at position (m), turned by yaw (rad,
    position = [0.6, -0.3, 0.0]             #   optional), scaled (optional, default [1, 1, 1])

    [terrain]                               # optional: the ground (default: flat, z = 0); kind = "plane",
    kind = "plane"                          #   "heightfield", "mesh" or "steps" and their keys
    pitch_deg = -5.0                        #   (:mod:`snakehead.scenes.terrain_table`)

Unknown keys, missing keys and values of the wrong kind raise ValueError naming the file, the entry and the key.

A scene file is not trusted: its ``robot`` file, a mesh obstacle's ``file`` and the terrain's must lie inside the
scene file's folder once symbolic links are resolved (:func:`~snakehead.scenes.terrain_table.scene_file_inside`):
``../``, an absolute path or a link leading out of the folder is an :class:`~snakehead._errors.InputError` naming the
scene file, the entry and the path (``snakehead plan`` exits with status 2 before anything is read or written). A
robot file elsewhere is the user's to give: ``snakehead plan --robot FILE`` (trusted, from anywhere) or
:func:`snakehead.plan`'s ``robot=``.

Names (``snakehead._validate.name_text``): a target's name is one line of printable text of at most
:data:`~snakehead._validate.MAX_NAME_CHARS` (200) characters -- anything but control, format and line-separator
characters (newline, tab, NUL, escape, zero-width and bidirectional marks); ``$``, ``\\``, ``<script>``, ``|``,
backticks and any script are names like others, shown literally in every figure and report. A scene's name also
names its output files (``NAME_trajectory.csv``, ``NAME.html``...), so it is a portable file name besides
(``file_name_part``: no ``/ \\ < > : " | ? *``, not ``.``, ``..`` or a Windows device name,
at most 100 bytes). A description may also hold newlines and tabs. Anything else is an
:class:`~snakehead._errors.InputError` naming the field.

:func:`save_scene` writes a scene file (:func:`scene_to_toml`: its text) that :func:`load_scene` reads back as the
same scene. Saved into another folder, a scene's mesh files and its terrain's file are copied into that folder,
beside the scene file (:func:`with_meshes_in`), since the file it writes may name only files in its own folder. Its
robot file is not copied (a robot is a folder: its URDF, meshes, map): a scene whose robot file lies outside the
folder it is saved in is refused, with nothing written, saying to save it in the robot file's folder (or a folder
above it) or to save it without its robot (``robot_file=None``) and give the robot when it is planned (``--robot``).

Sizes are bounded: a scene holds at most :data:`MAX_TARGETS` targets (via poses included) and a scene file is at
most :data:`MAX_SCENE_FILE_BYTES` bytes, refused before anything is planned (``snakehead.InputError``); a plan also
bounds the motion's length (``snakehead.planning.plan_bounds.MAX_MOTION_S``).
"""
from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .._errors import InputError, InputTypeError
from .._files import copy_into, write_text_atomic
from .._validate import (
    display_text,
    duration,
    file_name_part,
    file_problem,
    finite_float,
    name_text,
    sequence,
    unit_vector3,
    world_position,
)
from ..geometry.meshes import MAX_MESH_BYTES
from ..geometry.obstacles import OBSTACLE_TYPES, BoxObstacle, MeshObstacle, WallWithHole
from ..model.robot import BasePlacement, SnakeRobot
from ..model.robot_file import check_keys, path_from, read_toml, toml_string
from ..terrain.surfaces import TERRAIN_TYPES, FlatGround, HeightfieldTerrain, MeshTerrain, Terrain
from ..terrain.terrain_files import MAX_HEIGHTFIELD_BYTES
from .terrain_table import scene_file_inside, terrain_entry, terrain_from_table, written_inside

APPROACHES = ("free", "line")

#: The most targets (entries of ``[[targets]]``, via poses included) a scene may hold. Each is a whole-body solve
#: and a rest-to-rest move, so 1000 take minutes to plan (bench/RESULTS.md, "Many targets"); and a plan's motion is
#: at most MAX_SAMPLES 2 ms samples (2000 s, ``planning.plan_bounds.MAX_MOTION_S``), 2 s per target at 1000 targets,
#: about the shortest a move with a hold takes. A longer task is several scenes, planned one after the other.
MAX_TARGETS = 1000
#: The largest scene file (bytes): MAX_TARGETS targets written out in full (~200 bytes each), comments and obstacles.
MAX_SCENE_FILE_BYTES = 1 << 20
#: Default spacing (m) of the poses solved along a straight-line approach.
DEFAULT_LINE_STEP = 0.01


def check_target_count(count: int, where: str) -> None:
    """InputError unless ``count`` targets are at most :data:`MAX_TARGETS` (``where``: the scene or the file)."""
    if count > MAX_TARGETS:
        raise InputError(f"{where} has {count} targets; at most {MAX_TARGETS} (MAX_TARGETS): split it into scenes "
                         "planned one after the other")


@dataclass(frozen=True)
class Target:
    """One head target: ``position`` (3,) m and ``direction`` (3,) unit (the head's x-axis), world frame.

    hold_s: seconds the head stays there. approach: "free" (any whole-body move from the previous state) or
    "line" (the head moves along the straight line from the previous target, its pose solved every ``step_m``
    metres, so that it can thread through a hole). via: a pose passed through on the way, not reported as a
    target. sphere_diameter: draw the target as a sphere (m; None: as an arrow).
    """

    name: str
    position: np.ndarray
    direction: np.ndarray
    hold_s: float = 0.0
    approach: str = "free"
    step_m: float = DEFAULT_LINE_STEP
    via: bool = False
    sphere_diameter: float | None = None

    def __post_init__(self) -> None:
        name_text(self.name, "a target's name")
        object.__setattr__(self, "position", world_position(self.position, f"target {self.name!r} position"))
        object.__setattr__(self, "direction", unit_vector3(self.direction, f"target {self.name!r} direction"))
        object.__setattr__(self, "hold_s", duration(self.hold_s, f"target {self.name!r} hold_s", allow_zero=True))
        if not isinstance(self.approach, str) or self.approach not in APPROACHES:
            raise InputError(f"target {self.name!r}: approach must be one of {APPROACHES}, got {self.approach!r}")
        step = finite_float(self.step_m, f"target {self.name!r} step_m")
        if step <= 0:
            raise InputError(f"target {self.name!r}: step_m must be > 0, got {self.step_m!r}")
        object.__setattr__(self, "step_m", step)
        if not isinstance(self.via, (bool, np.bool_)):
            raise InputError(f"target {self.name!r}: via must be true or false, got {self.via!r}")
        if self.sphere_diameter is not None:
            d = finite_float(self.sphere_diameter, f"target {self.name!r} sphere_diameter")
            if d <= 0:
                raise InputError(f"target {self.name!r}: sphere_diameter must be > 0, got {self.sphere_diameter!r}")
            object.__setattr__(self, "sphere_diameter", d)


@dataclass(frozen=True)
class Scene:
    """Targets (visited in order) and obstacles; optionally the robot file and the base placement they go with, and
    the terrain (flat ground, z = 0, by default). ``path``: the file it was read from (then untrusted input)."""

    name: str
    targets: tuple[Target, ...]
    obstacles: tuple = ()
    robot_file: Path | None = None
    base: BasePlacement | None = None
    description: str = ""
    path: Path | None = None
    terrain: Terrain = field(default_factory=FlatGround)

    @property
    def robot_folder(self) -> Path | None:
        """The folder a robot this scene names may read from: the scene file's (a scene read from a file is untrusted
        input); None for a scene made in code."""
        return self.path.resolve().parent if self.path is not None else None

    def load_robot(self, *, trust_xacro: bool = False) -> SnakeRobot | None:
        """The robot ``robot_file`` names (None without one); its urdf, map and packages confined to
        :attr:`robot_folder`."""
        if self.robot_file is None:
            return None
        return SnakeRobot.from_file(self.robot_file, trust_xacro=trust_xacro, inside=self.robot_folder)

    def __post_init__(self) -> None:
        file_name_part(self.name, "a scene's name")  # the pipeline's outputs are NAME_trajectory.csv, NAME.gif...
        display_text(self.description, "a scene's description")
        targets = sequence(self.targets, f"scene {self.name!r} targets")
        if not targets:
            raise InputError(f"scene {self.name!r} has no targets")
        check_target_count(len(targets), f"scene {self.name!r}")
        for t in targets:
            if not isinstance(t, Target):
                raise InputTypeError(f"scene targets must be Target, got {type(t).__name__}")
        if targets[0].approach == "line":
            raise InputError(f"scene {self.name!r}: the first target cannot have approach = 'line' (a line starts at "
                             "the previous target)")
        if all(t.via for t in targets):
            raise InputError(f"scene {self.name!r}: every target is a via pose; at least one must be a target")
        names = [t.name for t in targets]
        if len(set(names)) != len(names):
            raise InputError(f"scene {self.name!r}: target names must differ, got {names}")
        obstacles = sequence(self.obstacles, f"scene {self.name!r} obstacles")
        for ob in obstacles:
            if not isinstance(ob, OBSTACLE_TYPES):
                raise InputTypeError("scene obstacles must be BoxObstacle, WallWithHole or MeshObstacle, got "
                                f"{type(ob).__name__}")
        object.__setattr__(self, "targets", targets)
        object.__setattr__(self, "obstacles", obstacles)
        if self.base is not None and not isinstance(self.base, BasePlacement):
            raise InputTypeError(f"scene base must be a BasePlacement, got {type(self.base).__name__}")
        if not isinstance(self.terrain, TERRAIN_TYPES):
            raise InputTypeError(f"scene terrain must be one of {[t.__name__ for t in TERRAIN_TYPES]}, got "
                                 f"{type(self.terrain).__name__}")

    @property
    def reported(self) -> tuple[Target, ...]:
        """The targets that are reported (not via poses)."""
        return tuple(t for t in self.targets if not t.via)

    @classmethod
    def from_targets(cls, pairs: Sequence, *, name: str = "target", obstacles: Sequence = (),
                     base: BasePlacement | None = None, hold_s: float = 1.0) -> "Scene":
        """A scene of (position, direction) pairs (or :class:`Target` objects), each held ``hold_s`` s."""
        file_name_part(name, "a scene's name")  # before it names the targets
        targets = []
        items = sequence(pairs, "targets")
        check_target_count(len(items), "targets")  # before a Target is made of each
        for k, item in enumerate(items):
            if isinstance(item, Target):
                targets.append(item)
                continue
            try:
                position, direction = item
            except (TypeError, ValueError):
                raise InputError(f"targets[{k}] must be a (position, direction) pair or a Target, "
                                 f"got {item!r}") from None
            label = name if len(items) == 1 else f"{name} {k + 1}"
            targets.append(Target(label, position, direction, hold_s=hold_s))
        return cls(name=name, targets=tuple(targets), obstacles=sequence(obstacles, "obstacles"), base=base)


# --- files ------------------------------------------------------------------------------------------------
_SCENE_KEYS = (("targets",), ("name", "description", "robot", "base", "obstacles", "terrain"))
_TARGET_KEYS = (("name", "position", "direction"), ("hold_s", "approach", "step_m", "via", "sphere_diameter"))
_BASE_KEYS = ((), ("x", "y", "yaw"))
_OBSTACLE_KEYS = {
    "box": (("kind", "centre", "size"), ("yaw",)),
    "wall_with_hole": (("kind", "hole_centre", "normal", "size", "hole_diameter"), ()),
    "mesh": (("kind", "file", "position"), ("yaw", "scale")),
}


def _number_list(value: Any, where: str, n: int = 3) -> list[float]:
    if not isinstance(value, list) or len(value) != n or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        raise InputError(f"{where} must be a list of {n} numbers, got {value!r}")
    if not all(math.isfinite(v) for v in value):
        raise InputError(f"{where} must be finite, got {value!r}")
    return [float(v) for v in value]


def _number(value: Any, where: str) -> float:
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise InputError(f"{where} must be a finite number, got {value!r}")
    return float(value)


def _table(value: Any, where: str) -> dict:
    if not isinstance(value, dict):
        raise InputError(f"{where} must be a table, got {value!r}")
    return value


def _target_from(entry: Any, where: str) -> Target:
    entry = _table(entry, where)
    check_keys(entry, *_TARGET_KEYS, where)
    name = name_text(entry["name"], f"{where}: name")
    kwargs: dict[str, Any] = {}
    for key in ("hold_s", "step_m", "sphere_diameter"):
        if key in entry:
            kwargs[key] = _number(entry[key], f"{where}: {key}")
    if "approach" in entry:
        kwargs["approach"] = entry["approach"]
    if "via" in entry:
        if not isinstance(entry["via"], bool):
            raise InputError(f"{where}: via must be true or false, got {entry['via']!r}")
        kwargs["via"] = entry["via"]
    try:
        return Target(name, np.asarray(_number_list(entry["position"], "position")),
                      np.asarray(_number_list(entry["direction"], "direction")), **kwargs)
    except ValueError as exc:  # the field's own message, said once where it is
        raise InputError(f"{where}: {exc}") from None


def _obstacle_from(entry: Any, where: str, folder: Path | None = None) -> BoxObstacle | WallWithHole | MeshObstacle:
    entry = _table(entry, where)
    kind = entry.get("kind")
    if not isinstance(kind, str) or kind not in _OBSTACLE_KEYS:  # (a list or a table is not hashable)
        raise InputError(f"{where}: kind must be one of {sorted(_OBSTACLE_KEYS)}, got {kind!r}")
    check_keys(entry, *_OBSTACLE_KEYS[kind], where)
    try:
        if kind == "mesh":  # untrusted: a file in the scene file's own folder only, as the terrain's
            path = scene_file_inside(folder if folder is not None else Path.cwd(), entry["file"], "mesh")
            return MeshObstacle.load(path, _number_list(entry["position"], "position"),
                                     _number(entry.get("yaw", 0.0), "yaw"),
                                     _number_list(entry.get("scale", [1.0, 1.0, 1.0]), "scale"), where="mesh")
        if kind == "box":
            return BoxObstacle.from_yaw(_number_list(entry["centre"], "centre"),
                                        _number_list(entry["size"], "size"),
                                        _number(entry.get("yaw", 0.0), "yaw"))
        return WallWithHole.standing(_number_list(entry["hole_centre"], "hole_centre"),
                                     _number_list(entry["normal"], "normal"),
                                     _number_list(entry["size"], "size"),
                                     _number(entry["hole_diameter"], "hole_diameter"))
    except ValueError as exc:
        raise InputError(f"{where}: {exc}") from None


def scene_from_dict(data: dict, *, name: str = "scene", folder: Path | None = None, where: str = "scene") -> Scene:
    """A :class:`Scene` from the contents of a scene file (``folder``: the scene file's, None: the working folder;
    the robot file's path is relative to it, and its mesh and terrain files lie inside it)."""
    data = _table(data, where)
    check_keys(data, *_SCENE_KEYS, where)
    if not isinstance(data["targets"], list) or not data["targets"]:
        raise InputError(f"{where}: targets must be a non-empty array of tables ([[targets]])")
    check_target_count(len(data["targets"]), where)  # before a Target is made of each
    targets = tuple(_target_from(e, f"{where}, targets[{k}]") for k, e in enumerate(data["targets"]))
    raw_obstacles = data.get("obstacles", [])
    if not isinstance(raw_obstacles, list):
        raise InputError(f"{where}: obstacles must be an array of tables ([[obstacles]])")
    obstacles = tuple(_obstacle_from(e, f"{where}, obstacles[{k}]", folder) for k, e in enumerate(raw_obstacles))
    base = None
    if "base" in data:
        b = _table(data["base"], f"{where}: base")
        check_keys(b, *_BASE_KEYS, f"{where}: base")
        x, y, yaw = (_number(b.get(k, 0.0), f"{where}: base.{k}") for k in ("x", "y", "yaw"))
        base = BasePlacement(x, y, yaw)  # in the world (scenes.ground_scene puts it in a slope's frame)
    robot_file = None
    if "robot" in data:  # untrusted: a file in the scene file's own folder only, as its meshes and terrain
        if not isinstance(data["robot"], str) or not data["robot"]:
            raise InputError(f"{where}: robot must be a robot file's path, got {data['robot']!r}")
        try:
            robot_file = scene_file_inside(folder if folder is not None else Path.cwd(), data["robot"],
                                           f"{where}: robot")
        except InputError as exc:
            raise InputError(f"{exc} (put the robot file beside the scene file, or give it with --robot)") from None
        if (problem := file_problem(robot_file)) is not None:
            raise InputError(f"{where}: its robot file {os.fspath(robot_file)!r}: {problem}")
    for key in ("name", "description"):
        if key in data and not isinstance(data[key], str):
            raise InputError(f"{where}: {key} must be a string, got {data[key]!r}")
    terrain = terrain_from_table(data["terrain"], folder, where) if "terrain" in data else FlatGround()
    try:
        return Scene(name=data.get("name", name), targets=targets, obstacles=obstacles, robot_file=robot_file,
                     base=base, description=data.get("description", ""), terrain=terrain)
    except ValueError as exc:  # a name or a description refused by Scene: the file's fault
        raise InputError(f"{where}: {exc}") from None


def load_scene(path: str | os.PathLike) -> Scene:
    """Read a scene file (see the module's docstring). ValueError names the file, the entry and the problem."""
    data = read_toml(path, "scene file", MAX_SCENE_FILE_BYTES)
    p = Path(path)
    scene = scene_from_dict(data, name=p.stem, folder=p.resolve().parent, where=f"scene file {os.fspath(p)!r}")
    return Scene(name=scene.name, targets=scene.targets, obstacles=scene.obstacles, robot_file=scene.robot_file,
                 base=scene.base, description=scene.description, path=p, terrain=scene.terrain)


# --- writing ----------------------------------------------------------------------------------------------
def save_scene(scene: Scene, path: str | os.PathLike) -> Path:
    """Write ``scene`` as a scene file at ``path`` (atomically) that :func:`load_scene` reads back as the same
    scene: its robot file named relative to the file's folder (it must lie there or below), its mesh and terrain files
    inside that folder (those elsewhere copied there first, :func:`with_meshes_in`). Returns the path. InputError,
    with nothing written or copied, for what a scene file cannot hold (see :func:`scene_to_toml`; a robot file outside
    the folder among it) or a path that cannot be written."""
    if not isinstance(scene, Scene):
        raise InputTypeError(f"scene must be a Scene, got {type(scene).__name__}")
    out = Path(path)
    folder = out.absolute().parent.resolve()  # where the file goes (a link at ``path`` is replaced, not followed)
    text = _scene_text(scene, folder, files_inside=False)  # what a scene file cannot say, before a file is copied
    files = _scene_files(scene)
    if files:
        if not folder.is_dir():
            raise InputError(f"cannot write {os.fspath(out)!r}: its folder {os.fspath(folder)!r} does not exist")
        for kind, file in files:
            if Path(file).resolve() == folder / out.name:
                raise InputError(f"cannot write {os.fspath(out)!r}: it is the scene's {kind} file")
        text = scene_to_toml(with_meshes_in(scene, folder, scene_file=folder / out.name), folder)
    return write_text_atomic(out, text)


def _scene_files(scene: Scene) -> list[tuple[str, Path]]:
    """The files a scene file names besides its robot file: (kind, path) of its mesh obstacles' and its terrain's."""
    files = [("mesh", Path(ob.path)) for ob in scene.obstacles if isinstance(ob, MeshObstacle)]
    if isinstance(scene.terrain, (HeightfieldTerrain, MeshTerrain)) and scene.terrain.source is not None:
        files.append(("terrain", Path(scene.terrain.source)))
    return files


def with_meshes_in(scene: Scene, folder: str | os.PathLike, *, scene_file: str | os.PathLike | None = None) -> Scene:
    """``scene`` with each mesh obstacle's file, and its terrain's file (a heightfield's or a mesh's), inside
    ``folder`` (an existing folder, where a scene file goes: a scene file names only files in its own folder). A file
    already inside it (links resolved) is kept; any other is copied into it, beside the scene file, under its own name
    (ASCII letters, digits, ``_`` and ``-``; others become ``_``) or, when a different file holds that name,
    ``NAME-2``, ``NAME-3``...; a file of that name with the same bytes is used as it is (one copy for the entries that
    share a file). Nothing is written over: a copy is a new file, written whole or not at all
    (``snakehead._files.copy_into``), nor named as the scene file about to be written (``scene_file``, if given).
    The robot file is left as it is (see :func:`save_scene`). InputError if a file cannot be read or copied."""
    if not isinstance(scene, Scene):
        raise InputTypeError(f"scene must be a Scene, got {type(scene).__name__}")
    root = Path(folder).resolve()
    taken = Path(scene_file).absolute().parent.resolve() / Path(scene_file).name if scene_file is not None else None
    copies: dict[Path, Path] = {}  # a source file -> its copy

    def inside(file: Path, where: str, kind: str, max_bytes: int) -> Path:
        source = Path(file).resolve()
        if source.is_relative_to(root):
            return file
        if source not in copies:
            copies[source] = copy_into(source, root, f"{where}: {kind} file", max_bytes, taken=taken, kind=kind)
        return copies[source]

    obstacles = tuple(dataclasses.replace(ob, path=inside(ob.path, f"scene {scene.name!r}, obstacles[{k}]", "mesh",
                                                          MAX_MESH_BYTES))
                      if isinstance(ob, MeshObstacle) else ob for k, ob in enumerate(scene.obstacles))
    terrain = scene.terrain
    if isinstance(terrain, (HeightfieldTerrain, MeshTerrain)) and terrain.source is not None:
        limit = MAX_HEIGHTFIELD_BYTES if isinstance(terrain, HeightfieldTerrain) else MAX_MESH_BYTES
        source = inside(Path(terrain.source), f"scene {scene.name!r}, terrain", "terrain", limit)
        if source != terrain.source:
            terrain = dataclasses.replace(terrain, source=source)
    return dataclasses.replace(scene, obstacles=obstacles, terrain=terrain)


def scene_to_toml(scene: Scene, folder: str | os.PathLike = ".") -> str:
    """The scene file (TOML text) of ``scene``, its paths relative to ``folder`` (where the file goes). Numbers are
    written to their last digit, so that they read back exactly. InputError for what a scene file cannot say: a box
    not upright (turned other than about z), a wall not standing on the ground (as ``WallWithHole.standing`` makes
    it), a mesh obstacle tilted, a mesh or terrain file outside ``folder`` (a scene file reads only files in its own
    folder: :func:`save_scene` copies them there, or :func:`with_meshes_in` first), a robot file outside ``folder``
    (it is not copied: see :func:`save_scene`), a terrain generated rather than read from a file (a heightfield's or
    a mesh's)."""
    if not isinstance(scene, Scene):
        raise InputTypeError(f"scene must be a Scene, got {type(scene).__name__}")
    return _scene_text(scene, folder)


def _scene_text(scene: Scene, folder: str | os.PathLike, files_inside: bool = True) -> str:
    """:func:`scene_to_toml`'s text (``files_inside``: a mesh or terrain file outside ``folder`` is an InputError;
    a robot file outside it always is)."""
    where = Path(folder).resolve()
    lines = [f"name = {toml_string(scene.name)}"]
    if scene.description:
        lines.append(f"description = {toml_string(scene.description)}")
    if scene.robot_file is not None:
        lines.append(f"robot = {toml_string(_robot_name(scene.name, scene.robot_file, where))}")
    if scene.base is not None:
        b = scene.base
        if not b.on_flat_ground:  # a file holds world poses and a [terrain]: ground-frame poses would load flat
            raise InputError(f"scene {scene.name!r}: its base lies in a slope's ground frame; a scene file holds world "
                             "poses with a [terrain] table (save the scene as loaded, not as planned)")
        lines.append(f"base = {{ x = {_toml_float(b.x)}, y = {_toml_float(b.y)}, yaw = {_toml_float(b.yaw)} }}")
    for t in scene.targets:
        lines += ["", "[[targets]]"] + [f"{k} = {v}" for k, v in _target_entry(t).items()]
    for k, ob in enumerate(scene.obstacles):
        entry = _obstacle_entry(ob, where, f"scene {scene.name!r}, obstacles[{k}]", files_inside)
        lines += ["", "[[obstacles]]"] + [f"{key} = {v}" for key, v in entry.items()]
    terrain = terrain_entry(scene.terrain, where, f"scene {scene.name!r}, terrain", files_inside)
    if terrain is not None:
        lines += ["", "[terrain]"] + [f"{key} = {v}" for key, v in terrain.items()]
    return "\n".join(lines) + "\n"


def _robot_name(scene: str, robot_file: Path, folder: Path) -> str:
    """The robot file as a scene file in ``folder`` names it; InputError if it lies outside ``folder`` (links
    resolved), where :func:`load_scene` would refuse it (the message names no absolute path: the live viewer shows
    it to a browser)."""
    name = path_from(folder, robot_file)
    try:
        scene_file_inside(folder, name, "robot")
    except InputError:
        raise InputError(f"scene {scene!r}: its robot file {name!r} lies outside the folder the scene file goes "
                         "in, and a scene file names only files in its own folder (a robot file is not copied): save "
                         "the scene in the robot file's folder or a folder above it, or save it without its robot "
                         "(robot_file=None) and give the robot when planning (--robot)") from None
    return name


def _toml_float(x: float) -> str:
    return repr(float(x))  # the shortest text that reads back as the same float; valid TOML (1e-05, 2.0)


def _toml_floats(v: Any) -> str:
    return "[" + ", ".join(_toml_float(x) for x in np.asarray(v, float).ravel()) + "]"


def _target_entry(t: Target) -> dict[str, str]:
    """A target's keys as TOML values: those that differ from their defaults only."""
    entry = {"name": toml_string(t.name), "position": _toml_floats(t.position), "direction": _toml_floats(t.direction)}
    if t.hold_s:
        entry["hold_s"] = _toml_float(t.hold_s)
    if t.approach != "free":
        entry["approach"] = toml_string(t.approach)
    if t.step_m != DEFAULT_LINE_STEP:
        entry["step_m"] = _toml_float(t.step_m)
    if t.via:
        entry["via"] = "true"
    if t.sphere_diameter is not None:
        entry["sphere_diameter"] = _toml_float(t.sphere_diameter)
    return entry


def _yaw_of(R: np.ndarray, where: str, what: str) -> float:
    """The yaw (rad) of a rotation about the world z-axis; InputError for any other rotation."""
    yaw = math.atan2(R[1, 0], R[0, 0])
    c, s = math.cos(yaw), math.sin(yaw)
    if not np.allclose(R, [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], atol=1e-9):
        raise InputError(f"{where}: {what} is turned other than about the world z-axis, which a scene file cannot "
                         "say (its yaw is the only rotation)")
    return yaw


def _obstacle_entry(ob: Any, folder: Path, where: str, inside: bool = True) -> dict[str, str]:
    """An obstacle's keys as TOML values (the entry :func:`_obstacle_from` reads; ``inside``: a mesh file outside
    ``folder`` is an InputError, as :func:`_obstacle_from` would refuse it)."""
    if isinstance(ob, BoxObstacle):
        return {"kind": '"box"', "centre": _toml_floats(ob.centre), "size": _toml_floats(ob.size),
                "yaw": _toml_float(_yaw_of(ob.rotation, where, "the box"))}
    if isinstance(ob, WallWithHole):
        standing = WallWithHole.standing(ob.centre, ob.normal, ob.size, ob.hole_diameter) \
            if abs(ob.normal[2]) <= 1e-9 and 0 < ob.centre[2] < ob.size[1] else None
        if standing is None or not np.allclose(standing.hole_offset, ob.hole_offset, atol=1e-9):
            raise InputError(f"{where}: the wall does not stand on the ground with its hole on its vertical centre "
                             "line (WallWithHole.standing), the only wall a scene file can say")
        return {"kind": '"wall_with_hole"', "hole_centre": _toml_floats(ob.centre), "normal": _toml_floats(ob.normal),
                "size": _toml_floats(ob.size), "hole_diameter": _toml_float(ob.hole_diameter)}
    if isinstance(ob, MeshObstacle):
        name = path_from(folder, ob.path)
        if inside:
            written_inside(folder, name, where)
        return {"kind": '"mesh"', "file": toml_string(name),
                "position": _toml_floats(ob.pose[:3, 3]),
                "yaw": _toml_float(_yaw_of(ob.pose[:3, :3], where, "the mesh")), "scale": _toml_floats(ob.scale)}
    raise InputTypeError(f"{where}: not an obstacle: {type(ob).__name__}")


#: The paper's scenes shipped with the package (Section 4): name -> file.
PAPER_SCENES = {"spheres": "spheres.toml", "hole": "hole.toml"}


def paper_scene(name: str) -> Scene:
    """One of the paper's two scenes: ``"spheres"`` (Section 4.1) or ``"hole"`` (Section 4.2)."""
    if name not in PAPER_SCENES:
        raise InputError(f"the paper's scenes are {sorted(PAPER_SCENES)}, got {name!r}")
    return load_scene(Path(__file__).with_name(PAPER_SCENES[name]))


__all__ = ["Target", "Scene", "load_scene", "save_scene", "scene_to_toml", "scene_from_dict", "paper_scene",
           "with_meshes_in", "PAPER_SCENES", "APPROACHES", "MAX_TARGETS", "MAX_SCENE_FILE_BYTES", "DEFAULT_LINE_STEP",
           "check_target_count"]
