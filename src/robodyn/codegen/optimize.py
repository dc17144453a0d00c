"""Straight-line programs made ready for printing: numbers folded in, duplicates merged, CSE.

The recursive programs of :mod:`robodyn.symbolic` already share their intermediate variables;
this pass substitutes the parameter values, merges assignments that compute the same thing
(``c1 = cos(q1)`` recorded by two recursions), inlines copies, drops what no output needs, runs
``sympy.cse`` over everything and orders the extracted subexpressions so that each is assigned
after what it uses and before its first use.
"""

from __future__ import annotations

import keyword
import re
from collections.abc import Iterable, Mapping, Sequence

import sympy as sp

from robodyn.symbolic.program import (
    eliminate_common_subexpressions as eliminate_common_subexpressions,  # re-exported
)

Assignment = tuple[sp.Symbol, sp.Expr]

#: Names no generated variable may take in any target language (keywords and common builtins).
RESERVED = frozenset(
    set(keyword.kwlist)
    | {
        # C
        "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else",
        "enum", "extern", "float", "for", "goto", "if", "inline", "int", "long", "register",
        "restrict", "return", "short", "signed", "sizeof", "static", "struct", "switch", "typedef",
        "union", "unsigned", "void", "volatile", "while", "sin", "cos", "tan", "sqrt", "exp", "log",
        "pow", "fabs", "abs", "main",
        # Fortran, MATLAB/Octave, Julia
        "real", "integer", "end", "function", "subroutine", "module", "program", "call", "then",
        "implicit", "none", "intent", "in", "out", "inout", "contains", "use", "merge", "pi",
        "nargin", "nargout", "zeros", "ones", "eye", "size", "begin", "let", "local", "global",
        "quote", "macro", "using", "export", "mutable", "type", "where", "elseif",
        "np", "numpy", "math", "i", "j", "e", "inf", "nan", "x", "N", "n",
    }
)
_VALID = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


def fold_parameters(assignments: Sequence[Assignment], outputs: Sequence[sp.Expr],
                    values: Mapping[sp.Symbol, float]) -> tuple[list[Assignment], list[sp.Expr]]:
    """Substitute parameter values, merge duplicate assignments, inline copies, prune.

    ``Heaviside(x, 0)`` (Coulomb friction) becomes ``Piecewise((1, x > 0), (0, True))``, which
    every printer knows.
    """
    numbers = {k: sp.Float(v) for k, v in values.items()}
    env: dict[sp.Symbol, sp.Expr] = {}
    seen: dict[sp.Expr, sp.Symbol] = {}
    kept: list[Assignment] = []
    for sym, expr in assignments:
        expr = _heaviside_to_piecewise(expr.xreplace(numbers).xreplace(env))
        if expr.is_Atom or (expr.is_Mul and len(expr.args) == 2 and expr.args[0] == -1
                            and expr.args[1].is_Symbol):
            # a number, a copy or a negated copy: inline it
            env[sym] = expr
        elif expr in seen:
            env[sym] = seen[expr]
        else:
            seen[expr] = sym
            kept.append((sym, expr))
    outs = [_heaviside_to_piecewise(sp.sympify(o).xreplace(numbers).xreplace(env)) for o in outputs]
    return prune(kept, outs), outs


def prune(assignments: Sequence[Assignment], outputs: Iterable[sp.Expr]) -> list[Assignment]:
    """Keep only the assignments some output depends on (order preserved)."""
    needed: set[sp.Symbol] = set()
    for o in outputs:
        needed |= sp.sympify(o).free_symbols
    kept: list[Assignment] = []
    for sym, expr in reversed(assignments):
        if sym in needed:
            kept.append((sym, expr))
            needed |= expr.free_symbols
    return kept[::-1]


def safe_names(assignments: Sequence[Assignment], reserved: Iterable[str]) -> dict[sp.Symbol, sp.Symbol]:
    """Renaming of intermediate symbols to identifiers valid and distinct in every target.

    Names are compared case-insensitively (Fortran) and kept when already valid.
    """
    used = {r.lower() for r in reserved} | {r.lower() for r in RESERVED}
    mapping: dict[sp.Symbol, sp.Symbol] = {}
    for sym, _ in assignments:
        base = sym.name if _VALID.match(sym.name) and not sym.name.endswith("_") else "v"
        name, k = base, 1
        while name.lower() in used or len(name) > 60:
            k += 1
            name = f"{base[:50]}_{k}"
        used.add(name.lower())
        if name != sym.name:
            mapping[sym] = sp.Symbol(name, real=True)
    return mapping


def _heaviside_to_piecewise(expr: sp.Expr) -> sp.Expr:
    if not expr.has(sp.Heaviside):
        return expr
    return expr.replace(
        lambda e: isinstance(e, sp.Heaviside),
        lambda e: sp.Piecewise((sp.Integer(1), e.args[0] > 0), (sp.Integer(0), True)),
    )


def depth_first(assignments: Sequence[Assignment], outputs: Sequence[sp.Expr]) -> list[Assignment]:
    """The assignments reordered depth first from the outputs (each output's inputs just before it).

    Each output, in order, pulls in what it needs and has not been emitted yet, post-order, the
    arguments of an assignment in their original order. A value is then computed close to its
    uses: for a forward-mode derivative (one output column per direction) a direction's chain is
    computed as a whole, where the recording order interleaves every direction assignment by
    assignment and keeps them all live at once.
    """
    position = {s: k for k, (s, _) in enumerate(assignments)}
    rhs = dict(assignments)
    emitted: set[sp.Symbol] = set()
    order: list[Assignment] = []
    for out in outputs:
        roots = sorted((s for s in sp.sympify(out).free_symbols if s in position), key=position.__getitem__)
        for root in roots:
            if root in emitted:
                continue
            # iterative post-order: (symbol, its arguments expanded?)
            stack: list[tuple[sp.Symbol, bool]] = [(root, False)]
            while stack:
                sym, expanded = stack.pop()
                if sym in emitted:
                    continue
                if expanded:
                    emitted.add(sym)
                    order.append((sym, rhs[sym]))
                    continue
                stack.append((sym, True))
                args = sorted((a for a in rhs[sym].free_symbols if a in position and a not in emitted),
                              key=position.__getitem__, reverse=True)
                stack.extend((a, False) for a in args)
    return order
