"""Whose fault is it? (issue 21): bad input is snakehead.InputError (the CLI's exit 2, and only it); valid input
without an answer is snakehead.Infeasible (exit 1); anything else on valid input is a bug (exit 3)."""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import snakehead
from snakehead import Infeasible, InputError, InputTypeError, InternalError, _core
from snakehead._errors import invariant
from snakehead._files import write_text_atomic
from snakehead.app import cli, pipeline
from snakehead.model.robot_file import read_toml


def _main(argv: list[str], capsys: pytest.CaptureFixture) -> tuple[int, str]:
    try:
        code = cli.main(argv)
    except SystemExit as exc:  # argparse's own errors (exit 2 with one line) end the program
        code = int(exc.code)
    return code, capsys.readouterr().err


# --- the types ------------------------------------------------------------------------------------------------
def test_the_types_say_whose_fault_it_is():
    assert issubclass(InputError, ValueError) and issubclass(InputTypeError, InputError)
    assert issubclass(InputTypeError, TypeError)
    assert not issubclass(Infeasible, ValueError)  # caught by name, never by an `except ValueError`
    assert issubclass(InternalError, AssertionError)
    invariant(True, "never raised")
    with pytest.raises(InternalError, match="broken"):
        invariant(False, "broken")


def test_the_core_raises_input_error_for_bad_input():
    with pytest.raises(InputError, match="malformed URDF"):
        _core.urdf_root_link("<robot")
    with pytest.raises(InputError, match="unknown tip link 'nope' in URDF robot 'r'"):
        snakehead.Chain.from_urdf("<robot name='r'><link name='a'/></robot>", "a", "nope")


def test_validators_raise_input_errors():
    from snakehead import _validate

    with pytest.raises(InputTypeError, match="x must be numbers, got str '1'"):
        _validate.finite_array("1", "x")
    with pytest.raises(InputError, match="NaN"):
        _validate.vector3([np.nan, 0, 0], "x")
    with pytest.raises(InputError, match="1000 m"):
        _validate.world_position([1e308, 0, 0], "p")


# --- the command line's exit statuses -------------------------------------------------------------------------
def test_cli_exit_statuses_follow_the_exception_type(monkeypatch, capsys, tmp_path):
    """InputError -> 2, Infeasible -> 1, any other exception -> 3 with "this is a bug" (a ValueError too: an
    internal step's refusal is not the user's mistake)."""
    def raising(exc: BaseException):
        def run_scenes(*args, **kwargs):
            raise exc
        return run_scenes

    argv = ["plan", "--position", "0.9", "0.3", "0.3", "--direction", "1", "0", "0", "--out", str(tmp_path),
            "--no-sim"]
    for exc, code, text in [(InputError("field x is wrong"), 2, "error: field x is wrong"),
                            (Infeasible("no curl on this base"), 1, "not possible: no curl on this base"),
                            (ValueError("neck_length must be > 0, got 0.0"), 3, "this is a bug"),
                            (TypeError("unsupported operand"), 3, "this is a bug"),
                            (InternalError("an invariant"), 3, "this is a bug")]:
        monkeypatch.setattr(pipeline, "run_scenes", raising(exc))
        got, err = _main(argv, capsys)
        assert got == code, (exc, err)
        assert text in err.strip().splitlines()[-1], err  # the last line (the progress lines come before it)


def test_a_long_error_is_still_one_short_line(monkeypatch, capsys, tmp_path):
    def run_scenes(*args, **kwargs):
        raise ValueError("x" * 5000 + "\n" + "y" * 5000)

    monkeypatch.setattr(pipeline, "run_scenes", run_scenes)
    code, err = _main(["plan", "--position", "0.9", "0.3", "0.3", "--direction", "1", "0", "0", "--out",
                       str(tmp_path), "--no-sim"], capsys)
    assert code == 3
    line = err.strip().splitlines()[-1]
    assert "this is a bug" in line and len(line) < cli.MAX_ERROR_CHARS + 300


@pytest.mark.parametrize("position, message", [
    (["-inf", "0.5", "0.4"], "must be a finite number"),     # was "expected 3 arguments": -inf read as an option
    (["1e308", "0.5", "0.4"], "farther than 1000 m"),         # was an internal error drawing the figures
    (["nan", "0.5", "0.4"], "must be a finite number"),
])
def test_cli_positions(position, message, capsys, tmp_path):
    code, err = _main(["plan", "--position", *position, "--direction", "0", "1", "0", "--out", str(tmp_path),
                       "--no-sim"], capsys)
    assert code == 2 and message in err, err


def test_negative_numbers_in_any_notation_are_numbers(monkeypatch, capsys, tmp_path):
    """argparse alone reads "-1e-1" and "-.5e1" as options; they are numbers. A huge direction is normalised
    without an overflow warning."""
    seen = []

    def run_scenes(scenes, *args, **kwargs):
        seen.append(scenes[0])
        return {"scenarios": {}}

    monkeypatch.setattr(pipeline, "run_scenes", run_scenes)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        code, err = _main(["plan", "--position", "-1e-1", "-.5e1", "0.4", "--direction", "1e308", "1e308", "0",
                           "--out", str(tmp_path), "--no-sim"], capsys)
    assert code == 0, err
    target = seen[0].targets[0]
    np.testing.assert_allclose(target.position, [-0.1, -5.0, 0.4])
    np.testing.assert_allclose(target.direction, [np.sqrt(0.5), np.sqrt(0.5), 0.0])


# --- files ------------------------------------------------------------------------------------------------------
def test_deeply_nested_toml_is_bad_input(tmp_path, capsys):
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "[" * 3000 + "]" * 3000 + "\n")
    with pytest.raises(InputError, match="too deeply"):
        read_toml(deep, "scene file")
    for argv in (["plan", "--scene", str(deep), "--out", str(tmp_path / "o")], ["info", "--robot", str(deep)]):
        code, err = _main(argv, capsys)
        assert code == 2 and "nests arrays or tables too deeply" in err, err


def test_a_byte_order_mark_is_read_as_absent(tmp_path):
    scene = snakehead.scenes.paper_scene("spheres")
    source = Path(scene.path).read_text(encoding="utf-8")
    bom = tmp_path / "bom.toml"
    bom.write_text("\ufeff" + source, encoding="utf-8")
    again = snakehead.load_scene(bom)
    assert [t.name for t in again.targets] == [t.name for t in scene.targets]


def test_a_directory_is_not_said_to_be_missing(tmp_path):
    (tmp_path / "snake.urdf").mkdir()
    robot = tmp_path / "r.toml"
    robot.write_text('urdf = "snake.urdf"\nbase_end = "base_end"\nneck_end = "neck_end"\nhead_tip = "head_tip"\n')
    with pytest.raises(InputError, match="is a directory"):
        snakehead.SnakeRobot.from_file(robot)


def test_an_output_that_cannot_be_written_names_the_file(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(InputError, match="cannot write .*report.json"):
        write_text_atomic(blocker / "report.json", "{}")


# --- far targets ------------------------------------------------------------------------------------------------
def test_a_target_beyond_the_relocation_range_fails_as_out_of_range():
    """A target 12 m away is valid input: the plan fails at once, saying why, instead of relocating the base
    across the world (a target 1e6 m away, once "planned" with a kilometre's relocation, is now bad input)."""
    from snakehead.planning.base_choice import MAX_RELOCATION_M

    robot = snakehead.SnakeRobot.default()
    far = MAX_RELOCATION_M + robot.body_length + 0.5
    result = snakehead.plan([([far, 0.3, 0.3], [1.0, 0.0, 0.0])], robot=robot)
    assert not result.success and result.relocation is None
    assert "out of range" in result.failure and f"{MAX_RELOCATION_M:g} m" in result.failure
    with pytest.raises(InputError, match="farther than 1000 m"):
        snakehead.plan([([1e6, 0.3, 0.3], [1.0, 0.0, 0.0])], robot=robot)


# --- validate once: after plan() has checked its input, an InputError inside is a bug -------------------------
def test_an_input_error_inside_plan_is_an_internal_error(monkeypatch):
    from snakehead.planning import planner

    robot = snakehead.SnakeRobot.default()
    with pytest.raises(InputError, match="method"):  # the caller's input, found where it entered
        snakehead.plan([([0.9, 0.3, 0.3], [1.0, 0.0, 0.0])], robot=robot, method="fast")

    def refusing(*args, **kwargs):  # an internal step that refuses what the planner computed
        raise InputError("neck_length must be > 0, got 0.0")

    monkeypatch.setattr(planner, "bending_state", refusing)
    with pytest.raises(InternalError, match="this is a bug") as caught:
        snakehead.plan([([0.9, 0.3, 0.3], [1.0, 0.0, 0.0])], robot=robot)
    assert not isinstance(caught.value, InputError)


def test_a_too_long_line_approach_is_refused_before_any_work(monkeypatch):
    from snakehead.planning import planner
    from snakehead.scenes import Scene, Target

    def never(*args, **kwargs):
        raise AssertionError("solved a target before the input was checked")

    monkeypatch.setattr(planner, "choose_base", never)
    scene = Scene(name="line", targets=(Target("a", [0.9, 0.3, 0.3], [1, 0, 0]),
                                        Target("b", [0.9, -0.3, 0.3], [1, 0, 0], approach="line", step_m=1e-4)))
    with pytest.raises(InputError, match="take a larger step_m"):
        snakehead.plan(scene)


def test_the_figure_process_keeps_the_fault_of_its_errors():
    """Figures are drawn in a forked process beside the simulation: an output it cannot write is still the user's
    (InputError, exit 2); anything else that goes wrong there is still a bug."""
    def unwritable(progress):
        raise InputError("cannot write '/full/figure.png': No space left on device")

    def broken(progress):
        raise KeyError("a bug")

    with pytest.raises(InputError, match="No space left"):
        pipeline.Beside(unwritable, pipeline.Progress()).files()
    with pytest.raises(RuntimeError, match="KeyError"):
        pipeline.Beside(broken, pipeline.Progress()).files()


def test_a_figure_process_that_dies_is_replaced_by_drawing_here(monkeypatch):
    """The forked figure process of a process with threads can crash (a SIGSEGV was seen once under load) or hang:
    the figures are then drawn in the main process, and the user is told, instead of the run ending as a bug or
    never ending. (The child is killed by SIGKILL here: a SIGSEGV would meet pytest's faulthandler, which can hang
    in a forked child -- the very case the time bound is for.)"""
    import os
    import signal
    import time

    parent = os.getpid()

    def dies_when_forked(progress):
        if os.getpid() != parent:
            os.kill(os.getpid(), signal.SIGKILL)
        return ["drawn here.png"]

    def hangs_when_forked(progress):
        if os.getpid() != parent:
            time.sleep(3600)
        return ["drawn here.png"]

    for work, said_what in [(dies_when_forked, "died (exit code -9)"), (hangs_when_forked, "gave no answer in 1 s")]:
        monkeypatch.setattr("snakehead.app.beside.FIGURE_PROCESS_TIMEOUT_S", 1.0)
        progress = pipeline.Progress()
        said: list[str] = []
        monkeypatch.setattr(progress, "say", said.append)
        assert pipeline.Beside(work, progress).files() == ["drawn here.png"]
        assert any(said_what in line for line in said), said


def test_an_obstacle_kind_of_the_wrong_type_is_bad_input():
    from snakehead.scenes.scene import scene_from_dict

    with pytest.raises(InputError, match="kind must be one of"):
        scene_from_dict({"name": "s", "targets": [{"name": "a", "position": [0.9, 0.3, 0.3], "direction": [1, 0, 0]}],
                         "obstacles": [{"kind": ["box"], "centre": [1, 1, 0.1], "size": [0.1, 0.1, 0.1]}]})


def test_the_figure_process_never_collects_the_parents_solvers(monkeypatch):
    """A TracIK left in a reference cycle when the figure process forks (its worker threads are the parent's) is not
    collected in the child (gc.freeze: the child's collections leave the parent's objects alone). That once kept the
    child alive -- the destructor joined threads the child does not have (SIGSEGV in 'Garbage-collecting'); the core
    is fork-safe now (test_trac_ik_fork.py). The child's own garbage is collected."""
    import gc
    import os

    from snakehead import SnakeRobot, TracIK

    ik = TracIK.from_chain(SnakeRobot.default().body)
    q0 = np.full(ik.chain.n_joints, 0.1)
    assert ik.ik(ik.fk(q0), np.zeros_like(q0)) is not None  # its worker threads ran
    cycle: list = [ik]
    cycle.append(cycle)  # unreachable once dropped: only the collector frees it
    del ik
    del cycle
    parent = os.getpid()

    def collects(progress):
        gc.collect()
        return [f"drawn {'beside' if os.getpid() != parent else 'here'}"]

    monkeypatch.setattr("snakehead.app.beside.FIGURE_PROCESS_TIMEOUT_S", 20.0)  # a regression hangs (the join)
    gc.disable()  # the cycle must still be there at the fork
    try:
        assert pipeline.Beside(collects, pipeline.Progress()).files() == ["drawn beside"]
    finally:
        gc.enable()
    assert gc.collect() > 0  # and the parent frees it


def test_a_process_beside_raises_snakeheads_own_errors_as_they_are():
    """A lane of scenes plans in a forked process: an Infeasible or an InternalError raised there is raised in the
    parent as it is (its fault and exit code), not as a bug of the process beside."""
    from snakehead import Infeasible, InternalError, MotionTooLong

    for error in (Infeasible("no base placement"), MotionTooLong("too long"), InternalError("broken invariant")):
        def fails(progress, error=error):
            raise error

        with pytest.raises(type(error), match=str(error)):
            pipeline.Beside(fails, pipeline.Progress()).result()
