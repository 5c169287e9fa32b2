"""Sphinx configuration of snakehead's documentation: ``python3 -m sphinx -W -q -b html docs build/docs-html``.

The API reference is generated from the docstrings of every public module and of the C++ core (a page each, written
at build time); the build then checks that every public name of the package is documented and that every
cross-reference resolves (nitpicky, with ``python_refs``): warnings, so errors with ``-W``. The CLI reference is the
argparse help of ``snakehead`` itself; the architecture page's figure is drawn from the import-linter contract
(``layer_figure``).
"""
from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
import sys
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import Directive
from sphinx.util import logging

import snakehead
from snakehead import sweep_defaults
from snakehead.app.cli import build_parser
from snakehead.planning import whole_body_reach

sys.path.insert(0, str(Path(__file__).parent))  # this folder's helpers, imported next
from layer_figure import LayersFigure, check_sections  # noqa: E402
from python_refs import resolve  # noqa: E402

project = "snakehead"
author = "the snakehead developers"
copyright = "the snakehead developers"
release = snakehead.__version__
version = snakehead.__version__

extensions = ["sphinx.ext.autodoc", "myst_parser"]
source_suffix = {".rst": "restructuredtext"}
templates_path = ["_templates"]
exclude_patterns = ["_build"]
API_DIR = "_api"  # one generated page per public module (write_api_pages)
html_theme = "furo"
html_static_path = ["_static"]
html_title = f"snakehead {release}"
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
# A module documents what it defines; a package's re-exports (its __all__) are documented where they are defined.
autodoc_default_options = {"members": True, "undoc-members": True, "show-inheritance": True,
                           "ignore-module-all": True}
myst_heading_anchors = 3
# Every cross-reference must resolve (with -W, a broken one fails the build); python_refs.resolve finds the names
# docstrings use as their module sees them.
nitpicky = True
# The base class of the C++ core's classes: pybind11's, not importable, documented nowhere.
nitpick_ignore = [("py:class", "pybind11_builtins.pybind11_object")]


def shared_numbers() -> str:
    """Substitutions for the numbers the pages quote, from where each is defined (``|reach_voxel|`` ...), so that
    the pages cannot drift from the code: the sweeps' defaults (snakehead.sweep_defaults) and limits."""
    numbers = {"reach_voxel": f"{sweep_defaults.REACH_VOXEL_M:g}",
               "reach_directions": sweep_defaults.REACH_DIRECTIONS,
               "reach_min_voxel": f"{whole_body_reach.MIN_VOXEL_M:g}",
               "reach_max_directions": whole_body_reach.MAX_DIRECTIONS}
    return "\n".join(f".. |{name}| replace:: {value}" for name, value in numbers.items())


rst_epilog = shared_numbers()
# The pages include Markdown files (bench/RESULTS.md) whose first heading is not level 1.
suppress_warnings = ["myst.header"]


#: The C++ core's module, documented beside the public ones: its classes appear in the package's signatures.
CORE_MODULE = "snakehead._core"


def public_modules() -> list[str]:
    """Every module of the package whose dotted name has no part starting with an underscore, and the C++ core."""
    names = ["snakehead", CORE_MODULE]
    for info in pkgutil.walk_packages(snakehead.__path__, "snakehead."):
        if not any(part.startswith("_") for part in info.name.split(".")):
            names.append(info.name)
    return sorted(names)


def public_names() -> dict[str, str]:
    """{documented name: where it is public} for every public function and class of the package: the names each
    public module lists in ``__all__``, and those defined in a public module without a leading underscore."""
    out: dict[str, str] = {}
    for modname in public_modules():
        module = importlib.import_module(modname)
        listed = getattr(module, "__all__", None)
        names = listed if listed is not None else [n for n in vars(module) if not n.startswith("_")]
        for name in names:
            obj = getattr(module, name)
            if not (inspect.isclass(obj) or inspect.isfunction(obj)):
                continue
            home = getattr(obj, "__module__", "") or ""
            if listed is None and home != modname:
                continue  # imported here, not defined here
            if not home.startswith("snakehead") or any(p.startswith("_") for p in home.split(".")[1:]):
                home = modname
            out[f"{home}.{obj.__qualname__}"] = f"{modname}.{name}"
    return out


def write_api_pages(app) -> None:
    """One page per public module (``automodule`` with its members) and their index, under ``_api``. Written
    here, not by autosummary: some modules share their name with a function their package exports
    (``snakehead.sim.compare``), which autosummary's lookup by attribute would take for the function."""
    folder = Path(app.srcdir) / API_DIR
    folder.mkdir(exist_ok=True)
    pages = {}
    for modname in public_modules():
        module = importlib.import_module(modname)
        summary = (inspect.getdoc(module) or "").strip().split("\n")[0]
        pages[modname] = summary
        text = f"{modname}\n{'=' * len(modname)}\n\n.. automodule:: {modname}\n"
        # names this module exports from a private module (e.g. viz.save from viz._common) are documented here
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            home = getattr(obj, "__module__", "") or ""
            if home.startswith("snakehead") and any(p.startswith("_") for p in home.split(".")[1:]):
                kind = "autoclass" if inspect.isclass(obj) else "autofunction"
                text += f"\n.. {kind}:: {modname}.{name}\n"
        path = folder / f"{modname}.rst"
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
    for stale in folder.glob("snakehead*.rst"):  # the page of a module that was moved or removed
        if stale.stem not in pages:
            stale.unlink()
    index = ["Modules", "=======", "", ".. toctree::", "   :maxdepth: 1", ""]
    index += [f"   {name} <{name}>" for name in pages]
    text = "\n".join(index) + "\n"
    path = folder / "index.rst"
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def check_every_public_name(app, env) -> None:
    """Warn for each public function and class of the package that no API page documents."""
    logger = logging.getLogger("snakehead.docs")
    documented = set(env.get_domain("py").objects)
    for name, where in sorted(public_names().items()):
        if name not in documented and where not in documented:
            logger.warning(f"public name {where} ({name}) is not in the API reference")


class CliHelp(Directive):
    """``.. snakehead-cli::``: the help of ``snakehead`` and of each subcommand, as argparse prints it."""

    def run(self):
        parser = build_parser()
        out = [nodes.literal_block(text=parser.format_help())]
        for action in parser._subparsers._group_actions:  # the subcommands, in the order they are listed
            for name, sub in action.choices.items():
                section = nodes.section(ids=[f"snakehead-{name}"])
                section += nodes.title(text=f"snakehead {name}")
                section += nodes.literal_block(text=sub.format_help())
                out.append(section)
        return out


_FIELD = re.compile(r"^[A-Za-z_][\w /*,()]*? : \S")  # "name : what it is", as the docstrings list parameters
_ITEM = re.compile(r"^(\s*)([-*]|\d+\.) \S")


def parseable_signature(app, what, name, obj, options, signature, return_annotation):
    """A dataclass field with a ``default_factory`` shows its default as ``<factory>``, which Sphinx cannot parse as
    Python: it then splits the signature at every comma, ``tuple[str, ...]`` included. Written ``...`` instead."""
    if signature and "<factory>" in signature:
        return signature.replace("<factory>", "..."), return_annotation
    return None


def plain_text_to_rst(app, what, name, obj, options, lines) -> None:
    """The docstrings are written for ``help()``: plain text with a little reStructuredText (````code````, roles).
    Make the plain-text habits valid reStructuredText: norms written |a - b| are not substitutions; a parameter
    line "name : what" continued on indented lines is one line; an indented block after "text:" is shown as
    written (a literal block); lists and indented blocks get the blank lines around them that reStructuredText
    needs."""
    text = [line.replace("|", "\\|") for line in lines]
    joined: list[str] = []
    for line in text:
        if joined and line.startswith(" ") and line.strip() and _FIELD.match(joined[-1]):
            joined[-1] += " " + line.strip()
        else:
            joined.append(line)
    # "text:" introducing an indented block (a formula, a table of values) makes it a literal block
    for i in range(len(joined) - 2):
        line, gap, block = joined[i], joined[i + 1], joined[i + 2]
        if (line.rstrip().endswith(":") and not line.rstrip().endswith("::") and not gap.strip()
                and block.startswith(" ") and block.strip() and not _ITEM.match(block)):
            joined[i] = line.rstrip() + ":"
    out: list[str] = []
    for line in joined:
        prev = out[-1] if out else ""
        item, prev_item = _ITEM.match(line), _ITEM.match(prev)
        indented, prev_indented = line.startswith(" "), prev.startswith(" ")
        if prev.strip() and line.strip():
            starts_list = item and not item.group(1)  # (items apart: "1." then "3." is two lists)
            leaves_block = not indented and not item and (prev_indented or prev_item)
            if starts_list or leaves_block:
                out.append("")
        out.append(line)
    lines[:] = out


def setup(app):
    app.connect("autodoc-process-docstring", plain_text_to_rst)
    app.connect("autodoc-process-signature", parseable_signature)
    app.add_directive("snakehead-cli", CliHelp)
    app.add_directive("snakehead-layers", LayersFigure)
    app.connect("doctree-read", check_sections)
    app.connect("missing-reference", resolve)
    app.connect("builder-inited", write_api_pages)
    app.connect("env-check-consistency", check_every_public_name)
    return {"parallel_read_safe": True}
