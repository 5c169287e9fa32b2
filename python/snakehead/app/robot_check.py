"""The robot check behind ``snakehead info``: what the parts are, whether the design can work, and when it cannot,
a split of the parts that does (computed, by trying it).

* :func:`describe_parts` -- each part's frames (where they sit along the body, on which joint), length, mass and
  joints.
* :func:`design_problems` -- the checks the planner's first steps make: an up curve that lifts the neck and head
  over the base (Section 3.3 (1)), a curl of the neck and head on the ground that the base holds, the head's map.
* :func:`suggest_split` -- other ``base_end`` / ``neck_end`` frames tried in turn; the first that passes.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._errors import Infeasible, InputError
from ..backbone.initial import initial_configuration
from ..kinematics import reachability
from ..model.body_frame import AXIS_TOLERANCE_DEG, NotStraight, straightness, suggest_home
from ..model.mass_properties import inertia_source, mass_findings
from ..model.robot import ALIGNED_SUFFIX, SnakeRobot
from ..model.robot_file import toml_string
from ..planning.start_state import ground_curl

__all__ = ["SPLIT_SEARCH", "PartReport", "RobotCheck", "frame_position", "describe_parts", "design_problems",
           "suggest_split", "map_summary", "check_robot", "description_lines", "home_suggestion", "check_lines"]

#: How far (joints) a suggested split moves base_end and neck_end from the robot file's.
SPLIT_SEARCH = (1, -1, 2, -2, 3, -3)


@dataclass(frozen=True)
class PartReport:
    """One part: its name, first and last frame (the URDF's names), where they sit (m along the body), its
    joints (names and kinds), length (m) and mass (kg)."""

    name: str
    start_frame: str
    end_frame: str
    start_m: float
    end_m: float
    joints: list[str]
    kinds: list[str]
    mass_kg: float

    @property
    def length_m(self) -> float:
        return self.end_m - self.start_m


@dataclass
class RobotCheck:
    """The check of one robot: its parts, its shapes, what cannot work and what would."""

    parts: list[PartReport]
    shapes: dict[str, int]
    problems: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    suggestion: str | None = None
    map_line: str = ""


def _user_name(name: str) -> str:
    return name[:-len(ALIGNED_SUFFIX)] if name.endswith(ALIGNED_SUFFIX) else name


def frame_position(robot: SnakeRobot, name: str) -> str:
    """Where a frame sits along the body, in words: on which joint, or how far after one."""
    s = robot.frame_arc_length(name)
    arcs = robot.joint_arc_lengths
    on = np.flatnonzero(np.abs(arcs - s) < 1e-6)
    if len(on):
        return f"{s:.4f} m, on {robot.joint_names[int(on[0])]}"
    before = np.flatnonzero(arcs < s)
    if len(before) == 0:
        return f"{s:.4f} m, before the first joint"
    j = int(before[-1])
    return f"{s:.4f} m, {s - arcs[j]:.4f} m after {robot.joint_names[j]}"


def describe_parts(robot: SnakeRobot) -> list[PartReport]:
    """The base, neck and head: frames, positions, joints, length and mass."""
    p = robot.parts
    out = []
    for name, sl, a, b, links in (("base", p.base, p.root, p.base_end, robot.base_links),
                                  ("neck", p.neck, p.base_end, p.neck_end, robot.neck_links),
                                  ("head", p.head, p.neck_end, p.head_tip, robot.head_links)):
        out.append(PartReport(name, _user_name(a), _user_name(b), robot.frame_arc_length(a), robot.frame_arc_length(b),
                              robot.joint_names[sl], list(robot.joint_kinds[sl]),
                              float(robot.masses[links].sum())))
    return out


def design_problems(robot: SnakeRobot) -> list[str]:
    """What keeps the planner from starting on this robot (empty when nothing does)."""
    problems = []
    try:
        q = initial_configuration(robot)
    except Infeasible as exc:
        problems.append(f"no initial state: {exc}")
        q = None
    if q is not None:
        try:
            ground_curl(robot, q)
        except Infeasible as exc:
            problems.append(f"no bending state: {exc}")
    return problems


def _boundary_frame(robot: SnakeRobot, joints_before: int) -> str | None:
    """The URDF frame that ends a part after ``joints_before`` joints: the frame just before the next joint's
    link (a marker at the distal end of the last link, or that link itself)."""
    if not 0 < joints_before < robot.n_joints:
        return None
    child = int(robot.joint_frames[joints_before])
    return _user_name(robot.link_names[child - 1])


def suggest_split(robot: SnakeRobot) -> tuple[str, SnakeRobot] | None:
    """The first of :data:`SPLIT_SEARCH`'s moves of base_end (neck_end moved alike, then kept) whose robot passes
    :func:`design_problems`: a robot-file change in words and the robot; None when none does."""
    p = robot.parts
    tried = set()
    for shift in SPLIT_SEARCH:
        for move_neck in (True, False):
            base_end = _boundary_frame(robot, p.base.stop + shift)
            neck_end = _boundary_frame(robot, p.neck.stop + shift) if move_neck else robot.user_frames["neck_end"]
            if base_end is None or neck_end is None or (base_end, neck_end) in tried:
                continue
            tried.add((base_end, neck_end))
            try:
                candidate = robot.with_parts(base_end=base_end, neck_end=neck_end)
            except InputError:
                continue
            if not design_problems(candidate):
                change = f'base_end = "{base_end}"'
                if neck_end != robot.user_frames["neck_end"]:
                    change += f', neck_end = "{neck_end}"'
                c = candidate.parts
                return (f"{change} (base {c.base.stop - c.base.start} joints, neck {c.neck.stop - c.neck.start}, "
                        f"head {c.head.stop - c.head.start})", candidate)
    return None


def map_summary(robot: SnakeRobot) -> tuple[str, str | None]:
    """A line about the head's map (the robot file's, if any) and a problem with it (None when there is none)."""
    if robot.map_path is None:
        return "none (plan computes one and caches it)", None
    m = reachability.load(robot.map_path)
    try:  # the planner's check: a whole map of this head with voxels enough for G0
        m.require_whole_for(robot, needs=("G0",), what="the map")
    except InputError as exc:
        return f"{robot.map_path}", str(exc)
    roll = "free roll" if m.params.get("free_roll") else f"{m.params.get('rolls')} rolls"
    line = f"{robot.map_path}: {len(m)} voxels, {m.params.get('directions')} directions x {roll}, " \
           f"best index {m.indices.max():.1f}"
    return line + f", dexterous workspace index >= {m.dexterous_threshold():.1f}", m.quality_problem()


def check_robot(robot: SnakeRobot, suggest: bool = True) -> RobotCheck:
    """The whole check (see the module)."""
    shapes: dict[str, int] = {}
    for s in robot.geometry.shapes:
        shapes[s.kind] = shapes.get(s.kind, 0) + 1
    check = RobotCheck(describe_parts(robot), shapes, design_problems(robot))
    if robot.lift_length <= 0:
        check.notes.append("the neck has no pitch joint: the segmented method (Eqs. 18-22) cannot lift the head's "
                           "base, so every target goes to the whole-body solve (name a base_end before a pitch joint "
                           "to give the neck one)")
    check.map_line, map_problem = map_summary(robot)
    if map_problem:
        check.problems.append(f"head map: {map_problem}")
    if suggest and any(not p.startswith("head map") for p in check.problems):
        found = suggest_split(robot)
        check.suggestion = None if found is None else found[0]
    return check


def description_lines(robot: SnakeRobot) -> list[str]:
    """What the description needed to be read as a snake (:mod:`snakehead.model.description_tree`): the largest
    joint-axis deviation, the side offsets at the straight pose, the joints turned around, the home pose, the side
    branches and the joints held."""
    j = int(np.argmax(robot.axis_deviations))
    st = robot.straightness
    lines = [f"description: joint axes within {np.degrees(robot.axis_deviations[j]):.3f} deg of the body's y or z "
             f"(largest: {robot.joint_names[j]}; at most {AXIS_TOLERANCE_DEG:g} deg); frames within "
             f"{1000 * st.offset:.2f} mm of the body's line (largest: {st.frame}; at most the half-section, "
             f"{1000 * robot.half_section:.1f} mm)"]
    changes = robot.tree_changes
    if changes.reversed_joints:
        lines.append(f"  the body runs against the URDF's tree: {len(changes.reversed_joints)} joints turned around "
                     f"({', '.join(changes.reversed_joints[:4])}{' ...' if len(changes.reversed_joints) > 4 else ''});"
                     " angles keep the description's signs")
    if changes.home:
        lines.append("  home (the body lies straight; planner angles = description's - home): "
                     + ", ".join(f"{name} = {value:.4f}" for name, value in changes.home))
    if changes.branch_links:
        mass = sum(b.mass for b in changes.branch_links)
        lines.append(f"  side branches: {len(changes.branch_links)} links ({mass:.3f} kg, "
                     f"{sum(b.shapes for b in changes.branch_links)} collision shapes) added to the body links they "
                     "hang from: " + ", ".join(f"{b.name} -> {b.onto}" for b in changes.branch_links[:6])
                     + (" ..." if len(changes.branch_links) > 6 else ""))
    if changes.held_joints:
        held = changes.held_joints
        zero_axis = [joint for joint, _, note in held if note == "axis 0 0 0"]
        lines.append(f"  held: {len(held)} moving joints off the body, at their [home] value or 0: "
                     + ", ".join(f"{joint} = {value:g}" for joint, value, _ in held[:4]) + (" ..." if len(held) > 4 else "")
                     + (f"; with axis 0 0 0: {', '.join(zero_axis)}" if zero_axis else ""))
    return lines


def home_suggestion(exc: NotStraight) -> list[str]:
    """The ``[home]`` table at which the body of a robot refused as not straight lies straight (least squares:
    :func:`snakehead.model.body_frame.suggest_home`), as robot-file lines; [] when none straightens it."""
    chain = exc.chain
    q = suggest_home(chain)
    _, d, st = straightness(chain, q)
    F = chain.fk_all(q)
    child = np.asarray(chain.model.joint_child_links)
    axes = np.einsum("jik,jk->ji", F[child, :3, :3], np.asarray(chain.model.joint_axes, float))
    across = np.abs(axes @ d) / np.linalg.norm(axes, axis=1)
    if st.out_of_order or st.offset > exc.max_offset or across.max() > np.sin(np.radians(AXIS_TOLERANCE_DEG)):
        return []
    home = q + exc.home
    rows = [f"{toml_string(name)} = {value:.6f}" for name, value in zip(chain.joint_names, home)
            if abs(value) > 1e-5]
    return [f"SUGGESTION: the body lies straight (frames within {1000 * st.offset:.2f} mm of one line) at these joint "
            "angles; add them to the robot file:", "[home]", *rows]


def check_lines(robot: SnakeRobot, check: RobotCheck) -> list[str]:
    """The check as the lines ``snakehead info`` prints."""
    lines = [f"robot: {robot.source}",
             f"joints: {robot.n_joints} ({', '.join(k[0] for k in robot.joint_kinds)}: y = yaw, p = pitch), "
             f"mass {robot.total_mass:.3f} kg, length {robot.body_length:.4f} m, body axis "
             f"{1000 * robot.body_axis_height:.1f} mm above the ground",
             "collision shapes: " + ", ".join(f"{n} {k}" for k, n in sorted(check.shapes.items()))]
    lines += description_lines(robot)
    for part in check.parts:
        lines.append(f"{part.name}: {part.start_frame} ({frame_position(robot, _frame(robot, part.start_frame))}) -> "
                     f"{part.end_frame} ({frame_position(robot, _frame(robot, part.end_frame))}); "
                     f"{part.length_m:.4f} m, {part.mass_kg:.3f} kg, {len(part.joints)} joints "
                     f"({' '.join(f'{j}:{k[0]}' for j, k in zip(part.joints, part.kinds))})")
    lines.append(f"head's map: {check.map_line}")
    lines.append(f"inertia: {inertia_source(robot)}")
    findings = mass_findings(robot)  # the masses and inertias the core, the stability checks and MuJoCo use
    lines.append("masses and inertias: " + (f"{len(findings)} implausible" if findings else "plausible"))
    lines += [f"  MASS: {finding}" for finding in findings]
    if not check.problems:
        lines.append("design: the base holds the lifted neck and head (an initial state and a bending state exist)")
    for note in check.notes:
        lines.append(f"note: {note}")
    for problem in check.problems:
        lines.append(f"PROBLEM: {problem}")
    if check.suggestion:
        lines.append(f"SUGGESTION: in the robot file, {check.suggestion} passes these checks")
    elif any(not p.startswith("head map") for p in check.problems):
        lines.append("no split within 3 joints of this one passes: the base is too short or light for the neck and "
                     "head (lengthen the base, or lighten the head)")
    return lines


def _frame(robot: SnakeRobot, user_name: str) -> str:
    aligned = user_name + ALIGNED_SUFFIX
    return aligned if aligned in robot.link_names else user_name
