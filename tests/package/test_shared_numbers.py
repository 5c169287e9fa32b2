"""Every shared number is defined once: gravity and the ground's friction (``model.physics``), the plans' margins
(``snakehead.margins``); the modules that use them import them (the same object, not an equal copy)."""
import ast
import importlib
import inspect
from pathlib import Path

import snakehead
from snakehead import margins
from snakehead.model import physics

PACKAGE = Path(snakehead.__file__).parent


def definitions(name):
    """The modules (paths relative to the package) that assign ``name`` at module level."""
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text())
        for node in tree.body:
            targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(
                node, ast.AnnAssign) else []
            if any(isinstance(t, ast.Name) and t.id == name for t in targets):
                out.append(str(path.relative_to(PACKAGE)))
    return out


def test_gravity_and_the_margins_are_defined_once():
    assert definitions("GRAVITY") == ["model/physics.py"]
    assert definitions("GROUND_FRICTION") == ["model/physics.py"]
    assert definitions("DETOUR_MARGIN") == ["margins.py"]
    assert definitions("OBSTACLE_CLEARANCE") == ["margins.py"]
    assert definitions("EXACT_DISTANCE_WITHIN") == ["margins.py"]
    assert definitions("ZMP_MARGIN") == ["margins.py"]
    assert definitions("SELF_CLEARANCE") == ["margins.py"]
    assert definitions("SOLUTION_MARGIN") == ["margins.py"]


def test_the_users_read_the_one_definition():
    from snakehead.retiming import stability_constraint, timing
    from snakehead.sim import mjcf, tracking
    from snakehead.solve import whole_body

    for name in ("dynamics.stability", "model.placement", "model.generate", "sim.gains", "sim.mjcf",
                 "sim.tracking"):  # (Newton-Euler takes g from the placement: model.placement)
        assert importlib.import_module(f"snakehead.{name}").GRAVITY is physics.GRAVITY, name
    assert whole_body.OBSTACLE_CLEARANCE is margins.OBSTACLE_CLEARANCE
    assert whole_body.SELF_CLEARANCE is margins.SELF_CLEARANCE and whole_body.MIN_MARGIN is margins.SOLUTION_MARGIN
    assert timing.ZMP_MARGIN is margins.ZMP_MARGIN and stability_constraint.GRAVITY is physics.GRAVITY
    assert timing.FRICTION == 0.5 * physics.GROUND_FRICTION
    # the simulation's ground is the one the retiming's friction is a share of
    assert inspect.signature(mjcf.build_spec).parameters["friction"].default == physics.GROUND_FRICTION
    assert inspect.signature(tracking.simulate_trajectory).parameters["friction"].default == physics.GROUND_FRICTION


def test_the_values_are_the_documented_ones():
    """Standard gravity (CGPM 1901) and the margins the plans were measured with (bench/RESULTS.md)."""
    assert physics.GRAVITY == 9.80665 and physics.GROUND_FRICTION == 0.8
    assert margins.ZMP_MARGIN == 0.005 and margins.DETOUR_MARGIN == 0.01 == 2 * margins.ZMP_MARGIN
    assert margins.OBSTACLE_CLEARANCE == 0.002 and margins.EXACT_DISTANCE_WITHIN == 0.005
    assert margins.SELF_CLEARANCE == 0.002 and margins.SOLUTION_MARGIN == margins.ZMP_MARGIN


def test_trac_iks_defaults_are_written_once_and_are_the_cores():
    """TRAC-IK's default budget and tolerance: kinematics.ik's, used by every Python entry point, equal to the C++
    core's (TracIKOptions in include/snakehead/trac_ik.hpp; the bindings' kdl_nr_jl_ik)."""
    import re

    from snakehead import _core
    from snakehead.kinematics import ik
    from snakehead.solve.head_controller import HeadController

    assert definitions("DEFAULT_TIMEOUT_S") == ["kinematics/ik.py"]
    assert definitions("DEFAULT_EPSILON") == ["kinematics/ik.py"]
    header = (Path(__file__).resolve().parents[2] / "include/snakehead/trac_ik.hpp")
    if header.is_file():  # (the source tree's; an installed wheel alone has no headers)
        options = re.search(r"struct TracIKOptions \{(.*?)\};", header.read_text(), re.S).group(1)
        assert float(re.search(r"double timeout = ([0-9.e-]+);", options).group(1)) == ik.DEFAULT_TIMEOUT_S
        assert float(re.search(r"double epsilon = ([0-9.e-]+);", options).group(1)) == ik.DEFAULT_EPSILON
    signature = _core.kdl_nr_jl_ik.__doc__.splitlines()[0]
    assert float(re.search(r"timeout: [^,=]+= ([0-9.e-]+)", signature).group(1)) == ik.DEFAULT_TIMEOUT_S
    assert float(re.search(r"epsilon: [^,=)]+= ([0-9.e-]+)", signature).group(1)) == ik.DEFAULT_EPSILON
    for fn in (ik.TracIK.__init__, ik.TracIK.from_chain, HeadController.__init__):
        params = inspect.signature(fn).parameters
        assert params["timeout"].default is ik.DEFAULT_TIMEOUT_S and params["epsilon"].default is ik.DEFAULT_EPSILON


def test_what_counts_as_touching_the_ground_is_defined_once():
    """One tolerance for the planner's ground, one for a body that is simulated or measured (ground_contact)."""
    from snakehead import ground_contact
    from snakehead.collision import body_collisions
    from snakehead.dynamics import sliding, stability
    from snakehead.solve import base_support

    assert definitions("GROUND_TOLERANCE") == ["ground_contact.py"]
    assert definitions("RESTING_TOLERANCE") == ["ground_contact.py"]
    for gone in ("CONTACT_TOLERANCE", "CONTACT_BAND", "RESTING_HEIGHT"):  # its earlier names
        assert definitions(gone) == [], gone
    assert body_collisions.GROUND_TOLERANCE is stability.GROUND_TOLERANCE is base_support.GROUND_TOLERANCE \
        is ground_contact.GROUND_TOLERANCE
    assert sliding.RESTING_TOLERANCE is ground_contact.RESTING_TOLERANCE
    assert ground_contact.GROUND_TOLERANCE == 1e-3 and ground_contact.RESTING_TOLERANCE == 3e-3


def test_the_estimate_and_the_simulator_use_the_planners_numbers():
    """The pose estimate's contact band is the resting tolerance; the simulated controller's period is the
    planner's control period (one number each, not a copy that can drift)."""
    from snakehead import ground_contact
    from snakehead.closed_loop import estimate
    from snakehead.sim import mjcf
    from snakehead.trajectory import interpolation

    assert estimate.CONTACT_HEIGHT is ground_contact.RESTING_TOLERANCE
    assert mjcf.DEFAULT_CONTROL_DT is interpolation.CONTROL_PERIOD
    assert definitions("CONTROL_PERIOD") == ["trajectory/interpolation.py"]
