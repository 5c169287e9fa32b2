"""The package's layout (docs/architecture.rst): one module per name, nothing taken from the root package but the
C++ core, and the old import paths of the modules that moved still working, with a DeprecationWarning, for one
release. The layers themselves are import-linter's (``lint-imports``, pyproject.toml)."""
from __future__ import annotations

import ast
import importlib
import sys
import warnings
from collections import Counter
from pathlib import Path

import pytest

import snakehead
from snakehead import _moved

PACKAGE = Path(snakehead.__file__).parent


def _modules() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def _dotted(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def test_no_two_modules_share_a_name():
    names = Counter(p.stem for p in _modules() if p.stem != "__init__")
    packages = {p.parent.name for p in _modules() if p.name == "__init__.py"}
    assert [n for n, c in names.items() if c > 1] == []
    assert sorted(names.keys() & packages) == []  # a module named like a package (viz/dynamics.py) reads as one


#: The longest module the layout allows (DESIGN.md): past it, a module holds more than one concept.
MAX_MODULE_LINES = 600


def test_no_module_is_over_the_line_limit():
    lengths = {str(p.relative_to(PACKAGE)): len(p.read_text().splitlines()) for p in _modules()}
    assert {name: n for name, n in lengths.items() if n > MAX_MODULE_LINES} == {}
    assert max(lengths.values()) > 100  # the walk found the package's modules


def test_submodules_take_only_the_core_from_the_root_package():
    """``from .. import X`` and ``from snakehead import X`` inside the package may only take modules (``_core``,
    ``limits``, ...), not the names the root re-exports (``plan``, ``SnakeRobot``): those would be upward imports
    that import-linter's ignore rule (``snakehead.** -> snakehead``) hides."""
    modules = {"_core", "__version__"} | {p.stem for p in PACKAGE.glob("*.py")} | {p.parent.name for p in PACKAGE.glob("*/__init__.py")}
    bad = []
    for path in _modules():
        if path.parent == PACKAGE and path.name == "__init__.py":
            continue
        module = _dotted(path)
        package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = package.split(".")
                target = ".".join(base[: len(base) - node.level + 1] + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target == "snakehead":
                bad += [f"{module}: {a.name}" for a in node.names if a.name not in modules]
    assert bad == []


@pytest.mark.parametrize("old, new", sorted(_moved.MOVED_MODULES.items()))
def test_an_old_module_path_warns_and_is_the_new_module(old, new):
    sys.modules.pop(old, None)
    with pytest.warns(DeprecationWarning) as warned:  # (its old package too, when that went away)
        module = importlib.import_module(old)
    assert any(f"{old} moved to {new};" in str(w.message) for w in warned)
    assert module is importlib.import_module(new)
    assert module.__name__ == new and module.__spec__.name == new  # the module keeps its own name and spec


def test_old_packages_give_their_names_and_submodules():
    for old in [*_moved.MOVED_PACKAGES, "snakehead.control.controller"]:
        sys.modules.pop(old, None)
    with pytest.warns(DeprecationWarning):
        from snakehead.motion import planner, retime  # noqa: F401  (the old spellings users hold)
    from snakehead.planning import planner as new_planner
    from snakehead.retiming import retime as new_retime

    assert planner is new_planner and retime is new_retime
    with pytest.warns(DeprecationWarning):
        from snakehead.control import HeadController
    assert HeadController is snakehead.HeadController
    with pytest.warns(DeprecationWarning):
        import snakehead.control.controller as controller
    assert controller.HeadController is snakehead.HeadController
    with pytest.raises(AttributeError):
        _ = importlib.import_module("snakehead.motion").no_such_name


def test_names_that_left_a_package_warn_and_resolve():
    import snakehead.geometry
    import snakehead.sim  # noqa: F401  (imported without mujoco: the plant's modules import it lazily)
    from snakehead.closed_loop import GaitSimulator
    from snakehead.collision import ground_clearance

    with pytest.warns(DeprecationWarning, match="snakehead.collision"):
        assert snakehead.geometry.ground_clearance is ground_clearance
    with pytest.warns(DeprecationWarning, match="snakehead.closed_loop"):
        assert snakehead.sim.GaitSimulator is GaitSimulator
    with pytest.raises(AttributeError):
        _ = snakehead.geometry.no_such_name


def test_the_new_paths_import_without_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        for path in _modules():
            if path.name != "__main__.py":  # (runs the command line)
                importlib.import_module(_dotted(path))
