"""Python cross-references that Sphinx's own lookup misses, resolved the way Python resolves the name.

The API reference documents each name once, where it is defined (``snakehead.planning.planner.plan``). A docstring
refers to a name as its module sees it: ``:func:`plan``` in ``snakehead``'s docstring, ``:class:`SnakeRobot``` where
the module imported it, ``:func:`st.zmp``` through a module alias, a type its annotations import only for the type
checker (``if TYPE_CHECKING:``). Sphinx looks such names up as text and finds nothing. Here (the
``missing-reference`` event) the name is looked up as Python would, from the module (and class) of the docstring.
The object found is linked to the page where it is documented. Left as plain text, because the reference has no
page for them:

- an object of another project (numpy, pathlib, matplotlib ...: no inventory of theirs is at hand offline);
- a type variable;
- a constant with a public name (autodoc documents a module's constants only when they have a ``#:`` comment);
- an attribute that instances get in ``__init__`` without a ``#:`` comment.

Anything else stays missing, so that nitpicky mode reports it:

- a name that does not exist (a stale reference);
- an old import path kept only for users (``snakehead.motion...``: it warns on import);
- a private name, which the reference does not document.
"""
from __future__ import annotations

import ast
import importlib
import importlib.util
import inspect
import sys
import textwrap
import types
import warnings
from typing import Any, TypeVar

from docutils import nodes
from sphinx import addnodes
from sphinx.util.nodes import make_refnode

from snakehead._moved import MOVED_MODULES, MOVED_PACKAGES

_MISSING = object()
#: {(id of a documented object, or of a value with its name): documented full name}, built once per build.
_INDEX: dict[tuple[int, str], str] = {}
_KEEP: list[Any] = []  # the indexed objects, kept alive so that their ids stay theirs


def _attribute_path(obj: Any, parts: list[str]) -> Any:
    for part in parts:
        obj = getattr(obj, part)
    return obj


def _absolute(name: str) -> Any:
    """The object at a dotted path: the longest prefix that imports as a module, then attributes."""
    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        try:
            module = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        try:
            return _attribute_path(module, parts[i:])
        except AttributeError:
            return _MISSING
    return _MISSING


def old_path(name: str) -> bool:
    """Whether a dotted path goes through a module or package that moved (``snakehead._moved``): such a path
    resolves, with a warning the first time only, so it is refused by name."""
    parts = name.split(".")
    prefixes = {".".join(parts[:i]) for i in range(1, len(parts) + 1)}
    return not prefixes.isdisjoint(MOVED_MODULES) or not prefixes.isdisjoint(MOVED_PACKAGES)


def _quiet_lookup(name: str, where: Any | None) -> Any:
    """``name`` from ``where`` (attributes), or absolute when ``where`` is None; _MISSING when it is not there or
    when it is an old path kept for users (it warns on import)."""
    if where is None and old_path(name):
        return _MISSING
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            obj = _absolute(name) if where is None else _attribute_path(where, name.split("."))
        except Exception:  # any failure of a lookup means "not found here"
            return _MISSING
    if any(issubclass(w.category, DeprecationWarning) for w in caught):
        return _MISSING
    return obj


def type_checking_imports(module: types.ModuleType) -> dict[str, str]:
    """{name: absolute dotted path} of what ``module`` imports under ``if TYPE_CHECKING:`` (names its annotations
    use that do not exist at run time)."""
    try:
        tree = ast.parse(inspect.getsource(module))
    except (OSError, TypeError, SyntaxError):
        return {}
    package = module.__name__ if hasattr(module, "__path__") else module.__name__.rpartition(".")[0]
    out: dict[str, str] = {}
    for node in tree.body:
        test = node.test if isinstance(node, ast.If) else None
        if not (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING"
                or isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"):
            continue
        for stmt in ast.walk(node):
            if isinstance(stmt, ast.ImportFrom):
                base = importlib.util.resolve_name("." * stmt.level + (stmt.module or ""), package) if stmt.level \
                    else stmt.module or ""
                for alias in stmt.names:
                    out[alias.asname or alias.name] = f"{base}.{alias.name}"
            elif isinstance(stmt, ast.Import):
                for alias in stmt.names:
                    out[alias.asname or alias.name.split(".")[0]] = alias.name if alias.asname else \
                        alias.name.split(".")[0]
    return out


def home_modules(obj: Any) -> list[types.ModuleType]:
    """The modules whose namespaces an object's annotations and docstring were written in: a function's own module,
    a class's and its bases' (an inherited field's annotation is its base's). A name a package re-exports is
    documented on the package's page, but its signature names what its own module imports."""
    owners = inspect.getmro(obj) if inspect.isclass(obj) else (obj,)
    names = [getattr(owner, "__module__", None) for owner in owners]
    return [sys.modules[name] for name in dict.fromkeys(names) if isinstance(name, str) and name in sys.modules]


def lookup(target: str, modname: str | None, classname: str | None, documented: Any = _MISSING) -> Any:
    """What ``target`` names in the docstring of ``modname`` (and ``classname``): with a leading dot, a name
    relative to the docstring's package; a member of the class, a name in the module's namespace or in the home
    modules of the ``documented`` object whose signature or docstring holds the reference, a submodule of the
    package, a name imported for the type checker, else an absolute path."""
    if target.startswith(".") and modname:  # relative to the docstring's package, as in a relative import
        package = modname if hasattr(sys.modules.get(modname), "__path__") else modname.rpartition(".")[0]
        obj = _quiet_lookup(f"{package}.{target.lstrip('.')}", None) if package else _MISSING
        if obj is not _MISSING:
            return obj
    target = target.lstrip(".~")
    scopes: list[Any] = []
    module = _quiet_lookup(modname, None) if modname else _MISSING
    if module is not _MISSING:
        if classname:
            cls = _quiet_lookup(classname, module)
            if cls is not _MISSING:
                scopes.append(cls)
        scopes.append(module)
    if documented is not _MISSING:
        scopes += home_modules(documented)
    for scope in scopes:
        obj = _quiet_lookup(target, scope)
        if obj is not _MISSING:
            return obj
    if modname:
        obj = _quiet_lookup(f"{modname}.{target}", None)  # a submodule (``:mod:`.curves``` in a package)
        if obj is not _MISSING:
            return obj
    first, _, rest = target.partition(".")
    for scope in scopes:
        checked = type_checking_imports(scope).get(first) if isinstance(scope, types.ModuleType) else None
        if checked is not None:
            return _quiet_lookup(f"{checked}.{rest}" if rest else checked, None)
    return _quiet_lookup(target, None)


def _unwrap(obj: Any) -> Any:
    return getattr(obj, "__func__", obj)  # a classmethod reached through its class is a new bound method each time


def _named(obj: Any) -> bool:
    """Whether the object has a name of its own (module, class, function, property), so that an alias of it
    (``st`` for ``stability``) still finds it; other values (numbers, strings) match by their name too."""
    return isinstance(obj, (types.ModuleType, type, types.FunctionType, types.BuiltinFunctionType, property))


def _key(obj: Any, name: str) -> tuple[int, str]:
    return (id(obj), "" if _named(obj) else name.rsplit(".", 1)[-1])


def _build_index(env) -> None:
    for fullname in sorted(env.get_domain("py").objects, key=lambda n: (len(n), n)):
        obj = _quiet_lookup(fullname, None)
        if obj is _MISSING:
            continue
        obj = _unwrap(obj)
        _KEEP.append(obj)
        _INDEX.setdefault(_key(obj, fullname), fullname)


def external(obj: Any) -> bool:
    """Whether the object belongs to another project or the standard library (a module, class, function or typing
    construct such as ``numpy.typing.ArrayLike``), or is a type variable."""
    if isinstance(obj, TypeVar):
        return True
    home = obj.__name__ if isinstance(obj, types.ModuleType) else getattr(obj, "__module__", None)
    return isinstance(home, str) and home.split(".")[0] != "snakehead"  # numbers, strings, arrays have none


def documented_object(node: nodes.Node) -> Any:
    """The object whose signature or docstring holds ``node``: the nearest enclosing object description's."""
    parent = node.parent
    while parent is not None:
        if isinstance(parent, addnodes.desc):
            signatures = [child for child in parent.children if isinstance(child, addnodes.desc_signature)]
            ids = signatures[0].get("ids", []) if signatures else []
            return _quiet_lookup(ids[0], None) if ids else _MISSING
        parent = parent.parent
    return _MISSING


def instance_attributes(cls: type) -> set[str]:
    """The attributes the instances of ``cls`` (and of its bases) get: annotated fields and ``self.NAME = ...``
    in its methods. They are not attributes of the class, so looking them up on it finds nothing."""
    names: set[str] = set()
    for owner in inspect.getmro(cls):
        names.update(getattr(owner, "__annotations__", {}))
        try:
            tree = ast.parse(textwrap.dedent(inspect.getsource(owner)))
        except (OSError, TypeError, SyntaxError):
            continue
        for node in ast.walk(tree):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(
                node, ast.AnnAssign) else []
            names.update(t.attr for t in targets if isinstance(t, ast.Attribute) and isinstance(t.value, ast.Name)
                         and t.value.id == "self")
    return names


def _instance_attribute(app, env, node, contnode, documented: Any) -> nodes.Node | None:
    """``Class.attribute`` for an attribute of the instances: a link where autodoc documents it (a field of the
    class or of a base), else plain text; None when the class has no such attribute."""
    parent, _, attr = node["reftarget"].lstrip(".~").rpartition(".")
    if not parent or attr.startswith("_"):
        return None
    cls = lookup(parent, node.get("py:module"), node.get("py:class"), documented)
    if not inspect.isclass(cls) or attr not in instance_attributes(cls):
        return None
    objects = env.get_domain("py").objects
    for owner in inspect.getmro(cls):
        fullname = f"{owner.__module__}.{owner.__qualname__}.{attr}"
        if fullname in objects:
            entry = objects[fullname]
            return make_refnode(app.builder, node["refdoc"], entry.docname, entry.node_id, contnode, fullname)
    return contnode


def resolve(app, env, node, contnode) -> nodes.Node | None:
    """The ``missing-reference`` handler: a link to where the object is documented, plain text for another
    project's object, None (still missing) otherwise."""
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"]
    if node.get("refspecific") and not target.startswith("."):
        target = "." + target  # Sphinx keeps ``.name``'s dot as this flag
    documented = documented_object(node)
    obj = lookup(target, node.get("py:module"), node.get("py:class"), documented)
    if obj is _MISSING:
        return _instance_attribute(app, env, node, contnode, documented)
    obj = _unwrap(obj)
    if external(obj):
        return contnode
    if not _INDEX:
        _build_index(env)
    fullname = _INDEX.get(_key(obj, target))
    if fullname is None:
        public_value = not _named(obj) and not target.rsplit(".", 1)[-1].startswith("_")
        return contnode if public_value else None
    entry = env.get_domain("py").objects[fullname]
    return make_refnode(app.builder, node["refdoc"], entry.docname, entry.node_id, contnode, fullname)
