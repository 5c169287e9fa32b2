"""Many targets in one scene: progress per target (``plan(progress=...)`` and the command line's lines), the bounds
on a scene's size and its motion's length checked before anything is solved, and the checks made a chunk of samples
at a time (the same results). Memory itself is measured by bench/many_targets.py, not here."""
from __future__ import annotations

import re
from dataclasses import replace

import numpy as np
import pytest

import snakehead
from snakehead import InputError, PlanProgress
from snakehead._errors import Infeasible, MotionTooLong
from snakehead.dynamics import stability
from snakehead.model.robot import SnakeRobot
from snakehead.planning import plan_bounds, waypoints
from snakehead.retiming import timing
from snakehead.samples.targets import reachable_targets
from snakehead.scenes import MAX_TARGETS, Scene, Target, load_scene, scene_from_dict
from snakehead.solve import whole_body
from snakehead.solve.head_controller import HeadController


@pytest.fixture(scope="module")
def controller():
    return HeadController(SnakeRobot.default(), method="free_roll", seed=0)


@pytest.fixture(scope="module")
def poses(controller):
    """Three head poses reachable by construction (stable, collision-free whole-body configurations)."""
    return reachable_targets(controller, "same", 3, np.random.default_rng(0))


@pytest.fixture(scope="module")
def three(poses):
    return Scene(name="three", targets=tuple(Target(f"t{k + 1}", p.position, p.direction, hold_s=0.1)
                                             for k, p in enumerate(poses)))


@pytest.fixture(scope="module")
def planned(three, controller):
    records: list = []
    result = snakehead.plan(three, controller=controller, progress=records.append)
    return result, records


@pytest.fixture
def no_solving(monkeypatch):
    """Fail the test if a target is solved (a refusal must come before any work)."""
    def solve(*args, **kwargs):
        raise AssertionError("a target was solved before the input was refused")
    monkeypatch.setattr(whole_body, "solve_target", solve)


def _toml(targets: list[tuple[str, np.ndarray, np.ndarray]], hold_s: float = 0.1) -> str:
    out = []
    for name, p, d in targets:
        out += ["[[targets]]", f'name = "{name}"', f"position = [{', '.join(repr(float(v)) for v in p)}]",
                f"direction = [{', '.join(repr(float(v)) for v in d)}]", f"hold_s = {hold_s}", ""]
    return "\n".join(out)


# ------------------------------------------------------------------------------------------------
# progress
# ------------------------------------------------------------------------------------------------
def test_progress_once_per_target_in_order(planned):
    result, records = planned
    assert all(isinstance(r, PlanProgress) for r in records)
    done = [r for r in records if r.kind == "target"]
    assert [(r.index, r.count, r.name) for r in done] == [(1, 3, "t1"), (2, 3, "t2"), (3, 3, "t3")]
    assert [r.solved for r in done] == [tg.solved for tg in result.targets]
    assert all(r.message == "" for r in done if r.solved)
    assert all(r.seconds >= 0 for r in done)
    elapsed = [r.elapsed_s for r in records]
    assert elapsed == sorted(elapsed) and elapsed[-1] <= result.planning_time_s
    # the stages over the whole plan, in order around the targets
    kinds = [r.name if r.kind == "stage" else "target" for r in records]
    assert kinds == ["base", "target", "target", "target", "timing", "checks"]
    assert all(r.message for r in records if r.kind == "stage")


def test_progress_of_line_approaches_and_via_poses_in_scene_order(poses, controller):
    """Targets approached along a line are solved backwards from the deepest; progress still comes in the scene's
    order, once per target, via poses included."""
    p, d = poses[0].position, poses[0].direction
    scene = Scene(name="line", targets=(Target("a", p - 0.02 * d, d), Target("b", p - 0.01 * d, d, via=True,
                                                                            approach="line"),
                                        Target("c", p, d, approach="line", hold_s=0.1)))
    records: list = []
    snakehead.plan(scene, controller=controller, progress=records.append)
    assert [(r.index, r.count, r.name) for r in records if r.kind == "target"] == [(1, 3, "a"), (2, 3, "b"),
                                                                                 (3, 3, "c")]


def test_progress_must_be_callable_and_can_stop_the_plan(three, controller):
    with pytest.raises(TypeError, match="progress must be a function"):
        snakehead.plan(three, controller=controller, progress="yes")

    class Stop(Exception):
        pass

    def stop(record):
        if record.kind == "target":
            raise Stop(record.name)

    with pytest.raises(Stop, match="t1"):
        snakehead.plan(three, controller=controller, progress=stop)


def test_cli_prints_a_line_per_target(poses, tmp_path, capsys):
    from snakehead.app import cli

    scene = tmp_path / "three.toml"
    scene.write_text(_toml([(f"t{k + 1}", p.position, p.direction) for k, p in enumerate(poses)]))
    status = cli.main(["plan", "--scene", str(scene), "--no-sim", "--fast", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert status in (0, 1), err
    lines = [line for line in err.splitlines() if re.search(r"three: target \d+/3 ", line)]
    assert len(lines) == 3, err
    for k, line in enumerate(lines):
        assert re.search(rf"target {k + 1}/3 't{k + 1}': (solved in \d+\.\d\d s|NOT solved in \d+\.\d\d s: .+)$",
                         line), line
    for stage in ("to choose the base ...", "timing the motion through", "checking the"):
        assert stage in err, stage


# ------------------------------------------------------------------------------------------------
# bounds, before any work
# ------------------------------------------------------------------------------------------------
def test_too_many_targets_are_refused_at_once(no_solving, controller, tmp_path):
    p, d = np.array([0.0, 0.5, 0.3]), np.array([0.0, 1.0, 0.0])
    many = MAX_TARGETS + 1
    message = f"has {many} targets; at most {MAX_TARGETS}"
    with pytest.raises(InputError, match=message):
        Scene(name="big", targets=tuple(Target(f"t{k}", p, d) for k in range(many)))
    with pytest.raises(InputError, match=message):
        snakehead.plan([(p, d)] * many, controller=controller)
    # a file's entries are counted before any is read as a target (these are not even valid ones)
    with pytest.raises(InputError, match=message):
        scene_from_dict({"targets": [{}] * many})
    path = tmp_path / "big.toml"
    path.write_text(_toml([(f"t{k}", p, d) for k in range(many)]))
    with pytest.raises(InputError, match=rf"scene file .*big.toml.* {message}"):
        load_scene(path)
    # the command line: one line, exit 2 (bad input)
    from snakehead.app import cli

    assert cli.main(["plan", "--scene", str(path), "--no-sim", "--out", str(tmp_path / "out")]) == 2


def test_a_scene_of_max_targets_loads(tmp_path):
    """MAX_TARGETS targets written out in full fit in a scene file."""
    rng = np.random.default_rng(0)
    path = tmp_path / "max.toml"
    path.write_text("# many targets\n" + _toml([(f"target {k:04d}", rng.normal(size=3), rng.normal(size=3))
                                                for k in range(MAX_TARGETS)]))
    assert len(load_scene(path).targets) == MAX_TARGETS


def test_too_long_holds_are_refused_at_once(no_solving, controller):
    p, d = np.array([0.0, 0.5, 0.3]), np.array([0.0, 1.0, 0.0])
    half = plan_bounds.MAX_MOTION_S / 2 + 1
    scene = Scene(name="long", targets=(Target("a", p, d, hold_s=half), Target("b", p, d, hold_s=half)))
    with pytest.raises(InputError, match=r"scene 'long': its targets' hold_s add up to 2002 s; a plan's motion "
                                         r"lasts at most 2000 s"):
        snakehead.plan(scene, controller=controller)


def test_too_many_line_poses_are_refused_at_once(no_solving, controller):
    d = np.array([0.0, 1.0, 0.0])
    step = 1.0 / plan_bounds.MAX_LINE_POSES  # each line the most poses one line may take
    lines = plan_bounds.MAX_POSES // plan_bounds.MAX_LINE_POSES + 1
    targets = [Target("t0", [0.0, 0.0, 0.3], d)]
    targets += [Target(f"t{k}", [0.0, float(k % 2), 0.3], d, approach="line", step_m=step) for k in range(1, lines + 1)]
    with pytest.raises(InputError, match=rf"scene 'lines': its {lines + 1} targets and the poses along their line "
                                         rf"approaches are \d+ whole-body solves; at most {plan_bounds.MAX_POSES}"):
        snakehead.plan(Scene(name="lines", targets=tuple(targets)), controller=controller)


def test_a_motion_too_long_stops_as_soon_as_the_targets_show_it(three, controller, monkeypatch):
    """The least duration of the moves solved so far (at the joints' velocity limits) and the holds: the plan stops
    at the first target that takes it beyond MAX_MOTION_S, without solving the others. The scene was valid input:
    its moves only turn out too long (MotionTooLong, an Infeasible: the command line's exit 1)."""
    assert issubclass(MotionTooLong, Infeasible) and not issubclass(MotionTooLong, InputError)
    monkeypatch.setattr(plan_bounds, "MAX_MOTION_S", 0.05)
    still = Scene(name="three", targets=tuple(replace(t, hold_s=0.0) for t in three.targets))
    records: list = []
    with pytest.raises(MotionTooLong, match=r"scene 'three': the motion to its target 1 of 3 \('t1'\) lasts at least"):
        snakehead.plan(still, controller=controller, progress=records.append)
    assert [r.name for r in records if r.kind == "target"] == ["t1"]


def test_a_timed_motion_too_long_is_refused_before_it_is_sampled(three, controller, monkeypatch):
    """The retiming stops once the motion timed so far exceeds MAX_SAMPLES samples; the planner does not fall back to
    a slower pace (which would be longer still)."""
    monkeypatch.setattr(timing, "MAX_SAMPLES", 1000)  # 2 s at 2 ms
    with pytest.raises(MotionTooLong, match=r"scene 'three': the timed motion lasts more than [\d.]+ s; at most 1.998 s "
                                         r"\(1000 samples at 0.002 s\): split the scene"):
        snakehead.plan(three, controller=controller)


def test_a_path_that_cannot_be_timed_still_fits_the_longest_motion(three, controller, monkeypatch):
    """A path the retiming cannot time is sampled at a slow pace to be looked at, and the plan fails on its timing;
    that pace quickens when it would make the motion longer than MAX_MOTION_S (it was an error, then)."""
    def untimeable(*args, **kwargs):
        raise Infeasible("no motion along the path keeps every limit near waypoint 3")

    monkeypatch.setattr(waypoints, "retime", untimeable)  # the name the path of moves times itself with
    monkeypatch.setattr(plan_bounds, "MAX_MOTION_S", 30.0)
    result = snakehead.plan(three, controller=controller)
    assert not result.success and "cannot be timed" in result.failure
    assert result.duration_s <= 30.0


# ------------------------------------------------------------------------------------------------
# memory: the checks by chunks, the snapshots bounded
# ------------------------------------------------------------------------------------------------
def test_dynamic_stability_by_chunks_equals_it_on_the_whole_frames(planned, monkeypatch):
    result = planned[0]
    robot, t, q, qd = result.robot, result.t[:2000], result.q[:2000], result.qd[:2000]
    whole = stability.dynamic_stability(robot, t, q, result.base, qd, contact="ground",
                                        frames=robot.frames_many(q, result.base))
    monkeypatch.setattr(stability, "SAMPLE_CHUNK", 37)
    seen = []
    chunked = stability.dynamic_stability(robot, t, q, result.base, qd, contact="ground",
                                          with_frames=lambda rows, f: seen.append((rows.start, rows.stop, len(f))))
    for key in ("zmp", "margin", "inside", "P", "L", "com"):
        np.testing.assert_array_equal(getattr(chunked, key), getattr(whole, key), err_msg=key)
    assert (chunked.min_margin, chunked.argmin) == (whole.min_margin, whole.argmin)
    starts = [s for s, _, _ in seen]
    assert starts == list(range(0, len(t), 37)) and all(n == b - a <= 37 for a, b, n in seen) and seen[-1][1] == len(t)


def test_the_plan_keeps_its_checks(planned):
    """The plan's checks (in the core, one pass) agree with the Python check of the whole trajectory at once: the
    ground exactly, the ZMP margins to round-off (the core sums the momenta in another order)."""
    result = planned[0]
    robot = result.robot
    frames = robot.frames_many(result.q, result.base)
    np.testing.assert_array_equal(result.ground_clearance, robot.lowest_z(frames, robot.lifted_links).min(axis=1))
    whole = stability.dynamic_stability(robot, result.t, result.q, result.base, result.qd, contact="ground",
                                        frames=frames)
    np.testing.assert_allclose(result.stability.margin, whole.margin, rtol=0, atol=1e-12)


def test_snapshots_stay_one_page_with_many_targets(planned):
    from snakehead.planning.plan_result import TargetResult
    from snakehead.viz import body

    result = planned[0]
    tg = result.targets[0]
    times = np.linspace(result.t[0], result.t[-1], 40)
    many = replace(result, targets=[TargetResult(f"x{k}", tg.position, tg.direction, float(s), tg.solution)
                                    for k, s in enumerate(times)])
    assert len(body.snapshot_states(many, 12)) <= 12
    assert len(body.snapshot_states(result, 12)) >= len(result.targets) + 2  # a few targets: each has its panel
