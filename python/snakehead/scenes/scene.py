"""Scenes: where the head must go (targets) and what is in the way (obstacles), as data.

A scene file is TOML::

    name = "spheres"                        # optional (default: the file's stem)
    description = "..."                     # optional
    robot = "my_snake.toml"                 # optional: a robot file, relative to the scene file
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
    kind = "mesh"                           # a mesh file's convex hull (STL, OBJ, DAE...; path relative to the
    file = "rock.stl"                       #   scene file), its origin at position (m), turned by yaw (rad,
    position = [0.6, -0.3, 0.0]             #   optional), scaled (optional, default [1, 1, 1])

Unknown keys, missing keys and values of the wrong kind raise ValueError naming the file, the entry and the key.

Sizes are bounded: a scene holds at most :data:`MAX_TARGETS` targets (via poses included) and a scene file is at
most :data:`MAX_SCENE_FILE_BYTES` bytes, refused before anything is planned (``snakehead.InputError``); a plan also
bounds the motion's length (``snakehead.motion.planner.MAX_MOTION_S``).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .._errors import InputError
from .._validate import duration, file_name_part, finite_float, sequence, unit_vector3, vector3
from ..geometry.obstacles import OBSTACLE_TYPES, BoxObstacle, MeshObstacle, WallWithHole
from ..model.robot import BasePlacement
from ..model.robot_file import check_keys, read_toml

APPROACHES = ("free", "line")

#: The most targets (entries of ``[[targets]]``, via poses included) a scene may hold. Each is a whole-body solve
#: and a rest-to-rest move: ~0.4-0.8 s of planning and ~5 s of motion each on the default robot (bench/RESULTS.md,
#: "Many targets"), so 1000 take minutes to plan; and a plan's motion is at most MAX_SAMPLES 2 ms samples (2000 s,
#: ``motion.planner.MAX_MOTION_S``), 2 s per target at 1000 targets, about the shortest a move with a hold takes.
#: A longer task is several scenes, planned one after the other.
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
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"a target's name must be a non-empty string, got {self.name!r}")
        object.__setattr__(self, "position", vector3(self.position, f"target {self.name!r} position"))
        object.__setattr__(self, "direction", unit_vector3(self.direction, f"target {self.name!r} direction"))
        object.__setattr__(self, "hold_s", duration(self.hold_s, f"target {self.name!r} hold_s", allow_zero=True))
        if not isinstance(self.approach, str) or self.approach not in APPROACHES:
            raise ValueError(f"target {self.name!r}: approach must be one of {APPROACHES}, got {self.approach!r}")
        step = finite_float(self.step_m, f"target {self.name!r} step_m")
        if step <= 0:
            raise ValueError(f"target {self.name!r}: step_m must be > 0, got {self.step_m!r}")
        object.__setattr__(self, "step_m", step)
        if not isinstance(self.via, (bool, np.bool_)):
            raise ValueError(f"target {self.name!r}: via must be true or false, got {self.via!r}")
        if self.sphere_diameter is not None:
            d = finite_float(self.sphere_diameter, f"target {self.name!r} sphere_diameter")
            if d <= 0:
                raise ValueError(f"target {self.name!r}: sphere_diameter must be > 0, got {self.sphere_diameter!r}")
            object.__setattr__(self, "sphere_diameter", d)


@dataclass(frozen=True)
class Scene:
    """Targets (visited in order) and obstacles; optionally the robot file and the base placement they go with."""

    name: str
    targets: tuple[Target, ...]
    obstacles: tuple = ()
    robot_file: Path | None = None
    base: BasePlacement | None = None
    description: str = ""
    path: Path | None = None

    def __post_init__(self) -> None:
        file_name_part(self.name, "a scene's name")  # the pipeline's outputs are NAME_trajectory.csv, NAME.gif...
        if not isinstance(self.description, str):
            raise TypeError(f"a scene's description must be a str, got {type(self.description).__name__}")
        targets = sequence(self.targets, f"scene {self.name!r} targets")
        if not targets:
            raise ValueError(f"scene {self.name!r} has no targets")
        check_target_count(len(targets), f"scene {self.name!r}")
        for t in targets:
            if not isinstance(t, Target):
                raise TypeError(f"scene targets must be Target, got {type(t).__name__}")
        if targets[0].approach == "line":
            raise ValueError(f"scene {self.name!r}: the first target cannot have approach = 'line' (a line starts at "
                             "the previous target)")
        if all(t.via for t in targets):
            raise ValueError(f"scene {self.name!r}: every target is a via pose; at least one must be a target")
        names = [t.name for t in targets]
        if len(set(names)) != len(names):
            raise ValueError(f"scene {self.name!r}: target names must differ, got {names}")
        obstacles = sequence(self.obstacles, f"scene {self.name!r} obstacles")
        for ob in obstacles:
            if not isinstance(ob, OBSTACLE_TYPES):
                raise TypeError("scene obstacles must be BoxObstacle, WallWithHole or MeshObstacle, got "
                                f"{type(ob).__name__}")
        object.__setattr__(self, "targets", targets)
        object.__setattr__(self, "obstacles", obstacles)
        if self.base is not None and not isinstance(self.base, BasePlacement):
            raise TypeError(f"scene base must be a BasePlacement, got {type(self.base).__name__}")

    @property
    def reported(self) -> tuple[Target, ...]:
        """The targets that are reported (not via poses)."""
        return tuple(t for t in self.targets if not t.via)

    @classmethod
    def from_targets(cls, pairs: Sequence, *, name: str = "target", obstacles: Sequence = (),
                     base: BasePlacement | None = None, hold_s: float = 1.0) -> "Scene":
        """A scene of (position, direction) pairs (or :class:`Target` objects), each held ``hold_s`` s."""
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
                raise ValueError(f"targets[{k}] must be a (position, direction) pair or a Target, got {item!r}") from None
            label = name if len(items) == 1 else f"{name} {k + 1}"
            targets.append(Target(label, position, direction, hold_s=hold_s))
        return cls(name=name, targets=tuple(targets), obstacles=sequence(obstacles, "obstacles"), base=base)


# --- files ------------------------------------------------------------------------------------------------
_SCENE_KEYS = (("targets",), ("name", "description", "robot", "base", "obstacles"))
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
        raise ValueError(f"{where} must be a list of {n} numbers, got {value!r}")
    if not all(math.isfinite(v) for v in value):
        raise ValueError(f"{where} must be finite, got {value!r}")
    return [float(v) for v in value]


def _number(value: Any, where: str) -> float:
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise ValueError(f"{where} must be a finite number, got {value!r}")
    return float(value)


def _table(value: Any, where: str) -> dict:
    if not isinstance(value, dict):
        raise ValueError(f"{where} must be a table, got {value!r}")
    return value


def _target_from(entry: Any, where: str) -> Target:
    entry = _table(entry, where)
    check_keys(entry, *_TARGET_KEYS, where)
    name = entry["name"]
    if not isinstance(name, str) or not name:
        raise ValueError(f"{where}: name must be a non-empty string, got {name!r}")
    kwargs: dict[str, Any] = {}
    for key in ("hold_s", "step_m", "sphere_diameter"):
        if key in entry:
            kwargs[key] = _number(entry[key], f"{where}: {key}")
    if "approach" in entry:
        kwargs["approach"] = entry["approach"]
    if "via" in entry:
        if not isinstance(entry["via"], bool):
            raise ValueError(f"{where}: via must be true or false, got {entry['via']!r}")
        kwargs["via"] = entry["via"]
    try:
        return Target(name, np.asarray(_number_list(entry["position"], "position")),
                      np.asarray(_number_list(entry["direction"], "direction")), **kwargs)
    except ValueError as exc:  # the field's own message, said once where it is
        raise ValueError(f"{where}: {exc}") from None


def _obstacle_from(entry: Any, where: str, folder: Path | None = None) -> BoxObstacle | WallWithHole | MeshObstacle:
    entry = _table(entry, where)
    kind = entry.get("kind")
    if kind not in _OBSTACLE_KEYS:
        raise ValueError(f"{where}: kind must be one of {sorted(_OBSTACLE_KEYS)}, got {kind!r}")
    check_keys(entry, *_OBSTACLE_KEYS[kind], where)
    try:
        if kind == "mesh":
            if not isinstance(entry["file"], str) or not entry["file"]:
                raise ValueError(f"file must be a mesh file's path, got {entry['file']!r}")
            return MeshObstacle.load((folder or Path(".")) / entry["file"], _number_list(entry["position"], "position"),
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
        raise ValueError(f"{where}: {exc}") from None


def scene_from_dict(data: dict, *, name: str = "scene", folder: Path | None = None, where: str = "scene") -> Scene:
    """A :class:`Scene` from the contents of a scene file (``folder`` resolves the robot file's path)."""
    data = _table(data, where)
    check_keys(data, *_SCENE_KEYS, where)
    if not isinstance(data["targets"], list) or not data["targets"]:
        raise ValueError(f"{where}: targets must be a non-empty array of tables ([[targets]])")
    check_target_count(len(data["targets"]), where)  # before a Target is made of each
    targets = tuple(_target_from(e, f"{where}, targets[{k}]") for k, e in enumerate(data["targets"]))
    raw_obstacles = data.get("obstacles", [])
    if not isinstance(raw_obstacles, list):
        raise ValueError(f"{where}: obstacles must be an array of tables ([[obstacles]])")
    obstacles = tuple(_obstacle_from(e, f"{where}, obstacles[{k}]", folder) for k, e in enumerate(raw_obstacles))
    base = None
    if "base" in data:
        b = _table(data["base"], f"{where}: base")
        check_keys(b, *_BASE_KEYS, f"{where}: base")
        base = BasePlacement(*(_number(b.get(k, 0.0), f"{where}: base.{k}") for k in ("x", "y", "yaw")))
    robot_file = None
    if "robot" in data:
        if not isinstance(data["robot"], str) or not data["robot"]:
            raise ValueError(f"{where}: robot must be a robot file's path, got {data['robot']!r}")
        robot_file = (folder or Path(".")) / data["robot"]
        if not robot_file.is_file():
            raise ValueError(f"{where}: its robot file {os.fspath(robot_file)!r} does not exist")
    for key in ("name", "description"):
        if key in data and not isinstance(data[key], str):
            raise ValueError(f"{where}: {key} must be a string, got {data[key]!r}")
    try:
        return Scene(name=data.get("name", name), targets=targets, obstacles=obstacles, robot_file=robot_file,
                     base=base, description=data.get("description", ""))
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def load_scene(path: str | os.PathLike) -> Scene:
    """Read a scene file (see the module's docstring). ValueError names the file, the entry and the problem."""
    data = read_toml(path, "scene file", MAX_SCENE_FILE_BYTES)
    p = Path(path)
    scene = scene_from_dict(data, name=p.stem, folder=p.resolve().parent, where=f"scene file {os.fspath(p)!r}")
    return Scene(name=scene.name, targets=scene.targets, obstacles=scene.obstacles, robot_file=scene.robot_file,
                 base=scene.base, description=scene.description, path=p)


#: The paper's scenes shipped with the package (Section 4): name -> file.
PAPER_SCENES = {"spheres": "spheres.toml", "hole": "hole.toml"}


def paper_scene(name: str) -> Scene:
    """One of the paper's two scenes: ``"spheres"`` (Section 4.1) or ``"hole"`` (Section 4.2)."""
    if name not in PAPER_SCENES:
        raise ValueError(f"the paper's scenes are {sorted(PAPER_SCENES)}, got {name!r}")
    return load_scene(Path(__file__).with_name(PAPER_SCENES[name]))


__all__ = ["Target", "Scene", "load_scene", "scene_from_dict", "paper_scene", "PAPER_SCENES", "APPROACHES", "MAX_TARGETS",
           "MAX_SCENE_FILE_BYTES"]
