"""The ``"xacro"`` style of :mod:`snakehead.samples.published`: the ReU-style snake as a xacro module macro (kept apart
so that each module stays short; :func:`snakehead.samples.published.reu_xacro` and ``write_robot("xacro", ...)`` use it).
"""
from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

from .published import REU_THIRDS, XACRO_DEFAULT_MODULES, StyleSpec, parts_comment, reu_robot_file
from .urdf_text import num

# --- "xacro": the ReU snake as a xacro macro ---------------------------------------------------------------------


def reu_xacro(spec: StyleSpec) -> str:
    """The ReU-style snake as a xacro file: a ``module`` macro unrolled by a recursive ``modules`` macro over
    ``$(arg n_modules)`` modules. Expanded with ``n_modules = spec.n_joints`` it is :func:`~snakehead.samples.published.reu_urdf` of ``spec``
    (same links, joints, numbers). ``spec.n_joints`` only sets the servo effort; the arg sets the length."""
    return _xacro_properties(spec) + _XACRO_LINK_MACROS + _xacro_module_macros() + _XACRO_CHAIN


def _xacro_properties(spec: StyleSpec) -> str:
    """The xacro file's head: its comment, the ``n_modules`` arg and the properties of ``spec``."""
    L = spec.module_length
    effort = spec.servo_effort(L / 2 + spec.n_joints * L)
    return f'''<?xml version="1.0"?>
<!-- {spec.name}: the ReU-style sample snake as a xacro macro, written by snakehead.samples.published;
     {parts_comment(spec)}. Expand with the PyPI xacro package (no ROS needed: no $(find ...) here). -->
<robot name={quoteattr(spec.name)} xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="n_modules" default="{XACRO_DEFAULT_MODULES}"/>
  <xacro:property name="n_modules" value="$(arg n_modules)"/>
  <xacro:property name="module_length" value="{num(L)}"/>
  <xacro:property name="radius" value="{num(spec.radius)}"/>
  <xacro:property name="module_mass" value="{num(spec.mass_per_module)}"/>
  <xacro:property name="head_joints" value="{spec.head_joints}"/>
  <xacro:property name="neck_joints" value="{spec.neck_joints}"/>
  <xacro:property name="base_joints" value="${{n_modules - neck_joints - head_joints}}"/>
  <xacro:property name="limit" value="${{radians({num(spec.joint_limit_deg)})}}"/>
  <xacro:property name="effort" value="{num(effort)}"/>
  <xacro:property name="velocity" value="{num(spec.velocity)}"/>

'''


#: The xacro file's macros of one cylinder link and of a fixed joint (no number of the spec in them).
_XACRO_LINK_MACROS = '''  <!-- A solid cylinder along x from 0 to length, of the module's section and mass per length. -->
  <xacro:macro name="cylinder_link" params="name length">
    <xacro:property name="mass" value="${module_mass * length / module_length}"/>
    <link name="${name}">
      <inertial>
        <origin xyz="${length / 2} 0 0" rpy="0 0 0"/>
        <mass value="${mass}"/>
        <inertia ixx="${mass * radius * radius / 2}" ixy="0" ixz="0"
                 iyy="${mass * (3 * radius * radius + length * length) / 12}" iyz="0"
                 izz="${mass * (3 * radius * radius + length * length) / 12}"/>
      </inertial>
      <visual>
        <origin xyz="${length / 2} 0 0" rpy="0 ${pi/2} 0"/>
        <geometry><cylinder radius="${radius}" length="${length}"/></geometry>
      </visual>
      <collision>
        <origin xyz="${length / 2} 0 0" rpy="0 ${pi/2} 0"/>
        <geometry><cylinder radius="${radius}" length="${length}"/></geometry>
      </collision>
    </link>
  </xacro:macro>

  <xacro:macro name="fixed" params="name parent child x">
    <joint name="${name}" type="fixed">
      <parent link="${parent}"/>
      <child link="${child}"/>
      <origin xyz="${x} 0 0" rpy="0 0 0"/>
    </joint>
  </xacro:macro>

'''


def _xacro_module_macros() -> str:
    """The xacro macros of a module (its joint and its three links, REU_THIRDS), of a marker frame and of the
    recursion over the modules."""
    (inp, in_share), (body, body_share), (out, out_share) = REU_THIRDS
    return f'''  <!-- Module i hangs from parent by its joint, x m along parent's x; odd joints yaw (z), even joints pitch (y). -->
  <xacro:macro name="module" params="i parent x">
    <joint name="reu_joint_${{i}}" type="revolute">
      <parent link="${{parent}}"/>
      <child link="reu_module_{inp}_${{i}}"/>
      <origin xyz="${{x}} 0 0" rpy="0 0 0"/>
      <axis xyz="${{'0 0 1' if i % 2 == 1 else '0 1 0'}}"/>
      <limit lower="${{-limit}}" upper="${{limit}}" effort="${{effort}}" velocity="${{velocity}}"/>
    </joint>
    <xacro:cylinder_link name="reu_module_{inp}_${{i}}" length="${{{in_share} * module_length}}"/>
    <xacro:fixed name="reu_module_{inp}_${{i}}_to_{body}" parent="reu_module_{inp}_${{i}}"
                 child="reu_module_{body}_${{i}}" x="${{{in_share} * module_length}}"/>
    <xacro:cylinder_link name="reu_module_{body}_${{i}}" length="${{{body_share} * module_length}}"/>
    <xacro:fixed name="reu_module_{body}_${{i}}_to_{out}" parent="reu_module_{body}_${{i}}"
                 child="reu_module_{out}_${{i}}" x="${{{body_share} * module_length}}"/>
    <xacro:cylinder_link name="reu_module_{out}_${{i}}" length="${{{out_share} * module_length}}"/>
  </xacro:macro>

  <!-- A marker frame (no body) at the distal end of module i: the next joint hangs from it. -->
  <xacro:macro name="marker" params="name i">
    <xacro:fixed name="${{name}}_joint" parent="reu_module_{out}_${{i}}" child="${{name}}"
                 x="${{{out_share} * module_length}}"/>
    <link name="${{name}}"/>
  </xacro:macro>

  <!-- Modules i .. n_modules, module i hanging from parent at x: recursion unrolls the chain. -->
  <xacro:macro name="modules" params="i parent x">
    <xacro:module i="${{i}}" parent="${{parent}}" x="${{x}}"/>
    <xacro:if value="${{i == base_joints}}">
      <xacro:marker name="base_end" i="${{i}}"/>
    </xacro:if>
    <xacro:if value="${{i == base_joints + neck_joints}}">
      <xacro:marker name="neck_end" i="${{i}}"/>
    </xacro:if>
    <xacro:if value="${{i == n_modules}}">
      <xacro:marker name="head_tip" i="${{i}}"/>
    </xacro:if>
    <xacro:if value="${{i &lt; n_modules}}">
      <xacro:if value="${{i == base_joints}}">
        <xacro:modules i="${{i + 1}}" parent="base_end" x="0"/>
      </xacro:if>
      <xacro:if value="${{i == base_joints + neck_joints}}">
        <xacro:modules i="${{i + 1}}" parent="neck_end" x="0"/>
      </xacro:if>
      <xacro:unless value="${{i == base_joints or i == base_joints + neck_joints}}">
        <xacro:modules i="${{i + 1}}" parent="reu_module_{out}_${{i}}" x="${{{out_share} * module_length}}"/>
      </xacro:unless>
    </xacro:if>
  </xacro:macro>

'''


#: The xacro file's chain: the tail, then the modules from the first.
_XACRO_CHAIN = '''  <xacro:cylinder_link name="reu_tail" length="${module_length / 2}"/>
  <xacro:modules i="1" parent="reu_tail" x="${module_length / 2}"/>
</robot>
'''


def write_xacro(spec: StyleSpec, folder: Path) -> Path:
    path = folder / "reu_snake.urdf.xacro"
    path.write_text(reu_xacro(spec), encoding="utf-8")
    return reu_robot_file(folder, "reu_snake_xacro", path.name, {"n_modules": spec.n_joints})
