"""snakehead: plan how a snake robot raises its head to a position and direction while its body stays stable.

The command is snakehead (also python -m snakehead). Subcommands:

  info        describe a robot (default: the shipped one; --robot FILE for yours)
  demo        the paper's two scenarios of Section 4 end to end, with figures, animations and a report
  plan        head targets (--position/--direction, or --scene FILE) with the same outputs
  workspace   compute a reachability map of a robot's head (Algorithm 1) into a .npz file
  reach       compute the whole body's stable reachability map (where a stable pose puts the head) into a .npz file
  view        the interactive 3-D viewer of the output of plan or demo, served to a web browser; --live plans
              as you drag the head's targets

Exit status:
  0    success
  1    a scenario or target was planned but not successfully (the outputs are written all the same), or valid input has no answer (snakehead.Infeasible: e.g. a robot whose neck and head cannot rise)
  2    bad arguments, bad input files, or outputs that cannot be written: snakehead.InputError, and only it (one line on stderr says which)
  3    an internal error: any other exception, a bug in snakehead (one line on stderr; please report it with its traceback)
  130  interrupted (Ctrl-C; but view, which runs until Ctrl-C, then exits with 0)
Errors are one line on stderr, never a traceback; set SNAKEHEAD_TRACEBACK=1 to see the Python traceback.
"""
from __future__ import annotations

import argparse
import math
import os
import re
import signal
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .._errors import Infeasible, InputError
from .pipeline import FAST, NORMAL, outcome_line

from typing import TYPE_CHECKING, Any, Callable

if TYPE_CHECKING:
    from ..model.robot import SnakeRobot


class UsageError(InputError):
    """A mistake in the command line (options that do not go together): reported on stderr, exit status 2."""


#: Exit statuses (the module's docstring says when).
EXIT_OK, EXIT_UNSUCCESSFUL, EXIT_BAD_INPUT, EXIT_INTERNAL_ERROR, EXIT_INTERRUPTED = 0, 1, 2, 3, 130


#: What argparse must take for a negative number, not an option: its own pattern knows only "-1" and "-.5", so
#: "-1e5", "-inf" and "-nan" would be read as unknown options ("expected 3 arguments").
_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


class _Parser(argparse.ArgumentParser):
    """argparse with its errors on one line (argparse prints the whole usage first): exit status 2."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message: str) -> Any:
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


# ----------------------------------------------------------------------------------------------
# argument types
# ----------------------------------------------------------------------------------------------
def _finite_float(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return x


def _positive_float(text: str) -> float:
    x = _finite_float(text)
    if x <= 0:
        raise argparse.ArgumentTypeError(f"must be positive, got {text!r}")
    return x


def _int(text: str, least: int) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if n < least:
        raise argparse.ArgumentTypeError(f"must be >= {least}, got {text!r}")
    return n


def _positive_int(text: str) -> int:
    return _int(text, 1)


def _seed(text: str) -> int:
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
    from ..kinematics.reachability import parse_shard

    try:
        parse_shard(text)
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def _port(text: str) -> int:
    n = _int(text, 0)
    if n > 65535:
        raise argparse.ArgumentTypeError(f"must be a port number (0-65535), got {text!r}")
    return n


def _writable_dir(path: str) -> Path:
    """Create ``path`` (and its parents) if needed and check that files can be written in it."""
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {path!r} exists and is not a directory")
    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=out, prefix=".snakehead-write-test-"):
            pass
    except OSError as exc:
        raise UsageError(f"cannot write to --out {path!r}: {exc.strerror or exc}") from None
    return out


# ----------------------------------------------------------------------------------------------
# the robot and its map
# ----------------------------------------------------------------------------------------------
def _robot(args: argparse.Namespace) -> SnakeRobot:
    from ..model.robot import SnakeRobot

    if getattr(args, "robot", None) is None:
        return SnakeRobot.default()
    return SnakeRobot.from_file(args.robot, trust_xacro=bool(getattr(args, "trust_xacro", False)))


def _map(args: argparse.Namespace, robot: SnakeRobot) -> Any:
    """The map given with --map, else None (the pipeline finds one): InputError unless a whole map (not a shard) of
    the robot's head with the voxels its dexterous centre G0 needs (the controller's check, made before any work)."""
    from ..kinematics import reachability as workspace

    if args.map is None:
        return None
    return workspace.load(args.map).require_whole_for(robot, needs=("G0",), what=f"--map {args.map!r}")


# ----------------------------------------------------------------------------------------------
# info
# ----------------------------------------------------------------------------------------------
def _info(args: argparse.Namespace) -> int:
    from ..model.body_frame import NotStraight
    from .robot_check import check_lines, check_robot, home_suggestion

    try:
        robot = _robot(args)
    except NotStraight as exc:  # refused (exit 2), with the home pose that would straighten it when one does
        for line in home_suggestion(exc):
            print(line)
        raise
    check = check_robot(robot, suggest=not args.quick)
    for line in check_lines(robot, check):
        print(line)
    np.set_printoptions(precision=4, suppress=True)
    print("head_tip at q = 0 (world; its x-axis is the head's direction):")
    print(robot.head_pose(np.zeros(robot.n_joints)))
    return 0 if not check.problems else 1


# ----------------------------------------------------------------------------------------------
# demo and plan
# ----------------------------------------------------------------------------------------------
def _settings(args: argparse.Namespace) -> Any:
    from .pipeline import Settings

    return Settings(method=args.method, seed=args.seed, fast=args.fast, simulate=not args.no_sim,
                    relocation=not args.no_relocation,
                    sensing=getattr(args, "sensing", "onboard").replace("outside-fix", "outside fix"))


def _add_sensing_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--sensing", choices=("onboard", "outside-fix"), default="onboard",
                   help="with --start: what the closed loop knows of where it is. onboard (default): the robot's "
                        "own sensors (joint encoders, an IMU, contact odometry, a head camera that sees markers at "
                        "the targets); outside-fix: perfect joints and IMU and one outside measurement of the neck's "
                        "base frame once the body rests in the bending state")


def _start(args: argparse.Namespace, paper_default: bool) -> Any:
    """What --start asks for: None (not given), the pipeline's PAPER_START (demo's bare --start) or the tail's
    placement (X Y YAW); a usage error without the simulation the loop runs in."""
    from ..model.robot import BasePlacement
    from .pipeline import PAPER_START, mujoco_available

    values = getattr(args, "start", None)
    if values is None:
        return None
    if args.no_sim:
        raise UsageError("--start runs the closed loop in MuJoCo (gaits, the curl, the head phases): drop --no-sim")
    if not mujoco_available():
        raise UsageError("--start needs MuJoCo, which is not installed (pip install snakehead[sim])")
    if len(values) == 0 and paper_default:
        return PAPER_START
    if len(values) != 3:
        raise UsageError(f"--start takes X Y YAW (the tail's position in m and the body's heading in rad), got "
                         f"{len(values)} value{'' if len(values) == 1 else 's'}")
    return BasePlacement(*values)


def _done(command: str, out: Path, report: dict, progress: Any) -> int:
    entries = report["scenarios"]
    ok = all(e["success"] for e in entries.values())
    progress.say(f"done in {progress.elapsed():.1f} s")
    print(f"snakehead {command}: wrote report.json, summary.md and "
          f"{sum(len(e['files']) for e in entries.values())} other files to {out.resolve()}")
    for name, e in entries.items():
        print(f"  {name}: {outcome_line(e['success'], e.get('failure'), e.get('relocation'))}")
    return 0 if ok else 1


def _demo(args: argparse.Namespace) -> int:
    from ..scenes import paper_scene
    from .pipeline import Progress, run_scenes

    start = _start(args, paper_default=True)
    out = _writable_dir(args.out)
    robot = _robot(args)
    progress = Progress()
    progress.say(f"snakehead demo -> {out}{' (--fast)' if args.fast else ''}"
                 f"{'' if start is None else ' from lying straight (--start)'}")
    notes = ["the simulated wall is boxes: the round hole is a staircase of strips inscribed in it "
             "(sim.obstacle_boxes), standing on the ground",
             "planned errors are the head's by forward kinematics of the planned joints; the simulated ones are "
             "MuJoCo's at the times the plan reaches each target; the paper's momentum errors are magnitude errors "
             "(our max_*_momentum_magnitude_error), ours without 'magnitude' are of the vector difference"]
    report = run_scenes([paper_scene("spheres"), paper_scene("hole")], out, robot=robot,
                        workspace_map=_map(args, robot), settings=_settings(args), progress=progress,
                        command="demo", notes=notes, start=start)
    return _done("demo", out, report, progress)


def _plan(args: argparse.Namespace) -> int:
    from .._validate import unit_vector3, world_position
    from ..scenes import Scene, load_scene
    from .pipeline import Progress, run_scenes

    if args.scene is not None and (args.position is not None or args.direction is not None):
        raise UsageError("give --scene or --position/--direction, not both")
    if args.scene is None:
        if args.position is None or args.direction is None:
            raise UsageError("give --position X Y Z and --direction DX DY DZ, or --scene FILE")
        scene = Scene.from_targets([(world_position(args.position, "--position"),
                                     unit_vector3(args.direction, "--direction"))], name="target")
    else:
        scene = load_scene(args.scene)
    if args.robot is None and scene.robot_file is not None:
        args.robot = scene.robot_file
    start = _start(args, paper_default=False)
    out = _writable_dir(args.out)
    robot = _robot(args)
    progress = Progress()
    what = (f"head to {np.round(scene.targets[0].position, 4).tolist()} m along "
            f"{np.round(scene.targets[0].direction, 4).tolist()}" if args.scene is None else f"scene {scene.name!r}")
    progress.say(f"snakehead plan: {what} -> {out}")
    report = run_scenes([scene], out, robot=robot, workspace_map=_map(args, robot), settings=_settings(args),
                        progress=progress, command="plan", solution_figure=True, start=start)
    return _done("plan", out, report, progress)


# ----------------------------------------------------------------------------------------------
# workspace
# ----------------------------------------------------------------------------------------------
def _workspace(args: argparse.Namespace) -> int:
    from ..kinematics import reachability as workspace

    out = Path(args.out)
    if out.suffix != ".npz":
        raise InputError(f"--out must end in .npz, got {args.out!r}")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"the directory of --out {args.out!r} does not exist")
    if not os.access(parent, os.W_OK):
        raise InputError(f"cannot write to the directory of --out {args.out!r}")
    if args.merge:
        return _merge_shards(args, out)
    robot = _robot(args)
    chain = robot.head_chain
    defaults = workspace.default_map_options(chain)
    voxel = args.voxel if args.voxel is not None else defaults["voxel"]
    options = dict(voxel=voxel, directions=args.directions, rolls=args.rolls, free_roll=args.free_roll,
                   timeout=args.timeout, seed=args.seed, threads=args.threads, shard=args.shard)
    workspace.check_options(chain, **options)  # bad values (the voxel against the head's reach) before any output
    t0 = time.perf_counter()
    print(f"snakehead workspace: head chain {chain.base} -> {chain.tip} ({chain.n_joints} joints), voxel {voxel} m, "
          f"{args.directions} directions x {'free roll' if args.free_roll else f'{args.rolls} rolls'}",
          file=sys.stderr, flush=True)
    m = workspace.compute(chain, progress=not args.quiet, **options)
    if args.shard is None and len(m) == 0:  # nothing written: a map without voxels is refused wherever it goes
        raise InputError(f"--voxel {voxel} m: no voxel of the grid lies inside the head's workspace; give a smaller "
                         "--voxel")
    workspace.save(m, out)
    print(f"snakehead workspace: {len(m)} voxels in {time.perf_counter() - t0:.1f} s; wrote {out.resolve()}")
    if m.shard == (0, 1) and len(m):
        print(m.summary())
    return 0


def _reach(args: argparse.Namespace) -> int:
    from ..planning import whole_body_reach as reach

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {args.out!r} is not a directory")
    parent = out if out.is_dir() else (out.parent if str(out.parent) else Path("."))
    if not parent.is_dir() or not os.access(parent, os.W_OK):
        raise InputError(f"cannot write into --out {args.out!r} (its parent directory must exist and be writable)")
    robot = _robot(args)
    voxel, directions = reach.check_options(robot, args.voxel, args.directions)  # before any work or output
    out.mkdir(exist_ok=True)
    executor, closing = _reach_executor(args)
    t0 = time.perf_counter()
    last = [0.0]

    def progress(stage: str, done: int, total: int) -> None:
        now = time.perf_counter() - t0
        if not args.quiet and (done == total or now - last[0] >= 5.0):
            last[0] = now
            print(f"snakehead reach: {stage}: {done}/{total} tasks, {now:.0f} s", file=sys.stderr, flush=True)

    try:
        print(f"snakehead reach: {robot.source or 'the robot'}, voxel {voxel:g} m, {directions} directions, "
              f"{'1 process' if executor is None else (args.scheduler or f'{args.workers} workers')}",
              file=sys.stderr, flush=True)
        m = reach.compute_reach(robot, voxel=voxel, directions=directions, executor=executor, seed=args.seed,
                                progress=progress)
        m.command = "snakehead reach " + " ".join(sys.argv[2:]) if sys.argv[1:2] == ["reach"] else m.command
        path = out / "reach.npz"
        m.save(path)  # (the one map writer writes a temporary file and renames it)
        reached = m.reached_units()
        print(f"snakehead reach: {len(m)} voxels x {m.tried} directions, {int(reached.sum())} poses reached "
              f"({100 * reached.mean():.1f} %) in {time.perf_counter() - t0:.1f} s; wrote {path.resolve()}")
        if args.check:
            c = reach.check_reach(m, robot, args.check, seed=args.seed, executor=executor)
            print(f"snakehead reach --check: {c.summary()}")
    finally:
        if closing is not None:
            closing()
    return 0


def _reach_executor(args: argparse.Namespace) -> tuple[Any, Any]:
    """The executor of --workers N (a pool of N processes) or --scheduler ADDRESS (a Dask cluster), and how to
    close it; (None, None) for one process."""
    if args.scheduler is not None:
        try:
            from distributed import Client
        except ImportError:
            raise InputError("--scheduler needs Dask (pip install 'snakehead[dist]')") from None
        try:
            client = Client(args.scheduler, timeout="20s")
        except OSError as exc:
            raise InputError(f"--scheduler {args.scheduler!r}: cannot connect ({exc})") from None
        return client, client.close
    if args.workers and args.workers > 1:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        from ..threads import set_core_threads, share_per_worker

        # spawned workers: a forked child of a process whose C++ threads hold locks can hang; each worker's core
        # uses its share of the cores, so that the pool uses them once
        pool = ProcessPoolExecutor(args.workers, mp_context=multiprocessing.get_context("spawn"),
                                   initializer=set_core_threads, initargs=(share_per_worker(args.workers),))
        return pool, pool.shutdown
    return None, None


def _merge_shards(args: argparse.Namespace, out: Path) -> int:
    """workspace --merge: the shards' files merged into --out (the one place shards are read as they are)."""
    from ..kinematics import reachability as workspace

    given = [name for name, value in (("--shard", args.shard), ("--voxel", args.voxel)) if value is not None]
    if given:
        raise InputError(f"--merge merges computed shards: {' and '.join(given)} cannot be given with it")
    shards = [workspace.load(path) for path in args.merge]
    m = workspace.merge(shards)
    if args.robot is not None:  # the shards must be of this robot's head
        m.require_whole_for(_robot(args), what=f"the merged map of {len(shards)} shards")
    m.command = f"snakehead workspace --merge ({len(shards)} shards)"
    workspace.save(m, out)
    print(f"snakehead workspace: merged {len(shards)} shards into {len(m)} voxels; wrote {out.resolve()}")
    if len(m):
        print(m.summary())
    return 0

# ----------------------------------------------------------------------------------------------
# view
# ----------------------------------------------------------------------------------------------
def _view(args: argparse.Namespace) -> int:
    from ..kinematics import reachability as workspace
    from ..viz import viewer

    if args.live:
        if args.map is not None:
            raise UsageError("--map shows a reach map as a still scene: not with --live")
        if args.dir is not None:
            raise UsageError(f"--live plans as you drag the targets and shows no folder: drop {args.dir!r} (--scene "
                             "FILE starts from a scene's targets and obstacles)")
        return _view_live(args)
    if args.dir is None and args.map is None:
        raise UsageError("give DIR (the --out folder of 'snakehead plan' or 'demo'), --map REACH.npz, or --live")
    if args.scene is not None:
        raise UsageError("--scene goes with --live (DIR's scenes hold their robot and targets)")
    if args.robot is not None and args.map is None:
        raise UsageError("--robot goes with --live or --map (DIR's scenes hold their robot)")
    if args.save_dir is not None:
        raise UsageError("--save-dir goes with --live (only the live viewer's page saves scene files)")
    directory = None if args.dir is None else Path(args.dir)
    if directory is not None and not directory.is_dir():
        raise UsageError(f"{args.dir!r} is not a directory (give the --out folder of 'snakehead plan' or 'demo')")
    extra = [] if args.map is None else [viewer.reach_scene(workspace.load(args.map), _robot(args))]
    shown = viewer.serve(directory, host=args.host, port=args.port, extra=extra, allow_hosts=args.allow_host)
    try:  # from here on Ctrl-C is how the viewer ends (the line below tells the user so, and may be interrupted)
        where = " and ".join(([str(directory.resolve())] if directory is not None else []) + ([args.map] if args.map
                                                                                             else []))
        print(f"snakehead view: {shown.url} shows {', '.join(shown.scenes)} from {where}; Ctrl-C stops", flush=True)
        _warn_if_exposed(args.host)
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        return 0
    finally:
        shown.close()


def _view_live(args: argparse.Namespace) -> int:
    from ..scenes import load_scene
    from ..viz.live import LiveViewer

    scene = load_scene(args.scene) if args.scene is not None else None
    live = LiveViewer(scene, robot_file=args.robot, host=args.host, port=args.port, save_dir=args.save_dir,
                      allow_hosts=args.allow_host)
    try:  # from here on Ctrl-C is how the viewer ends
        what = f"scene {scene.name!r}" if scene is not None else "a target where the head starts"
        print(f"snakehead view --live: {live.url} plans {what} again whenever a target's gizmo is let go; the page "
              f"saves scene files into {live.saves.folder}; Ctrl-C stops", flush=True)
        _warn_if_exposed(args.host)
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        return 0
    finally:
        live.close()


def _warn_if_exposed(host: str) -> None:
    """A line on stderr when the viewer listens beyond this machine: plain HTTP, its token readable on the way."""
    if host not in ("127.0.0.1", "localhost", "::1"):
        print(f"snakehead view: listening on {host}: other machines can reach this server over plain HTTP (the "
              "token in the URL is all that keeps them out, and anyone on the network path can read it)",
              file=sys.stderr, flush=True)


# ----------------------------------------------------------------------------------------------
# the parser
# ----------------------------------------------------------------------------------------------
def _add_robot_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--robot", default=None, metavar="ROBOT.toml",
                   help="a robot file (TOML: urdf, base_end, neck_end, head_tip, optional root and map); "
                        "default: the shipped 16-joint robot")
    p.add_argument("--trust-xacro", action="store_true",
                   help="expand the robot's xacro with xacro's own Python evaluator, the environment and any file "
                        "(only for a description you trust; by default a xacro runs no code and reads only the "
                        "robot's folders: SECURITY.md)")


def _add_planning_options(p: argparse.ArgumentParser) -> None:
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
    p = sub.add_parser(name, help=help_text, description=description, epilog=_OUTPUTS,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_planning_options(p)
    p.set_defaults(func=func)
    return p


def build_parser() -> argparse.ArgumentParser:
    """The command line: one sub-command per helper below."""
    parser = _Parser(prog="snakehead", description=__doc__.split("\n\n")[0],
                     epilog=__doc__.split("\n\n", 1)[1],
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in (_add_info, _add_demo, _add_plan, _add_workspace, _add_reach, _add_view):
        add(sub)
    return parser


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
    p.set_defaults(func=_info)


def _add_demo(sub: Any) -> None:
    """snakehead demo: the paper's two scenarios."""
    demo = _planning_parser(sub, "demo", _demo, "the paper's two scenarios (Section 4) with figures, animations and a report",
                     "Plan the paper's two scenarios (catching two spheres, Section 4.1; getting the head through a "
                     "hole in a wall, Section 4.2; on the default robot unless --robot), check them in MuJoCo (the "
                     "hole's wall included), and write a report, trajectories, figures and animations. NAME is "
                     "spheres and hole.")
    demo.add_argument("--start", type=_finite_float, nargs="*", default=None, metavar="X Y YAW",
                      help="start from the body lying straight, as the paper does (its 'current state'), and run "
                           "the closed loop in MuJoCo (gaits, the curl into the bending state, the head phases): "
                           "bare --start lies where the curl alone brings the base to the scene's placement; "
                           "--start X Y YAW puts the tail at (X, Y) m with the body along YAW rad. Adds "
                           "NAME_path.png and NAME_loop.gif, and phases to the report")
    _add_sensing_option(demo)


def _add_plan(sub: Any) -> None:
    """snakehead plan: head targets or a scene file."""
    p = _planning_parser(sub, "plan", _plan, "head targets: --position/--direction, or a scene file",
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
    from .. import sweep_defaults as defaults
    from ..kinematics import reachability as ws

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
    p.set_defaults(func=_workspace)


def _add_reach(sub: Any) -> None:
    """snakehead reach: the whole body's stable reachability map."""
    from .. import sweep_defaults as defaults
    from ..planning import whole_body_reach as rc


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
    p.set_defaults(func=_reach)


def _add_view(sub: Any) -> None:
    """snakehead view: the 3-D viewer."""
    from ..viz.save_folder import DEFAULT_SAVE_DIR

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
    p.set_defaults(func=_view)

def _traceback_wanted() -> bool:
    return os.environ.get("SNAKEHEAD_TRACEBACK", "") not in ("", "0")


#: The longest error line printed (a message quoting a whole file or array is cut, its end kept).
MAX_ERROR_CHARS = 400


def _one_line(exc: BaseException) -> str:
    text = " ".join(line.strip() for line in str(exc).splitlines() if line.strip()) or type(exc).__name__
    return text if len(text) <= MAX_ERROR_CHARS else text[:MAX_ERROR_CHARS - 60] + " ... " + text[-55:]


def main(argv: list[str] | None = None) -> int:
    """Run the command line ``argv`` (default: ``sys.argv[1:]``); returns the exit status (see the module)."""
    command = "snakehead"
    try:
        parser = build_parser()
        args = parser.parse_args(argv)  # bad arguments: one line and SystemExit(2)
        command = f"snakehead {args.command}"
        return int(args.func(args))
    except KeyboardInterrupt:
        if argv is None:  # the program (not a call from Python) exits now: a Ctrl-C that arrives while the
            # interpreter shuts down (threads joined, files closed) would kill it by the signal instead of 130
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        print(f"{command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except InputError as exc:  # what the user gave (or where outputs go) is wrong
        if _traceback_wanted():
            raise
        print(f"{command}: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except Infeasible as exc:  # valid input with no answer (outside a plan, whose failures are in its report)
        if _traceback_wanted():
            raise
        print(f"{command}: not possible: {_one_line(exc)}", file=sys.stderr)
        return EXIT_UNSUCCESSFUL
    except Exception as exc:  # noqa: BLE001 -- anything else is a bug: one line, the traceback on request
        if _traceback_wanted():
            raise
        print(f"{command}: internal error ({type(exc).__name__}: {_one_line(exc)}); this is a bug in snakehead: run "
              "again with SNAKEHEAD_TRACEBACK=1 to see the traceback, and report it", file=sys.stderr)
        return EXIT_INTERNAL_ERROR
