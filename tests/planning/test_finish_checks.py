"""The end of a plan (``Waypoints.sample`` and ``Waypoints.finish_checks``): the lift and the rest concatenated from
their own samples equal both pieces' splines evaluated at every time (the formula before the reuse, bit for bit), and
a plan whose lift's ZMP check is kept from an earlier plan takes it over and reports what a check from scratch does."""
from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import snakehead
from snakehead.dynamics import stability
from snakehead.planning import waypoints
from snakehead.trajectory import interpolation as interp


@pytest.fixture(scope="module")
def planned() -> dict[str, Any]:
    """Two plans from the same base (the second from the kept lift), the pieces each concatenated, the kept
    samples each check took over."""
    robot = snakehead.SnakeRobot.default()
    controller = snakehead.HeadController(robot, method="free_roll", seed=1)
    H = robot.head_pose(controller.q_initial)
    pieces: list = []
    kept: list = []
    real_concatenate, real_core = waypoints.concatenate_motions, stability.dynamic_stability_in_core

    def concatenate(a: Any, b: Any) -> Any:
        pieces.append((a, b))
        return real_concatenate(a, b)

    def core(*args: Any, **kwargs: Any) -> Any:
        out = real_core(*args, **kwargs)
        kept.append(args[8].resumed if len(args) > 8 and args[8] is not None else None)
        return out

    waypoints.concatenate_motions, stability.dynamic_stability_in_core = concatenate, core
    try:
        plans = [snakehead.plan([(H[:3, 3] + [0.0, dy, -0.05], H[:3, 0])], controller=controller) for dy in (0.0, 0.03)]
    finally:
        waypoints.concatenate_motions, stability.dynamic_stability_in_core = real_concatenate, real_core
    return {"robot": robot, "plans": plans, "pieces": pieces, "resumed": kept}


def test_concatenated_motion_equals_the_pieces_splines(planned: dict[str, Any]) -> None:
    assert planned["pieces"], "the plans must time their lift apart (a kept lift)"
    for a, b in planned["pieces"]:
        out = waypoints.concatenate_motions(a, b)
        offset = float(a.t[-1])
        t = interp.sample_times(0.0, offset + float(b.t[-1]), float(a.t[1] - a.t[0]))
        first = t <= offset
        np.testing.assert_array_equal(out.t, t)
        for nu, got in enumerate((out.q, out.qd, out.qdd)):
            want = np.empty_like(got)
            want[first] = a.spline(t[first], nu)
            want[~first] = b.spline(t[~first] - offset, nu)
            if nu == 0:
                want[-1] = b.q[-1]
            np.testing.assert_array_equal(got, want, err_msg=f"derivative {nu}")


def test_a_kept_lift_check_gives_the_checks_from_scratch(planned: dict[str, Any]) -> None:
    robot = planned["robot"]
    first, second = planned["plans"]
    assert planned["resumed"][0] == 0 and planned["resumed"][1] > 0, "the second plan takes the lift's check over"
    for plan in (first, second):
        dyn, clearance = stability.dynamic_stability_with_clearance(robot, plan.t, plan.q, plan.base, plan.qd)
        for name in ("zmp", "margin", "P", "L", "com"):
            np.testing.assert_array_equal(getattr(plan.stability, name), getattr(dyn, name), err_msg=name)
        np.testing.assert_array_equal(plan.ground_clearance, clearance)
        assert plan.motion_proof is not None and plan.motion_proof.clear and plan.success
