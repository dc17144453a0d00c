"""Whitelist parser for the numeric fields of robot descriptions.

A description field is a number or a short arithmetic expression over the description's named
parameters, e.g. ``"l/2"``, ``"-m*g"``, ``"2*pi/3"``, ``"sqrt(2)/2"``, ``"l^2"``. The text is
parsed with :func:`ast.parse` and the syntax tree is walked node by node; only these constructs
are accepted:

* numeric literals (``int`` and ``float``; ``bool`` and ``complex`` are rejected),
* the names of declared parameters (real SymPy symbols) and the constant ``pi``,
* ``+ - * / **`` (``^`` is read as ``**``) and unary ``+``/``-``,
* calls, with positional arguments only, of ``sqrt sin cos tan asin acos atan atan2 exp log abs``.

Nothing else (attribute access, subscripts, lambdas, strings, comparisons, keyword arguments,
unknown names or functions) is evaluated: each raises :class:`DescriptionError`. The raw text is
never handed to ``eval``, ``exec`` or ``sympify``. Size is bounded: at most
``MAX_EXPRESSION_LENGTH`` characters, syntax trees at most ``MAX_EXPRESSION_DEPTH`` deep (checked
without recursion before anything is evaluated), exponents at most 100 in magnitude and constant
powers below ``10**300``. Integer literals stay exact, so ``"pi/2"`` is
exactly ``sympy.pi/2`` and ``"1/3"`` is ``Rational(1, 3)``; float literals become ``sympy.Float``.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Mapping

import sympy as sp

from robodyn.robot.errors import DescriptionError

__all__ = [
    "CONSTANTS",
    "FUNCTIONS",
    "MAX_EXPRESSION_DEPTH",
    "MAX_EXPRESSION_LENGTH",
    "parameter_symbol",
    "parse_value",
]

#: Functions an expression may call: name -> (SymPy function, number of arguments).
FUNCTIONS: Mapping[str, tuple[Callable[..., sp.Expr], int]] = {
    "sqrt": (sp.sqrt, 1),
    "sin": (sp.sin, 1),
    "cos": (sp.cos, 1),
    "tan": (sp.tan, 1),
    "asin": (sp.asin, 1),
    "acos": (sp.acos, 1),
    "atan": (sp.atan, 1),
    "atan2": (sp.atan2, 2),
    "exp": (sp.exp, 1),
    "log": (sp.log, 1),
    "abs": (sp.Abs, 1),
}

#: Named constants an expression may use (reserved: no parameter may take these names).
CONSTANTS: Mapping[str, sp.Expr] = {"pi": sp.pi}

#: Longest expression text accepted, characters.
MAX_EXPRESSION_LENGTH = 1000

#: Deepest syntax tree accepted (``"-" * 998 + "1"`` is 999 levels deep): nesting levels.
MAX_EXPRESSION_DEPTH = 100

#: Largest magnitude of a numeric exponent (guards against ``10**10**10``).
_MAX_EXPONENT = 100

#: Largest base-10 order of magnitude of a constant power (guards against ``((9**99)**99)**99``).
_MAX_MAGNITUDE = 300

_BINOPS: Mapping[type[ast.operator], Callable[[sp.Expr, sp.Expr], sp.Expr]] = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.Pow: lambda a, b: a**b,
}


def parameter_symbol(name: str) -> sp.Symbol:
    """The SymPy symbol of a named description parameter (``real=True``).

    Parameters
    ----------
    name : str
        Parameter name as declared in the description.

    Returns
    -------
    sympy.Symbol
    """
    return sp.Symbol(name, real=True)


class _Reject(Exception):
    """Internal: the expression is not acceptable; carries the reason."""


def parse_value(
    value: object, names: Mapping[str, sp.Symbol], *, where: str
) -> sp.Expr:
    """Parse one numeric description field into a SymPy expression.

    Parameters
    ----------
    value : int, float or str
        The field as read from the description: a number, or an expression text over the
        declared parameter names (see the module docstring for what is accepted).
    names : Mapping[str, sympy.Symbol]
        Declared parameter names and their symbols (normally ``parameter_symbol(name)``).
    where : str
        File and field path used in error messages, e.g. ``"arm.yaml: joints[2].link.mass"``.

    Returns
    -------
    sympy.Expr
        Exact for integer arithmetic (``Integer``/``Rational``/``pi``), ``Float`` where a float
        literal appears; symbols are those of ``names``.

    Raises
    ------
    DescriptionError
        For a value of another type, a non-finite number, a syntax error, an undeclared name, an
        unknown function or any construct outside the whitelist. The message names ``where``,
        the offending text and the reason.
    """
    if isinstance(value, bool):
        raise DescriptionError(
            f"{where}: expected a number or an expression, got the boolean {value!r}"
        )
    if isinstance(value, int):
        return sp.Integer(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise DescriptionError(f"{where}: expected a finite number, got {value!r}")
        return sp.Float(value)
    if value is None:
        raise DescriptionError(f"{where}: expected a number or an expression, got nothing (null)")
    if not isinstance(value, str):
        raise DescriptionError(
            f"{where}: expected a number or an expression, got {_type_name(value)} {value!r}"
        )
    text = value.strip()
    if not text:
        raise DescriptionError(f"{where}: expected a number or an expression, got an empty text")
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise DescriptionError(
            f"{where}: expression of {len(text)} characters is too long "
            f"(at most {MAX_EXPRESSION_LENGTH})"
        )
    try:
        tree = ast.parse(text.replace("^", "**"), mode="eval")
    except (SyntaxError, ValueError) as exc:
        reason = getattr(exc, "msg", None) or str(exc)
        raise DescriptionError(
            f"{where}: invalid expression {value!r}: syntax error ({reason})"
        ) from None
    except (RecursionError, MemoryError):
        raise DescriptionError(
            f"{where}: invalid expression {value!r}: nested too deeply to parse"
        ) from None
    depth = _depth(tree.body)
    if depth > MAX_EXPRESSION_DEPTH:
        raise DescriptionError(
            f"{where}: invalid expression {value[:40]!r}...: nested {depth} levels deep "
            f"(at most {MAX_EXPRESSION_DEPTH})"
        )
    try:
        result = _walk(tree.body, names)
    except _Reject as exc:
        raise DescriptionError(f"{where}: invalid expression {value!r}: {exc}") from None
    if result.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise DescriptionError(
            f"{where}: invalid expression {value!r}: the value is not finite ({result})"
        )
    if result.is_real is False:
        raise DescriptionError(
            f"{where}: invalid expression {value!r}: the value is not real ({result})"
        )
    return result


def _type_name(value: object) -> str:
    """A user-facing name of a YAML value's type."""
    return {
        "dict": "a mapping",
        "list": "a list",
        "str": "a text",
    }.get(type(value).__name__, type(value).__name__)


def _depth(root: ast.AST) -> int:
    """Depth of a syntax tree, counted with an explicit stack (no recursion)."""
    deepest = 0
    stack = [(root, 1)]
    while stack:
        node, level = stack.pop()
        deepest = max(deepest, level)
        stack.extend((child, level + 1) for child in ast.iter_child_nodes(node))
    return deepest


def _walk(node: ast.AST, names: Mapping[str, sp.Symbol]) -> sp.Expr:
    """Evaluate one whitelisted syntax-tree node to a SymPy expression."""
    if isinstance(node, ast.Constant):
        v = node.value
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise _Reject(f"constant {v!r} of type {type(v).__name__} is not allowed")
        if isinstance(v, int):
            return sp.Integer(v)
        if not math.isfinite(v):
            raise _Reject(f"number {v!r} is not finite")
        return sp.Float(v)
    if isinstance(node, ast.Name):
        if node.id in names:
            return names[node.id]
        if node.id in CONSTANTS:
            return CONSTANTS[node.id]
        if node.id in FUNCTIONS:
            raise _Reject(f"function {node.id!r} must be called, as {node.id}(...)")
        declared = ", ".join(sorted(names)) or "none"
        raise _Reject(f"name {node.id!r} is not a declared parameter (declared: {declared})")
    if isinstance(node, ast.BinOp):
        op = _BINOPS.get(type(node.op))
        if op is None:
            raise _Reject(f"operator {type(node.op).__name__} is not allowed")
        left = _walk(node.left, names)
        right = _walk(node.right, names)
        if isinstance(node.op, ast.Pow):
            _check_power(left, right)
        return op(left, right)
    if isinstance(node, ast.UnaryOp):
        operand = _walk(node.operand, names)
        if isinstance(node.op, ast.USub):
            return -operand
        if isinstance(node.op, ast.UAdd):
            return operand
        raise _Reject(f"operator {type(node.op).__name__} is not allowed")
    if isinstance(node, ast.Call):
        return _call(node, names)
    raise _Reject(f"construct {type(node).__name__} is not allowed")


def _check_power(base: sp.Expr, exponent: sp.Expr) -> None:
    """Reject ``base**exponent`` when the exponent or a constant result would be huge."""
    if not exponent.is_number:
        return
    if abs(exponent) > _MAX_EXPONENT:
        raise _Reject(f"exponent {exponent} is too large (at most {_MAX_EXPONENT} in magnitude)")
    if base.is_number and base != 0:
        # |base**exponent| = 10**(exponent * log10|base|): bounded both ways
        try:
            magnitude = float(exponent) * math.log10(abs(complex(sp.N(base, 15))))
        except (TypeError, ValueError, OverflowError):
            return  # not a finite number: reported once the whole value is known
        if abs(magnitude) > _MAX_MAGNITUDE:
            raise _Reject(
                f"a constant power of about 10**{magnitude:.0f} is out of range "
                f"(at most 10**{_MAX_MAGNITUDE} in magnitude, at least 10**-{_MAX_MAGNITUDE})"
            )


def _call(node: ast.Call, names: Mapping[str, sp.Symbol]) -> sp.Expr:
    """Evaluate a call of a whitelisted function."""
    if not isinstance(node.func, ast.Name):
        raise _Reject(
            f"construct {type(node.func).__name__} is not allowed as a function; "
            f"allowed functions: {', '.join(sorted(FUNCTIONS))}"
        )
    fname = node.func.id
    if fname not in FUNCTIONS:
        raise _Reject(
            f"function {fname!r} is not allowed (allowed: {', '.join(sorted(FUNCTIONS))})"
        )
    if node.keywords:
        raise _Reject(f"keyword arguments are not allowed in {fname}(...)")
    if any(isinstance(a, ast.Starred) for a in node.args):
        raise _Reject(f"construct Starred is not allowed in {fname}(...)")
    func, arity = FUNCTIONS[fname]
    if len(node.args) != arity:
        raise _Reject(
            f"{fname}() takes {arity} argument{'s' if arity != 1 else ''}, "
            f"got {len(node.args)}"
        )
    return func(*(_walk(a, names) for a in node.args))
