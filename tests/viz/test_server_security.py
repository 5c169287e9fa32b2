"""The viewers' web servers as an attacker meets them (issue 37): ``snakehead view --live`` (:class:`LiveViewer`)
and ``snakehead view`` (:class:`snakehead.viz.viewer.Viewer`), each served on 127.0.0.1 and driven by real
websocket and HTTP clients (the ``websockets`` package, http.client), as a page of another site, a rebound DNS
name or a hostile browser tab would.

* Who gets in: a foreign ``Origin``, a missing or wrong token, a ``Host`` that is not this server's are refused
  (403) on HTTP and on the websocket; the page is framed by nobody (``frame-ancestors 'none'``).
* What the page may write: bare names in the save folder only; absolute paths, ``../`` paths, hidden names and
  existing files are refused, the decoys untouched, and the reply names no server path. Each browser has its own
  file box.
* What a client may send: speeds and times out of range are refused and playback goes on; 500 "add target"
  clicks leave :data:`MAX_TARGETS` targets; uploads, share requests and widget options are dropped; an oversized
  message closes the connection.

Every loop is bounded; the servers are stopped at the end of the module.
"""
from __future__ import annotations

import http.client
import math
import os
import socket
import threading
import time
from pathlib import Path

import msgspec
import numpy as np
import pytest
import viser
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect

from snakehead import InputError
from snakehead.scenes import Scene, Target
from snakehead.viz import live as live_module
from snakehead.viz.live import MAX_TARGETS, SPEEDS, LiveViewer
from snakehead.viz.save_folder import MAX_NAME_CHARS, SaveFolder, bare_name
from snakehead.viz.server_guard import MAX_MESSAGE_BYTES, MAX_REFUSED_MESSAGES, ServerGuard
from snakehead.viz.viewer import Viewer, viewer_scene

NEAR = ((0.10, 0.55, 0.32), (0.05, 0.50, 0.32))
FORWARD = (0.0, 1.0, 0.0)
TIMEOUT_S = 120.0
SUBPROTOCOL = f"viser-v{viser.__version__}"
DECOY_TEXT = "# a file the viewer must never touch\n"


# ----------------------------------------------------------------------------------------------
# the servers, and clients as an attacker writes them
# ----------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def folders(tmp_path_factory):
    """The live viewer's save folder, and a decoy beside it and one in it (files of someone else's)."""
    root = tmp_path_factory.mktemp("security")
    saves = root / "saves"
    saves.mkdir()
    for decoy in (root / "decoy.toml", saves / "existing.toml", root / ".bashrc"):
        decoy.write_text(DECOY_TEXT)
    return root, saves


@pytest.fixture(scope="module")
def live(folders):
    scene = Scene(name="security", targets=(Target("target", NEAR[0], FORWARD, hold_s=1.0),))
    viewer = LiveViewer(scene, port=0, save_dir=folders[1])
    try:
        assert viewer.wait_for_plan(TIMEOUT_S).playing is not None
        yield viewer
    finally:
        viewer.close()


@pytest.fixture(scope="module")
def static(live):
    viewer = Viewer([viewer_scene(live.latest)], port=0)
    try:
        yield viewer
    finally:
        viewer.close()


@pytest.fixture(params=["live", "static"])
def server(request):
    """Each of the two servers in turn."""
    return request.getfixturevalue(request.param)


def own_origin(port: int) -> str:
    return f"http://127.0.0.1:{port}"


def http_get(port: int, path: str = "/", headers: dict | None = None) -> tuple[int, dict, bytes]:
    """GET ``path`` from 127.0.0.1:``port`` (``headers`` may replace Host): status, headers, body."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        c.putrequest("GET", path, skip_host="Host" in (headers or {}))
        for name, value in (headers or {}).items():
            c.putheader(name, value)
        c.endheaders()
        r = c.getresponse()
        return r.status, {k.lower(): v for k, v in r.getheaders()}, r.read()
    finally:
        c.close()


def handshake(port: int, *, token: str | None = None, origin: str | None = "own", cookie: str | None = None,
              host: str | None = None) -> int:
    """The status of a websocket's opening handshake (101 if it opened; it is closed at once). ``host``: the name
    the URL gives (the Host header), the connection still made to 127.0.0.1 -- as after DNS rebinding."""
    query = f"/?token={token}" if token is not None else "/"
    sock = socket.create_connection(("127.0.0.1", port), timeout=10)
    try:
        with connect(f"ws://{host or f'127.0.0.1:{port}'}{query}", sock=sock,
                     origin=own_origin(port) if origin == "own" else origin,
                     additional_headers={"Cookie": cookie} if cookie is not None else None,
                     subprotocols=[SUBPROTOCOL], open_timeout=10, max_size=None):
            return 101
    except InvalidStatus as exc:
        return exc.response.status_code
    finally:
        sock.close()


CAMERA = {"type": "ViewerCameraMessage", "wxyz": [1.0, 0.0, 0.0, 0.0], "position": [1.0, 1.0, 1.0], "fov": 0.8,
          "near": 0.01, "far": 100.0, "image_height": 480, "image_width": 640, "look_at": [0.0, 0.0, 0.0],
          "up_direction": [0.0, 0.0, 1.0]}


class Client:
    """A browser tab written by hand: a websocket with the token and its own Origin that reads everything the
    server sends (in a thread) and sends what it is told, viser's message format (msgpack)."""

    def __init__(self, port: int, token: str) -> None:
        self.ws = connect(f"ws://127.0.0.1:{port}/?token={token}", origin=own_origin(port),
                          subprotocols=[SUBPROTOCOL], open_timeout=10, max_size=None)
        self.received = 0
        self.closed: ConnectionClosed | None = None
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self.send(CAMERA)  # viser counts a client from its first camera pose

    def _read(self) -> None:
        try:
            while True:
                self.ws.recv()
                self.received += 1
        except ConnectionClosed as exc:
            self.closed = exc

    def send(self, message: dict) -> None:
        self.ws.send(msgspec.msgpack.encode(message))

    def set(self, handle, value) -> None:
        """What a browser sends when a widget's value changes (a click: True)."""
        self.send({"type": "GuiUpdateMessage", "uuid": handle._impl.uuid, "updates": {"value": value}})

    def close(self) -> None:
        self.ws.close()
        self._reader.join(timeout=10)


def wait_for(condition, timeout: float = 20.0, what: str = "the condition"):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(0.02)
    raise AssertionError(f"{what} not met within {timeout} s")


@pytest.fixture
def tab(live):
    """A browser tab on the live viewer with its own part of the panel."""
    before = {p.client_id for p in live._panels.all()}
    client = Client(live.port, live.guard.token)
    client.panel = wait_for(lambda: next((p for p in live._panels.all() if p.client_id not in before), None),
                            what="the tab's panel")
    try:
        yield client
    finally:
        client.close()


def after_clicks(live, client: Client, handle, value=True) -> None:
    """Send a value and give viser a moment to handle it (the tests then wait for what it does)."""
    client.set(handle, value)
    time.sleep(0.3)


def save_reply(live, client: Client, panel, name: str) -> str:
    """Type ``name`` in ``panel``'s file box and click "save scene" from ``client``: what the panel then says."""
    client.set(panel.file, name)
    wait_for(lambda: panel.file.value == name, what=f"the file box holding {name!r}")
    panel.saved.content = ""
    client.set(live._save_button, True)
    return wait_for(lambda: panel.saved.content, what=f"the reply to saving {name!r}")


# ----------------------------------------------------------------------------------------------
# who gets in
# ----------------------------------------------------------------------------------------------
def test_a_websocket_from_another_origin_is_refused(server):
    port, token = server.port, server.guard.token
    assert handshake(port, token=token) == 101  # the page's own origin, with the token
    for origin in ("http://evil.example", f"http://evil.example:{port}", "http://127.0.0.1:1", "null",
                   f"https://127.0.0.1:{port}", f"http://127.0.0.1:{port}.evil.example"):
        assert handshake(port, token=token, origin=origin) == 403, origin
    assert server.guard.refused["origin"] >= 6


def test_a_websocket_or_page_without_the_token_is_refused(server):
    port, token = server.port, server.guard.token
    assert handshake(port) == 403  # no token
    assert handshake(port, origin=None) == 403  # not a browser, no token
    assert handshake(port, token=token[:-1] + ("A" if token[-1] != "A" else "B")) == 403  # wrong token
    assert handshake(port, token="") == 403
    assert handshake(port, cookie=f"snakehead-token-{port + 1}={token}") == 403  # another server's cookie name
    assert handshake(port, cookie=f"snakehead-token-{port}=nope") == 403
    assert handshake(port, cookie=f"snakehead-token-{port}={token}") == 101  # the page's cookie
    assert handshake(port, token=token, origin=None) == 101  # a script of the user's own, with the token
    status, headers, body = http_get(port, "/")
    assert status == 403 and b"token" in body and len(body) < 200  # no page
    assert http_get(port, "/?token=wrong")[0] == 403


def test_a_host_that_is_not_this_servers_is_refused(server):
    """DNS rebinding: a name the attacker points at 127.0.0.1 arrives as that name in Host."""
    port, token = server.port, server.guard.token
    for host in (f"evil.example:{port}", "evil.example", f"127.0.0.1.evil.example:{port}", f"127.0.0.1:{port + 1}",
                 f"localhost:{port}@evil.example", ""):
        assert http_get(port, f"/?token={token}", {"Host": host})[0] == 403, host
        if host and "@" not in host:
            assert handshake(port, token=token, host=host, origin=None) == 403, host
            assert handshake(port, token=token, host=host, origin=f"http://{host}") == 403, host
    assert handshake(port, token=token, host=f"localhost:{port}", origin=f"http://localhost:{port}") == 101
    for host in (f"localhost:{port}", f"127.0.0.1:{port}", f"LOCALHOST:{port}"):
        assert http_get(port, f"/?token={token}", {"Host": host})[0] == 303, host
    assert server.guard.refused["host"] >= 10


def test_the_token_url_sets_a_cookie_and_no_one_frames_the_page(server):
    port, token = server.port, server.guard.token
    assert server.url == f"http://127.0.0.1:{port}/?token={token}"
    status, headers, _ = http_get(port, f"/?token={token}&x=1")
    assert status == 303 and headers["location"] == "/?x=1"  # the token leaves the address bar
    cookie = headers["set-cookie"]
    assert cookie.startswith(f"snakehead-token-{port}={token};")
    assert "HttpOnly" in cookie and "SameSite=Strict" in cookie and "Path=/" in cookie
    assert http_get(port, f"//evil.example/?token={token}")[1]["location"] == "/"  # never a redirect elsewhere
    status, headers, body = http_get(port, "/", {"Cookie": cookie.split(";")[0]})
    assert status == 200 and b"<html" in body[:200].lower()
    for status, headers, _ in (http_get(port, "/", {"Cookie": cookie.split(";")[0]}), http_get(port, "/")):
        assert headers["content-security-policy"] == "frame-ancestors 'none'"
        assert headers["x-frame-options"] == "DENY" and headers["x-content-type-options"] == "nosniff"
        assert headers["referrer-policy"] == "no-referrer"


def test_more_host_names_only_when_given():
    with pytest.raises(InputError, match="not a host name"):
        ServerGuard(["http://robot-pc"])
    with pytest.raises(InputError, match="not a host name"):
        ServerGuard(["robot-pc:8080"])
    assert ServerGuard(["Robot-PC", "::1", "192.168.1.5"]).extra_hosts == ("robot-pc", "[::1]", "192.168.1.5")
    a, b = ServerGuard(), ServerGuard()
    assert a.token != b.token and len(a.token) >= 43  # 32 random bytes


def test_an_allowed_host_name_is_served(live):
    scene = viewer_scene(live.latest)
    viewer = Viewer([scene], port=0, allow_hosts=["robot-pc"])
    try:
        port, token = viewer.port, viewer.guard.token
        assert http_get(port, f"/?token={token}", {"Host": f"robot-pc:{port}"})[0] == 303
        assert handshake(port, token=token, host=f"robot-pc:{port}", origin=f"http://robot-pc:{port}") == 101
        assert http_get(port, f"/?token={token}", {"Host": f"other-pc:{port}"})[0] == 403
    finally:
        viewer.close()


# ----------------------------------------------------------------------------------------------
# what a client may send
# ----------------------------------------------------------------------------------------------
def test_uploads_share_requests_and_widget_options_are_dropped(live, tab):
    refused = live.guard.refused["message"]
    tab.send({"type": "FileTransferStartUpload", "source_component_uuid": tab.panel.file._impl.uuid,
              "transfer_uuid": "t", "filename": "x", "mime_type": "text/plain", "part_count": 1000,
              "size_bytes": 10**9})
    tab.send({"type": "ShareUrlRequest"})
    tab.send({"type": "GuiUpdateMessage", "uuid": live._speed._impl.uuid, "updates": {"options": ["1e9x"]}})
    tab.send({"type": "GuiUpdateMessage", "uuid": live._speed._impl.uuid,
              "updates": {"value": "8x", "update_cb": []}})
    wait_for(lambda: live.guard.refused["message"] >= refused + 4, what="four messages refused")
    assert live._speed.options == SPEEDS and live._speed._impl.update_cb  # its options and callbacks as they were
    assert not live.server.gui._current_file_upload_states  # nothing held for an upload
    assert live.server._share_tunnel is None


def test_an_oversized_message_or_many_refused_ones_close_the_connection(live):
    big = Client(live.port, live.guard.token)
    big.ws.send(b"\x81" + b"x" * (MAX_MESSAGE_BYTES + 1))
    wait_for(lambda: big.closed is not None, what="the connection closed")
    assert big.closed.rcvd is not None and big.closed.rcvd.code == 1009  # message too big
    big.close()
    noisy = Client(live.port, live.guard.token)
    for _ in range(MAX_REFUSED_MESSAGES + 5):
        try:
            noisy.send({"type": "ShareUrlRequest"})
        except ConnectionClosed:
            break
    wait_for(lambda: noisy.closed is not None, what="the connection closed")
    assert noisy.closed.rcvd is not None and noisy.closed.rcvd.code == 1008
    noisy.close()


def test_speeds_and_times_out_of_range_do_not_stop_playback(live, tab):
    bad_speeds = ("fast", "1e9x", "x", "-4x", "nanx", "infx", "0x", "", "4", 4)
    bad_times = (math.nan, math.inf, -math.inf, -1.0, 1e9, "abc", "nan")
    for value in bad_speeds:
        after_clicks(live, tab, live._speed, value)
    wait_for(lambda: live._speed.value in SPEEDS, what="the speed set back")
    assert live._speed_factor in {float(s.rstrip("x")) for s in SPEEDS}
    assert "speed must be one of" in tab.panel.notice.content
    for value in bad_times:
        after_clicks(live, tab, live._time, value)
        assert math.isfinite(live._t) and 0.0 <= live._t <= live.motion.duration_s + live_module.HOLD_S
    t0 = live._t
    wait_for(lambda: live._t != t0, 5.0, "the player stepping on")
    assert live.player_errors == 0 and all(thread.is_alive() for thread in live._threads)
    after_clicks(live, tab, live._speed, "2x")  # good values are taken
    assert live._speed_factor == 2.0
    after_clicks(live, tab, live._playing, False)
    after_clicks(live, tab, live._time, 0.5)
    assert live._t == 0.5
    after_clicks(live, tab, live._playing, True)


def test_the_static_viewer_refuses_what_it_does_not_offer(static):
    client = Client(static.port, static.guard.token)
    try:
        name = static.scenario.value
        for handle, value in ((static.speed, "fast"), (static.speed, "1e9x"), (static.speed, "nanx"),
                              (static.time, math.nan), (static.time, math.inf), (static.time, -5.0),
                              (static.scenario, "no such scene")):
            client.set(handle, value)
        time.sleep(0.5)
        wait_for(lambda: static.speed.value in Viewer.SPEEDS and static.scenario.value == name,
                 what="the menus set back")
        assert math.isfinite(static._factor) and static._factor in {float(s.rstrip("x")) for s in Viewer.SPEEDS}
        t0 = static._t
        wait_for(lambda: static._t != t0, 5.0, "the player stepping on")
        assert static._thread.is_alive() and static.player_errors == 0
        assert math.isfinite(static.time.value)
    finally:
        client.close()


def test_a_gizmo_left_at_a_pose_that_is_no_target_goes_back(live, tab):
    handle = live._gizmos.handles[0]
    before = live.targets[0]
    records = len(live.records)
    owner = ""  # the server scope's gizmos
    tab.send({"type": "TransformControlsDragStartMessage", "name": handle.name, "owner": owner})
    tab.send({"type": "TransformControlsUpdateMessage", "name": handle.name, "owner": owner,
              "wxyz": [1.0, 0.0, 0.0, 0.0], "position": [math.nan, 0.5, 0.3]})
    tab.send({"type": "TransformControlsDragEndMessage", "name": handle.name, "owner": owner})
    wait_for(lambda: "Not done" in tab.panel.notice.content, what="the refusal told")
    assert len(live.records) == records and np.array_equal(live.targets[0].position, before.position)
    wait_for(lambda: np.allclose(handle.position, before.position), what="the gizmo back on its target")


def test_500_added_targets_are_capped(live, tab):
    add = live._add
    for _ in range(500):
        tab.set(add, True)
    wait_for(lambda: len(live.targets) == MAX_TARGETS and "at most" in tab.panel.notice.content, 60.0,
             "the targets capped")
    time.sleep(1.0)  # what was still queued
    assert len(live.targets) == MAX_TARGETS and len(live._gizmos.handles) == MAX_TARGETS
    with pytest.raises(InputError, match=f"at most {MAX_TARGETS} targets"):
        live.add_target()
    assert tab.panel.chosen.options == tuple(t.name for t in live.targets)  # its menu follows
    while len(live.targets) > 1:
        live.remove_target(len(live.targets) - 1)
    assert live.wait_for_plan(TIMEOUT_S).playing is not None
    many = Scene(name="many", targets=tuple(Target(f"t{k}", NEAR[0], FORWARD) for k in range(MAX_TARGETS + 1)))
    with pytest.raises(InputError, match=f"at most {MAX_TARGETS}"):
        LiveViewer(many, port=0)


def test_a_motion_longer_than_the_viewer_plays_is_not_drawn(live, monkeypatch):
    monkeypatch.setattr(live_module, "MAX_MOTION_S", 0.5)
    number = live.move_target(0, NEAR[1], FORWARD)
    record = live.wait_for_plan(TIMEOUT_S)
    assert record.number == number and record.playing is None and "the live viewer plays" in record.error
    monkeypatch.undo()
    live.move_target(0, NEAR[0], FORWARD)
    assert live.wait_for_plan(TIMEOUT_S).playing is not None


# ----------------------------------------------------------------------------------------------
# what the page may write
# ----------------------------------------------------------------------------------------------
def test_saves_outside_the_folder_or_over_other_files_are_refused(live, tab, folders):
    root, saves = folders
    decoys = [root / "decoy.toml", saves / "existing.toml", root / ".bashrc"]
    stamps = [(d.read_text(), d.stat().st_mtime_ns) for d in decoys]
    (saves / "link.toml").symlink_to(root / "decoy.toml")
    attempts = [str(root / "decoy.toml"), str(root / "decoy"), "../decoy.toml", "../decoy", "..", "../../etc/x",
                "existing.toml", "existing", "link", ".bashrc", "../.bashrc", "a/b", "a\\b", "C:x", "", " ",
                "x" * MAX_NAME_CHARS, "nul", "café", "~/.bashrc", "%2e%2e/decoy", "a\nb"]
    for name in attempts:
        reply = save_reply(live, tab, tab.panel, name)
        assert reply.startswith("**Not saved:**"), (name, reply)
        assert str(root) not in reply and "Errno" not in reply and "directory" not in reply.lower(), reply
    assert [(d.read_text(), d.stat().st_mtime_ns) for d in decoys] == stamps  # untouched
    assert sorted(p.name for p in saves.iterdir()) == ["existing.toml", "link.toml"]
    assert save_reply(live, tab, tab.panel, "mine") == "Saved as `mine.toml` in the viewer's save folder."
    assert "[[targets]]" in (saves / "mine.toml").read_text()
    assert save_reply(live, tab, tab.panel, "mine.toml").startswith("Saved as `mine.toml`")  # its own: replaced


def test_each_tab_saves_to_its_own_file_box(live, tab, folders):
    before = {p.client_id for p in live._panels.all()}
    other = Client(live.port, live.guard.token)
    try:
        theirs = wait_for(lambda: next((p for p in live._panels.all() if p.client_id not in before), None),
                          what="the second tab's panel")
        tab.set(tab.panel.file, "aimed_by_the_other_tab")  # one tab aims the file box it sees...
        wait_for(lambda: tab.panel.file.value == "aimed_by_the_other_tab", what="the first tab's file box")
        tab.panel.saved.content = ""
        assert save_reply(live, other, theirs, "own_choice").startswith("Saved as `own_choice.toml`")  # ...in vain
        assert not (folders[1] / "aimed_by_the_other_tab.toml").exists()
        assert tab.panel.saved.content == ""  # and the first tab is told nothing of the other's save
        assert theirs.file.value == "own_choice" and tab.panel.file.value == "aimed_by_the_other_tab"
    finally:
        other.close()


def test_the_save_folder_takes_bare_names_only(tmp_path, monkeypatch):
    assert bare_name("scene") == "scene.toml" and bare_name("My scene-2.TOML") == "My scene-2.toml"
    assert bare_name("v1.2") == "v1.2.toml"
    refused = {"/etc/passwd": "without a folder", "../x": "without a folder", "a/b": "without a folder",
               ".hidden": "must not start with a dot", "a..b": "must not hold '..'", "x.": "dots \\(not first or last\\)",
               " x": "dots \\(not first or last\\)", "CON": "device name on Windows",
               "lpt1.toml": "device name on Windows", "é": "dots \\(not first or last\\)", 3: "must be text, got int",
               None: "must be text, got NoneType"}
    for name, message in refused.items():
        with pytest.raises(InputError, match=message):
            bare_name(name)
    folder = SaveFolder(tmp_path / "saves")
    assert not folder.folder.exists()  # made at the first save
    assert folder.write("a", "one\n") == "a.toml" and (tmp_path / "saves" / "a.toml").read_text() == "one\n"
    os.replace(tmp_path / "saves" / "a.toml", tmp_path / "kept.toml")  # someone else's file where the session's was
    (tmp_path / "saves" / "a.toml").write_text(DECOY_TEXT)
    with pytest.raises(InputError, match="not saved by this session"):
        folder.write("a.toml", "two\n")
    assert (tmp_path / "saves" / "a.toml").read_text() == DECOY_TEXT
    monkeypatch.setattr("snakehead.viz.save_folder.MAX_SAVED_FILES", 2)
    folder.write("b", "x")
    with pytest.raises(InputError, match="saved 2 files"):
        folder.write("c", "x")
    (tmp_path / "file").write_text("")
    with pytest.raises(InputError, match="not a folder"):
        SaveFolder(tmp_path / "file")


def test_the_command_line_takes_the_save_folder_and_host_names(tmp_path, capsys):
    from snakehead.app.cli import main

    assert main(["view", str(tmp_path), "--save-dir", str(tmp_path)]) == 2
    assert "--save-dir goes with --live" in capsys.readouterr().err
    assert main(["view", "--live", "--allow-host", "http://x/", "--port", "0"]) == 2
    assert "--allow-host" in capsys.readouterr().err
    assert Path(tmp_path).is_dir()
