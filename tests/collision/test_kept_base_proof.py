"""The whole-body solve's proof that a target is out of the lifted chain's reach with the base kept
(``BodyProblem.out_of_reach``, through ``TargetSearch.beyond_reach`` and ``lifted_candidates``): it must never
refuse a target the kept base reaches (the heads of real poses, reachable-by-construction targets of the "same"
set, the "shape" set's targets from their own base shape), on the default robot and on others; and what it
refuses, the lifted chain's IK (the whole batch, no proof asked) and the segmented solve do not reach either."""
from __future__ import annotations

import numpy as np
import pytest
from conftest import pitch_first

import snakehead as sh
from snakehead.margins import DETOUR_MARGIN
from snakehead.samples import published
from snakehead.samples.targets import reachable_targets
from snakehead.solve import whole_body as wb
from snakehead.solve.head import frame_along


def _robot(name: str, folder) -> sh.SnakeRobot:
    if name == "default":
        return sh.SnakeRobot.default()
    if name == "pitch_first":
        return pitch_first()
    return sh.SnakeRobot.from_file(published.write_robot(name, folder / name))


@pytest.fixture(scope="module", params=["default", "pitch_first", "reu"])
def controller(request, tmp_path_factory) -> sh.HeadController:
    robot = _robot(request.param, tmp_path_factory.mktemp("robots"))
    return sh.HeadController(robot, method="free_roll", seed=1)


def _search(controller, position, direction, q_prev=None) -> wb.TargetSearch:
    return wb.TargetSearch(controller, np.asarray(position, float), np.asarray(direction, float), q_prev, None, (),
                           DETOUR_MARGIN, wb.SOLVE_BUDGET, controller.body_problem, 0, None)


def test_never_refuses_the_head_of_a_real_pose(controller):
    """Random lifted joints with the base as it lies at the start: the head's pose is reached (a pose exists: this
    one), whatever its stability; the proof must not refuse it."""
    robot, prob = controller.robot, controller.body_problem
    rng = np.random.default_rng(5)
    start = robot.lift_joints.start
    for _ in range(300):
        q = robot.random_configuration(rng)
        q[:start] = controller.q_initial[:start]
        H = robot.head_pose(q, controller.base)
        assert not prob.out_of_reach(controller.q_initial, controller.base, H[:3, 3], H[:3, 0])
        assert not _search(controller, H[:3, 3], H[:3, 0]).beyond_reach()


def test_never_refuses_a_reachable_target(controller):
    """The "same" set's targets from the start, and the "shape" set's from their own base shape (the kept base
    they were made on)."""
    for t in reachable_targets(controller, "same", 40, np.random.default_rng(2)):
        assert not _search(controller, t.position, t.direction).beyond_reach()
    for t in reachable_targets(controller, "shape", 40, np.random.default_rng(3)):
        assert not _search(controller, t.position, t.direction, q_prev=t.q).beyond_reach()


def _batch(controller, q, position, direction, rng) -> tuple[np.ndarray, np.ndarray]:
    """lifted_candidates' batch from q at the controller's base: the rolled frames, first from q, then from random
    joints (poses (16, 4, 4) in the lift frame, starts (16, m))."""
    robot, ik = controller.robot, controller.body_problem.lifted_ik(0)
    T0 = robot.frame(q, robot.lift_frame, controller.base)
    target = np.linalg.inv(T0) @ frame_along(position, direction)
    angles = 2 * np.pi * np.arange(wb.CANDIDATE_ROLLS) / wb.CANDIDATE_ROLLS
    poses = np.concatenate([wb.rolled_frames(target, angles)] * wb.CANDIDATE_SEEDS)
    inits = np.vstack([np.tile(q[robot.lift_joints.start:], (wb.CANDIDATE_ROLLS, 1)),
                       rng.uniform(ik.lower, ik.upper, (wb.CANDIDATE_ROLLS * (wb.CANDIDATE_SEEDS - 1), ik.n_joints))])
    return poses, inits


def _ik_batch(controller, q, position, direction) -> np.ndarray:
    """The lifted chain's IK from q at the controller's base towards the rolled frames, as lifted_candidates asks
    for them but with no proof asked first: which succeeded."""
    poses, inits = _batch(controller, q, position, direction, np.random.default_rng(0))
    first = slice(0, wb.CANDIDATE_ROLLS)
    return controller.body_problem.lifted_ik(0).ik_many(poses[first], inits[first])[1]


def test_what_it_refuses_is_not_reached(controller, request):
    """Targets of other base shapes that the proof refuses from the start: the IK batch finds no pose and the
    segmented solve's pose fails the checks; and the proof refuses more than the lifted chain's length does (the
    bound it replaces: the head is not a point) on the default robot and the published style (on pitch_first, a
    shorter head, the targets it refuses are beyond the chain's length too)."""
    robot = controller.robot
    origin = robot.frame(controller.q_initial, robot.lift_frame, controller.base)[:3, 3]
    reach = robot.sub_chain(robot.lift_frame, robot.parts.head_tip).reach
    refused, closer = 0, 0
    for t in reachable_targets(controller, "shape", 30, np.random.default_rng(4)):
        search = _search(controller, t.position, t.direction)
        if not search.beyond_reach():
            continue
        refused += 1
        closer += np.linalg.norm(t.position - origin) <= reach + wb.POSITION_TOLERANCE
        if refused <= 3:  # (each IK batch that fails spends its whole budget)
            assert not _ik_batch(controller, controller.q_initial, t.position, t.direction).any()
            assert wb.lifted_candidates(controller.body_problem, controller.q_initial, controller.base, t.position,
                                        t.direction) == []
            seg = search.segmented_at(controller.q_initial, controller.base, clear=False)
            assert search.check(seg.q, seg.base)["reason"] is not None
    assert refused >= 3
    assert closer >= (request.node.callspec.params["controller"] != "pitch_first")


def test_choice_of_base_past_the_proof_is_deterministic(controller):
    """A target the proof refuses from the start: the base's choice (its relocation search) gives the same base,
    shape and solution twice, each with its own plan's solves, and that base reaches the target with the base kept
    (the solve's own check)."""
    from snakehead.planning import base_choice
    from snakehead.scenes import Target

    refused = next(t for t in reachable_targets(controller, "shape", 30, np.random.default_rng(4))
                   if _search(controller, t.position, t.direction).beyond_reach())
    target = Target("t", refused.position, refused.direction)
    first = base_choice.choose_base(controller, [target], solved=wb.PlanSolves())
    again = base_choice.choose_base(controller, [target], solved=wb.PlanSolves())
    assert first[0] == again[0] and first[2] is not None and first[2] == again[2]
    np.testing.assert_array_equal(first[1], again[1])
    sol = wb.solve_target(controller, refused.position, refused.direction, q_prev=first[1], base=first[0],
                          allow_base_move=False, problem=controller.body_problem, min_margin=DETOUR_MARGIN)
    assert sol.success


def test_candidates_skip_the_random_starts_of_rolls_the_current_joints_miss(controller):
    """lifted_candidates' IK (``rolls_reached``) solves every roll from the current joints, then from random
    starts only the rolls reached from there: each target it solves gives, bit for bit, what one batch of all of
    them gives (its index in the batch is its stream), and the others are reported not found at their start. On
    the default robot and on others; targets of other base shapes asked from the initial one, where some rolls are
    out of the chain's reach."""
    ik = controller.body_problem.lifted_ik(0)
    rng = np.random.default_rng(5)
    missed = 0
    for t in reachable_targets(controller, "shape", 8, np.random.default_rng(6)):
        if missed >= 3:
            break
        poses, inits = _batch(controller, controller.q_initial, t.position, t.direction, rng)
        q_all, ok_all = ik.ik_many(poses, inits)
        q, ok = wb.rolls_reached(ik, poses, inits)
        first = ok_all[:wb.CANDIDATE_ROLLS]
        solved = np.concatenate([np.ones(wb.CANDIDATE_ROLLS, bool), first])
        np.testing.assert_array_equal(q[solved], q_all[solved])
        np.testing.assert_array_equal(ok[solved], ok_all[solved])
        assert not ok[~solved].any()
        np.testing.assert_array_equal(q[~solved], inits[~solved])
        missed += int((~first).sum())
    assert missed > 0  # (the skipped branch was taken)
