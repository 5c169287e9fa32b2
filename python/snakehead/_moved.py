"""Import paths of the modules that moved when the package was laid out one package per concept (0.3), kept for
one release: importing an old path warns (DeprecationWarning) and gives the module at its new place, the very
same module object, so that state and ``isinstance`` checks are shared.

:data:`MOVED_MODULES` maps each old module path to its new one; :data:`MOVED_PACKAGES` maps the two packages that
went away (``snakehead.motion``, ``snakehead.control``) to the packages that took their names. :func:`moved_names`
gives a package a module ``__getattr__`` for names it no longer exports. The finder is installed by
``snakehead/__init__.py``.
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types
import warnings
from typing import Any, Callable, Sequence

#: Old module path -> new module path.
MOVED_MODULES: dict[str, str] = {
    "snakehead.geometry.collision": "snakehead.collision.body_collisions",
    "snakehead.geometry.path_check": "snakehead.collision.path_proof",
    "snakehead.control.controller": "snakehead.solve.head_controller",
    "snakehead.control.neck": "snakehead.solve.neck",
    "snakehead.control.head": "snakehead.solve.head",
    "snakehead.control.whole_body": "snakehead.solve.whole_body",
    "snakehead.control.initial_state": "snakehead.solve.initial_state",
    "snakehead.motion.reach_bounds": "snakehead.solve.pose_bounds",
    "snakehead.kinematics.workspace": "snakehead.kinematics.reachability",
    "snakehead.kinematics.map_queries": "snakehead.kinematics.reachability.map_queries",
    "snakehead.kinematics.kmeans": "snakehead.kinematics.reachability.kmeans",
    "snakehead.motion.interpolation": "snakehead.trajectory.interpolation",
    "snakehead.motion.cartesian": "snakehead.trajectory.cartesian",
    "snakehead.motion.timing": "snakehead.retiming.timing",
    "snakehead.motion._topp": "snakehead.retiming.topp_ra",
    "snakehead.motion.planner": "snakehead.planning.planner",
    "snakehead.motion.plan_many": "snakehead.planning.plan_many",
    "snakehead.motion.plan_result": "snakehead.planning.plan_result",
    "snakehead.motion.plan_bounds": "snakehead.planning.plan_bounds",
    "snakehead.motion.plan_cache": "snakehead.planning.plan_cache",
    "snakehead.motion.start_state": "snakehead.planning.start_state",
    "snakehead.motion.base_choice": "snakehead.planning.base_choice",
    "snakehead.motion.target_solves": "snakehead.planning.target_solves",
    "snakehead.motion.waypoints": "snakehead.planning.waypoints",
    "snakehead.motion.fallbacks": "snakehead.planning.fallbacks",
    "snakehead.motion.reach": "snakehead.planning.whole_body_reach",
    "snakehead.motion.gaits": "snakehead.locomotion.gaits",
    "snakehead.motion.locomotion": "snakehead.locomotion.goals",
    "snakehead.motion.ground_path": "snakehead.locomotion.ground_path",
    "snakehead.sim.plan": "snakehead.sim.simulate_plan",
    "snakehead.sim.loop": "snakehead.closed_loop.loop",
    "snakehead.sim.estimate": "snakehead.closed_loop.estimate",
    "snakehead.sim.servo": "snakehead.closed_loop.servo",
    "snakehead.sim.gaits": "snakehead.closed_loop.gait_runner",
    "snakehead.model.published": "snakehead.samples.published",
    "snakehead.model.published_quirks": "snakehead.samples.published_quirks",
    "snakehead.model.published_xacro": "snakehead.samples.published_xacro",
    "snakehead.motion.targets": "snakehead.samples.targets",
    "snakehead.viz.loop": "snakehead.viz.loop_figures",
    "snakehead.viz.workspace": "snakehead.viz.reachability_figures",
    "snakehead.viz.backbone": "snakehead.viz.backbone_figures",
    "snakehead.viz.dynamics": "snakehead.viz.dynamics_figures",
}

#: Packages that went away -> the packages whose names they exported.
MOVED_PACKAGES: dict[str, tuple[str, ...]] = {
    "snakehead.motion": ("snakehead.trajectory", "snakehead.retiming", "snakehead.locomotion", "snakehead.planning"),
    "snakehead.control": ("snakehead.solve",),
}

#: The release that drops the old paths.
REMOVED_IN = "0.4"


def _warn(old: str, new: str) -> None:
    warnings.warn(f"{old} moved to {new}; the old path goes in snakehead {REMOVED_IN}", DeprecationWarning,
                  stacklevel=3)


def _old_package(name: str) -> types.ModuleType:
    """A stand-in for a package that went away: its submodules through the finder, its names from the new
    packages."""
    module = types.ModuleType(name, f"Moved: see {', '.join(MOVED_PACKAGES[name])}.")
    module.__path__ = []

    def __getattr__(attr: str) -> Any:
        sub = f"{name}.{attr}"
        if sub in MOVED_MODULES:
            return importlib.import_module(sub)
        for new in MOVED_PACKAGES[name]:
            package = importlib.import_module(new)
            if attr in getattr(package, "__all__", ()):
                _warn(f"{name}.{attr}", f"{new}.{attr}")
                value = getattr(package, attr)
                setattr(module, attr, value)  # warned once: ``from old import name`` looks a name up twice
                return value
        raise AttributeError(f"module {name!r} has no attribute {attr!r}")

    module.__getattr__ = __getattr__  # type: ignore[method-assign]
    return module


class _MovedLoader(importlib.abc.Loader):
    def __init__(self) -> None:
        self.own_spec: importlib.machinery.ModuleSpec | None = None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType:
        if spec.name in MOVED_PACKAGES:
            _warn(spec.name, " and ".join(MOVED_PACKAGES[spec.name]))
            return _old_package(spec.name)
        _warn(spec.name, MOVED_MODULES[spec.name])
        module = importlib.import_module(MOVED_MODULES[spec.name])
        self.own_spec = module.__spec__
        return module

    def exec_module(self, module: types.ModuleType) -> None:
        """Nothing to run: the module is the one at its new place. The import system has just given it the old
        path's spec; it gets its own back (its name, for reloads and tools, stays the new one)."""
        if self.own_spec is not None:
            module.__spec__ = self.own_spec


class MovedFinder(importlib.abc.MetaPathFinder):
    """Finds the old paths (and only those), ahead of the other finders."""

    def find_spec(self, fullname: str, path: Sequence[str] | None = None,
                  target: types.ModuleType | None = None) -> importlib.machinery.ModuleSpec | None:
        if fullname in MOVED_MODULES or fullname in MOVED_PACKAGES:
            return importlib.machinery.ModuleSpec(fullname, _MovedLoader(), is_package=fullname in MOVED_PACKAGES)
        return None


def install() -> None:
    """Put the finder first on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, MovedFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, MovedFinder())


def moved_names(package: str, names: dict[str, str]) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``package``: each name in ``names`` (name -> the module that has it now) warns
    and is taken from its new module."""

    def __getattr__(attr: str) -> Any:
        if attr not in names:
            raise AttributeError(f"module {package!r} has no attribute {attr!r}")
        _warn(f"{package}.{attr}", f"{names[attr]}.{attr}")
        return getattr(importlib.import_module(names[attr]), attr)

    return __getattr__


__all__ = ["MOVED_MODULES", "MOVED_PACKAGES", "REMOVED_IN", "MovedFinder", "install", "moved_names"]
