"""Describe a snake robot by its numbers and get its URDF: a chain of box-shaped modules joined by revolute
joints whose axes alternate between yaw and pitch (the paper's Fig. 1 configuration).

:class:`SnakeSpec` holds the numbers (joint count, module length, section, mass, first axis, sizes of the tail
and head links, names); :func:`snake_urdf` writes the URDF. The shipped robot (``urdf/generate_snake16.py``) and
the tests' robots are written with it; a robot file (:mod:`snakehead.model.robot_file`) then names the frames
that bound its parts.

Conventions of the URDF written: link ``i``'s frame sits at its proximal joint (the tail link's at the tail end)
with x along the body towards the head; joint ``i`` joins link ``i-1`` to link ``i`` at the distal end of link
``i-1``; each link's centre of mass is at its middle with a solid box's inertia; each link's collision (and
visual) box has the module's section. Marker frames (fixed joints) may be put inline at the distal end of any
link (the next joint then hangs from the marker), so that chains can start at them; one more marker sits at the
end of the head link.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any
from xml.sax.saxutils import quoteattr

from .._errors import InputError, InputTypeError
from .._validate import finite_float
from .physics import GRAVITY

__all__ = ["holding_effort", "SnakeSpec", "snake_urdf"]


def holding_effort(mass_per_metre: float, body_length: float) -> float:
    """A servo effort (N m) that can hold half of a uniform body (``mass_per_metre`` kg/m, ``body_length`` m)
    straight out as a cantilever, with 50 % to spare, and at least 10 N m: lifting a neck and head needs about
    that at the neck's first joint. Every generated snake (here and in :mod:`snakehead.samples.published`) uses it."""
    weight_per_metre = mass_per_metre * GRAVITY
    half = body_length / 2
    return max(10.0, round(1.5 * weight_per_metre * half * half / 2, 1))


@dataclass(frozen=True)
class SnakeSpec:
    """The numbers of a snake robot (SI units; angles in degrees where the name says ``_deg``).

    n_joints: revolute joints (links = n_joints + 1). module_length: length of every link but the tail and the
    head link (m). tail_length / head_length: the first (tail) and last (head) link (m; default half a module).
    section: the modules' square cross-section (m). mass_per_module: kg per ``module_length`` of body (every
    link's mass is proportional to its length). first_axis: "yaw" (local z) or "pitch" (local y) for joint 1;
    the axes then alternate. joint_limit_deg: symmetric limit of every joint. effort (N m) and velocity (rad/s):
    the servo limits written into the URDF (effort default: :meth:`default_effort`). markers: {frame name: k}
    puts a fixed marker frame at the distal end of link k. tip_name: the marker at the end of the head link.
    link_prefix / joint_prefix: names ``{link_prefix}{i}`` and ``{joint_prefix}{i}``. name: the robot's name.
    comment: text for the file's header comment.
    """

    n_joints: int = 16
    module_length: float = 0.0865
    tail_length: float | None = None
    head_length: float | None = None
    section: float = 0.043
    mass_per_module: float = 0.2
    first_axis: str = "yaw"
    joint_limit_deg: float = 90.0
    effort: float | None = None
    velocity: float = 3.0
    markers: dict = field(default_factory=dict)
    tip_name: str = "head_tip"
    link_prefix: str = "link_"
    joint_prefix: str = "joint_"
    name: str = "snake"
    comment: str = ""

    def __post_init__(self) -> None:
        if isinstance(self.n_joints, bool) or not isinstance(self.n_joints, int) or self.n_joints < 1:
            raise InputError(f"n_joints must be a positive integer, got {self.n_joints!r}")
        for key in ("module_length", "section", "mass_per_module", "joint_limit_deg", "velocity"):
            if not finite_float(getattr(self, key), key) > 0:
                raise InputError(f"{key} must be positive, got {getattr(self, key)!r}")
        for key in ("tail_length", "head_length", "effort"):
            v = getattr(self, key)
            if v is not None and not finite_float(v, key) > 0:
                raise InputError(f"{key} must be positive, got {v!r}")
        if self.joint_limit_deg > 180:
            raise InputError(f"joint_limit_deg must be at most 180, got {self.joint_limit_deg}")
        if self.first_axis not in ("yaw", "pitch"):
            raise InputError(f"first_axis must be 'yaw' or 'pitch', got {self.first_axis!r}")
        names = [self.tip_name]
        for marker, k in dict(self.markers).items():
            if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k < self.n_joints:
                raise InputError(f"marker {marker!r} must sit at the end of a link 0..{self.n_joints - 1}, got {k!r}")
            names.append(marker)
        links = {f"{self.link_prefix}{i}" for i in range(self.n_joints + 1)}
        for n in names:
            if not isinstance(n, str) or not n or n in links:
                raise InputError(f"marker name {n!r} must be a non-empty name that no link has")
        if len(set(names)) != len(names):
            raise InputError("marker names must differ")

    def link_length(self, i: int) -> float:
        """Length of link i (m): the tail link 0, the modules, the head link n_joints."""
        if i == 0:
            return self.tail_length if self.tail_length is not None else self.module_length / 2
        if i == self.n_joints:
            return self.head_length if self.head_length is not None else self.module_length / 2
        return self.module_length

    @property
    def length(self) -> float:
        """Total body length (m)."""
        return sum(self.link_length(i) for i in range(self.n_joints + 1))

    @property
    def total_mass(self) -> float:
        return self.mass_per_module * self.length / self.module_length

    def default_effort(self) -> float:
        """The servo effort (N m) of :func:`holding_effort` for this snake's body."""
        return holding_effort(self.mass_per_module / self.module_length, self.length)

    def axis(self, joint: int) -> str:
        """"yaw" or "pitch" for joint ``joint`` (1-based)."""
        odd = joint % 2 == 1
        return self.first_axis if odd else ("pitch" if self.first_axis == "yaw" else "yaw")


def _num(x: float) -> str:
    return f"{x:.6g}"


def _link_xml(spec: SnakeSpec, i: int) -> str:
    length = spec.link_length(i)
    m = spec.mass_per_module * length / spec.module_length
    a = spec.section
    ixx = m / 12.0 * (a * a + a * a)
    iyy = m / 12.0 * (length * length + a * a)
    box = f'<box size="{_num(length)} {_num(a)} {_num(a)}"/>'
    origin = f'<origin xyz="{_num(length / 2)} 0 0" rpy="0 0 0"/>'
    return f"""  <link name={quoteattr(spec.link_prefix + str(i))}>
    <inertial>
      {origin}
      <mass value="{m:.12g}"/>
      <inertia ixx="{ixx:.12g}" ixy="0" ixz="0" iyy="{iyy:.12g}" iyz="0" izz="{iyy:.12g}"/>
    </inertial>
    <visual>
      {origin}
      <geometry>{box}</geometry>
    </visual>
    <collision>
      {origin}
      <geometry>{box}</geometry>
    </collision>
  </link>
"""


def _marker_xml(name: str, parent: str, x: float) -> str:
    return f"""  <link name={quoteattr(name)}/>
  <joint name={quoteattr(name + "_joint")} type="fixed">
    <parent link={quoteattr(parent)}/>
    <child link={quoteattr(name)}/>
    <origin xyz="{_num(x)} 0 0" rpy="0 0 0"/>
  </joint>
"""


def snake_urdf(spec: SnakeSpec | None = None, **kwargs: Any) -> str:
    """The URDF (XML text) of the snake ``spec`` (or ``SnakeSpec(**kwargs)``)."""
    if spec is None:
        spec = SnakeSpec(**kwargs)
    elif kwargs:
        raise InputTypeError("give a SnakeSpec or keyword arguments, not both")
    if not isinstance(spec, SnakeSpec):
        raise InputTypeError(f"spec must be a SnakeSpec, got {type(spec).__name__}")
    effort = spec.effort if spec.effort is not None else spec.default_effort()
    limit = math.radians(spec.joint_limit_deg)
    n = spec.n_joints
    header = spec.comment or (
        f"{spec.name}: a snake robot written by snakehead.model.generate.snake_urdf. {n + 1} links, {n} revolute "
        f"joints "
        f"alternating yaw (local z) and pitch (local y), joint 1 {spec.first_axis}; +-{spec.joint_limit_deg:g} deg; "
        f"modules {spec.module_length:g} m long, {spec.section:g} m square, {spec.mass_per_module:g} kg each; "
        f"{spec.length:.6g} m, {spec.total_mass:.6g} kg in all.")
    parts = ['<?xml version="1.0"?>\n', f"<!-- {header.replace('--', '- -')} -->\n",
             f"<robot name={quoteattr(spec.name)}>\n"]
    for i in range(n + 1):
        parts.append(_link_xml(spec, i))
    for i in range(1, n + 1):
        prev = i - 1
        parent = f"{spec.link_prefix}{prev}"
        x = spec.link_length(prev)
        for marker, host in spec.markers.items():
            if host == prev:
                parts.append(_marker_xml(marker, parent, x))
                parent, x = marker, 0.0
        axis = "0 0 1" if spec.axis(i) == "yaw" else "0 1 0"
        parts.append(f"""  <joint name={quoteattr(spec.joint_prefix + str(i))} type="revolute">
    <parent link={quoteattr(parent)}/>
    <child link={quoteattr(spec.link_prefix + str(i))}/>
    <origin xyz="{_num(x)} 0 0" rpy="0 0 0"/>
    <axis xyz="{axis}"/>
    <limit lower="{-limit:.17g}" upper="{limit:.17g}" effort="{effort:g}" velocity="{spec.velocity:g}"/>
  </joint>
""")
    parts.append(_marker_xml(spec.tip_name, f"{spec.link_prefix}{n}", spec.link_length(n)))
    parts.append("</robot>\n")
    return "".join(parts)
