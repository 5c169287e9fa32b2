"""The ROS 2 messages snakehead writes into its bags (:mod:`snakehead.app.ros_bag`): their definitions, the schema
text the ROS 2 MCAP profile carries, and their CDR encoding. No ROS installation is needed.

* :data:`DEFINITIONS` -- each message's fields as in ROS 2 Humble's ``.msg`` files (comments and default values
  left out; Jazzy's are the same but for a constant Marker adds, ARROW_STRIP, which is not on the wire):
  ``sensor_msgs/msg/JointState``, ``tf2_msgs/msg/TFMessage``, ``std_msgs/msg/String``,
  ``visualization_msgs/msg/MarkerArray`` and what they contain.
* :func:`schema_text` -- a type's definition followed by those of every type it uses, each after a line of 80 ``=``
  and ``MSG: pkg/Type``: the ``ros2msg`` schema encoding of the MCAP ``ros2`` profile (what ``ros2 bag record``
  writes).
* :func:`encoder` -- a function that encodes a message given as nested dicts and lists to CDR (little endian, with
  its 4-byte encapsulation header), by mcap-ros2-support's encoder for the schema text.
* :func:`joint_state_cdr`, :func:`tf_message_cdr` -- many ``sensor_msgs/msg/JointState`` or
  ``tf2_msgs/msg/TFMessage`` messages at once, laid out by hand with numpy: a motion sampled every 2 ms has tens of
  thousands of joint states, too many for the generic encoder, one message at a time. Their layout is checked
  against two independent decoders in the tests (rosbags' and mcap-ros2-support's).
"""
from __future__ import annotations

import re
import struct
from typing import Any, Callable, Sequence

import numpy as np
import numpy.typing as npt

# mcap-ros2-support's Writer encodes with this encoder but takes no pre-encoded messages and no channel metadata,
# which a bag needs (snakehead.app.ros_bag): its encoder, private to the package, is used directly (tested with 0.6)
from mcap_ros2._dynamic import serialize_dynamic  # noqa: PLC2701 (see above)

from .._errors import invariant

__all__ = ["DEFINITIONS", "ARROW", "CUBE", "SPHERE", "CYLINDER", "LINE_STRIP", "TEXT_VIEW_FACING", "TRIANGLE_LIST",
           "dependencies", "schema_text", "encoder", "stamp", "joint_state_cdr", "tf_message_cdr"]

#: Field definitions per type (ROS 2 Humble; Jazzy has the same fields). Nested types are named ``pkg/Type`` as .msg
#: files name them.
DEFINITIONS: dict[str, str] = {
    "builtin_interfaces/msg/Time": "int32 sec\nuint32 nanosec\n",
    "builtin_interfaces/msg/Duration": "int32 sec\nuint32 nanosec\n",
    "std_msgs/msg/Header": "builtin_interfaces/Time stamp\nstring frame_id\n",
    "std_msgs/msg/String": "string data\n",
    "std_msgs/msg/ColorRGBA": "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
    "geometry_msgs/msg/Point": "float64 x\nfloat64 y\nfloat64 z\n",
    "geometry_msgs/msg/Vector3": "float64 x\nfloat64 y\nfloat64 z\n",
    "geometry_msgs/msg/Quaternion": "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
    "geometry_msgs/msg/Pose": "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
    "geometry_msgs/msg/Transform": "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n",
    "geometry_msgs/msg/TransformStamped": ("std_msgs/Header header\nstring child_frame_id\n"
                                           "geometry_msgs/Transform transform\n"),
    "tf2_msgs/msg/TFMessage": "geometry_msgs/TransformStamped[] transforms\n",
    "sensor_msgs/msg/JointState": ("std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
                                   "float64[] effort\n"),
    "sensor_msgs/msg/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data\n",
    "visualization_msgs/msg/UVCoordinate": "float32 u\nfloat32 v\n",
    "visualization_msgs/msg/MeshFile": "string filename\nuint8[] data\n",
    "visualization_msgs/msg/Marker": (
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\nint32 LINE_LIST=5\n"
        "int32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\nint32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\n"
        "int32 TRIANGLE_LIST=11\nint32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n"
        "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\ngeometry_msgs/Pose pose\n"
        "geometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\nbuiltin_interfaces/Duration lifetime\n"
        "bool frame_locked\ngeometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\nstring texture_resource\n"
        "sensor_msgs/CompressedImage texture\nvisualization_msgs/UVCoordinate[] uv_coordinates\nstring text\n"
        "string mesh_resource\nvisualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials\n"),
    "visualization_msgs/msg/MarkerArray": "visualization_msgs/Marker[] markers\n",
}

#: The Marker types snakehead draws with (visualization_msgs/msg/Marker's constants).
ARROW, CUBE, SPHERE, CYLINDER, LINE_STRIP, TEXT_VIEW_FACING, TRIANGLE_LIST = 0, 1, 2, 3, 4, 9, 11

_SEPARATOR = "=" * 80
_FIELD_TYPE = re.compile(r"^([A-Za-z_]\w*/[A-Za-z_]\w*)(?:\[\d*\])?\s", re.MULTILINE)


def _full_name(short: str) -> str:
    package, name = short.split("/")
    return f"{package}/msg/{name}"


def dependencies(type_name: str) -> list[str]:
    """Every type ``type_name`` uses, directly or not, in the order of first use (itself not included)."""
    out: list[str] = []

    def visit(name: str) -> None:
        for short in _FIELD_TYPE.findall(DEFINITIONS[name]):
            full = _full_name(short)
            if full not in out:
                out.append(full)
                visit(full)

    visit(type_name)
    return out


def schema_text(type_name: str) -> str:
    """The ``ros2msg`` schema of ``type_name`` (see the module): its definition, then its dependencies'."""
    invariant(type_name in DEFINITIONS, f"no definition of {type_name}")
    parts = [DEFINITIONS[type_name]]
    for dep in dependencies(type_name):
        package, _, name = dep.split("/")
        parts.append(f"{_SEPARATOR}\nMSG: {package}/{name}\n{DEFINITIONS[dep]}")
    return "".join(parts)


def encoder(type_name: str) -> Callable[[Any], bytes]:
    """A CDR encoder of ``type_name`` messages given as nested dicts (field name -> value; lists for arrays)."""
    return serialize_dynamic(type_name, schema_text(type_name))[type_name]


def stamp(ns: int) -> dict[str, int]:
    """A ``builtin_interfaces/msg/Time`` of ``ns`` nanoseconds (>= 0)."""
    return {"sec": int(ns) // 1_000_000_000, "nanosec": int(ns) % 1_000_000_000}


class _Cdr:
    """A little-endian CDR buffer (alignment counted from after the 4-byte encapsulation header)."""

    def __init__(self) -> None:
        self.data = bytearray(b"\x00\x01\x00\x00")  # CDR_LE

    def align(self, n: int) -> None:
        self.data.extend(b"\x00" * (-(len(self.data) - 4) % n))

    def uint32(self, value: int) -> int:
        """Write ``value``; returns its offset."""
        self.align(4)
        self.data.extend(struct.pack("<I", value))
        return len(self.data) - 4

    def string(self, text: str) -> None:
        raw = text.encode("utf-8") + b"\x00"
        self.uint32(len(raw))
        self.data.extend(raw)

    def float64s(self, n: int) -> int:
        """Room for n float64 (zeros); returns the offset of the first."""
        if n:
            self.align(8)
        self.data.extend(b"\x00" * (8 * n))
        return len(self.data) - 8 * n

    def rows(self, count: int) -> np.ndarray:
        """``count`` copies of the buffer, (count, size) uint8, to write each message's values into."""
        return np.tile(np.frombuffer(bytes(self.data), np.uint8), (count, 1))


def _put(rows: np.ndarray, at: int, values: np.ndarray, dtype: str) -> None:
    """Write ``values`` (count, k) as ``dtype`` into every row of ``rows`` from byte ``at``."""
    raw = np.ascontiguousarray(values, dtype).reshape(len(rows), -1).view(np.uint8)
    rows[:, at:at + raw.shape[1]] = raw


def _put_stamps(rows: np.ndarray, at: int, stamps: np.ndarray) -> None:
    """builtin_interfaces/Time (int32 sec, uint32 nanosec) of ``stamps`` (count,) ns at byte ``at``."""
    _put(rows, at, stamps // 1_000_000_000, "<i4")
    _put(rows, at + 4, stamps % 1_000_000_000, "<u4")


def _checked_stamps(stamps_ns: npt.ArrayLike) -> np.ndarray:
    stamps = np.asarray(stamps_ns, np.int64).reshape(-1)
    invariant(bool((stamps >= 0).all()) and bool((stamps // 1_000_000_000 < 2**31).all()),
              "time stamps must lie in [0, 2^31) s")
    return stamps


def joint_state_cdr(stamps_ns: npt.ArrayLike, names: Sequence[str], position: npt.ArrayLike,
                    velocity: npt.ArrayLike | None = None, frame_id: str = "") -> list[bytes]:
    """CDR-encoded ``sensor_msgs/msg/JointState`` messages: one per row of ``position`` (T, n) rad (and
    ``velocity`` (T, n) rad/s; None: empty), stamped ``stamps_ns`` (T,) ns, ``names`` (n,), no efforts. Every
    message has the same layout (the names do not change), so one is laid out and the rows are written into copies
    of it."""
    stamps = _checked_stamps(stamps_ns)
    q = np.asarray(position, float)
    invariant(q.ndim == 2 and q.shape == (len(stamps), len(names)), f"position {q.shape} for {len(stamps)} stamps "
              f"and {len(names)} names")
    qd = None if velocity is None else np.asarray(velocity, float)
    invariant(qd is None or qd.shape == q.shape, "velocity and position differ in shape")
    n = q.shape[1]
    cdr = _Cdr()
    at_stamp = cdr.uint32(0)  # header.stamp.sec, then .nanosec
    cdr.uint32(0)
    cdr.string(frame_id)
    cdr.uint32(n)
    for name in names:
        cdr.string(name)
    cdr.uint32(n)
    at_q = cdr.float64s(n)
    cdr.uint32(0 if qd is None else n)
    at_qd = cdr.float64s(0 if qd is None else n)
    cdr.uint32(0)  # effort: empty
    rows = cdr.rows(len(stamps))
    _put_stamps(rows, at_stamp, stamps)
    _put(rows, at_q, q, "<f8")
    if qd is not None:
        _put(rows, at_qd, qd, "<f8")
    return [row.tobytes() for row in rows]


def tf_message_cdr(stamps_ns: npt.ArrayLike, parent: str | Sequence[str], children: Sequence[str],
                   translation: npt.ArrayLike, rotation: npt.ArrayLike) -> list[bytes]:
    """CDR-encoded ``tf2_msgs/msg/TFMessage`` messages: one per stamp of ``stamps_ns`` (T,) ns, each with a
    transform ``parent`` (one frame for all, or one per child) -> ``children[j]`` stamped alike: ``translation``
    (T, m, 3) m and ``rotation`` (T, m, 4) quaternions (x, y, z, w). Laid out once and filled in, as
    :func:`joint_state_cdr`."""
    stamps = _checked_stamps(stamps_ns)
    m = len(children)
    parents = [parent] * m if isinstance(parent, str) else list(parent)
    invariant(len(parents) == m, f"{len(parents)} parents for {m} children")
    p = np.asarray(translation, float).reshape(len(stamps), m, 3)
    r = np.asarray(rotation, float).reshape(len(stamps), m, 4)
    cdr = _Cdr()
    cdr.uint32(m)
    at = []
    for frame, child in zip(parents, children):
        at_stamp = cdr.uint32(0)
        cdr.uint32(0)
        cdr.string(frame)
        cdr.string(child)
        at.append((at_stamp, cdr.float64s(3), cdr.float64s(4)))
    rows = cdr.rows(len(stamps))
    for j, (at_stamp, at_p, at_r) in enumerate(at):
        _put_stamps(rows, at_stamp, stamps)
        _put(rows, at_p, p[:, j], "<f8")
        _put(rows, at_r, r[:, j], "<f8")
    return [row.tobytes() for row in rows]
