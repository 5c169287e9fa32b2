"""The interactive 3-D viewer (viser): a plan's motion in a web browser.

What it shows: the robot's collision shapes (boxes, cylinders, spheres, mesh hulls; base grey, neck orange, head
blue) moving along the planned motion, with play/pause and a time slider; the targets (spheres or arrows along the
desired direction); the obstacles; the support polygon and the zero-moment point's trace on the ground (with the
ZMP and the centre of mass's ground projection now); the head tip's path; and the head's reachability map as voxels
coloured by their index (the paper's 20-step bar, Figs. 4-5), attached to the head's base frame and hidden until
toggled on. On a slope all of it is drawn in the plan's ground frame under one node that holds the frame's world
pose, on a tilted ground grid; a scene's terrain (a heightfield, a mesh, a staircase) is drawn in the world.

Three ways to it:

* :func:`~.viewer_arrays.viewer_scene` turns a :class:`~snakehead.planning.plan_result.Plan` into a
  :class:`~.viewer_arrays.ViewerScene` (plain arrays), which :func:`~.viewer_file.save_viewer_scene` writes as
  ``NAME_viewer.npz`` (``numpy.load`` reads it) and :func:`~.viewer_file.load_viewer_scene` reads back --
  ``snakehead plan`` and ``snakehead demo`` write one per scenario;
* :func:`write_html`: a single HTML file that opens from disk in a browser, with no server and no network (viser's
  client, with the recorded scene inside the file). ``plan`` and ``demo`` write ``NAME.html`` beside the GIF;
  the scene tree (the tree icon at the bottom right) toggles the map, the ZMP, the targets and the obstacles;
* :func:`serve` (``snakehead view DIR``): a live viser server over the scenes in a folder, with a scenario menu,
  play/pause, a time slider, a speed menu and check boxes for the layers;
* :func:`~.viewer_arrays.reach_scene`: a still scene of a whole-body reach map (``snakehead reach``; ``snakehead
  view --map reach.npz``): the robot at its start and the voxels it reaches, coloured by the share of directions
  reached, shown at once.

This module holds the page and the server; the scene's arrays are in :mod:`.viewer_arrays`, its file in
:mod:`.viewer_file`, its nodes in a viser scene in :mod:`.viewer_nodes` (all re-exported here). viser is a
dependency of snakehead; a server is started only when a page is made or served.
"""
from __future__ import annotations

import contextlib
import html
import io
import logging
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterator, Sequence

import numpy as np

from .._errors import InputError
from .._files import write_text_atomic
from .server_guard import ServerGuard, guarded_server
from .viewer_arrays import (
    CAMERA_FOV_DEG,
    CAMERA_VIEW_DEG,
    FRAME_STEP_S,
    GROUND_FIELDS,
    MESH_FIELDS,
    OBSTACLE_FIELDS,
    VIEWER_SEGMENTS,
    ViewerScene,
    camera_for,
    distinct_polygons,
    frame_indices,
    ground_arrays,
    obstacle_arrays,
    quaternions_wxyz,
    reach_scene,
    rgb255,
    robot_meshes,
    shape_colors,
    shape_poses,
    viewer_scene,
)
from .viewer_file import (
    FLAT_SCENE_FORMAT,
    MAX_SCENE_BYTES,
    SCENE_FORMAT,
    SCENE_SUFFIX,
    load_viewer_scene,
    save_viewer_scene,
    scenes_in,
)
from .viewer_nodes import (
    COM_RGB,
    CUBE_TRIANGLES,
    CUBE_VERTICES,
    OBSTACLE_RGB,
    POLYGON_RGB,
    TARGET_ARROW_M,
    TARGET_LABEL_HEIGHT_M,
    TARGET_RGB,
    TIP_PATH_RGB,
    WALL_RGB,
    ZMP_RGB,
    RobotNodes,
    SceneNodes,
    add_ground,
    add_obstacles,
    add_target_marker,
    camera_to,
    light_scene,
    node_name,
)

if TYPE_CHECKING:
    import viser

__all__ = [
    "html_page", "write_html", "Viewer", "serve",
    # re-exported: the scene's arrays (viewer_arrays), its file (viewer_file), its nodes in viser (viewer_nodes)
    "CAMERA_FOV_DEG", "CAMERA_VIEW_DEG", "FRAME_STEP_S", "GROUND_FIELDS", "MESH_FIELDS", "OBSTACLE_FIELDS",
    "VIEWER_SEGMENTS", "ViewerScene", "camera_for", "distinct_polygons", "frame_indices", "ground_arrays",
    "obstacle_arrays", "quaternions_wxyz", "reach_scene", "rgb255", "robot_meshes", "shape_colors", "shape_poses",
    "viewer_scene", "FLAT_SCENE_FORMAT", "MAX_SCENE_BYTES", "SCENE_FORMAT", "SCENE_SUFFIX", "load_viewer_scene", "save_viewer_scene", "scenes_in",
    "COM_RGB", "CUBE_TRIANGLES", "CUBE_VERTICES", "OBSTACLE_RGB", "POLYGON_RGB", "TARGET_ARROW_M",
    "TARGET_LABEL_HEIGHT_M", "TARGET_RGB", "TIP_PATH_RGB", "WALL_RGB", "ZMP_RGB", "RobotNodes", "SceneNodes",
    "add_ground", "add_obstacles", "add_target_marker", "camera_to", "light_scene", "node_name",
]


def _camera_to(target: Any, data: ViewerScene) -> None:
    """Point a viser camera so that it sees the whole of ``data`` (:meth:`ViewerScene.camera`)."""
    camera_to(target, *data.camera())


@contextlib.contextmanager
def _quiet_server(port: int = 0) -> Iterator[viser.ViserServer]:
    """A viser server on the loopback interface (a free port by default) that prints nothing; stopped after. It is
    behind a guard whose token nobody is told (:mod:`.server_guard`): while a page is recorded, no browser gets in."""
    server = guarded_server(ServerGuard(), "127.0.0.1", port)
    try:
        yield server
    finally:
        with contextlib.redirect_stdout(io.StringIO()):
            server.stop()


def html_page(data: ViewerScene) -> str:
    """A standalone HTML page (str) playing ``data``: viser's client with the recorded scene inside, for a browser
    that opens it from disk -- no server, no network. Play/pause and the time slider are at the bottom; the scene
    tree (bottom right) toggles the layers (the reachability map starts hidden)."""
    with _quiet_server() as server:
        _camera_to(server.initial_camera, data)
        recording = server.get_scene_serializer()
        nodes = SceneNodes(server.scene, data)
        for k in range(1, data.n_frames):
            recording.insert_sleep(float(data.times[k] - data.times[k - 1]))
            nodes.show_frame(k)
        recording.insert_sleep(1.0)  # hold the last frame a moment before the player loops
        page = recording.as_html()
    return page.replace("<title>Viser</title>", f"<title>snakehead: {_escape(data.title)}</title>", 1)


def _escape(text: str) -> str:
    """``text`` as HTML shows it literally (``<script>`` is text, not an element)."""
    return html.escape(text, quote=True)


def write_html(data: ViewerScene, path: str | Path) -> Path:
    """Write :func:`html_page` of ``data`` to ``path`` (atomically); returns the path."""
    return write_text_atomic(path, html_page(data))



class Viewer:
    """A live viser server over viewer scenes (``snakehead view``): the GUI picks the scenario, plays and pauses,
    scrubs time, sets the speed and toggles the layers (one scene, shared by every browser). Served at :attr:`url`
    behind :mod:`.server_guard` (Host, Origin, the token in the URL; ``allow_hosts``: names besides this
    machine's). What a browser sends is checked: a scenario or a speed not offered, a time that is not one of the
    motion are set back, and playback goes on. :meth:`close` stops it."""

    SPEEDS = ("0.5x", "1x", "2x", "4x", "8x", "16x")

    def __init__(self, scenes: Sequence[ViewerScene], *, host: str = "127.0.0.1", port: int = 8080,
                 allow_hosts: Sequence[str] = ()) -> None:
        if not scenes:
            raise InputError("no viewer scenes to show")
        self.scenes = {s.name: s for s in scenes}
        self.guard = ServerGuard(allow_hosts)
        self._host = host
        self.server = guarded_server(self.guard, host, port)
        self.lock = threading.RLock()  # re-entered: a value set here calls its callback on this thread
        gui = self.server.gui
        gui.configure_theme(control_width="medium")
        self.scenario = gui.add_dropdown("scenario", tuple(self.scenes), initial_value=scenes[0].name)
        self.playing = gui.add_checkbox("play", initial_value=True)
        self.time = gui.add_slider("time (s)", min=0.0, max=1.0, step=0.1, initial_value=0.0)
        self.speed = gui.add_dropdown("speed", self.SPEEDS, initial_value="4x")
        self.layers = {name: gui.add_checkbox(name, initial_value=name != "reachability map")
                       for name in SceneNodes.LAYERS}
        self.nodes: SceneNodes | None = None
        self._stop = threading.Event()
        self._t, self._factor, self._shown = 0.0, 4.0, scenes[0].name  # the checked time, speed and scenario
        self.player_errors = 0  # what the player's loop survived (it logs the first)
        self._load(scenes[0].name)
        self.scenario.on_update(lambda _: self._load(self.scenario.value))
        self.time.on_update(lambda event: self._seek(self.time.value, event.client is not None))
        self.speed.on_update(lambda _: self._speed_changed())
        for layer in self.layers.values():
            layer.on_update(lambda _: self._apply_layers())
        self._thread = threading.Thread(target=self._play, name="snakehead-viewer", daemon=True)
        self._thread.start()

    @property
    def port(self) -> int:
        return int(self.server.get_port())

    @property
    def url(self) -> str:
        """The page's address with this session's token (what ``snakehead view`` prints)."""
        return self.guard.url(self._host, self.port)

    def _load(self, name: str) -> None:
        with self.lock:
            if name not in self.scenes:  # not a scenario offered: the menu set back
                self.scenario.value = self._shown  # type: ignore[misc]  # (viser: assignable, typed read-only)
                return
            self._shown, self._t = name, 0.0
            data = self.scenes[name]
            self.server.scene.reset()
            self.nodes = SceneNodes(self.server.scene, data)
            _camera_to(self.server.initial_camera, data)
            for client in self.server.get_clients().values():
                _camera_to(client.camera, data)
            duration = float(data.times[-1] - data.times[0])
            step = float(max(0.01, np.round(duration / 1000, 2)))
            self.time.max = max(round(duration, 2), step)
            self.time.step = step
            self.time.value = 0.0  # type: ignore[misc]  # viser's handles are assignable (typed read-only)
            if data.n_frames == 1 and len(data.voxel_centers):  # a still scene (a reach map) is there for its map
                self.layers["reachability map"].value = True  # type: ignore[misc]  # (as above)
            self._apply_layers()

    def _frame_at(self, t_rel: float) -> int:
        assert self.nodes is not None
        times = self.nodes.data.times
        return int(np.searchsorted(times - times[0], t_rel + 1e-9, side="right") - 1)

    def _seek(self, t_rel: float, by_client: bool = True) -> None:
        """Show the frame at ``t_rel`` s; a browser's time that is not a number of the motion (NaN, inf, before 0,
        after the end) is refused and the slider set back."""
        with self.lock:
            if self.nodes is None:
                return
            if not (isinstance(t_rel, (int, float)) and np.isfinite(t_rel) and 0.0 <= t_rel <= self.time.max):
                self.time.value = self._t  # type: ignore[misc]  # (viser: assignable, typed read-only)
                return
            if by_client:
                self._t = float(t_rel)
            self.nodes.show_frame(self._frame_at(float(t_rel)))

    def _speed_changed(self) -> None:
        """A speed of :attr:`SPEEDS` is taken; anything else is refused and the menu set back."""
        if self.speed.value in self.SPEEDS:
            self._factor = float(self.speed.value.rstrip("x"))
        else:
            self.speed.value = f"{self._factor:g}x"  # type: ignore[misc]  # (viser: assignable, typed read-only)

    def _apply_layers(self) -> None:
        if self.nodes is None:
            return
        self.nodes.robot.visible = self.layers["robot"].value
        if self.nodes.voxels is not None:
            self.nodes.voxels.visible = self.layers["reachability map"].value
        for layer, group in self.nodes.groups.items():
            group.visible = self.layers[layer].value

    def _play(self, tick_s: float = 0.05) -> None:
        """Step the time along until :meth:`close`, from the checked time and speed only; a step that fails is
        logged (the first time) and counted in ``player_errors``, and the next step comes."""
        last = time.perf_counter()
        while not self._stop.wait(tick_s):
            now = time.perf_counter()
            dt, last = now - last, now
            try:
                if not self.playing.value or self.nodes is None:
                    continue
                t_next = self._t + self._factor * dt
                self._t = t_next if 0.0 <= t_next <= self.time.max else 0.0
                self.time.value = self._t  # type: ignore[misc]  # (viser: assignable, typed read-only); moves the scene
            except Exception:  # noqa: BLE001 -- the player outlives any one step
                self.player_errors += 1
                if self.player_errors == 1:
                    logging.getLogger("snakehead.viz.server").exception("the viewer's player failed a step")

    def close(self) -> None:
        """Stop the player and the server."""
        self._stop.set()
        self._thread.join(timeout=2.0)
        self.server.stop()


def serve(directory: str | Path | None, *, host: str = "127.0.0.1", port: int = 8080,
          extra: Sequence[ViewerScene] = (), allow_hosts: Sequence[str] = ()) -> Viewer:
    """Serve the viewer scenes of ``directory`` (the output of ``snakehead plan`` or ``demo``; None: none) and
    ``extra`` scenes (e.g. :func:`reach_scene`'s) at http://HOST:PORT (the next free port if PORT is taken; the
    page at the returned viewer's ``url``, with its token); returns the running :class:`Viewer`."""
    paths = scenes_in(directory) if directory is not None else []
    if not paths and not extra:
        raise InputError(f"{directory} holds no viewer scenes (*{SCENE_SUFFIX}); 'snakehead plan' and "
                         "'snakehead demo' write them")
    return Viewer([load_viewer_scene(p) for p in paths] + list(extra), host=host, port=port, allow_hosts=allow_hosts)
