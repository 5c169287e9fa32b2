"""What each ``snakehead`` command does, given its parsed arguments (:mod:`.cli_options` parses them): one function
per command, returning the exit status (:mod:`.exit_status`), and the steps they share (the robot, its map, the
pipeline's settings, where a run from lying straight starts, the output folder)."""
from __future__ import annotations

import argparse
import multiprocessing
import os
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import InputError
from .._validate import unit_vector3, world_position
from ..kinematics import reachability
from ..model.body_frame import NotStraight
from ..model.robot import BasePlacement, SnakeRobot
from ..planning import whole_body_reach
from ..scenes import Scene, load_scene, paper_scene
from ..threads import set_core_threads, share_per_worker
from .exit_status import UsageError
from .progress import Progress, outcome_line
from .robot_check import check_lines, check_robot, home_suggestion
from .settings import PAPER_START, Settings, mujoco_available

__all__ = ["info_command", "demo_command", "plan_command", "workspace_command", "reach_command", "view_command",
           "settings_of", "reach_executor"]


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


def _robot(args: argparse.Namespace) -> SnakeRobot:
    """The robot of --robot (with --trust-xacro), else the default one."""
    if getattr(args, "robot", None) is None:
        return SnakeRobot.default()
    return SnakeRobot.from_file(args.robot, trust_xacro=bool(getattr(args, "trust_xacro", False)),
                                inside=getattr(args, "robot_inside", None))


def _map(args: argparse.Namespace, robot: SnakeRobot) -> Any:
    """The map given with --map, else None (the pipeline finds one): InputError unless a whole map (not a shard) of
    the robot's head with the voxels its dexterous centre G0 needs (the controller's check, made before any work)."""
    if args.map is None:
        return None
    return reachability.load(args.map).require_whole_for(robot, needs=("G0",), what=f"--map {args.map!r}")


def info_command(args: argparse.Namespace) -> int:
    """snakehead info: the robot's check; 1 when its design has a problem."""
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


def settings_of(args: argparse.Namespace) -> Settings:
    """The pipeline's settings that demo's or plan's options ask for."""
    return Settings(method=args.method, seed=args.seed, fast=args.fast, simulate=not args.no_sim,
                    relocation=not args.no_relocation,
                    sensing=getattr(args, "sensing", "onboard").replace("outside-fix", "outside fix"))


def _start(args: argparse.Namespace, paper_default: bool) -> Any:
    """What --start asks for: None (not given), the pipeline's PAPER_START (demo's bare --start) or the tail's
    placement (X Y YAW); a usage error without the simulation the loop runs in."""
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


def _done(command: str, out: Path, report: dict, progress: Progress) -> int:
    """The lines that end demo and plan (what was written where, each scenario's outcome); 1 unless all succeeded."""
    entries = report["scenarios"]
    ok = all(e["success"] for e in entries.values())
    progress.say(f"done in {progress.elapsed():.1f} s")
    print(f"snakehead {command}: wrote report.json, summary.md and "
          f"{sum(len(e['files']) for e in entries.values())} other files to {out.resolve()}")
    for name, e in entries.items():
        print(f"  {name}: {outcome_line(e['success'], e.get('failure'), e.get('relocation'))}")
    return 0 if ok else 1


def demo_command(args: argparse.Namespace) -> int:
    """snakehead demo: the paper's two scenarios through the pipeline."""
    from . import pipeline  # heavy (its figures, the closed loop): loaded by demo and plan only

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
    report = pipeline.run_scenes([paper_scene("spheres"), paper_scene("hole")], out, robot=robot,
                                 workspace_map=_map(args, robot), settings=settings_of(args), progress=progress,
                                 command="demo", notes=notes, start=start)
    return _done("demo", out, report, progress)


def plan_command(args: argparse.Namespace) -> int:
    """snakehead plan: head targets, or a scene file's, through the pipeline."""
    from . import pipeline  # heavy (its figures, the closed loop): loaded by demo and plan only

    if args.scene is not None and (args.position is not None or args.direction is not None):
        raise UsageError("give --scene or --position/--direction, not both")
    if args.scene is None:
        if args.position is None or args.direction is None:
            raise UsageError("give --position X Y Z and --direction DX DY DZ, or --scene FILE")
        scene = Scene.from_targets([(world_position(args.position, "--position"),
                                     unit_vector3(args.direction, "--direction"))], name="target")
    else:
        scene = load_scene(args.scene)
    if args.robot is None and scene.robot_file is not None:  # the scene's, confined to its folder
        args.robot, args.robot_inside = scene.robot_file, scene.robot_folder
    start = _start(args, paper_default=False)
    out = _writable_dir(args.out)
    robot = _robot(args)
    progress = Progress()
    what = (f"head to {np.round(scene.targets[0].position, 4).tolist()} m along "
            f"{np.round(scene.targets[0].direction, 4).tolist()}" if args.scene is None else f"scene {scene.name!r}")
    progress.say(f"snakehead plan: {what} -> {out}")
    report = pipeline.run_scenes([scene], out, robot=robot, workspace_map=_map(args, robot),
                                 settings=settings_of(args), progress=progress, command="plan", solution_figure=True,
                                 start=start)
    return _done("plan", out, report, progress)


def workspace_command(args: argparse.Namespace) -> int:
    """snakehead workspace: a head's reachability map into a .npz file (or shards merged into one)."""
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
    defaults = reachability.default_map_options(chain)
    voxel = args.voxel if args.voxel is not None else defaults["voxel"]
    options = dict(voxel=voxel, directions=args.directions, rolls=args.rolls, free_roll=args.free_roll,
                   timeout=args.timeout, seed=args.seed, threads=args.threads, shard=args.shard)
    reachability.check_options(chain, **options)  # bad values (the voxel against the head's reach) before any output
    t0 = time.perf_counter()
    print(f"snakehead workspace: head chain {chain.base} -> {chain.tip} ({chain.n_joints} joints), voxel {voxel} m, "
          f"{args.directions} directions x {'free roll' if args.free_roll else f'{args.rolls} rolls'}",
          file=sys.stderr, flush=True)
    m = reachability.compute(chain, progress=not args.quiet, **options)
    if args.shard is None and len(m) == 0:  # nothing written: a map without voxels is refused wherever it goes
        raise InputError(f"--voxel {voxel} m: no voxel of the grid lies inside the head's workspace; give a smaller "
                         "--voxel")
    reachability.save(m, out)
    print(f"snakehead workspace: {len(m)} voxels in {time.perf_counter() - t0:.1f} s; wrote {out.resolve()}")
    if m.shard == (0, 1) and len(m):
        print(m.summary())
    return 0


def reach_command(args: argparse.Namespace) -> int:
    """snakehead reach: the whole body's stable reachability map into DIR/reach.npz (and its check)."""
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {args.out!r} is not a directory")
    parent = out if out.is_dir() else (out.parent if str(out.parent) else Path("."))
    if not parent.is_dir() or not os.access(parent, os.W_OK):
        raise InputError(f"cannot write into --out {args.out!r} (its parent directory must exist and be writable)")
    robot = _robot(args)
    # before any work or output
    voxel, directions = whole_body_reach.check_options(robot, args.voxel, args.directions)
    out.mkdir(exist_ok=True)
    executor, closing = reach_executor(args)
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
        m = whole_body_reach.compute_reach(robot, voxel=voxel, directions=directions, executor=executor,
                                           seed=args.seed, progress=progress)
        m.command = "snakehead reach " + " ".join(sys.argv[2:]) if sys.argv[1:2] == ["reach"] else m.command
        path = out / "reach.npz"
        m.save(path)  # (the one map writer writes a temporary file and renames it)
        reached = m.reached_units()
        print(f"snakehead reach: {len(m)} voxels x {m.tried} directions, {int(reached.sum())} poses reached "
              f"({100 * reached.mean():.1f} %) in {time.perf_counter() - t0:.1f} s; wrote {path.resolve()}")
        if args.check:
            c = whole_body_reach.check_reach(m, robot, args.check, seed=args.seed, executor=executor)
            print(f"snakehead reach --check: {c.summary()}")
    finally:
        if closing is not None:
            closing()
    return 0


def reach_executor(args: argparse.Namespace) -> tuple[Any, Any]:
    """The executor of --workers N (a pool of N processes) or --scheduler ADDRESS (a Dask cluster), and how to
    close it; (None, None) for one process."""
    if args.scheduler is not None:
        try:
            from distributed import Client  # Dask: optional (pip install 'snakehead[dist]')
        except ImportError:
            raise InputError("--scheduler needs Dask (pip install 'snakehead[dist]')") from None
        try:
            client = Client(args.scheduler, timeout="20s")
        except OSError as exc:
            raise InputError(f"--scheduler {args.scheduler!r}: cannot connect ({exc})") from None
        return client, client.close
    if args.workers and args.workers > 1:
        # spawned workers: a forked child of a process whose C++ threads hold locks can hang; each worker's core
        # uses its share of the cores, so that the pool uses them once
        pool = ProcessPoolExecutor(args.workers, mp_context=multiprocessing.get_context("spawn"),
                                   initializer=set_core_threads, initargs=(share_per_worker(args.workers),))
        return pool, pool.shutdown
    return None, None


def _merge_shards(args: argparse.Namespace, out: Path) -> int:
    """workspace --merge: the shards' files merged into --out (the one place shards are read as they are)."""
    given = [name for name, value in (("--shard", args.shard), ("--voxel", args.voxel)) if value is not None]
    if given:
        raise InputError(f"--merge merges computed shards: {' and '.join(given)} cannot be given with it")
    shards = [reachability.load(path) for path in args.merge]
    m = reachability.merge(shards)
    if args.robot is not None:  # the shards must be of this robot's head
        m.require_whole_for(_robot(args), what=f"the merged map of {len(shards)} shards")
    m.command = f"snakehead workspace --merge ({len(shards)} shards)"
    reachability.save(m, out)
    print(f"snakehead workspace: merged {len(shards)} shards into {len(m)} voxels; wrote {out.resolve()}")
    if len(m):
        print(m.summary())
    return 0


def view_command(args: argparse.Namespace) -> int:
    """snakehead view: DIR's scenes (and --map's) served until Ctrl-C, or (--live) the live viewer."""
    from ..viz import viewer  # the viewer's modules: loaded by view only

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
    extra = [] if args.map is None else [viewer.reach_scene(reachability.load(args.map), _robot(args))]
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
    """snakehead view --live: the live viewer served until Ctrl-C."""
    from ..viz.live import LiveViewer  # the live viewer's modules: loaded by view --live only

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
