"""What ``snakehead demo`` and ``snakehead plan`` write: ``report.json``, ``summary.md`` and trajectory CSVs.

The JSON report holds, per scenario under ``scenarios.<name>`` (see :func:`scenario_entry`):

* ``success`` (bool), ``targets`` (list of ``name``, ``position_error_m``, ``direction_error_deg``: the planned
  head against the desired pose), ``min_zmp_margin_m``, ``min_ground_clearance_m``, ``planning_time_s``;
* ``sim``: null when the dynamics check did not run, else ``position_error_m``, ``direction_error_deg``,
  ``max_linear_momentum_error`` (kg m/s), ``max_angular_momentum_error`` (kg m^2/s), ``zmp_inside`` and the
  other numbers of :func:`snakehead.sim.compare`;
* ``paper``: the paper's reported figures for the scenario, when it has them;
* from lying straight (``--start``, :func:`snakehead.app.pipeline.run_loop_scene`): ``phases`` (list of ``name``,
  ``kind`` one of gait/curl/lift/move/hold, ``t0_s``, ``t1_s``), ``sim.base_travel_m`` (the tail's path length over
  the ground), ``estimate`` (the pose estimate's error after every ground phase and at the fix), ``start``,
  ``total_time_s``, ``corrections``.

Units are SI (m, s, kg) unless a key names them (``_deg``, ``_mm``). Non-finite floats are written as null, so
the file is strict JSON.
"""
from __future__ import annotations

import csv
import json
import math
import os
import platform
import re
import unicodedata
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from .._errors import InputError
from .._files import atomic_open, write_text_atomic
from ..model.robot import default_robot_file

__all__ = ["PAPER", "SIM_KEYS", "CSV_BLOCK_ROWS", "is_default_robot", "jsonable", "scenario_entry", "environment",
           "cpu_name", "write_json", "write_trajectory_csv", "markdown_text", "markdown_code", "summary_markdown",
           "write_summary"]


def is_default_robot(robot: Any) -> bool:
    """Whether ``robot`` was read from the shipped robot file (the paper's numbers are that robot's)."""
    source = getattr(robot, "source", None)
    return source is not None and Path(source).resolve() == default_robot_file().resolve()


#: The paper's reported results (Section 4), beside which ours are put. The momentum errors are of the
#: magnitudes ("the maximum errors of the angular and linear momentum magnitudes").
PAPER: dict[str, dict[str, Any]] = {
    "spheres": {"section": "4.1 (Figs. 17-20)", "position_error_m": 1.8e-3, "direction_error_deg": 0.76,
                "max_angular_momentum_magnitude_error": 0.0383, "max_linear_momentum_magnitude_error": 0.216,
                "zmp_inside": True, "duration_s": 36.0, "figures": (17, (18, 19), 20)},
    "hole": {"section": "4.2 (Figs. 22-25)", "position_error_m": 1.39e-3, "direction_error_deg": 0.95,
             "max_angular_momentum_magnitude_error": 0.0416, "max_linear_momentum_magnitude_error": 0.195,
             "zmp_inside": True, "duration_s": 23.0, "figures": (22, (23, 24), 25)},
}

#: The keys of a scenario's ``sim`` entry that every report has (more may follow).
SIM_KEYS = ("position_error_m", "direction_error_deg", "max_linear_momentum_error", "max_angular_momentum_error",
            "zmp_inside")


def jsonable(x: Any) -> Any:
    """``x`` with numpy scalars and arrays turned into Python numbers and lists, non-finite floats into None,
    tuples into lists and dict keys into strings (recursively)."""
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        x = float(x)
        return x if math.isfinite(x) else None
    if x is None or isinstance(x, str):
        return x
    if isinstance(x, os.PathLike):
        return os.fspath(x)
    return str(x)


def scenario_entry(result: Any, sim_metrics: dict | None = None, *, extra: dict | None = None) -> dict:
    """The report entry of one planned scenario (``snakehead.scenarios.ScenarioResult``).

    ``sim_metrics``: the dict of :func:`snakehead.sim.compare` (None without a dynamics check). ``extra``: more
    keys to add (e.g. timings, file names).
    """
    if sim_metrics is not None:
        missing = [k for k in SIM_KEYS if k not in sim_metrics]
        if missing:
            raise InputError(f"sim_metrics lacks {missing}")
    entry = {
        "success": bool(result.success),
        "failure": result.failure,
        "targets": [{"name": tg.name, "position_error_m": float(tg.position_error_m),
                     "direction_error_deg": float(tg.direction_error_deg),
                     "position_m": tg.position.tolist(), "direction": tg.direction.tolist(),
                     "time_s": float(tg.time_s), "solved": bool(tg.solution.success),
                     "stage": getattr(tg.solution, "stage", None),
                     "message": tg.solution.message} for tg in result.targets],
        "min_zmp_margin_m": float(result.min_zmp_margin_m),
        "min_ground_clearance_m": float(result.min_ground_clearance_m),
        "planning_time_s": float(result.planning_time_s),
        "sim": None if sim_metrics is None else {**{k: sim_metrics[k] for k in SIM_KEYS}, **sim_metrics},
        "duration_s": float(result.t[-1] - result.t[0]),
        "samples": int(len(result.t)),
        "control_period_s": float(np.median(np.diff(result.t))) if len(result.t) > 1 else None,
        "base": {"x_m": result.base.x, "y_m": result.base.y, "yaw_rad": result.base.yaw},
        "dynamically_stable": bool(result.stability.stable),
        "touches_obstacle": bool(result.touches_obstacle),
        "min_obstacle_distance_m": result.min_obstacle_distance_m,
        "segments": [{"segment": s, "interpolation": m} for s, m in result.segments],
        "relocation": None if result.relocation is None else result.relocation.as_dict(),
        "notes": list(result.notes),
    }
    if result.name in PAPER and is_default_robot(result.robot):  # the paper's numbers are its robot's
        entry["paper"] = dict(PAPER[result.name])
    if extra:
        entry.update(extra)
    return jsonable(entry)


def environment() -> dict:
    """The machine and the versions of snakehead and its main dependencies."""
    versions: dict[str, str | None] = {"snakehead": __version__, "python": platform.python_version()}
    for dist in ("numpy", "scipy", "matplotlib", "mujoco", "scikit-learn", "pillow"):
        try:
            versions[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            versions[dist] = None
    return {"machine": {"cpu": cpu_name(), "cores": os.cpu_count(), "system": platform.platform()},
            "versions": versions}


def cpu_name() -> str:
    """The CPU's model name (Linux: /proc/cpuinfo), else what ``platform`` knows."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def write_json(report: dict, path: str | os.PathLike) -> Path:
    """Write ``report`` as indented strict JSON (see :func:`jsonable`); returns the path."""
    return write_text_atomic(path, json.dumps(jsonable(report), indent=2, allow_nan=False) + "\n")


def write_trajectory_csv(result: Any, path: str | os.PathLike, joint_names: list[str] | None = None) -> Path:
    """The planned trajectory as CSV: a header ``time_s,<joint 1>_rad,...`` then one row per 2 ms sample,
    time in s (to 1 us) and the joint angles in rad (to 1e-7 rad): T rows of 1 + n columns.

    The angles are the description's: for a result with a ``robot`` (a :class:`~snakehead.planning.plan_result.Plan`),
    ``robot.description_angles(result.q)`` (the planner's ``q`` plus the robot file's ``[home]``); without one,
    ``result.q`` as it is."""
    t, q = np.asarray(result.t, float), np.asarray(result.q, float)
    if q.ndim != 2 or q.shape[0] != t.shape[0]:
        raise InputError(f"t {t.shape} and q {q.shape} do not match")
    robot = getattr(result, "robot", None)
    if robot is not None:
        q = robot.description_angles(q)
    names = joint_names or [f"joint_{j + 1}" for j in range(q.shape[1])]
    if len(names) != q.shape[1]:
        raise InputError(f"{len(names)} joint names for {q.shape[1]} joints")
    path = Path(path)
    with atomic_open(path, "w", newline="") as f:  # a failed write leaves no CSV cut mid-row
        csv.writer(f).writerow(["time_s"] + [f"{n}_rad" for n in names])  # (rows end in "\r\n", as csv's)
        row = ",".join(["%.6f"] + ["%.7f"] * q.shape[1]) + "\r\n"  # numbers: nothing to quote
        for start in range(0, len(t), CSV_BLOCK_ROWS):  # formatted a block of rows at once, in C
            block = np.column_stack([t[start:start + CSV_BLOCK_ROWS], q[start:start + CSV_BLOCK_ROWS]]).tolist()
            f.write("".join([row % tuple(values) for values in block]))
    return path


#: Rows of the trajectory CSV formatted at once (a bounded copy of the trajectory).
CSV_BLOCK_ROWS = 4096


#: What Markdown (CommonMark and GitHub's tables, strikethrough and math) reads as markup within a line: escapes,
#: code, emphasis, links, raw HTML and entities, table cells, strikethrough, math, headings.
_MARKDOWN_SPECIAL = frozenset("\\`*_[]<>&|~$#")


def markdown_text(text: Any) -> str:
    r"""``text`` (a name, a message) as Markdown shows it literally, within a line or a table cell: each character
    that Markdown reads as markup (``_MARKDOWN_SPECIAL``) backslash-escaped (``<script>`` is text, a ``|`` does
    not split a cell, a ``\`` stays), a leading ``-``, ``+``, ``=`` or ``1.`` kept from starting a list (in a list
    item), line breaks and other control characters made spaces and lone surrogates U+FFFD (a name has none: they
    are refused where names enter; a message may). Surrounding whitespace is dropped, as a table cell drops it."""
    def one(c: str) -> str:
        category = unicodedata.category(c)
        if category in ("Cc", "Zl", "Zp"):
            return " "
        if category == "Cs":
            return "\ufffd"
        return "\\" + c if c in _MARKDOWN_SPECIAL else c

    out = "".join(map(one, str(text))).strip()
    numbered = re.match(r"\d{1,9}[.)]", out)
    if numbered:
        return out[:numbered.end() - 1] + "\\" + out[numbered.end() - 1:]
    return "\\" + out if out[:1] in ("-", "+", "=") else out


def markdown_code(text: Any) -> str:
    """``text`` (a file name) as a Markdown code span that shows it literally: fenced by one backtick more than its
    longest run of backticks, padded with a space where it begins or ends with one (CommonMark's rule); line breaks
    and other control characters made spaces (a code span cannot hold a line break)."""
    t = "".join(" " if unicodedata.category(c) in ("Cc", "Zl", "Zp") else "\ufffd" if unicodedata.category(c) == "Cs"
                else c for c in str(text))
    fence = "`" * (max((len(r) for r in re.findall("`+", t)), default=0) + 1)
    pad = " " if t[:1] == "`" or t[-1:] == "`" or (t[:1] == " " and t[-1:] == " " and t.strip()) else ""
    return f"{fence}{pad}{t}{pad}{fence}"


def _fmt(x: Any, scale: float = 1.0, digits: int = 2) -> str:
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    return f"{x * scale:.{digits}f}"


def summary_markdown(report: dict) -> str:
    """A readable summary of ``report`` (the dict written to report.json), as Markdown. Every text taken from the
    report -- scene and target names, phases, notes, stages, settings -- is shown literally (:func:`markdown_text`;
    file names as code, :func:`markdown_code`): a name is never read as markup, and a table row always has its
    columns."""
    lines = _header_lines(report)
    for name, sc in report.get("scenarios", {}).items():
        lines += _scenario_lines(name, sc)
    lines += _closing_lines(report)
    return "\n".join(lines)


def _header_lines(report: dict) -> list[str]:
    """The title, the machine and versions the run was on, and its settings."""
    md = markdown_text
    lines = [f"# snakehead {md(report.get('command', ''))}", ""]
    m, v = report.get("machine") or {}, report.get("versions") or {}
    if m:
        lines += [f"Run on {md(m.get('cpu'))} ({md(m.get('cores'))} cores), {md(m.get('system'))}; snakehead "
                  f"{md(v.get('snakehead'))}, Python {md(v.get('python'))}, "
                  f"MuJoCo {md(v.get('mujoco') or 'not installed')}. "
                  f"Total run time {_fmt(report.get('run_time_s'), 1, 1)} s.", ""]
    if report.get("settings"):
        lines += ["Settings: " + ", ".join(f"{md(k)} = {md(val)}" for k, val in report["settings"].items()), ""]
    return lines


def _scenario_lines(name: str, sc: dict) -> list[str]:
    """One scenario: its verdict and motion, its targets, the checks against the paper, the phases of a closed
    loop, its notes and files."""
    md = markdown_text
    lines = [f"## {md(name)}: {'success' if sc['success'] else 'NOT successful'}", ""]
    # escaped as a whole: an unknown duration made it "- s of motion", a list item
    lines += [md(f"{_fmt(sc.get('duration_s'), 1, 1)} s of motion, {sc.get('samples')} samples at "
                 f"{_fmt(sc.get('control_period_s'), 1000, 0)} ms, "
                 f"planned in {_fmt(sc['planning_time_s'], 1, 1)} s. "
                 f"Base at x = {_fmt(sc['base']['x_m'], 1, 3)} m, y = {_fmt(sc['base']['y_m'], 1, 3)} m, "
                 f"yaw = {_fmt(sc['base']['yaw_rad'], 1, 3)} rad."), ""]
    lines += ["| target | planned position error (mm) | planned direction error (deg) | solved |",
              "|---|---|---|---|"]
    for tg in sc["targets"]:
        lines.append(f"| {md(tg['name'])} | {_fmt(tg['position_error_m'], 1000, 4)} | "
                     f"{_fmt(tg['direction_error_deg'], 1, 4)} | {_fmt(tg.get('solved'))} |")
    lines += ["", "| check | ours (plan) | ours (MuJoCo) | paper |", "|---|---|---|---|"]
    for label, ours, simv, pap, scale, digits in _check_rows(sc):
        if ours is None and simv is None and pap is None:
            continue
        lines.append(f"| {label} | {_fmt(ours, scale, digits)} | {_fmt(simv, scale, digits)} | "
                     f"{_fmt(pap, scale, digits)} |")
    if sc.get("sim") is None:
        lines += ["", "No dynamics check (MuJoCo not installed, --no-sim, or the simulation failed)."]
    if sc.get("phases"):
        lines += ["", f"From lying straight (closed loop): {_fmt(sc.get('total_time_s'), 1, 1)} s in all, "
                  f"{sc.get('corrections', 0)} correction(s).", "", "| phase | kind | from (s) | to (s) |",
                  "|---|---|---|---|"]
        lines += [f"| {md(ph['name'])} | {md(ph['kind'])} | {_fmt(ph['t0_s'], 1, 1)} | {_fmt(ph['t1_s'], 1, 1)} |"
                  for ph in sc["phases"]]
    notes = list(sc.get("notes") or [])
    if notes:
        lines += ["", "Notes:", ""] + [f"- {md(n)}" for n in notes]
    files = sc.get("files") or []
    if files:
        lines += ["", "Files: " + ", ".join(markdown_code(f) for f in files)]
    lines.append("")
    return lines


def _check_rows(sc: dict) -> list[tuple[str, Any, Any, Any, float, int]]:
    """The rows of a scenario's check table: (label, the plan's value, MuJoCo's, the paper's, scale, digits)."""
    paper = sc.get("paper") or {}
    s = sc.get("sim") or {}
    return [
        ("head position error (mm, worst target)", max((t["position_error_m"] for t in sc["targets"]),
                                                       default=None), s.get("position_error_m"),
         paper.get("position_error_m"), 1000, 3),
        ("head direction error (deg, worst target)", max((t["direction_error_deg"] for t in sc["targets"]),
                                                         default=None), s.get("direction_error_deg"),
         paper.get("direction_error_deg"), 1, 3),
        ("max angular momentum error ‖L_sim − L_plan‖ (kg m²/s)", None, s.get("max_angular_momentum_error"),
         None, 1, 4),
        ("max angular momentum magnitude error (kg m²/s)", None,
         s.get("max_angular_momentum_magnitude_error"), paper.get("max_angular_momentum_magnitude_error"), 1, 4),
        ("max linear momentum error ‖P_sim − P_plan‖ (kg m/s)", None, s.get("max_linear_momentum_error"),
         None, 1, 4),
        ("max linear momentum magnitude error (kg m/s)", None, s.get("max_linear_momentum_magnitude_error"),
         paper.get("max_linear_momentum_magnitude_error"), 1, 4),
        ("ZMP inside the support polygon", sc.get("dynamically_stable"), s.get("zmp_inside"),
         paper.get("zmp_inside"), 1, 0),
        ("min ZMP margin (mm)", sc["min_zmp_margin_m"], s.get("zmp_min_margin_m"), None, 1000, 1),
        ("min ground clearance of neck and head (mm)", sc["min_ground_clearance_m"], None, None, 1000, 1),
        ("min distance to the obstacles (mm)", sc.get("min_obstacle_distance_m"), None, None, 1000, 1),
        ("base slide in simulation (mm)", None, s.get("base_slide_m"), None, 1000, 2),
        ("the tail's travel over the ground, whole sequence (m)", None, s.get("base_travel_m"), None, 1, 2),
        ("max joint torque in simulation (N m)", None, s.get("max_torque_nm"), None, 1, 2),
        ("motion duration (s)", sc.get("duration_s"), None, paper.get("duration_s"), 1, 1),
    ]


def _closing_lines(report: dict) -> list[str]:
    """The run's own notes and where its time went."""
    md = markdown_text
    lines: list[str] = []
    if report.get("notes"):
        lines += ["## Notes", ""] + [f"- {md(n)}" for n in report["notes"]] + [""]
    if report.get("stages"):
        lines += ["## Where the time went", "", "| stage | s |", "|---|---|"]
        lines += [f"| {md(st['stage'])} | {st['seconds']:.1f} |" for st in report["stages"]] + [""]
    return lines


def write_summary(report: dict, path: str | os.PathLike) -> Path:
    """Write :func:`summary_markdown` of ``report`` to ``path``; returns the path."""
    return write_text_atomic(path, summary_markdown(jsonable(report)))
