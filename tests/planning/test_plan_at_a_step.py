"""Plans at the foot of a step (a "steps" terrain rising from the base's level): the steps become box obstacles the
neck and head keep clear of, checked against the terrain's own surface (its triangles, by the C++ terrain query),
and a base that does not lie at the foot is Infeasible by name."""
from __future__ import annotations

import numpy as np
import pytest

import snakehead
from snakehead._errors import Infeasible
from snakehead.model.placement import BasePlacement
from snakehead.samples.targets import reachable_targets
from snakehead.scenes.ground_scene import scene_in_ground_frame
from snakehead.scenes.scene import Scene, Target
from snakehead.solve.solution_checks import clear_of_obstacles
from snakehead.terrain.generated import step

STEP = step(0.04, heading_deg=0.0, start=(0.0, 0.0, 0.0))  # 4 cm up at x = 0, the foot for x in [-1, 0)


def test_the_risen_blocks_are_the_ground_above_the_foot():
    rng = np.random.default_rng(0)
    p = rng.uniform([-1.2, -1.2, 0.0], [2.2, 1.2, 0.08], (20000, 3))
    blocks = STEP.risen_blocks()
    inside = np.zeros(len(p), bool)
    for b in blocks:
        inside |= np.all(np.abs((p - b.centre) @ b.rotation) <= b.size / 2, axis=1)
    h = STEP.height(p[:, :2])
    below_surface = np.isfinite(h) & (p[:, 0] >= 0.0) & (p[:, 2] < np.where(np.isfinite(h), h, -1.0))
    assert np.array_equal(inside, below_surface)


def test_a_plan_at_the_foot_of_a_step_keeps_the_head_clear_of_it():
    robot = snakehead.SnakeRobot.default()
    base = BasePlacement(-0.55, -0.3, 0.0)
    controller = snakehead.HeadController(robot, base_pose=base, seed=1)
    blocks = STEP.risen_blocks()
    rng = np.random.default_rng(4)
    targets = [t for t in reachable_targets(controller, "same", 12, rng)
               if clear_of_obstacles(robot, t.q, blocks, base)][:2]
    assert targets
    scene = Scene("step", tuple(Target(f"t{k}", t.position, t.direction, hold_s=0.5) for k, t in enumerate(targets)),
                  base=base, terrain=STEP)
    ground_scene, _ = scene_in_ground_frame(scene)
    assert len(ground_scene.obstacles) == len(blocks)
    plan = snakehead.plan(scene, controller=controller)
    assert plan.success, (plan.failure, plan.notes)
    # every link's frame origin along the motion stays above the step's surface (the terrain's own query)
    frames = robot.frames_many(plan.q[::25], plan.base)
    origins = frames[:, :, :3, 3].reshape(-1, 3)
    assert STEP.signed_distance(origins).min() > 0.0


def test_a_base_that_does_not_lie_at_the_foot_is_infeasible():
    scene = Scene("on the step", (Target("t", np.array([0.5, 0.0, 0.3]), np.array([1.0, 0.0, 0.0])),),
                  base=BasePlacement(0.3, 0.0, 0.0), terrain=STEP)
    with pytest.raises(Infeasible, match="foot of its staircase"):
        snakehead.plan(scene)
