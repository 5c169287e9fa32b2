import os
import re
from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parent / "data"


# --- a missing test dependency fails the run in CI --------------------------------------------------------------
#: The pip name of a test dependency whose import name differs (pyproject.toml's test, docs and lint extras).
PIP_NAMES = {"pinocchio": "pin", "sklearn": "scikit-learn", "dask": "dask[distributed]",
             "distributed": "dask[distributed]", "bs4": "beautifulsoup4", "markdown_it": "markdown-it-py",
             "yaml": "pyyaml"}
#: What pytest.importorskip says when it skips (pytest's own wording, either cause).
_IMPORTORSKIP = re.compile(r"could not import '(?P<a>[^']+)'|module '(?P<b>[^']+)' has __version__")


def in_ci() -> bool:
    """Whether the environment variable CI is set to a true value (.ci/run sets CI=true; CI runners set it too)."""
    return os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no", "off")


def missing_import(report: pytest.CollectReport | pytest.TestReport) -> str | None:
    """The module a skip was for, when ``report`` is a skip by pytest.importorskip (else None)."""
    if not report.skipped or not isinstance(report.longrepr, tuple):
        return None
    found = _IMPORTORSKIP.search(str(report.longrepr[2]))
    return None if found is None else found["a"] or found["b"]


def _fail_in_ci(report: pytest.CollectReport | pytest.TestReport) -> None:
    """Under CI, a skip for a missing import becomes a failure that names the package: in CI every test dependency is
    installed (bash .ci/setup), so a skip there would drop a feature's tests silently."""
    module = missing_import(report) if in_ci() else None
    if module is None:
        return
    top = module.split(".")[0]
    package = PIP_NAMES.get(module, PIP_NAMES.get(top, top))
    reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else ""
    report.outcome = "failed"
    report.longrepr = (f"missing test dependency {package!r} (import {module!r}): CI is set, so a test that needs it "
                       f"fails instead of skipping; install the test extras (bash .ci/setup, or pip install "
                       f"'.[test,docs,lint]'). pytest said: {reason}")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    _fail_in_ci(outcome.get_result())


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    outcome = yield
    _fail_in_ci(outcome.get_result())


@pytest.fixture(scope="session")
def mujoco():
    """The mujoco module, for the tests that simulate (skipped without it, a failure in CI)."""
    return pytest.importorskip("mujoco")


@pytest.fixture(scope="session")
def toppra():
    """The toppra module, for the tests that compare the core's TOPP-RA with it (skipped without it, a failure in
    CI)."""
    return pytest.importorskip("toppra")


def head6_robot():
    """The default robot with the 6-DOF head of the paper's Section 2.2 (its shipped robot file)."""
    from snakehead import SnakeRobot, default_robot_file

    return SnakeRobot.from_file(default_robot_file().with_name("snake16_head6.toml"))


def pitch_first():
    """A generated snake unlike the default: 13 joints starting with a pitch joint, 10 cm modules, 6 cm section,
    0.3 kg per module."""
    from snakehead import SnakeRobot
    from snakehead.model.generate import SnakeSpec, snake_urdf

    urdf = snake_urdf(SnakeSpec(n_joints=13, module_length=0.10, section=0.06, mass_per_module=0.3,
                                first_axis="pitch", markers={"p0": 6, "b0": 7}))
    return SnakeRobot.from_urdf(urdf, base_end="p0", neck_end="b0", head_tip="head_tip")


#: Two generated snakes unlike the default (their SnakeSpec and the robot file's three frames), shared by the tests
#: that run on several robots: long20, 20 joints, 7 cm modules, 5 cm section, 0.15 kg/module, a 2-joint neck that
#: begins with a yaw joint (its first link stays on the ground) and an 8-DOF head; pitchy, 13 joints starting with a
#: pitch joint, 10 cm modules, 6 cm section, 0.3 kg/module, parts named by link frames, a 1-joint neck and a 6-DOF
#: head (whose map has no voxel of index 100).
def generated_specs() -> dict:
    from snakehead.model.generate import SnakeSpec

    return {
        "long20": (SnakeSpec(n_joints=20, module_length=0.07, section=0.05, mass_per_module=0.15, first_axis="yaw",
                             markers={"p0": 10, "b0": 12}, tip_name="tip", name="long20"),
                   dict(base_end="p0", neck_end="b0", head_tip="tip")),
        "pitchy": (SnakeSpec(n_joints=13, module_length=0.1, section=0.06, mass_per_module=0.3, first_axis="pitch",
                             link_prefix="seg", joint_prefix="j", tip_name="nose", name="pitchy"),
                   dict(base_end="seg6", neck_end="seg7", head_tip="nose")),
    }


#: A coarse, quick reachability map of the default robot's head (a few seconds): the options the map tests share.
SMALL_MAP = dict(voxel=0.15, directions=6, rolls=2, cloud_samples=3000, seed=3, timeout=3e-4)


@pytest.fixture(scope="session")
def small_map():
    """The default robot's head map with SMALL_MAP's options, computed once per session."""
    from snakehead import SnakeRobot
    from snakehead.kinematics import reachability as workspace

    return workspace.compute(SnakeRobot.default(), progress=False, **SMALL_MAP)


@pytest.fixture(scope="session")
def mixed_urdf() -> str:
    """A chain with revolute, continuous, prismatic and fixed joints (tests/data/mixed_chain.urdf)."""
    return str(DATA / "mixed_chain.urdf")


def plan_agrees(robot, m, pairs) -> list:
    """Each (voxel, direction) of the whole-body reach map ``m`` planned in full with snakehead.plan: whether the plan's
    success agrees with the map's bit (an independent check of the map)."""
    import snakehead

    bits = m.reached_units()
    out = []
    for v, k in pairs:
        d = m.sphere_directions[k]
        p = m.centers[v] + 0.5 * m.voxel_size * d
        out.append(snakehead.plan([(p, d)], robot=robot).success == bits[v, k])
    return out


def reachable_plan_in_mujoco(robot):
    """One reachable target ("same" kind, seed 0) of ``robot`` planned and run in MuJoCo: the simulation (asserts the
    plan succeeded and the head arrived within 2 mm and 1 deg)."""
    import numpy as np

    import snakehead
    from snakehead.samples.targets import reachable_targets

    controller = snakehead.HeadController(robot, method="free_roll", seed=1)
    (t,) = reachable_targets(controller, "same", 1, np.random.default_rng(0))
    plan = snakehead.plan([(t.position, t.direction)], controller=controller)
    assert plan.success, plan.failure
    sim = snakehead.simulate(plan)
    assert sim.position_error_m <= 2e-3 and sim.direction_error_deg <= 1.0, (sim.position_error_m,
                                                                            sim.direction_error_deg)
    return sim
