"""The guard in front of the viewers' web servers (``snakehead view`` and ``snakehead view --live``).

Both viewers are viser servers: one port serves the page (HTTP) and the websocket that carries the scene to the
page and the panel's values back. A page of any other site in the user's browser can reach a server on
127.0.0.1, and a name that an attacker's DNS points at 127.0.0.1 reaches it as that name (DNS rebinding). So every
request passes :class:`ServerGuard` before viser sees it:

* **Host**: the ``Host`` header must be a name of this server -- ``localhost``, ``127.0.0.1``, ``[::1]``, the
  address the connection came in on, or a name given with ``allow_hosts`` (``--allow-host``) -- with the server's
  port. Anything else is refused (403): a rebound name never gets the page.
* **Origin**: a request that carries an ``Origin`` (every browser's websocket does) must come from one of those
  names and port over http; a page of another origin gets no upgrade (403).
* **Token**: a random token per server (:data:`TOKEN_BYTES` bytes from :mod:`secrets`), printed in the URL
  (``http://127.0.0.1:PORT/?token=...``, as Jupyter does). A request with the right ``?token=`` is sent on to the
  page with a cookie (``HttpOnly``, ``SameSite=Strict``, named after the port) that the page's websocket then
  carries (viser's page connects to the URL it was loaded from without its query); the token leaves the address
  bar by a redirect. A request or websocket without the token (in the query or the cookie) is refused (403).
  Tokens are compared in constant time.
* **Frames and headers**: every response carries ``Content-Security-Policy: frame-ancestors 'none'`` and
  ``X-Frame-Options: DENY`` (no other site can frame the page and click it), ``X-Content-Type-Options: nosniff``,
  ``Referrer-Policy: no-referrer`` and ``Cache-Control: no-store``.
* **Messages**: a websocket message is at most :data:`MAX_MESSAGE_BYTES` (a larger one closes the connection), and
  only the kinds of message the viewers' pages send pass on to viser (:data:`CLIENT_MESSAGES`: the camera, a panel
  value, a gizmo's drag); a panel update may set a value only (never a widget's options, bounds or callbacks).
  Everything else -- file uploads, requests for a public share URL, form and command messages -- is dropped, and
  a client that sends :data:`MAX_REFUSED_MESSAGES` of them is disconnected. At most :data:`MAX_CLIENTS` browsers
  at once.

How: viser starts its server with ``websockets.asyncio.server.serve`` on a thread of its own, inside
``viser.ViserServer()``. :func:`guarded_server` makes that call pass through ``_guarded_serve``, which adds the
guard's ``process_request``, ``process_response``, message size and connection class to viser's own (its static
page server stays behind the guard). If viser ever starts its server another way the guard is not applied, and
:func:`guarded_server` stops the server and raises rather than serve unguarded.
"""
from __future__ import annotations

import collections
import contextlib
import hmac
import http
import io
import ipaddress
import logging
import secrets
import threading
from typing import TYPE_CHECKING, Any, Callable, Sequence
from urllib.parse import parse_qsl, urlencode, urlsplit

import msgspec
import websockets.asyncio.server as ws_server
from websockets.asyncio.server import ServerConnection

from .._errors import InputError

if TYPE_CHECKING:
    import viser
    from websockets.http11 import Request, Response

__all__ = ["TOKEN_BYTES", "TOKEN_PARAMETER", "COOKIE_PREFIX", "LOOPBACK_NAMES", "MAX_MESSAGE_BYTES",
           "MAX_REFUSED_MESSAGES", "MAX_CLIENTS", "CLIENT_MESSAGES", "SECURITY_HEADERS", "REFUSED_HOST",
           "REFUSED_ORIGIN", "REFUSED_TOKEN", "REFUSED_FULL", "ServerGuard", "host_name", "guarded_server"]

LOG = logging.getLogger("snakehead.viz.server")

#: Bytes of randomness in a server's token (256 bits; URL-safe base64 in the URL).
TOKEN_BYTES = 32
#: The token's query parameter, and the prefix of its cookie's name (the port follows: cookies are not kept apart
#: by port, so two servers on one machine need two names).
TOKEN_PARAMETER = "token"
COOKIE_PREFIX = "snakehead-token-"
#: The names a server on this machine is always reached by (with its port).
LOOPBACK_NAMES = ("localhost", "127.0.0.1", "[::1]")
#: Bytes: the largest websocket message a client may send (the pages send camera poses and panel values of a few
#: hundred bytes; viser's own limit is 50 MB). websockets buffers at most 16 of them per client.
MAX_MESSAGE_BYTES = 64 * 1024
#: Messages refused on one connection before it is closed.
MAX_REFUSED_MESSAGES = 100
#: Browsers connected at once (a further websocket is refused with 503 until one leaves).
MAX_CLIENTS = 8
#: The messages a client may send (viser's message classes, by name): the camera, a panel value, a gizmo's drag,
#: and the pointer and click events viser's page may report. Everything else is dropped before viser sees it.
CLIENT_MESSAGES = frozenset({
    "ViewerCameraMessage", "GuiUpdateMessage", "TransformControlsUpdateMessage",
    "TransformControlsDragStartMessage", "TransformControlsDragEndMessage", "ScenePointerMessage",
    "SceneNodeClickMessage", "SceneNodeDragMessage"})
#: Headers on every HTTP response: no framing by another site, no type sniffing, no referrer, no caching.
SECURITY_HEADERS = (("Content-Security-Policy", "frame-ancestors 'none'"), ("X-Frame-Options", "DENY"),
                    ("X-Content-Type-Options", "nosniff"), ("Referrer-Policy", "no-referrer"),
                    ("Cache-Control", "no-store"))
#: What a refused request is told (nothing about the server beyond the rule it broke).
REFUSED_HOST = "Refused: the Host header is not this server's name (snakehead view --allow-host adds one).\n"
REFUSED_ORIGIN = "Refused: requests from another site are not served.\n"
REFUSED_TOKEN = "Refused: open the URL snakehead printed (it carries this session's token).\n"
REFUSED_FULL = "Refused: too many browsers are connected to this viewer.\n"


class ServerGuard:
    """The checks of one server (see the module): its token, the extra host names it answers to, and counts of
    what it refused (``refused``: reason -> count, for logs and tests). ``allow_hosts``: names (``robot-pc``,
    ``192.168.1.5``) besides this machine's loopback names and the address a connection comes in on; InputError
    for a name with a scheme, a path, a port or spaces."""

    def __init__(self, allow_hosts: Sequence[str] = ()) -> None:
        if isinstance(allow_hosts, str):
            allow_hosts = (allow_hosts,)
        self.token = secrets.token_urlsafe(TOKEN_BYTES)
        self.extra_hosts = tuple(host_name(h) for h in allow_hosts)
        self.refused: collections.Counter[str] = collections.Counter()
        self.applied = False
        self._lock = threading.Lock()

    # --- what the user is told ---------------------------------------------------------------------------------
    def url(self, host: str, port: int) -> str:
        """The page's URL with the token (a wildcard address is shown as 127.0.0.1)."""
        return f"http://{_url_host(host)}:{int(port)}/?{TOKEN_PARAMETER}={self.token}"

    # --- HTTP and the websocket's opening handshake --------------------------------------------------------------
    def process_request(self, inner: Callable[..., Any] | None) -> Callable[[ServerConnection, Request], Any]:
        """websockets' ``process_request``: the checks, then ``inner`` (viser's page server) for a page request
        that passed them; None (go on with the handshake) for a websocket that passed them."""

        def check(connection: ServerConnection, request: Request) -> Response | None:
            port = int(connection.local_address[1])
            names = self._names(connection, port)
            hosts = request.headers.get_all("Host")
            if len(hosts) != 1 or hosts[0].strip().lower() not in names:
                return self._refuse(connection, "host", http.HTTPStatus.FORBIDDEN, REFUSED_HOST)
            origins = request.headers.get_all("Origin")
            if len(origins) > 1 or (origins and origins[0].strip().lower() not in {f"http://{n}" for n in names}):
                return self._refuse(connection, "origin", http.HTTPStatus.FORBIDDEN, REFUSED_ORIGIN)
            upgrade = "websocket" in request.headers.get("Upgrade", "").lower()
            query = urlsplit(request.path).query
            in_query = [v for k, v in parse_qsl(query, keep_blank_values=True) if k == TOKEN_PARAMETER]
            if any(self._is_token(v) for v in in_query):
                if upgrade:
                    return self._admit(connection)
                return self._redirect_with_cookie(connection, port, query)
            if not any(self._is_token(v) for v in _cookies(request, COOKIE_PREFIX + str(port))):
                return self._refuse(connection, "token", http.HTTPStatus.FORBIDDEN, REFUSED_TOKEN)
            if upgrade:
                return self._admit(connection)
            return inner(connection, request) if inner is not None else None

        return check

    @staticmethod
    def process_response(connection: ServerConnection, request: Request, response: Response) -> None:
        """websockets' ``process_response``: :data:`SECURITY_HEADERS` on every HTTP response."""
        if response.status_code != http.HTTPStatus.SWITCHING_PROTOCOLS:
            for name, value in SECURITY_HEADERS:
                response.headers[name] = value

    def _names(self, connection: ServerConnection, port: int) -> set[str]:
        """The Host values this server answers to: its names with its port (and without, on port 80)."""
        here = _url_host(str(connection.local_address[0]))
        names = {*LOOPBACK_NAMES, here, *self.extra_hosts}
        return {f"{n}:{port}" for n in names} | (names if port == 80 else set())

    def _is_token(self, value: str) -> bool:
        return hmac.compare_digest(value.encode("utf-8", "replace"), self.token.encode())

    def _admit(self, connection: ServerConnection) -> Response | None:
        if len(connection.server.connections) >= MAX_CLIENTS:
            return self._refuse(connection, "clients", http.HTTPStatus.SERVICE_UNAVAILABLE, REFUSED_FULL)
        return None

    def _redirect_with_cookie(self, connection: ServerConnection, port: int, query: str) -> Response:
        """The page again without the token in its URL (out of the address bar, the history and any referrer),
        with the token as a cookie. Always to "/" of this server: never a redirect elsewhere."""
        rest = urlencode([(k, v) for k, v in parse_qsl(query, keep_blank_values=True) if k != TOKEN_PARAMETER])
        response = connection.respond(http.HTTPStatus.SEE_OTHER, "")
        response.headers["Location"] = "/" + (f"?{rest}" if rest else "")
        response.headers["Set-Cookie"] = (f"{COOKIE_PREFIX}{port}={self.token}; Path=/; HttpOnly; "
                                          "SameSite=Strict")
        return response

    def _refuse(self, connection: ServerConnection, reason: str, status: http.HTTPStatus, text: str) -> Response:
        with self._lock:
            self.refused[reason] += 1
        LOG.warning("refused a request from %s: %s", connection.remote_address, reason)
        return connection.respond(status, text)

    # --- websocket messages ------------------------------------------------------------------------------------
    def admits(self, data: Any) -> bool:
        """Whether a message a client sent goes on to viser (see :data:`CLIENT_MESSAGES`)."""
        if not isinstance(data, bytes):
            return False
        try:
            message = msgspec.msgpack.decode(data)
        except Exception:  # noqa: BLE001 -- anything that does not decode is refused
            return False
        if not isinstance(message, dict) or message.get("type") not in CLIENT_MESSAGES:
            return False
        if message["type"] == "GuiUpdateMessage":
            updates = message.get("updates")
            return isinstance(updates, dict) and list(updates) == ["value"]
        return True

    def refuse_message(self) -> None:
        with self._lock:
            self.refused["message"] += 1

    def connection_class(self) -> type:
        """A websockets ``ServerConnection`` whose ``recv`` drops what :meth:`admits` refuses, and closes the
        connection after :data:`MAX_REFUSED_MESSAGES` of them."""
        guard = self

        class GuardedConnection(ServerConnection):
            refused_messages = 0

            async def recv(self, decode: bool | None = None) -> Any:
                while True:
                    data = await super().recv(decode)
                    if guard.admits(data):
                        return data
                    guard.refuse_message()
                    self.refused_messages += 1
                    if self.refused_messages >= MAX_REFUSED_MESSAGES:
                        LOG.warning("closed the connection of %s: %d messages refused", self.remote_address,
                                    self.refused_messages)
                        await self.close(1008, "too many refused messages")

        return GuardedConnection


def host_name(name: str) -> str:
    """A host name or address for ``--allow-host`` as a Host header spells it (lower case, IPv6 in brackets);
    InputError for anything else (a scheme, a port, a path, spaces)."""
    if not isinstance(name, str):
        raise InputError(f"--allow-host takes a host name or address, got {type(name).__name__}")
    text = name.strip().lower()
    with contextlib.suppress(ValueError):
        address = ipaddress.ip_address(text.strip("[]"))
        return f"[{address}]" if address.version == 6 else str(address)
    labels = text.split(".")
    if not text or len(text) > 253 or not all(label and len(label) <= 63 and label.replace("-", "").isalnum()
                                              and label.isascii() and not label.startswith("-")
                                              for label in labels):
        raise InputError(f"--allow-host: {name!r} is not a host name or an IP address (no scheme, port or path)")
    return text


def _url_host(host: str) -> str:
    """``host`` as a URL spells it: a wildcard address as 127.0.0.1 (or [::1]), an IPv6 address in brackets."""
    bare = host.strip("[]")
    if bare in ("", "0.0.0.0"):
        return "127.0.0.1"
    if bare == "::":
        return "[::1]"
    with contextlib.suppress(ValueError):
        address = ipaddress.ip_address(bare.split("%")[0])
        return f"[{address}]" if address.version == 6 else str(address)
    return host.lower()


def _cookies(request: Request, name: str) -> list[str]:
    """The values of the cookies called ``name`` in the request."""
    values = []
    for header in request.headers.get_all("Cookie"):
        for part in header.split(";"):
            key, sep, value = part.strip().partition("=")
            if sep and key == name:
                values.append(value.strip().strip('"'))
    return values


# ----------------------------------------------------------------------------------------------
# starting viser behind the guard
# ----------------------------------------------------------------------------------------------
_starting = threading.Lock()  # one guarded server starts at a time: _pending belongs to it
_pending: ServerGuard | None = None
_original_serve: Any = None


def _guarded_serve(handler: Any, host: Any = None, port: Any = None, **kwargs: Any) -> Any:
    """``websockets.asyncio.server.serve`` as viser calls it, with the pending guard's checks (none pending:
    unchanged, for any other server in the process)."""
    guard = _pending
    if guard is None:
        return _original_serve(handler, host, port, **kwargs)
    kwargs["process_request"] = guard.process_request(kwargs.get("process_request"))
    kwargs["process_response"] = guard.process_response
    kwargs["max_size"] = MAX_MESSAGE_BYTES
    kwargs["create_connection"] = guard.connection_class()
    guard.applied = True
    return _original_serve(handler, host, port, **kwargs)


def guarded_server(guard: ServerGuard, host: str, port: int) -> viser.ViserServer:
    """A viser server at ``host``:``port`` (the next free port if it is taken) behind ``guard``, printing nothing.
    RuntimeError (the server stopped) if the guard could not be put in front of it."""
    global _original_serve, _pending
    import viser  # heavy: imported when a server starts, not with the viewer's modules

    with _starting:
        if _original_serve is None:
            _original_serve = ws_server.serve
            ws_server.serve = _guarded_serve  # type: ignore[misc,assignment]
        _pending = guard
        try:
            with contextlib.redirect_stdout(io.StringIO()):  # viser's banner: the caller prints the URL
                server = viser.ViserServer(host=host, port=port, verbose=False)
        finally:
            _pending = None
    if not guard.applied:
        with contextlib.redirect_stdout(io.StringIO()):
            server.stop()
        raise RuntimeError("viser did not start its server through websockets.asyncio.server.serve: the viewer's "
                           "guard (Host, Origin, token) could not be applied, so nothing is served")
    return server
