"""The command line's parsers: the argument types (numbers checked before any work), the options each command
takes, and a parser whose errors are one line (:class:`OneLineParser`). :func:`add_commands` adds every command,
each with its function of :mod:`.commands`."""
from __future__ import annotations

import argparse
import math
import re
from typing import Any, Callable

from .. import sweep_defaults as defaults
from .._errors import InputError
from ..kinematics import reachability as ws
from ..planning import whole_body_reach as rc
from ..viz.save_folder import DEFAULT_SAVE_DIR
from . import commands
from .exit_status import EXIT_BAD_INPUT
from .settings import FAST, NORMAL

__all__ = ["OneLineParser", "add_commands"]

#: What argparse must take for a negative number, not an option: its own pattern knows only "-1" and "-.5", so
#: "-1e5", "-inf" and "-nan" would be read as unknown options ("expected 3 arguments").
_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


class OneLineParser(argparse.ArgumentParser):
    """argparse with its errors on one line (argparse prints the whole usage first): exit status 2."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message: str) -> Any:
        """Exit with status 2 after one line: the message and where to find the usage."""
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _finite_float(text: str) -> float:
    """An argument type: a finite number (not NaN or inf)."""
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return x


def _positive_float(text: str) -> float:
    """An argument type: a finite number over 0."""
    x = _finite_float(text)
    if x <= 0:
        raise argparse.ArgumentTypeError(f"must be positive, got {text!r}")
    return x


def _int(text: str, least: int) -> int:
    """``text`` as an integer of at least ``least`` (argparse's error otherwise)."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if n < least:
        raise argparse.ArgumentTypeError(f"must be >= {least}, got {text!r}")
    return n


def _seed(text: str) -> int:
    """An argument type: a seed, an integer >= 0."""
    return _int(text, 0)


def _bounded_int(least: int, most: int) -> Callable[[str], int]:
    """An argument type: an integer within [least, most] (a number beyond is refused here, before any work)."""
    def parse(text: str) -> int:
        n = _int(text, least)
        if n > most:
            raise argparse.ArgumentTypeError(f"must be at most {most}, got {text!r}")
        return n

    return parse


def _shard(text: str) -> str:
    """An argument type: i/N with 0 <= i < N <= the most shards a map has (kinematics.reachability.MAX_SHARDS)."""
    try:
        ws.parse_shard(text)
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def _port(text: str) -> int:
    """An argument type: a port number, 0 to 65535."""
    n = _int(text, 0)
    if n > 65535:
        raise argparse.ArgumentTypeError(f"must be a port number (0-65535), got {text!r}")
    return n


def _add_robot_option(p: argparse.ArgumentParser) -> None:
    """--robot and --trust-xacro."""
    p.add_argument("--robot", default=None, metavar="ROBOT.toml",
                   help="a robot file (TOML: urdf, base_end, neck_end, head_tip, optional root and map); "
                        "default: the shipped 16-joint robot")
    p.add_argument("--trust-xacro", action="store_true",
                   help="expand the robot's xacro with xacro's own Python evaluator, the environment and any file "
                        "(only for a description you trust; by default a xacro runs no code and reads only the "
                        "robot's folders: SECURITY.md)")


def _add_planning_options(p: argparse.ArgumentParser) -> None:
    """The options demo and plan share."""
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (created if needed)")
    _add_robot_option(p)
    p.add_argument("--no-sim", action="store_true", help="skip the MuJoCo dynamics check")
    p.add_argument("--no-relocation", action="store_true",
                   help="keep the base where it lies: a target it cannot reach from there fails instead of moving "
                        "the base first (by locomotion)")
    p.add_argument("--seed", type=_seed, default=1, metavar="N",
                   help="seed of the head's TRAC-IK (the plan is a function of it; default 1)")
    p.add_argument("--method", choices=("rotated", "free_roll"), default="rotated",
                   help="head IK: the paper's rotated frames (Fig. 9, default) or one call with the roll free")
    p.add_argument("--map", default=None, metavar="MAP.npz",
                   help="the head's reachability map (default: the robot file's; for a robot without one, a map "
                        "computed on the first run and cached)")
    p.add_argument("--fast", action="store_true",
                   help=f"quicker outputs: {FAST['max_frames']}-frame animations instead of {NORMAL['max_frames']}")


def _add_sensing_option(p: argparse.ArgumentParser) -> None:
    """--sensing (demo's and plan's, with --start)."""
    p.add_argument("--sensing", choices=("onboard", "outside-fix"), default="onboard",
                   help="with --start: what the closed loop knows of where it is. onboard (default): the robot's "
                        "own sensors (joint encoders, an IMU, contact odometry, a head camera that sees markers at "
                        "the targets); outside-fix: perfect joints and IMU and one outside measurement of the neck's "
                        "base frame once the body rests in the bending state")



_OUTPUTS = """outputs (in DIR):
  report.json               per scenario: success, targets (errors), min ZMP margin, min ground clearance,
                            planning time, sim (null without MuJoCo or with --no-sim), the paper's figures
  summary.md                the same, readable
  NAME_trajectory.csv       time_s and the joint angles (rad) every 2 ms
  NAME_snapshots.png        the body in 3-D at the scenario's states (Figs. 17 / 22)
  NAME_momenta.png          planned (and simulated) angular and linear momenta (Figs. 18-19 / 23-24)
  NAME_zmp.png              the ZMP in the support polygon (Figs. 20 / 25)
  NAME.gif                  an animation of the motion
  NAME.html                 the interactive 3-D viewer of the motion: opens from disk, no server, no network
  NAME_viewer.npz           what the viewer shows (link collision shapes per frame, targets, obstacles, ZMP, the head's map);
                            snakehead view DIR serves it
  NAME_path.png             with --start: the tail's path over the ground with the phases, from above
  NAME_loop.gif             with --start: the whole sequence (gaits, curl, lift, targets) as MuJoCo ran it
"""


def _planning_parser(sub: Any, name: str, func: Callable[..., Any], help_text: str, description: str
                     ) -> argparse.ArgumentParser:
    """A sub-parser of demo's or plan's kind: the planning options, the outputs listed after the options."""
    p = sub.add_parser(name, help=help_text, description=description, epilog=_OUTPUTS,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_planning_options(p)
    p.set_defaults(func=func)
    return p


def add_commands(sub: Any) -> None:
    """Every command, as a sub-parser of ``sub`` (``add_subparsers``'s), each with its function as ``func``."""
    for add in (_add_info, _add_demo, _add_plan, _add_workspace, _add_reach, _add_view):
        add(sub)


def _add_info(sub: Any) -> None:
    """snakehead info: check a robot."""
    p = sub.add_parser(
        "info", help="check a robot: its parts, whether its design can work, a split of the parts that does",
        description="Check a robot: each part's frames (where they sit along the body), length, mass and joints; "
                    "its collision shapes; whether the base can hold the lifted neck and head (an initial state and a "
                    "bending state exist); its head's map; and when something cannot work, a split of the parts "
                    "(base_end, neck_end) that passes, found by trying. Exits 1 when the design has a problem.")
    _add_robot_option(p)
    p.add_argument("--quick", action="store_true", help="do not search for a split of the parts that works")
    p.set_defaults(func=commands.info_command)


def _add_demo(sub: Any) -> None:
    """snakehead demo: the paper's two scenarios."""
    demo = _planning_parser(sub, "demo", commands.demo_command,
                            "the paper's two scenarios (Section 4) with figures, animations and a report",
                            "Plan the paper's two scenarios (catching two spheres, Section 4.1; getting the head "
                            "through a hole in a wall, Section 4.2; on the default robot unless --robot), check them "
                            "in MuJoCo (the hole's wall included), and write a report, trajectories, figures and "
                            "animations. NAME is spheres and hole.")
    demo.add_argument("--start", type=_finite_float, nargs="*", default=None, metavar="X Y YAW",
                      help="start from the body lying straight, as the paper does (its 'current state'), and run "
                           "the closed loop in MuJoCo (gaits, the curl into the bending state, the head phases): "
                           "bare --start lies where the curl alone brings the base to the scene's placement; "
                           "--start X Y YAW puts the tail at (X, Y) m with the body along YAW rad. Adds "
                           "NAME_path.png and NAME_loop.gif, and phases to the report")
    _add_sensing_option(demo)


def _add_plan(sub: Any) -> None:
    """snakehead plan: head targets or a scene file."""
    p = _planning_parser(sub, "plan", commands.plan_command, "head targets: --position/--direction, or a scene file",
                         "Plan the head from the bending state on the ground to POSITION pointing along DIRECTION "
                         "(world frame, z up, ground at z = 0), or through the targets of a scene file (--scene; "
                         "TOML: targets and obstacles), check it, and write the same outputs as demo with NAME = "
                         "target (or the scene's name).")
    p.add_argument("--position", type=_finite_float, nargs=3, default=None, metavar=("X", "Y", "Z"),
                   help="desired head position (m, world)")
    p.add_argument("--direction", type=_finite_float, nargs=3, default=None, metavar=("DX", "DY", "DZ"),
                   help="desired head direction (the head link's x-axis; any non-zero length)")
    p.add_argument("--scene", default=None, metavar="SCENE.toml",
                   help="a scene file: targets (name, position, direction, hold_s, ...) and obstacles; its robot "
                        "file is used unless --robot is given")
    p.add_argument("--start", type=_finite_float, nargs=3, default=None, metavar=("X", "Y", "YAW"),
                   help="start from the body lying straight with its tail at (X, Y) m and its body along YAW rad "
                        "(world) and run the closed loop in MuJoCo: gaits that move the body where the targets need "
                        "its base, the curl into the bending state, the head phases. Adds NAME_path.png and "
                        "NAME_loop.gif, and phases to the report")
    _add_sensing_option(p)


def _add_workspace(sub: Any) -> None:
    """snakehead workspace: a head's reachability map (Algorithm 1)."""
    p = sub.add_parser("workspace", help="compute a reachability map of a robot's head (Algorithm 1)",
                       description="Compute the reachability map of a robot's head (neck_end -> head_tip; default "
                                   "robot: its 7-DOF head; the 6-DOF variant is the robot file snake16_head6.toml "
                                   "beside the default one) with snakehead.kinematics.reachability.compute and save it "
                                   "as .npz. For shards over many machines or without Python, use the workspace_gen "
                                   "executable installed with the package (workspace_gen --help).")
    p.add_argument("--out", required=True, metavar="MAP.npz", help="output file (.npz)")
    _add_robot_option(p)

    p.add_argument("--voxel", type=_positive_float, default=None, metavar="M",
                   help="voxel edge (m; default: a twelfth of the head's reach rounded to 5 mm, 0.045 on the default "
                        f"robot); the grid, of side 2 x the head's reach, must hold {ws.MIN_VOXELS_PER_AXIS} to "
                        f"{ws.MAX_VOXELS_PER_AXIS} voxels per axis (so a voxel under 2/3 of the reach)")
    p.add_argument("--directions", type=_bounded_int(1, ws.MAX_DIRECTIONS), default=defaults.HEAD_DIRECTIONS,
                   metavar="N", help=f"points per voxel sphere, 1 to {ws.MAX_DIRECTIONS} (default %(default)s)")
    p.add_argument("--rolls", type=_bounded_int(1, ws.MAX_ROLLS), default=defaults.HEAD_ROLLS, metavar="R",
                   help=f"frames about the approach axis per point, 1 to {ws.MAX_ROLLS}, and directions x rolls at "
                        f"most {ws.MAX_FRAMES_PER_VOXEL} (default %(default)s)")
    p.add_argument("--free-roll", action="store_true", help="one IK call per point with the roll left free")
    p.add_argument("--timeout", type=_positive_float, default=defaults.HEAD_TIMEOUT_S, metavar="S",
                   help=f"TRAC-IK budget per call (s, over 0 and at most {ws.MAX_TIMEOUT_S:g}; default %(default)g)")
    p.add_argument("--seed", type=_bounded_int(0, ws.MAX_SEED), default=defaults.HEAD_SEED, metavar="N",
                   help="random seed, 0 to 2^64 - 1 (default %(default)s)")
    p.add_argument("--threads", type=_bounded_int(1, ws.MAX_THREADS), default=None, metavar="N",
                   help=f"worker threads, 1 to {ws.MAX_THREADS} (default: snakehead.core_threads(), all cores unless "
                        "SNAKEHEAD_NUM_THREADS or OMP_NUM_THREADS says fewer)")
    p.add_argument("--shard", type=_shard, default=None, metavar="i/N",
                   help=f"compute only shard i of N (0 <= i < N <= {ws.MAX_SHARDS}); merge the N files afterwards "
                        "with --merge")
    p.add_argument("--merge", nargs="+", default=None, metavar="SHARD.npz",
                   help="instead of computing, merge the files of the shards 0/N ... N-1/N of one map into --out (a "
                        "shard alone is refused wherever a map is taken)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=commands.workspace_command)


def _add_reach(sub: Any) -> None:
    """snakehead reach: the whole body's stable reachability map."""
    p = sub.add_parser("reach", help="compute the whole body's stable reachability map",
                       description="For voxels around the robot (a cube of side 2 x the body's length, from the "
                                   "ground up to the highest the head gets) and directions per voxel, whether the "
                                   "planner's whole-body solve finds a stable, collision-free pose that puts the "
                                   "head there (with the base as it lies, or moved), and with which base shape and "
                                   "placement: a map of kind 'whole-body' written to DIR/reach.npz "
                                   "(snakehead.load_map(path).reachable(positions, directions) answers from it).")
    _add_robot_option(p)
    p.add_argument("--voxel", type=_positive_float, default=defaults.REACH_VOXEL_M, metavar="M",
                   help=f"voxel edge (m, default %(default)g; at least {rc.MIN_VOXEL_M:g})")
    p.add_argument("--directions", type=_bounded_int(1, rc.MAX_DIRECTIONS), default=defaults.REACH_DIRECTIONS,
                   metavar="N", help=f"directions per voxel, 1 to {rc.MAX_DIRECTIONS} (default %(default)s)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=_bounded_int(1, rc.MAX_WORKERS), default=None, metavar="N",
                       help="a pool of N worker processes on this machine (default: this process)")
    where.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="a Dask scheduler (tcp://host:port) whose workers do the work")
    p.add_argument("--check", type=_bounded_int(0, 100_000), default=0, metavar="K",
                   help="then plan K sampled poses (half reached, half not) in full and report the agreement")
    p.add_argument("--seed", type=_bounded_int(0, 2**32 - 1), default=1, metavar="N",
                   help="the head IK's seed, and the check's sample (default 1)")
    p.add_argument("--out", default="reach", metavar="DIR", help="output directory (default ./reach)")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.set_defaults(func=commands.reach_command)


def _add_view(sub: Any) -> None:
    """snakehead view: the 3-D viewer."""
    p = sub.add_parser("view", help="the interactive 3-D viewer of the output of plan or demo, or (--live) of "
                                    "plans made as you drag targets (a web page)",
                       description="Serve the scenes that 'snakehead plan' or 'snakehead demo' wrote into DIR "
                                   "(NAME_viewer.npz) at http://HOST:PORT until Ctrl-C: the robot moving along its "
                                   "motion with play/pause and a time slider, the targets, the obstacles, the "
                                   "support polygon and the ZMP's trace, and the head's reachability map (toggled "
                                   "on in the panel). Without a server, open DIR/NAME.html: the same scene. With "
                                   "--live (no DIR): the robot in its initial state and the targets as gizmos to "
                                   "drag, turn, add and remove; the plan is made again and played whenever one is "
                                   "let go, its failure shown with its reason; buttons check the motion in MuJoCo "
                                   "and save the targets and obstacles as a scene file (a bare name, into "
                                   "--save-dir). The URL printed carries a token: open it as printed (the server "
                                   "answers only to this machine's names and to pages of its own origin).")
    p.add_argument("dir", metavar="DIR", nargs="?", default=None,
                   help="the --out folder of snakehead plan or demo (not with --live)")
    p.add_argument("--live", action="store_true",
                   help="plan as you drag the targets (default: one where the head starts; --scene for a scene's)")
    p.add_argument("--map", default=None, metavar="REACH.npz",
                   help="show a whole-body reach map (snakehead reach's DIR/reach.npz; --robot: its robot) as a still "
                        "scene: the robot at its start and the voxels reached, coloured by the share of directions")
    _add_robot_option(p)
    p.add_argument("--scene", default=None, metavar="SCENE.toml",
                   help="with --live: start from a scene file's targets, obstacles and base (its robot file unless "
                        "--robot is given)")
    p.add_argument("--save-dir", default=None, metavar="DIR",
                   help=f"with --live: the one folder the page saves scene files into (default ./{DEFAULT_SAVE_DIR}, "
                        "made at the first save); the page gives a bare file name and never replaces a file this "
                        "session did not write")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1: this machine only; 0.0.0.0 for every interface, "
                        "over plain HTTP)")
    p.add_argument("--port", type=_port, default=8080, metavar="N",
                   help="port (default 8080; the next free one if taken)")
    p.add_argument("--allow-host", action="append", default=[], metavar="NAME",
                   help="a host name the server also answers to (repeatable; e.g. this machine's name when serving "
                        "other machines with --host 0.0.0.0). Always: localhost, 127.0.0.1, [::1] and the address "
                        "a request came in on; any other Host header is refused (DNS rebinding)")
    p.set_defaults(func=commands.view_command)
