"""A restricted evaluator of the Python-like expressions a robot description holds (xacro's ``${...}`` and
``$(eval ...)``), for descriptions that are not trusted.

xacro evaluates ``${...}`` with Python's ``eval`` and a name check that a lambda or a comprehension escapes, so a
description could run any code. This evaluator walks the expression's syntax tree itself and knows only what
descriptions use:

* numbers, strings, booleans, ``None``, lists, tuples, dicts and sets, written or computed;
* arithmetic, comparisons, ``and``/``or``/``not``, ``a if c else b``, indexing and slicing, list comprehensions;
* names: the description's properties (given by a lookup function) and :data:`SAFE_NAMES` (``math``'s functions
  and constants, a few builtins such as ``len``, ``min``, ``range``, ``str``, ``float``);
* calls of those functions and of the functions a caller adds (xacro's ``xacro.arg``, ``xacro.load_yaml``...),
  and a few methods of strings, lists and dicts that only compute (``split``, ``join``, ``get``...).

Nothing else: no lambda, no attribute whose name starts with ``_``, no ``str.format`` (its fields reach
attributes), no f-string, no other object's attributes. Work is bounded (:data:`MAX_STEPS` steps, sequences and
strings of :data:`MAX_ITEMS`, integers of :data:`MAX_INT_BITS`), so an expression cannot hold the process either.
A refused or failing expression raises :class:`ExpressionError` naming what was refused.
"""
from __future__ import annotations

import ast
import itertools
import math
import operator
import re
from dataclasses import dataclass, field
from typing import Any, Callable, Iterator, Mapping

__all__ = ["MAX_STEPS", "MAX_ITEMS", "MAX_INT_BITS", "MAX_EXPRESSION_CHARS", "ExpressionError", "Namespace",
           "SAFE_NAMES", "evaluate"]

#: Steps (syntax nodes evaluated, comprehension items) one expression may take.
MAX_STEPS = 1_000_000
#: Items of a sequence (or characters of a string) an expression may build.
MAX_ITEMS = 1_000_000
#: Bits of an integer an expression may build.
MAX_INT_BITS = 4096
#: Characters of an expression's text.
MAX_EXPRESSION_CHARS = 100_000


class ExpressionError(Exception):
    """An expression that the restricted evaluator refuses or cannot evaluate; the message says which part."""


class Namespace(dict):
    """Names reached with a dot (``math.pi``, ``xacro.arg``): a dict whose items are read as attributes."""


def _bounded_range(*args: int) -> range:
    r = range(*args)
    if len(r) > MAX_ITEMS:
        raise ExpressionError(f"range of {len(r)} items (at most {MAX_ITEMS})")
    return r


#: math's functions whose work grows with their arguments' values (factorial(10**7) takes minutes) are left out.
_UNBOUNDED_MATH = frozenset({"factorial", "comb", "perm", "prod", "lcm"})
_MATH = Namespace({k: v for k, v in vars(math).items() if not k.startswith("_") and k not in _UNBOUNDED_MATH})
_BUILTINS: dict[str, Any] = {f.__name__: f for f in (
    abs, all, any, bool, dict, divmod, enumerate, filter, float, frozenset, int, len, list, map, max, min, ord, chr,
    repr, reversed, round, set, sorted, str, sum, tuple, zip)}
_BUILTINS["range"] = _bounded_range

#: The names every expression may use: math's (``pi``, ``sin``, ``radians``... also as ``math.NAME``), the builtins
#: above (also as ``python.NAME``), ``True``/``False``/``None``.
SAFE_NAMES: dict[str, Any] = {**_MATH, **_BUILTINS, "math": _MATH, "python": Namespace(_BUILTINS),
                              "True": True, "False": False, "None": None}

#: Methods that only compute, by the type they are called on.
_METHODS: dict[type, frozenset[str]] = {
    str: frozenset({"split", "rsplit", "join", "strip", "lstrip", "rstrip", "lower", "upper", "replace",
                    "startswith", "endswith", "find", "count", "isdigit", "splitlines", "title", "capitalize"}),
    list: frozenset({"index", "count"}),
    tuple: frozenset({"index", "count"}),
    dict: frozenset({"get", "keys", "values", "items"}),
}

_BINARY: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod, ast.Pow: operator.pow, ast.BitAnd: operator.and_,
    ast.BitOr: operator.or_, ast.BitXor: operator.xor}
_UNARY: dict[type, Callable[[Any], Any]] = {ast.USub: operator.neg, ast.UAdd: operator.pos, ast.Not: operator.not_,
                                           ast.Invert: operator.invert}
_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt,
    ast.GtE: operator.ge, ast.In: lambda a, b: a in b, ast.NotIn: lambda a, b: a not in b,
    ast.Is: operator.is_, ast.IsNot: operator.is_not}

#: Types an expression's values may have (a property's value of any other type is refused when used).
_DATA = (int, float, complex, str, bool, type(None), list, tuple, dict, set, frozenset, range, Namespace)


@dataclass
class _Run:
    lookup: Callable[[str], Any]
    functions: frozenset[int]
    steps: int = 0
    local: list[dict[str, Any]] = field(default_factory=list)

    def step(self) -> None:
        self.steps += 1
        if self.steps > MAX_STEPS:
            raise ExpressionError(f"the expression takes more than {MAX_STEPS} steps")


def evaluate(text: str, lookup: Callable[[str], Any], functions: Mapping[str, Any] | None = None) -> Any:
    """The value of the expression ``text``. ``lookup(name)`` gives a name's value or raises KeyError (then
    :data:`SAFE_NAMES`, then ``functions``: extra names such as a ``xacro`` Namespace of callables, which may be
    called). Raises :class:`ExpressionError` for what is refused or fails."""
    if len(text) > MAX_EXPRESSION_CHARS:
        raise ExpressionError(f"an expression of {len(text)} characters (at most {MAX_EXPRESSION_CHARS})")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except (SyntaxError, ValueError, RecursionError) as exc:
        raise ExpressionError(f"not an expression: {text.strip()!r} ({type(exc).__name__})") from None
    extra = dict(functions or {})
    callables = _SAFE_CALLABLES | {id(f) for f in _callables(extra)}

    def names(name: str) -> Any:
        try:
            return lookup(name)
        except KeyError:
            pass
        if name in extra:
            return extra[name]
        if name in SAFE_NAMES:
            return SAFE_NAMES[name]
        raise ExpressionError(f"name {name!r} is not defined") from None

    run = _Run(names, callables)
    try:
        return _value(_eval(tree.body, run))
    except ExpressionError:
        raise
    except RecursionError:
        raise ExpressionError("the expression is nested too deeply") from None
    except (ArithmeticError, TypeError, ValueError, KeyError, IndexError, AttributeError) as exc:
        raise ExpressionError(f"{type(exc).__name__}: {exc}") from None


def _callables(names: Mapping[str, Any]) -> list[Any]:
    out = []
    for value in names.values():
        if isinstance(value, Namespace):
            out += _callables(value)
        elif callable(value):
            out.append(value)
    return out


#: The functions of SAFE_NAMES, by identity: what an expression may call besides a caller's own.
_SAFE_CALLABLES = frozenset(id(f) for f in _callables(SAFE_NAMES))


def _value(v: Any) -> Any:
    """``v`` if an expression may hold it (plain data, bounded), else an ExpressionError."""
    if isinstance(v, bool) or v is None:
        return v
    if isinstance(v, int):
        if v.bit_length() > MAX_INT_BITS:
            raise ExpressionError(f"an integer of {v.bit_length()} bits (at most {MAX_INT_BITS})")
        return v
    if isinstance(v, (str, list, tuple, dict, set, frozenset)) and len(v) > MAX_ITEMS:
        raise ExpressionError(f"a {type(v).__name__} of {len(v)} items (at most {MAX_ITEMS})")
    if isinstance(v, _DATA):
        return v
    raise ExpressionError(f"a value of type {type(v).__name__} cannot be used in an expression")


def _eval(node: ast.AST, run: _Run) -> Any:
    run.step()
    handler = _HANDLERS.get(type(node))
    if handler is None:
        raise ExpressionError(f"{_what(node)} is not allowed in a description's expression")
    return handler(node, run)


def _what(node: ast.AST) -> str:
    names = {ast.Lambda: "a lambda", ast.JoinedStr: "an f-string", ast.NamedExpr: "an assignment (:=)",
             ast.GeneratorExp: "a generator", ast.DictComp: "a dict comprehension", ast.SetComp: "a set comprehension",
             ast.Await: "await", ast.Yield: "yield", ast.Starred: "a starred argument"}
    return names.get(type(node), f"syntax {type(node).__name__}")


def _constant(node: ast.Constant, run: _Run) -> Any:
    if isinstance(node.value, bytes):
        raise ExpressionError("bytes literals are not allowed in a description's expression")
    return node.value


def _name(node: ast.Name, run: _Run) -> Any:
    for scope in reversed(run.local):
        if node.id in scope:
            return scope[node.id]
    value = run.lookup(node.id)
    if callable(value) and not isinstance(value, Namespace):
        if id(value) not in run.functions:
            raise ExpressionError(f"name {node.id!r} is not a value or function an expression may use")
        return value
    return _value(value)


def _attribute(node: ast.Attribute, run: _Run) -> Any:
    if node.attr.startswith("_"):
        raise ExpressionError(f"attribute {node.attr!r}: names starting with '_' are not allowed")
    owner = _eval(node.value, run)
    if isinstance(owner, Namespace):
        if node.attr not in owner:
            raise ExpressionError(f"{node.attr!r} is not defined in its namespace")
        return owner[node.attr]
    if isinstance(owner, dict) and node.attr in owner:  # xacro's YAML dicts read keys as attributes
        return _value(owner[node.attr])
    for kind, methods in _METHODS.items():
        if isinstance(owner, kind) and node.attr in methods:
            return getattr(owner, node.attr)
    raise ExpressionError(f"attribute {node.attr!r} of a {type(owner).__name__} is not allowed")


def _call(node: ast.Call, run: _Run) -> Any:
    function = _eval(node.func, run)
    if not _is_allowed_method(function) and id(function) not in run.functions:
        raise ExpressionError(f"{ast.unparse(node.func)!r} is not a function an expression may call")
    args = [_eval(a, run) for a in node.args]
    kwargs = {}
    for k in node.keywords:
        if k.arg is None:
            raise ExpressionError("**keyword arguments are not allowed in a description's expression")
        kwargs[k.arg] = _eval(k.value, run)
    result = function(*args, **kwargs)
    if isinstance(result, Iterator):  # map, zip, reversed...: their items are built here, under the bounds
        result = list(itertools.islice(result, MAX_ITEMS + 1))
    return _value(result)


def _is_allowed_method(function: Any) -> bool:
    """Whether ``function`` is a method of :data:`_METHODS` bound to a value (what :func:`_attribute` gives)."""
    owner = getattr(function, "__self__", None)
    name = getattr(function, "__name__", "")
    return any(isinstance(owner, kind) and name in methods for kind, methods in _METHODS.items())


def _binary(node: ast.BinOp, run: _Run) -> Any:
    op = _BINARY.get(type(node.op))
    if op is None:
        raise ExpressionError(f"operator {type(node.op).__name__} is not allowed in a description's expression")
    left, right = _eval(node.left, run), _eval(node.right, run)
    _check_size(node.op, left, right)
    return _value(op(left, right))


def _check_size(op: ast.operator, left: Any, right: Any) -> None:
    """Refuse, before computing it, a power or a repetition whose result would break the bounds."""
    if isinstance(op, ast.Pow) and isinstance(left, int) and isinstance(right, int) and abs(left) > 1:
        if right * max(abs(left).bit_length(), 1) > MAX_INT_BITS:
            raise ExpressionError(f"{left} ** {right} is too large (integers of at most {MAX_INT_BITS} bits)")
    if isinstance(op, ast.Mult):
        for seq, n in ((left, right), (right, left)):
            if isinstance(seq, (str, list, tuple)) and isinstance(n, int) and len(seq) * n > MAX_ITEMS:
                raise ExpressionError(f"a repetition of {len(seq) * n} items (at most {MAX_ITEMS})")
    if isinstance(op, ast.Mod) and isinstance(left, str):  # '%999999999d' % 1 would build a gigabyte
        widths = [int(w) for w in re.findall(r"%[^a-zA-Z%]*?(\d+)", left)]
        if widths and max(widths) > MAX_ITEMS:
            raise ExpressionError(f"a format width of {max(widths)} (at most {MAX_ITEMS})")


def _unary(node: ast.UnaryOp, run: _Run) -> Any:
    return _value(_UNARY[type(node.op)](_eval(node.operand, run)))


def _boolean(node: ast.BoolOp, run: _Run) -> Any:
    value: Any = None
    for operand in node.values:
        value = _eval(operand, run)
        if isinstance(node.op, ast.And) != bool(value):
            return value
    return value


def _compare(node: ast.Compare, run: _Run) -> bool:
    left = _eval(node.left, run)
    for op, comparator in zip(node.ops, node.comparators):
        right = _eval(comparator, run)
        if not _COMPARE[type(op)](left, right):
            return False
        left = right
    return True


def _if(node: ast.IfExp, run: _Run) -> Any:
    return _eval(node.body, run) if _eval(node.test, run) else _eval(node.orelse, run)


def _subscript(node: ast.Subscript, run: _Run) -> Any:
    owner = _eval(node.value, run)
    if not isinstance(owner, (str, list, tuple, dict, range)):
        raise ExpressionError(f"a {type(owner).__name__} cannot be indexed in a description's expression")
    return _value(owner[_eval(node.slice, run)])


def _slice(node: ast.Slice, run: _Run) -> slice:
    def part(p: ast.expr | None) -> Any:
        return None if p is None else _eval(p, run)

    return slice(part(node.lower), part(node.upper), part(node.step))


def _list(node: ast.List | ast.Tuple | ast.Set, run: _Run) -> Any:
    items = [_eval(e, run) for e in node.elts]
    kind = {ast.List: list, ast.Tuple: tuple, ast.Set: set}[type(node)]
    return _value(kind(items))


def _dict(node: ast.Dict, run: _Run) -> dict:
    if any(k is None for k in node.keys):
        raise ExpressionError("**unpacking is not allowed in a description's expression")
    return _value({_eval(k, run): _eval(v, run) for k, v in zip(node.keys, node.values) if k is not None})


def _list_comprehension(node: ast.ListComp, run: _Run) -> list:
    out: list[Any] = []
    run.local.append({})
    try:
        _generate(node.generators, 0, node.elt, run, out)
    finally:
        run.local.pop()
    return _value(out)


def _generate(generators: list[ast.comprehension], k: int, element: ast.expr, run: _Run, out: list) -> None:
    if k == len(generators):
        out.append(_eval(element, run))
        if len(out) > MAX_ITEMS:
            raise ExpressionError(f"a comprehension of more than {MAX_ITEMS} items")
        return
    g = generators[k]
    if g.is_async or not isinstance(g.target, (ast.Name, ast.Tuple)):
        raise ExpressionError("a comprehension may only bind names")
    for item in _eval(g.iter, run):
        run.step()
        _bind(g.target, item, run.local[-1])
        if all(_eval(condition, run) for condition in g.ifs):
            _generate(generators, k + 1, element, run, out)


def _bind(target: ast.expr, item: Any, scope: dict[str, Any]) -> None:
    if isinstance(target, ast.Name):
        scope[target.id] = _value(item)
        return
    if not isinstance(target, ast.Tuple) or not all(isinstance(e, (ast.Name, ast.Tuple)) for e in target.elts):
        raise ExpressionError("a comprehension may only bind names")
    values = list(item)
    if len(values) != len(target.elts):
        raise ExpressionError(f"cannot unpack {len(values)} values into {len(target.elts)} names")
    for e, v in zip(target.elts, values):
        _bind(e, v, scope)


_HANDLERS: dict[type, Callable[[Any, _Run], Any]] = {
    ast.Constant: _constant, ast.Name: _name, ast.Attribute: _attribute, ast.Call: _call, ast.BinOp: _binary,
    ast.UnaryOp: _unary, ast.BoolOp: _boolean, ast.Compare: _compare, ast.IfExp: _if, ast.Subscript: _subscript,
    ast.Slice: _slice, ast.List: _list, ast.Tuple: _list, ast.Set: _list, ast.Dict: _dict,
    ast.ListComp: _list_comprehension}
