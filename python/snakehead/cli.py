"""snakehead: plan how a snake robot raises its head to a position and direction while its body stays stable.

The command is snakehead (also python -m snakehead). Subcommands:

  info        describe the default robot
  demo        the paper's two scenarios of Section 4 end to end, with figures, animations and a report
  plan        one head target (position and direction) from the initial state, with the same outputs
  workspace   compute a reachability map of the head (Algorithm 1) into a .npz file

Exit status: 0 on success; 1 when a scenario or target was planned but not successfully (the outputs are
written all the same); 2 for bad arguments or input files; 130 when interrupted.
Set SNAKEHEAD_TRACEBACK=1 to see the Python traceback of an error.
"""
from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


class UsageError(Exception):
    """A mistake in the command line or its input files: reported on stderr, exit status 2."""


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
# progress on stderr
# ----------------------------------------------------------------------------------------------
class Progress:
    """Stage lines on stderr (``[  12.3 s] what ...`` / ``... done in 1.2 s``) and a record of the stage times."""

    def __init__(self, quiet: bool = False):
        self.t0 = time.perf_counter()
        self.quiet = quiet
        self.stages: list[dict] = []

    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def say(self, text: str) -> None:
        if not self.quiet:
            print(f"[{self.elapsed():7.1f} s] {text}", file=sys.stderr, flush=True)

    @contextlib.contextmanager
    def stage(self, what: str):
        self.say(f"{what} ...")
        start = time.perf_counter()
        yield
        dt = time.perf_counter() - start
        self.stages.append({"stage": what, "seconds": dt})
        self.say(f"{what}: done in {dt:.1f} s")


# ----------------------------------------------------------------------------------------------
# info
# ----------------------------------------------------------------------------------------------
def _info(args: argparse.Namespace) -> int:
    from .robot import SnakeRobot

    robot = SnakeRobot.default()
    print(f"robot: {robot.urdf}")
    print(f"joints: {robot.n_joints}, mass {robot.total_mass:.3f} kg, frames: {', '.join(robot.link_names)}")
    q = np.zeros(robot.n_joints)
    np.set_printoptions(precision=4, suppress=True)
    print("head_tip at q = 0 (world):")
    print(robot.head_pose(q))
    return 0


# ----------------------------------------------------------------------------------------------
# demo and plan
# ----------------------------------------------------------------------------------------------
#: What --fast changes (documented in the help): the scenarios are planned with joints twice as fast and
#: shorter segments (so half the 2 ms samples to simulate), and the animations have fewer frames.
FAST = {"speed": 0.24, "min_segment": 1.0, "max_frames": 30}
NORMAL = {"speed": 0.12, "min_segment": 2.0, "max_frames": 100}
#: Horizontal strips of the simulated wall's staircase hole (``sim.wall_with_hole``).
HOLE_SLICES = 32


def _controller(args: argparse.Namespace, progress: Progress):
    from . import workspace
    from .controller import HeadController

    with progress.stage("loading the head's workspace map and its dexterous centre G0"):
        if args.map is not None:
            m = workspace.load(args.map)
        else:
            try:
                m = workspace.default_map("head")
            except ValueError as exc:
                raise UsageError(f"{exc}\nthe shipped map is missing: compute one with `snakehead workspace --out "
                                 "map.npz` and pass --map map.npz") from None
        controller = HeadController(workspace_map=m, method=args.method, seed=args.seed)
    return controller


def _sim_available() -> bool:
    import importlib.util

    return importlib.util.find_spec("mujoco") is not None


def _run_scenario(name: str, plan_fn, controller, out: Path, args, progress: Progress, *, spheres=(),
                  sim_obstacles=(), figures=(17, 18, 19, 20), label: str = "", solution_figure: bool = False) -> dict:
    """Plan one scenario, simulate it (unless --no-sim), write its CSV, figures and animation; its report entry."""
    from . import report, scenario_plots

    robot = controller.robot
    settings = FAST if args.fast else NORMAL
    label = label or name
    with progress.stage(f"{name}: planning {label}"):
        result = plan_fn(controller)
    progress.say(f"{name}: {'success' if result.success else 'NOT successful'}, "
                 f"{result.t[-1] - result.t[0]:.1f} s of motion, {len(result.t)} samples; targets: "
                 + "; ".join(f"{tg.name} {1000 * tg.position_error_m:.3f} mm / {tg.direction_error_deg:.3f} deg"
                             for tg in result.targets))
    files = []
    csv_path = report.write_trajectory_csv(result, out / f"{name}_trajectory.csv",
                                           [f"joint_{j + 1}" for j in range(robot.n_joints)])
    files.append(csv_path.name)
    if solution_figure and result.targets:
        path = scenario_plots.plot_head_solution(robot, result.targets[0].solution, out / f"{name}_solution.png")
        files.append(path.name)

    sim_result, metrics, notes = None, None, []
    if args.no_sim:
        notes.append("dynamics check skipped (--no-sim)")
    elif not _sim_available():
        notes.append("dynamics check skipped: MuJoCo is not installed (pip install snakehead[sim])")
        progress.say(f"{name}: MuJoCo is not installed; no dynamics check")
    else:
        from . import sim

        with progress.stage(f"{name}: MuJoCo simulation of {result.t[-1] - result.t[0]:.1f} s "
                            f"({len(sim_obstacles)} obstacle boxes)"):
            try:
                sim_result = sim.simulate(robot, result.t, result.q, result.base, obstacles=list(sim_obstacles))
            except RuntimeError as exc:
                notes.append(f"the simulation failed: {exc}")
                progress.say(f"{name}: the simulation failed: {exc}")
        if sim_result is not None:
            with progress.stage(f"{name}: comparing the simulation with the plan"):
                metrics = sim.compare(robot, result.t, result.q, sim_result, base=result.base,
                                      targets=[(tg.time, tg.position, tg.direction) for tg in result.targets])
            progress.say(f"{name}: simulated head error {1000 * metrics['position_error_m']:.2f} mm / "
                         f"{metrics['direction_error_deg']:.2f} deg; momentum errors "
                         f"{metrics['max_angular_momentum_error']:.4f} kg m^2/s, "
                         f"{metrics['max_linear_momentum_error']:.4f} kg m/s; ZMP inside: {metrics['zmp_inside']}")

    snap, mom1, mom2, zmp = figures
    with progress.stage(f"{name}: figures"):
        cols = 4 if len(result.targets) + 2 > 9 or name == "spheres" else 3
        n_panels = 12 if cols == 4 else 9
        paths = [
            scenario_plots.plot_snapshots(robot, result, out / f"{name}_snapshots.png", spheres=spheres,
                                          n_panels=n_panels, columns=cols,
                                          title=f"{label}{f' (cf. the paper Fig. {snap})' if snap else ''}: "
                                                "the body at its states (collision boxes; axes in m, equal scales)"),
            scenario_plots.plot_momenta(result, out / f"{name}_momenta.png", sim_result=sim_result,
                                        figures=(mom1, mom2),
                                        title=f"{label}: momenta about the world origin, planned"
                                              + (" and simulated" if sim_result is not None else "")),
            scenario_plots.plot_zmp(robot, result, out / f"{name}_zmp.png", sim_result=sim_result, figure=zmp,
                                    title=f"{label}: zero-moment point"),
        ]
    files += [p.name for p in paths]
    with progress.stage(f"{name}: animation"):
        gif = scenario_plots.animate(robot, result, out / f"{name}.gif", spheres=spheres,
                                     max_frames=settings["max_frames"])
    files.append(gif.name)
    entry = report.scenario_entry(result, metrics, extra={"files": files})
    entry["notes"] = list(entry["notes"]) + notes
    return entry


def _settings(args) -> dict:
    s = FAST if args.fast else NORMAL
    return {"method": args.method, "seed": args.seed, "map": args.map or "shipped (workspace.default_map('head'))",
            "fast": bool(args.fast), "speed_rad_s": s["speed"], "min_segment_s": s["min_segment"],
            "simulation": not args.no_sim and _sim_available()}


def _finish(command: str, out: Path, entries: dict, progress: Progress, args, notes=()) -> int:
    from . import report

    rep = {"command": command, "scenarios": entries, "settings": _settings(args),
           "run_time_s": progress.elapsed(), "stages": progress.stages, "notes": list(notes),
           "paper": report.PAPER, **report.environment()}
    report.write_json(rep, out / "report.json")
    report.write_summary(rep, out / "summary.md")
    ok = all(e["success"] for e in entries.values())
    progress.say(f"done in {progress.elapsed():.1f} s")
    print(f"snakehead {command}: wrote report.json, summary.md and "
          f"{sum(len(e['files']) for e in entries.values())} other files to {out.resolve()}")
    for name, e in entries.items():
        print(f"  {name}: {'success' if e['success'] else 'NOT successful'}")
    return 0 if ok else 1


def _demo(args: argparse.Namespace) -> int:
    from . import scenarios, sim

    out = _writable_dir(args.out)
    progress = Progress()
    progress.say(f"snakehead demo -> {out}{' (--fast)' if args.fast else ''}")
    controller = _controller(args, progress)
    s = FAST if args.fast else NORMAL
    spheres = [(scenarios.SPHERE_1, scenarios.SPHERE_DIAMETER), (scenarios.SPHERE_2, scenarios.SPHERE_DIAMETER)]
    entries = {}
    entries["spheres"] = _run_scenario(
        "spheres", lambda c: scenarios.catch_spheres(c, speed=s["speed"], min_segment=s["min_segment"]),
        controller, out, args, progress, spheres=spheres, figures=(17, 18, 19, 20),
        label="catching the spheres (Section 4.1)")
    # 32 strips: the staircase inscribed in the round hole is then within 0.3 mm of the circle where the
    # head's corners pass (the default 8 strips block a head rolled ~45 deg that the round hole lets through)
    wall = sim.wall_with_hole(hole_center=scenarios.HOLE_CENTRE, wall_size=scenarios.WALL_SIZE,
                              hole_diameter=scenarios.HOLE_DIAMETER, slices=HOLE_SLICES)
    entries["hole"] = _run_scenario(
        "hole", lambda c: scenarios.through_hole(c, speed=s["speed"], min_segment=s["min_segment"]),
        controller, out, args, progress, sim_obstacles=wall, figures=(22, 23, 24, 25),
        label="getting through the hole (Section 4.2)")
    notes = [f"the simulated wall is {len(wall)} boxes: the round hole is a staircase of {HOLE_SLICES} strips "
             "inscribed in it (sim.wall_with_hole), standing on the ground",
             "planned errors are the head's by forward kinematics of the planned joints; the simulated ones are "
             "MuJoCo's at the times the plan reaches each target; the paper's momentum errors are magnitude errors "
             "(our max_*_momentum_magnitude_error), ours without 'magnitude' are of the vector difference"]
    return _finish("demo", out, entries, progress, args, notes)


def _plan(args: argparse.Namespace) -> int:
    from . import scenarios

    position = np.array(args.position, float)
    direction = np.array(args.direction, float)
    norm = float(np.linalg.norm(direction))
    if norm < 1e-9:
        raise UsageError(f"--direction must not be zero, got {args.direction}")
    direction = direction / norm
    out = _writable_dir(args.out)
    progress = Progress()
    progress.say(f"snakehead plan: head to {position.tolist()} m along {np.round(direction, 4).tolist()} -> {out}")
    controller = _controller(args, progress)
    s = FAST if args.fast else NORMAL
    entries = {"target": _run_scenario(
        "target", lambda c: scenarios.reach_target(c, position, direction, speed=s["speed"],
                                                   min_segment=s["min_segment"]),
        controller, out, args, progress, figures=(None, 18, 19, 20),
        label=f"the head to ({', '.join(f'{v:g}' for v in position)}) m along "
              f"({', '.join(f'{v:.3g}' for v in direction)})", solution_figure=True)}
    return _finish("plan", out, entries, progress, args)


# ----------------------------------------------------------------------------------------------
# workspace
# ----------------------------------------------------------------------------------------------
def _workspace(args: argparse.Namespace) -> int:
    from . import workspace
    from .robot import SnakeRobot

    out = Path(args.out)
    if out.suffix != ".npz":
        raise UsageError(f"--out must end in .npz, got {args.out!r}")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise UsageError(f"the directory of --out {args.out!r} does not exist")
    if not os.access(parent, os.W_OK):
        raise UsageError(f"cannot write to the directory of --out {args.out!r}")
    robot = SnakeRobot.default()
    chain = robot.head_chain if args.part == "head" else robot.head6_chain
    t0 = time.perf_counter()
    print(f"snakehead workspace: {args.part} chain {chain.base} -> {chain.tip}, voxel {args.voxel} m, "
          f"{args.directions} directions x {args.rolls} rolls", file=sys.stderr, flush=True)
    m = workspace.compute(chain, voxel=args.voxel, directions=args.directions, rolls=args.rolls,
                          free_roll=args.free_roll, timeout=args.timeout, seed=args.seed, threads=args.threads,
                          shard=args.shard, progress=not args.quiet)
    workspace.save(m, out)
    dexterous = int(np.sum(m.indices >= 100.0))
    print(f"snakehead workspace: {len(m)} voxels, {dexterous} dexterous (index 100), in "
          f"{time.perf_counter() - t0:.1f} s; wrote {out.resolve()}")
    return 0


# ----------------------------------------------------------------------------------------------
# the parser
# ----------------------------------------------------------------------------------------------
def _add_planning_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (created if needed)")
    p.add_argument("--no-sim", action="store_true", help="skip the MuJoCo dynamics check")
    p.add_argument("--seed", type=_seed, default=1, metavar="N",
                   help="seed of the head's TRAC-IK (the plan is a function of it; default 1)")
    p.add_argument("--method", choices=("rotated", "free_roll"), default="rotated",
                   help="head IK: the paper's rotated frames (Fig. 9, default) or one call with the roll free")
    p.add_argument("--map", default=None, metavar="MAP.npz",
                   help="the head's reachability map (default: the one shipped with the package)")
    p.add_argument("--fast", action="store_true",
                   help=f"quicker run of the same pipeline: joints planned at {FAST['speed']} rad/s instead of "
                        f"{NORMAL['speed']} with {FAST['min_segment']:g} s segments (shorter motions, so fewer 2 ms "
                        f"samples to check and simulate) and {FAST['max_frames']}-frame animations")


_OUTPUTS = """outputs (in DIR):
  report.json               per scenario: success, targets (errors), min ZMP margin, min ground clearance,
                            planning time, sim (null without MuJoCo or with --no-sim), the paper's figures
  summary.md                the same, readable
  NAME_trajectory.csv       time_s and the 16 joint angles (rad) every 2 ms
  NAME_snapshots.png        the body in 3-D at the scenario's states (Figs. 17 / 22)
  NAME_momenta.png          planned (and simulated) angular and linear momenta (Figs. 18-19 / 23-24)
  NAME_zmp.png              the ZMP in the support polygon (Figs. 20 / 25)
  NAME.gif                  an animation of the motion
"""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="snakehead", description=__doc__.split("\n\n")[0],
                                     epilog=__doc__.split("\n\n", 1)[1],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    p = sub.add_parser("info", help="describe the default robot and print its head pose at q = 0",
                       description="Describe the default robot and print its head pose at q = 0.")
    p.set_defaults(func=_info)

    p = sub.add_parser("demo", help="the paper's two scenarios (Section 4) with figures, animations and a report",
                       description="Plan the paper's two scenarios on the default robot (catching two spheres, "
                                   "Section 4.1; getting the head through a hole in a wall, Section 4.2), check them "
                                   "in MuJoCo (the hole's wall included), and write a report, trajectories, "
                                   "figures and animations. NAME is spheres and hole.",
                       epilog=_OUTPUTS, formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_planning_options(p)
    p.set_defaults(func=_demo)

    p = sub.add_parser("plan", help="one head target: position and direction",
                       description="Plan the head from the controller's initial state to POSITION pointing along "
                                   "DIRECTION (world frame, z up, ground at z = 0) with the scenarios' machinery, "
                                   "check it, and write the same outputs as demo with NAME = target.",
                       epilog=_OUTPUTS, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--position", type=_finite_float, nargs=3, required=True, metavar=("X", "Y", "Z"),
                   help="desired head position (m, world)")
    p.add_argument("--direction", type=_finite_float, nargs=3, required=True, metavar=("DX", "DY", "DZ"),
                   help="desired head direction (the head link's x-axis; any non-zero length)")
    _add_planning_options(p)
    p.set_defaults(func=_plan)

    p = sub.add_parser("workspace", help="compute a reachability map of the head (Algorithm 1)",
                       description="Compute the reachability map of the default robot's head (7 DOF, 'head') or its "
                                   "6-DOF variant ('head6') with snakehead.workspace.compute and save it as .npz. "
                                   "For other robots, shards over many machines or without Python, use the "
                                   "workspace_gen executable installed with the package (workspace_gen --help).")
    p.add_argument("--out", required=True, metavar="MAP.npz", help="output file (.npz)")
    p.add_argument("--part", choices=("head", "head6"), default="head", help="which head chain (default head)")
    p.add_argument("--voxel", type=_positive_float, default=0.05, metavar="M", help="voxel edge (m, default 0.05)")
    p.add_argument("--directions", type=_positive_int, default=20, metavar="N",
                   help="points per voxel sphere (default 20)")
    p.add_argument("--rolls", type=_positive_int, default=4, metavar="R",
                   help="frames about the approach axis per point (default 4)")
    p.add_argument("--free-roll", action="store_true", help="one IK call per point with the roll left free")
    p.add_argument("--timeout", type=_positive_float, default=3e-4, metavar="S",
                   help="TRAC-IK budget per call (s, default 0.0003)")
    p.add_argument("--seed", type=_seed, default=1, metavar="N", help="random seed (default 1)")
    p.add_argument("--threads", type=_positive_int, default=None, metavar="N", help="worker threads (default all)")
    p.add_argument("--shard", default=None, metavar="i/N", help="compute only shard i of N (merge them afterwards)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_workspace)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except KeyboardInterrupt:
        print("snakehead: interrupted", file=sys.stderr)
        return 130
    except (UsageError, ValueError, TypeError, OSError) as exc:
        if os.environ.get("SNAKEHEAD_TRACEBACK"):
            raise
        print(f"snakehead {args.command}: error: {exc}", file=sys.stderr)
        return 2
