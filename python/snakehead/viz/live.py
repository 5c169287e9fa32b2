"""The live viewer (``snakehead view --live``): drag the head's targets in a web browser and the plan follows.

What it shows (viser; drawn with :mod:`.viewer_nodes`' pieces): the robot's collision shapes, first in its initial state,
then playing the plan of the current targets; each target as a gizmo (drag its arrows or planes to move it, its
rings to turn it: its x-axis, the red arrow, is the head's direction) with its name; the scene's obstacles; the
current plan's support polygon at its start, the ZMP's trace and the ZMP now, and the head tip's path. The panel:
the plan's state (planning, its errors, or why it failed), play/pause, time and speed; adding and removing targets;
the MuJoCo check of the current plan (its errors beside the plan's); saving the targets and obstacles as a scene
file (TOML) in the viewer's save folder. What one browser chooses (the target to remove, the file name) and what it
is told about its own actions are its own (:class:`.live_panel.ClientPanel`); the rest is shared. On a slope (a base
on a ground frame) all of it is in the ground frame, under one node at the frame's world pose (:mod:`.live_nodes`).

Safe to serve: the server sits behind :mod:`.server_guard` (Host and Origin allow-lists, a token in the printed
URL, no framing, only the messages the page sends; :attr:`LiveViewer.url`). The page saves only bare file names
into one folder fixed at start, never over a file this session did not write (:mod:`.save_folder`); the scene's
mesh files are copied there beside them, never over a file either. Every value a
browser sends is checked here: a speed not offered, a time that is not a number of the motion, a gizmo's pose that
is not finite are refused (the panel says so to that browser) and playback goes on. At most :data:`MAX_TARGETS`
targets; a motion longer than :data:`MAX_MOTION_S` is not played.

How: one :class:`~snakehead.solve.HeadController` (one robot, its map and its TRAC-IK threads) plans every
target set in one worker thread. Each change (a gizmo released, a target added or removed) is a request; a request
made while a plan runs supersedes it: that plan finishes (a plan cannot be stopped) and is dropped, and the newest
target set is planned next, so that only the latest target set's motion is drawn, never two at once. A new motion
starts at once by moving the nodes the viewer already has (the robot's shapes, fixed-size paths): nothing is
rebuilt (:mod:`.live_nodes`: the nodes, and a plan as frames). A player thread steps it along. Each request keeps
a :class:`Replan` record of when it was released, planned and shown.

The Python API (what tests and benchmarks drive, without a mouse): :class:`LiveViewer` with ``move_target``,
``add_target``, ``remove_target``, ``wait_for_plan``, ``check_dynamics``, ``wait_for_check``, ``save_scene``,
``latest``, ``records`` and ``url``; ``save_named`` saves as the page's button does (into the save folder),
``save_scene`` anywhere (the caller's own code is trusted).
"""
from __future__ import annotations

import dataclasses
import importlib.util
import logging
import os
import sys
import threading
import time
import traceback
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError
from .._validate import unit_vector3, world_position
from ..geometry.obstacles import MeshObstacle
from ..model.robot import SnakeRobot
from ..planning.planner import plan
from ..scenes.scene import Scene, Target, save_scene, scene_to_toml, with_meshes_in
from ..sim.simulate_plan import simulate
from ..solve.head_controller import HeadController
from ..terrain.surfaces import FlatGround
from .live_nodes import LiveMotion, draw_live_scene, gizmo_pose, live_motion
from .live_panel import MOTION_WATCH_JS, ClientPanel, ClientPanels, DynamicsCheck, Replan, errors_text, shown_text
from .save_folder import SaveFolder, bare_name
from .server_guard import ServerGuard, guarded_server
from .viewer_arrays import FRAME_STEP_S

__all__ = ["LiveViewer", "Replan", "DynamicsCheck", "MOTION_WATCH_JS", "MAX_TARGETS", "MAX_MOTION_S", "SPEEDS"]

LOG = logging.getLogger("snakehead.viz.server")

if TYPE_CHECKING:
    from ..planning.plan_result import Plan

#: s between two steps of the player (30 per second).
TICK_S = 1.0 / 30.0
#: s between two moves of the time slider while a motion plays (each is work for the browser's page).
SLIDER_STEP_S = 0.25
#: s the last frame of a motion is held before it plays again.
HOLD_S = 1.0
#: s after a new motion's first frame when its paths (head tip, ZMP, support polygon) are sent: a browser without a
#: GPU takes a frame's time to take in new paths, which the first frame would otherwise wait for.
PATHS_DELAY_S = 0.5
#: Playback speeds offered, and the one at start.
SPEEDS = ("1x", "2x", "4x", "8x")
DEFAULT_SPEED = "4x"
#: Shares of the body's length: a gizmo's size, and how far beside the last target a new target is put.
GIZMO_SHARE = 0.08
NEW_TARGET_SHARE = 0.05
#: s a target added in the viewer (or the one made when no scene is given) is held, as Scene.from_targets does.
NEW_TARGET_HOLD_S = 1.0
#: Targets at most in the live viewer (a scene with more is refused at start; "add target" stops there): each adds
#: a few seconds to the motion and to every plan.
MAX_TARGETS = 16
#: s: the longest motion the live viewer plays (a longer plan is reported, not drawn).
MAX_MOTION_S = 300.0


# ----------------------------------------------------------------------------------------------
# the viewer
# ----------------------------------------------------------------------------------------------
class LiveViewer:
    """A viser server where the user drags the head's targets and the plan follows (``snakehead view --live``).

    scene: the targets, obstacles, base and robot file to start from (default: one target where the robot's head
    is in its initial state, no obstacles). robot: the robot (default: ``robot_file``'s, else the scene's robot
    file's, else the shipped one); robot_file: the robot file the saved scene names (default: the scene's).
    controller: the :class:`~snakehead.solve.HeadController` that plans every request (default: one for the
    robot with seed 1, as ``snakehead plan``). save_dir: the one folder the page saves into (default
    ``./snakehead-scenes``, :mod:`.save_folder`); allow_hosts: host names the server answers to besides this
    machine's (:mod:`.server_guard`). Served at :attr:`url` (http://HOST:PORT/?token=..., the next free port if
    PORT is taken); :meth:`close` stops it. The first plan (of the scene's targets) is requested at once.
    """

    def __init__(self, scene: Scene | None = None, *, robot: SnakeRobot | None = None,
                 robot_file: str | os.PathLike | None = None, controller: HeadController | None = None,
                 host: str = "127.0.0.1", port: int = 8080, frame_step_s: float = FRAME_STEP_S,
                 save_dir: str | os.PathLike | None = None, allow_hosts: tuple[str, ...] | list[str] = ()) -> None:
        if scene is not None and not isinstance(scene, Scene):
            raise InputTypeError(f"scene must be a Scene (snakehead.load_scene), got {type(scene).__name__}")
        if not (np.isfinite(frame_step_s) and frame_step_s > 0):
            raise InputError(f"frame_step_s must be a positive number of seconds, got {frame_step_s!r}")
        if scene is not None and not isinstance(scene.terrain, FlatGround):  # its gizmos move ground-frame targets
            raise InputError(f"scene {scene.name!r}: the live viewer takes scenes on flat ground; for a slope give a "
                             "scene whose base lies on the slope's ground frame, its targets in that frame")
        if scene is not None and len(scene.targets) > MAX_TARGETS:
            raise InputError(f"scene {scene.name!r} has {len(scene.targets)} targets: the live viewer takes at most "
                             f"{MAX_TARGETS} ('snakehead plan --scene' plans any number)")
        self.saves = SaveFolder(save_dir)
        self.guard = ServerGuard(allow_hosts)
        self._host = host
        self.controller = _controller(scene, robot, robot_file, controller)
        self.robot = self.controller.robot
        self.frame_step_s = float(frame_step_s)
        start = scene if scene is not None else Scene(name="scene", targets=(self._initial_target(),))
        self._scene = dataclasses.replace(start, robot_file=Path(robot_file) if robot_file is not None
                                          else start.robot_file)
        self._targets = list(self._scene.targets)
        self._records: list[Replan] = []
        self._pending: tuple[Replan, Scene] | None = None
        self._changed = threading.Condition()  # targets, requests, records, checks
        self._draw = threading.RLock()  # the motion shown and its nodes
        self._motion: LiveMotion | None = None
        self._t = 0.0
        self._paths_due: float | None = None  # perf_counter time to draw the motion's paths
        self._check: DynamicsCheck | None = None
        self._checking = False
        self._panels = ClientPanels(self._say)  # each browser's own part of the panel
        self._speed_factor = float(DEFAULT_SPEED.rstrip("x"))  # the last speed a browser chose that is offered
        self.player_errors = 0  # what the player's loop survived (it logs the first)
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._serve(host, port)
        self._threads = [threading.Thread(target=self._run_worker, name="snakehead-live-planner", daemon=True),
                         threading.Thread(target=self._run_player, name="snakehead-live-player", daemon=True)]
        for thread in self._threads:
            thread.start()
        with self._changed:
            self._request("the scene's targets" if scene is not None else "the start")

    # --- the public API -------------------------------------------------------------------------------------------
    @property
    def port(self) -> int:
        return int(self.server.get_port())

    @property
    def url(self) -> str:
        """The page's address with this session's token (what ``snakehead view --live`` prints)."""
        return self.guard.url(self._host, self.port)

    @property
    def targets(self) -> list[Target]:
        with self._changed:
            return list(self._targets)

    @property
    def records(self) -> list[Replan]:
        """Every request so far, oldest first (see :class:`Replan`)."""
        with self._changed:
            return list(self._records)

    @property
    def latest(self) -> Plan | None:
        """The plan whose motion is shown (None before the first)."""
        with self._draw:
            return None if self._motion is None else self._motion.plan

    @property
    def motion(self) -> LiveMotion | None:
        """The motion shown (None before the first)."""
        with self._draw:
            return self._motion

    def scene(self) -> Scene:
        """The current targets with the scene's obstacles, base and robot file."""
        with self._changed:
            return dataclasses.replace(self._scene, targets=tuple(self._targets))

    def move_target(self, index: int, position: npt.ArrayLike, direction: npt.ArrayLike | None = None) -> int:
        """Move target ``index`` (0-based, in visiting order) to ``position`` (3,) m, pointing along ``direction``
        (3,) (default: as before), as releasing its gizmo does; returns the number of the replan requested."""
        with self._changed:
            k = self._index(index)
            old = self._targets[k]
            moved = dataclasses.replace(old, position=world_position(position, "position"),
                                        direction=old.direction if direction is None
                                        else unit_vector3(direction, "direction"))
            number = self._change(self._targets[:k] + [moved] + self._targets[k + 1:], f"moved {old.name!r}")
            self._gizmos.place(k, moved)
            return number

    def add_target(self, position: npt.ArrayLike | None = None, direction: npt.ArrayLike | None = None,
                   name: str | None = None) -> int:
        """Add a target after the last one, at ``position`` (default: beside the last one) pointing along
        ``direction`` (default: as the last one), held 1 s; returns the number of the replan requested. InputError
        beyond :data:`MAX_TARGETS`."""
        with self._changed:
            if len(self._targets) >= MAX_TARGETS:
                raise InputError(f"at most {MAX_TARGETS} targets in the live viewer: remove one first")
            last = self._targets[-1]
            side = np.cross([0.0, 0.0, 1.0], last.direction)
            side = side / np.linalg.norm(side) if np.linalg.norm(side) > 1e-6 else np.array([1.0, 0.0, 0.0])
            p = (last.position + NEW_TARGET_SHARE * self.robot.body_length * side if position is None
                 else world_position(position, "position"))
            d = last.direction if direction is None else unit_vector3(direction, "direction")
            label = name if name is not None else self._free_name()
            try:
                target = Target(label, p, d, hold_s=NEW_TARGET_HOLD_S)
            except ValueError as exc:
                raise InputError(str(exc)) from None
            number = self._change([*self._targets, target], f"added {label!r}")
            self._gizmos.add(target)
            return number

    def remove_target(self, index: int) -> int:
        """Remove target ``index`` (0-based); returns the number of the replan requested. InputError for the only
        target (a plan needs one) or a change the scene refuses (a line approach left first)."""
        with self._changed:
            k = self._index(index)
            if len(self._targets) == 1:
                raise InputError("the only target cannot be removed: a plan needs one")
            name = self._targets[k].name
            number = self._change(self._targets[:k] + self._targets[k + 1:], f"removed {name!r}")
            self._gizmos.remove(k)
            return number

    def wait_for_plan(self, timeout: float | None = None) -> Replan:
        """Wait until the latest request is settled (its motion playing, or planning it raised); its record.
        TimeoutError after ``timeout`` s."""
        with self._changed:
            if not self._changed.wait_for(lambda: self._records[-1].settled, timeout):
                raise TimeoutError(f"request {self._records[-1].number} not shown within {timeout} s")
            return self._records[-1]

    def check_dynamics(self) -> int:
        """Check the motion shown in MuJoCo (``snakehead.simulate``) in the background; its number. Its errors show
        beside the plan's; :meth:`wait_for_check` waits for them."""
        motion = self.motion
        if motion is None:
            raise InputError("no motion to check yet: the first plan is still running")
        with self._changed:
            if self._checking:
                raise InputError("a MuJoCo check is running already")
            self._checking = True
        threading.Thread(target=self._run_check, args=(motion,), name="snakehead-live-mujoco", daemon=True).start()
        return motion.number

    def wait_for_check(self, timeout: float | None = None) -> DynamicsCheck:
        """Wait for the MuJoCo check started last (TimeoutError after ``timeout`` s); its result."""
        with self._changed:
            if not self._changed.wait_for(lambda: not self._checking and self._check is not None, timeout):
                raise TimeoutError(f"the MuJoCo check did not end within {timeout} s")
            assert self._check is not None
            return self._check

    def save_scene(self, path: str | os.PathLike) -> Path:
        """Write the current targets and the scene's obstacles as a scene file (TOML) at ``path``; the path. (The
        caller's own path, trusted: the page saves through :meth:`save_named`.)"""
        return save_scene(self.scene(), path)

    def save_named(self, name: str) -> str:
        """Save the scene as the page's "save scene" does: as the bare file ``name`` (``.toml`` added) in the save
        folder, never over a file this session did not write (:class:`.save_folder.SaveFolder`); the bare name.
        The scene's mesh files are copied into the save folder first unless they are there already (a scene file
        reads only files in its own folder; :func:`~snakehead.scenes.scene.with_meshes_in`: never over a file).
        InputError, in words a browser may be shown, if not saved."""
        bare = bare_name(name)  # the client's name is checked before anything is written
        scene = self.scene()
        if any(isinstance(ob, MeshObstacle) for ob in scene.obstacles):
            try:
                self.saves.folder.mkdir(parents=True, exist_ok=True)
                scene = with_meshes_in(scene, self.saves.folder)
            except (OSError, InputError) as exc:  # the details (paths, the OS's words) stay on the server
                LOG.warning("could not copy the scene's mesh files into %s: %s", self.saves.folder, exc)
                raise InputError(f"{bare} was not saved: the scene's mesh files could not be copied beside it (the "
                                 "server's log says why)") from None
        return self.saves.write(bare, scene_to_toml(scene, self.saves.folder))

    def close(self) -> None:
        """Stop the threads and the server (a plan running is left to finish in its daemon thread)."""
        if self._stop.is_set():
            return
        self._stop.set()
        with self._changed:
            self._changed.notify_all()
        for thread in self._threads:
            thread.join(timeout=2.0)
        self.server.stop()

    def __enter__(self) -> "LiveViewer":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- targets --------------------------------------------------------------------------------------------------
    def _initial_target(self) -> Target:
        """The head's pose in the robot's initial state, as the one target when no scene is given."""
        head = self.robot.head_pose(self.controller.q_initial, self.controller.base)
        return Target("target 1", head[:3, 3], head[:3, 0], hold_s=NEW_TARGET_HOLD_S)

    def _index(self, index: int) -> int:
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)):
            raise InputTypeError(f"a target's index must be an integer, got {type(index).__name__}")
        if not 0 <= index < len(self._targets):
            raise InputError(f"no target {index}: there are {len(self._targets)} (0 to {len(self._targets) - 1})")
        return int(index)

    def _free_name(self) -> str:
        names = {t.name for t in self._targets}
        return next(f"target {k}" for k in range(1, len(names) + 2) if f"target {k}" not in names)

    def _change(self, targets: list[Target], what: str) -> int:
        """Take ``targets`` (checked as a scene) and request their plan; the request's number. Holds _changed."""
        try:
            dataclasses.replace(self._scene, targets=tuple(targets))
        except ValueError as exc:  # the scene's own checks (a line approach first, names alike...): the user's
            raise InputError(str(exc)) from None
        self._targets = targets
        self._panels.set_targets(tuple(t.name for t in targets))
        return self._request(what)

    def _request(self, what: str) -> int:
        """Plan the current targets next (superseding a request not started yet). Holds _changed."""
        record = Replan(number=len(self._records), what=what, released=time.time())
        self._records.append(record)
        if self._pending is not None:
            self._pending[0].superseded = True
        self._pending = (record, dataclasses.replace(self._scene, targets=tuple(self._targets)))
        self._changed.notify_all()
        return record.number

    def _released(self, handle: Any, client: Any = None) -> None:
        """A gizmo let go (viser's thread): its pose is the target's. A pose that is no target's (not finite, a
        direction of length 0) puts the gizmo back where its target is."""
        with self._changed:
            k = self._gizmos.index(handle)
        if k < 0:
            return
        if not self._panels.reported(client, lambda: self.move_target(k, *gizmo_pose(handle))):
            with self._changed:
                if k < len(self._targets):
                    self._gizmos.place(k, self._targets[k])

    # --- planning and playing -------------------------------------------------------------------------------------
    def _run_worker(self) -> None:
        while True:
            with self._changed:
                self._changed.wait_for(lambda: self._pending is not None or self._stop.is_set())
                if self._stop.is_set():
                    return
                assert self._pending is not None
                (record, scene), self._pending = self._pending, None
            self._replan(record, scene)

    def _replan(self, record: Replan, scene: Scene) -> None:
        self._say(f"Planning request {record.number} ({record.what}) ...")
        record.plan_started = time.time()
        try:
            result = plan(scene, controller=self.controller)
            record.planned = time.time()
            record.failure = result.failure
            if self._superseded(record):
                return
            duration = float(result.t[-1] - result.t[0])
            if not duration <= MAX_MOTION_S:
                raise InputError(f"its motion lasts {duration:.0f} s, longer than the {MAX_MOTION_S:.0f} s the live "
                                 "viewer plays: remove targets or shorten their holds")
            motion = live_motion(record.number, result, self._nodes.origins, self.frame_step_s)
            record.drawn = time.time()
        except Exception as exc:  # noqa: BLE001 -- the viewer shows it and keeps serving; the traceback to stderr
            if not isinstance(exc, InputError):
                traceback.print_exc(file=sys.stderr)
            record.error = f"{type(exc).__name__}: {exc}"
            self._say(f"**Request {record.number} ({record.what}) raised** {record.error}")
            with self._changed:
                self._changed.notify_all()
            return
        self._start(record, motion)

    def _superseded(self, record: Replan) -> bool:
        with self._changed:
            if self._pending is not None:
                record.superseded = True
                self._changed.notify_all()
            return record.superseded

    def _start(self, record: Replan, motion: LiveMotion) -> None:
        """Show ``motion`` from its first frame, with its status, in one message window sent at once (unless a
        newer request came meanwhile)."""
        with self._draw:
            if self._superseded(record):
                return
            with self.server.atomic():
                self._motion, self._t = motion, 0.0
                self._root.place(motion.plan.base.ground)  # (a plan's ground frame is the scene's: no change)
                self._nodes.start(motion)
                self._paths_due = time.perf_counter() + PATHS_DELAY_S
                self._time.max = max(round(motion.duration_s, 1), 0.1)
                self._time.value = 0.0  # type: ignore[misc]  # viser's handles are assignable (typed read-only)
                self._shown.content = shown_text(record, motion)
                self._errors.content = errors_text(motion, self._check)
                self._status.content = "Ready: drag a target's gizmo, or add one."
            self.server.flush()
            record.playing = time.time()
        with self._changed:
            self._changed.notify_all()

    def _run_player(self) -> None:
        """Step the motion shown along, :data:`TICK_S` apart, until :meth:`close`. Nothing a browser sends stops it:
        it reads only values checked when they came (:meth:`_speed_changed`, :meth:`_seek`), and whatever else goes
        wrong in a step is logged (the first time) and counted in ``player_errors``, and the next step comes."""
        last = slider_moved = time.perf_counter()
        while not self._stop.wait(TICK_S):
            now = time.perf_counter()
            dt, last = now - last, now
            try:
                if self._step(now, dt, now - slider_moved >= SLIDER_STEP_S):
                    slider_moved = now
            except Exception:  # noqa: BLE001 -- the player outlives any one step
                self.player_errors += 1
                if self.player_errors == 1:
                    LOG.exception("the live viewer's player failed a step (it goes on)")

    def _step(self, now: float, dt: float, move_slider: bool) -> bool:
        """One step of the player; whether it moved the time slider."""
        with self._draw:
            m = self._motion
            if m is not None and self._paths_due is not None and now >= self._paths_due:
                self._paths_due = None
                self._nodes.draw_paths(m)
            if m is None or not self._playing.value:
                return False
            self._t = self._t + self._speed_factor * dt
            if not 0.0 <= self._t <= m.duration_s + HOLD_S:
                self._t = 0.0
            self._nodes.show(m, m.frame_at(self._t))
            if move_slider:
                self._time.value = round(min(self._t, m.duration_s), 1)  # type: ignore[misc]
            return move_slider

    def _speed_changed(self, event: Any) -> None:
        """A speed chosen: one of :data:`SPEEDS` is taken; anything else is refused and the menu set back."""
        value = self._speed.value
        if value in SPEEDS:
            self._speed_factor = float(value.rstrip("x"))
            return
        shown = f"{self._speed_factor:g}x"
        self._speed.value = shown if shown in SPEEDS else DEFAULT_SPEED  # type: ignore[misc]
        self._panels.tell(event.client, f"**Not done:** speed must be one of {', '.join(SPEEDS)}")

    def _seek(self, event: Any) -> None:
        """The time slider moved by a browser: a time of the motion shown is taken (its frame shown); anything
        else (not a number, NaN, inf, before 0 or after the end) is refused and the slider set back."""
        if event.client is None:  # the player moved the slider
            return
        with self._draw:
            if self._motion is None:
                return
            t = self._time.value
            if not (isinstance(t, (int, float)) and np.isfinite(t) and 0.0 <= t <= self._time.max):
                self._time.value = round(min(self._t, self._motion.duration_s), 1)  # type: ignore[misc]
                self._panels.tell(event.client, f"**Not done:** the time must be between 0 and {self._time.max:g} s")
                return
            self._t = float(t)
            self._nodes.show(self._motion, self._motion.frame_at(self._t))

    def _run_check(self, motion: LiveMotion) -> None:
        self._errors.content = errors_text(motion, None) + "\n\nMuJoCo: simulating ..."
        started = time.perf_counter()
        check = DynamicsCheck(motion.number)
        try:
            if importlib.util.find_spec("mujoco") is None:
                raise InputError("MuJoCo is not installed (pip install snakehead[sim])")
            check.simulation = simulate(motion.plan)
        except Exception as exc:  # noqa: BLE001 -- shown in the panel; the viewer keeps serving
            if not isinstance(exc, InputError):
                traceback.print_exc(file=sys.stderr)
            check.error = f"{type(exc).__name__}: {exc}"
        check.seconds = time.perf_counter() - started
        with self._changed:
            self._check, self._checking = check, False
            self._changed.notify_all()
        shown = self.motion
        if shown is not None:
            self._errors.content = errors_text(shown, check)

    # --- the server and its panel ---------------------------------------------------------------------------------
    def _serve(self, host: str, port: int) -> None:
        self.server = guarded_server(self.guard, host, port)
        try:
            self._draw_scene()
            self._panel()
        except BaseException:
            self.server.stop()
            raise

    def _draw_scene(self) -> None:
        """The still scene (:func:`.live_nodes.draw_live_scene`), in the ground frame of the controller's base."""
        self._root, self._nodes, self._gizmos = draw_live_scene(
            self.server, self.robot, self.controller.q_initial, self.controller.base,
            dataclasses.replace(self._scene, targets=tuple(self._targets)), GIZMO_SHARE * self.robot.body_length,
            self._released)

    def _panel(self) -> None:
        """The shared panel; each browser's own part is added when it connects (:meth:`_client_panel`)."""
        gui = self.server.gui
        gui.configure_theme(control_width="medium")
        self._status = gui.add_markdown("Planning the first motion ...")
        self._shown = gui.add_markdown("")
        self._errors = gui.add_markdown("")
        with gui.add_folder("Motion"):
            self._playing = gui.add_checkbox("play", initial_value=True)
            self._time = gui.add_slider("time (s)", min=0.0, max=1.0, step=0.1, initial_value=0.0)
            self._speed = gui.add_dropdown("speed", SPEEDS, initial_value=DEFAULT_SPEED)
        self._targets_folder = gui.add_folder("Targets")
        with self._targets_folder:
            self._add, self._remove = gui.add_button("add target"), gui.add_button("remove target")
        with gui.add_folder("MuJoCo"):
            check = gui.add_button("check the motion in MuJoCo")
        self._file_folder = gui.add_folder("Scene file")
        with self._file_folder:
            self._save_button = gui.add_button("save scene")
        self._time.on_update(self._seek)
        self._speed.on_update(self._speed_changed)
        self._add.on_click(lambda event: self._with_panel(event, lambda _: self.add_target()))
        self._remove.on_click(lambda event: self._with_panel(
            event, lambda panel: self.remove_target(self._chosen_index(panel))))
        check.on_click(lambda event: self._with_panel(event, lambda _: self.check_dynamics()))
        self._save_button.on_click(lambda event: self._with_panel(event, self._save))
        self._panels.bind(self.server, self._status, (self._targets_folder, self._add),
                          (self._file_folder, self._save_button), lambda: (tuple(t.name for t in self.targets),
                                                                           f"{self._scene.name}_live.toml"))

    def _with_panel(self, event: Any, action: Callable[[ClientPanel], Any]) -> None:
        """Run a button's ``action`` with the panel of the browser that clicked (none yet: nothing is done)."""
        panel = self._panels.of(event.client)
        if panel is not None:
            self._panels.reported(event.client, lambda: action(panel))

    def _chosen_index(self, panel: ClientPanel) -> int:
        names = [t.name for t in self.targets]
        if panel.chosen.value not in names:
            raise InputError("choose a target in the menu first")
        return names.index(panel.chosen.value)

    def _save(self, panel: ClientPanel) -> None:
        """The browser's "save scene": its file box's name in the save folder; it is told the bare name only."""
        try:
            panel.saved.content = f"Saved as `{self.save_named(panel.file.value)}` in the viewer's save folder."
        except InputError as exc:
            panel.saved.content = f"**Not saved:** {exc}"

    def _say(self, text: str) -> None:
        self._status.content = text


def _controller(scene: Scene | None, robot: SnakeRobot | None, robot_file: str | os.PathLike | None,
                controller: HeadController | None) -> HeadController:
    """The controller the viewer plans with (see :class:`LiveViewer`)."""
    if controller is not None:
        if not isinstance(controller, HeadController):
            raise InputTypeError(f"controller must be a HeadController, got {type(controller).__name__}")
        return controller
    if robot is None:  # the caller's robot_file (trusted), else the scene's (confined to the scene file's folder)
        if robot_file is not None:
            robot = SnakeRobot.from_file(robot_file)
        else:
            robot = (scene.load_robot() if scene is not None else None) or SnakeRobot.default()
    elif not isinstance(robot, SnakeRobot):
        raise InputTypeError(f"robot must be a SnakeRobot, got {type(robot).__name__}")
    return HeadController(robot, base_pose=scene.base if scene is not None else None, seed=1)
