"""The core's limits and the sweeps' defaults are each defined once: the limits in C++ (include/snakehead/limits.hpp,
read by snakehead.limits from the bindings), a head map's defaults in C++ (WorkspaceOptions, read by
snakehead.sweep_defaults), a reach map's in snakehead.sweep_defaults; the API's signatures, the command line's defaults
and help, and the modules that check options read them from there."""
from __future__ import annotations

import ast
import inspect
import re
from pathlib import Path

import pytest

import snakehead
from snakehead import _core, _validate, limits
from snakehead import sweep_defaults as defaults
from snakehead.app import cli
from snakehead.kinematics import reachability as ws
from snakehead.planning import whole_body_reach as rc

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = Path(snakehead.__file__).parent
#: The header's name of each Python name.
CPP_NAMES = {"MAX_TIMEOUT_S": "kMaxTimeoutSeconds", "MAX_URDF_BYTES": "kMaxUrdfBytes", "MAX_URDF_DEPTH": "kMaxUrdfDepth",
             "MAX_IK_JOINTS": "kMaxIKJoints", "MAX_VOXELS_PER_AXIS": "kMaxVoxelsPerAxis",
             "MAX_DIRECTIONS": "kMaxDirections", "MAX_ROLLS": "kMaxRolls", "MAX_FRAMES_PER_VOXEL": "kMaxFramesPerVoxel",
             "MAX_CLOUD_SAMPLES": "kMaxCloudSamples", "MAX_THREADS": "kMaxThreads",
             "MAX_TERRAIN_CELLS": "kMaxTerrainCells", "MAX_TERRAIN_TRIANGLES": "kMaxTerrainTriangles"}


def cpp_value(text: str) -> float:
    """A C++ constant expression of the headers' kinds (``8u << 20``, ``10'000'000``, ``86400.0``) as a number."""
    text = text.replace("'", "")
    text = re.sub(r"(?<=\d)[uU]?[lL]*\b", "", text)
    tree = ast.parse(text, mode="eval")
    for node in ast.walk(tree):  # numbers and << only: never evaluate anything else
        assert isinstance(node, (ast.Expression, ast.Constant, ast.BinOp, ast.LShift)), ast.dump(node)
    return eval(compile(tree, "<header>", "eval"))  # noqa: S307 -- checked above: literals and shifts


def header_constants(path: Path) -> dict[str, float]:
    """``constexpr TYPE NAME = VALUE;`` of a header, read from its text (independent of the bindings)."""
    pattern = re.compile(r"constexpr\s+[\w:]+\s+(k\w+)\s*=\s*([^;]+);")
    return {m.group(1): cpp_value(m.group(2)) for m in pattern.finditer(path.read_text())}


def header_defaults(path: Path, struct: str) -> dict[str, str]:
    """``TYPE NAME = VALUE;`` of a struct's members in a header, as text."""
    body = re.search(rf"struct {struct} \{{(.*?)\n\}};", path.read_text(), re.S)
    assert body, struct
    return {m.group(1): m.group(2).strip() for m in re.finditer(r"^\s+[\w:]+\s+(\w+)\s*=\s*([^;]+);", body.group(1),
                                                                    re.M)}


def test_the_python_limits_are_the_headers():
    header = header_constants(ROOT / "include/snakehead/limits.hpp")
    assert set(CPP_NAMES.values()) == set(header)  # every limit of the header has its Python name
    assert set(limits.CORE_LIMITS) == set(CPP_NAMES) == set(limits.__all__) - {"CORE_LIMITS"}
    for name, cpp in CPP_NAMES.items():
        assert getattr(limits, name) == header[cpp], name
        assert getattr(_core.Limits, name) == header[cpp], name
    assert header["kMaxDirections"] == 4096 and header["kMaxUrdfBytes"] == 8 << 20  # the parser itself


def test_the_checks_read_the_core_limits():
    for name in ("MAX_DIRECTIONS", "MAX_ROLLS", "MAX_FRAMES_PER_VOXEL", "MAX_VOXELS_PER_AXIS", "MAX_CLOUD_SAMPLES",
                 "MAX_THREADS", "MAX_TIMEOUT_S"):
        assert getattr(ws, name) == getattr(limits, name), name
    assert _validate.MAX_DURATION_S == limits.MAX_TIMEOUT_S
    assert rc.MAX_WORKERS == limits.MAX_THREADS
    assert ws.MAX_SHARDS == (limits.MAX_VOXELS_PER_AXIS // 4) ** 2  # the largest grid's tiles of 4 x 4 lines


def module_level_literals(name: str) -> list[str]:
    """The modules of the package (but snakehead.limits) that assign ``name`` a number literal at module level
    (alone or in a tuple assignment)."""
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name == "limits.py" and path.parent == PACKAGE:
            continue
        for node in ast.parse(path.read_text()).body:
            if not isinstance(node, (ast.Assign, ast.AnnAssign)) or node.value is None:
                continue
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                pairs = (zip(target.elts, node.value.elts) if isinstance(target, ast.Tuple)
                         and isinstance(node.value, ast.Tuple) else [(target, node.value)])
                out += [str(path.relative_to(PACKAGE)) for t, v in pairs
                        if isinstance(t, ast.Name) and t.id == name and isinstance(v, ast.Constant)]
    return out


#: Limits of the same name that are another thing's: a reach map's directions (each a whole-body solve) are far fewer.
OWN_LIMITS = {"MAX_DIRECTIONS": ["planning/whole_body_reach.py"]}


@pytest.mark.parametrize("name", sorted(CPP_NAMES))
def test_no_module_repeats_a_core_limit(name):
    assert module_level_literals(name) == OWN_LIMITS.get(name, [])


def test_a_reach_maps_own_direction_limit_is_within_the_cores():
    assert 1 <= rc.MAX_DIRECTIONS < limits.MAX_DIRECTIONS


def test_a_head_maps_defaults_are_the_cores():
    """sweep_defaults' head map = WorkspaceOptions' defaults, read from the header's text and from the bindings."""
    header = header_defaults(ROOT / "include/snakehead/workspace.hpp", "WorkspaceOptions")
    core = _core.WorkspaceOptions()
    for ours, member in (("HEAD_VOXEL_M", "voxel_size"), ("HEAD_DIRECTIONS", "directions"), ("HEAD_ROLLS", "rolls"),
                         ("HEAD_TIMEOUT_S", "timeout"), ("HEAD_EPSILON", "epsilon"),
                         ("HEAD_CLOUD_SAMPLES", "cloud_samples"), ("HEAD_SEED", "seed"), ("HEAD_SHRINK", "shrink")):
        assert getattr(defaults, ours) == getattr(core, member) == cpp_value(header[member]), ours


def parameter_defaults(fn) -> dict:
    return {k: p.default for k, p in inspect.signature(fn).parameters.items() if p.default is not p.empty}


def test_the_api_takes_its_defaults_from_sweep_defaults():
    head = dict(voxel=defaults.HEAD_VOXEL_M, directions=defaults.HEAD_DIRECTIONS, rolls=defaults.HEAD_ROLLS,
                timeout=defaults.HEAD_TIMEOUT_S, epsilon=defaults.HEAD_EPSILON, seed=defaults.HEAD_SEED)
    for fn in (ws.compute, ws.evaluate, snakehead.compute_map):
        got = parameter_defaults(fn)
        assert {k: got[k] for k in head} == head, fn.__name__
    assert parameter_defaults(ws.compute)["cloud_samples"] == defaults.HEAD_CLOUD_SAMPLES
    assert parameter_defaults(ws.compute)["shrink"] == defaults.HEAD_SHRINK
    reach = dict(voxel=defaults.REACH_VOXEL_M, directions=defaults.REACH_DIRECTIONS)
    for fn in (rc.compute_reach, rc.check_options):
        got = parameter_defaults(fn)
        assert {k: got[k] for k in reach} == reach, fn.__name__


def test_default_map_options_scale_the_voxel_by_the_shared_share():
    robot = snakehead.SnakeRobot.default()
    o = ws.default_map_options(robot)
    reach = robot.head_chain.reach
    assert abs(o["voxel"] - reach / 12) <= 0.0025 + 1e-12 and round(o["voxel"] / 0.005, 9) % 1 == 0
    assert (o["directions"], o["rolls"], o["timeout"], o["seed"]) == (
        defaults.HEAD_DIRECTIONS, defaults.HEAD_ROLLS, defaults.HEAD_TIMEOUT_S, defaults.HEAD_SEED)


def subcommand(parser, name: str):
    for action in parser._subparsers._group_actions:
        if name in action.choices:
            return action.choices[name]
    raise KeyError(name)


def option(sub, flag: str):
    return next(a for a in sub._actions if flag in a.option_strings)


def test_the_cli_defaults_and_help_come_from_the_shared_definitions(monkeypatch):
    """The defaults and limits the help states are read when the parser is built: changed values show up in both."""
    changed = dict(HEAD_DIRECTIONS=21, HEAD_ROLLS=3, HEAD_TIMEOUT_S=0.0007, HEAD_SEED=5, REACH_VOXEL_M=0.13,
                   REACH_DIRECTIONS=9)
    for name, value in changed.items():
        monkeypatch.setattr(defaults, name, value)
    monkeypatch.setattr(rc, "MAX_WORKERS", 17)
    parser = cli.build_parser()
    work, reach = subcommand(parser, "workspace"), subcommand(parser, "reach")
    expect = [(work, "--directions", 21, "(default 21)"), (work, "--rolls", 3, "(default 3)"),
              (work, "--timeout", 0.0007, "default 0.0007"), (work, "--seed", 5, "(default 5)"),
              (reach, "--voxel", 0.13, "default 0.13"), (reach, "--directions", 9, "(default 9)")]
    for sub, flag, value, said in expect:
        assert option(sub, flag).default == value, flag
        assert said in sub.format_help().replace("\n", " ").replace("  ", " "), flag
    assert reach.parse_args(["--workers", "17"]).workers == 17
    with pytest.raises(SystemExit, match="^2$"):  # argparse's usage error
        reach.parse_args(["--workers", "18"])


def test_the_cli_states_the_core_limits():
    parser = cli.build_parser()
    text = " ".join(subcommand(parser, "workspace").format_help().split())
    for said in (f"1 to {limits.MAX_DIRECTIONS}", f"1 to {limits.MAX_ROLLS}", f"at most {limits.MAX_FRAMES_PER_VOXEL}",
                 f"at most {limits.MAX_TIMEOUT_S:g}", f"1 to {limits.MAX_THREADS}",
                 f"{limits.MAX_VOXELS_PER_AXIS} voxels per axis"):
        assert said in text, said
    assert option(subcommand(parser, "workspace"), "--directions").default == defaults.HEAD_DIRECTIONS
    assert option(subcommand(parser, "reach"), "--directions").default == defaults.REACH_DIRECTIONS
