"""What a plan may be asked for, checked before anything is solved: the most targets, poses and seconds of motion
a plan takes (:data:`MAX_MOTION_S`, :data:`MAX_POSES`, :data:`MAX_LINE_POSES`), the retiming options it takes
(:data:`TIMING_OPTIONS`), and the poses along a straight-line approach (counted here)."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .._errors import InputError, MotionTooLong
from .._validate import MAX_SAMPLES
from ..model.robot import SnakeRobot
from ..retiming.timing import resolve_limits
from ..scenes.scene import Scene, Target, check_target_count
from ..trajectory import interpolation as interp

#: s: the longest motion a plan may have: MAX_SAMPLES samples at the 2 ms control period (2000 s). Checked before
#: anything is solved (the targets' holds alone), after each target is solved (the holds and the least time the
#: joints' velocity limits allow for the moves so far) and while the path is timed (``retiming.timing.retime``),
#: before anything is sampled: a scene that needs more raises ``snakehead.InputError`` (split it into scenes).
MAX_MOTION_S = (MAX_SAMPLES - 1) * interp.CONTROL_PERIOD
#: The most poses a plan solves: its targets and the poses along its straight-line approaches (each a whole-body
#: solve, ~0.1-0.5 s on the default robot), counted before any is solved.
MAX_POSES = 5000


#: The retiming options ``plan(timing=...)`` takes; the planner sets the others (holds, stops, the 2 ms control
#: period: a coarser period would leave the motion between samples unchecked).
TIMING_OPTIONS = ("velocity_limit", "acceleration_limit", "torque_limit", "zmp_margin", "friction")


def check_timing(robot: SnakeRobot, timing: dict[str, Any]) -> None:
    """InputError naming an unknown option of ``timing`` or a bad value (``retiming.timing.resolve_limits``)."""
    unknown = [key for key in timing if key not in TIMING_OPTIONS]
    if unknown:
        raise InputError(f"timing has no option {unknown[0]!r}; its options are {', '.join(TIMING_OPTIONS)}")
    resolve_limits(robot, **timing)


#: The most poses solved along one straight-line approach (approach = "line"; each is a whole-body solve).
MAX_LINE_POSES = 2000


def check_lines(targets: Sequence[Target]) -> None:
    """InputError for a target approached along a line (approach = "line") in more than MAX_LINE_POSES steps."""
    for a, b in zip(targets, targets[1:]):
        length = float(np.linalg.norm(b.position - a.position))
        if b.approach == "line" and length / b.step_m > MAX_LINE_POSES:  # each pose is a whole-body solve
            raise InputError(f"target {b.name!r}: the line from {a.name!r} is {length:.4g} m long; at step_m = "
                             f"{b.step_m:g} m that is {length / b.step_m:.3g} poses, at most {MAX_LINE_POSES}: take "
                             "a larger step_m")


def line_poses(a: Target, b: Target) -> list[np.ndarray]:
    """Positions from target ``a`` to target ``b`` every ``b.step_m`` m (b included, a excluded; their number was
    checked by :func:`check_lines`)."""
    d = b.position - a.position
    length = float(np.linalg.norm(d))
    n = int(np.ceil(length / b.step_m - 1e-9))
    steps = [min(k * b.step_m, length) for k in range(1, n + 1)]
    if length > 0 and steps and abs(steps[-1] - length) > 1e-12:
        steps.append(length)
    return [a.position + (s / length) * d for s in steps] if length > 0 else [b.position.copy()]


def check_size(scene: Scene) -> dict[int, list[np.ndarray]]:
    """InputError (naming the scene) for a scene too large to plan, before anything is solved (see
    :func:`~snakehead.planning.planner.plan`); the poses along its line approaches (target index -> positions), which are counted here."""
    targets = scene.targets
    check_target_count(len(targets), f"scene {scene.name!r}")
    check_lines(targets)  # before the poses along the lines are made
    hold = float(sum(t.hold_s for t in targets))
    if hold > MAX_MOTION_S:
        raise InputError(f"scene {scene.name!r}: its targets' hold_s add up to {hold:g} s; a plan's motion lasts at "
                         f"most {MAX_MOTION_S:g} s (MAX_MOTION_S: {MAX_SAMPLES} samples at "
                         f"{interp.CONTROL_PERIOD:g} s): split the scene into scenes planned one after the other")
    lines = {j: line_poses(targets[j - 1], targets[j]) for j in range(1, len(targets)) if targets[j].approach == "line"}
    poses = len(targets) + sum(len(line) - 1 for line in lines.values())
    if poses > MAX_POSES:
        raise InputError(f"scene {scene.name!r}: its {len(targets)} targets and the poses along their line approaches "
                         f"are {poses} whole-body solves; at most {MAX_POSES} (MAX_POSES): take a larger step_m or "
                         "split the scene")
    return lines


def check_motion_length(duration_s: float, how: str = "") -> None:
    """MotionTooLong when a motion of ``duration_s`` is longer than :data:`MAX_MOTION_S` (before it is sampled)."""
    if duration_s > MAX_MOTION_S:
        raise MotionTooLong(f"the timed motion lasts {duration_s:.1f} s{' ' + how if how else ''}; at most "
                         f"{MAX_MOTION_S:g} s ({MAX_SAMPLES} samples at {interp.CONTROL_PERIOD:g} s)")


__all__ = ["MAX_MOTION_S", "MAX_POSES", "MAX_LINE_POSES", "TIMING_OPTIONS", "check_timing", "check_lines",
           "line_poses", "check_size", "check_motion_length"]
