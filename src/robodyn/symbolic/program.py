"""Straight-line programs: equations kept as named intermediate variables.

A :class:`Recorder` turns each non-trivial expression a recursive algorithm produces into a new
symbol (``w3_x = ...``), so that the equations stay short and their cost grows linearly with the
number of joints; zeros and ones fold automatically because SymPy simplifies on construction.
A frozen :class:`Program` holds the assignments and the outputs, and can expand them back into
expressions of the joint variables and parameters.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import sympy as sp


def is_trivial(expr: sp.Expr) -> bool:
    """True for numbers, symbols and a negated symbol: not worth a variable of their own."""
    if expr.is_Atom:
        return True
    return bool(expr.is_Mul and len(expr.args) == 2 and expr.args[0] == -1 and expr.args[1].is_Atom)


class Recorder:
    """Collects assignments ``symbol = expression`` in evaluation order.

    Parameters
    ----------
    reserved : iterable of str
        Names already in use (robot parameters, joint variables) that must not be reused.
    record : bool
        When False the recorder returns expressions unchanged (direct, nested expressions).
    """

    def __init__(self, reserved: Iterable[str] = (), *, record: bool = True,
                 prefix: str = "") -> None:
        self.assignments: list[tuple[sp.Symbol, sp.Expr]] = []
        self._used = set(reserved)
        self.record = record
        self.prefix = prefix

    def scalar(self, expr: sp.Expr, name: str) -> sp.Expr:
        """Record ``expr`` under ``name`` unless it is trivial; return what to use in its place."""
        expr = sp.sympify(expr)
        if not self.record or is_trivial(expr):
            return expr
        name = self.prefix + name
        unique = name
        k = 1
        while unique in self._used:
            k += 1
            unique = f"{name}_{k}"
        self._used.add(unique)
        sym = sp.Symbol(unique, real=True)
        self.assignments.append((sym, expr))
        return sym

    def vector(self, vec: sp.MatrixBase, name: str) -> sp.ImmutableMatrix:
        """Record each component of a (3, 1) vector as ``name_x``, ``name_y``, ``name_z``."""
        return sp.ImmutableMatrix(
            [self.scalar(vec[k], f"{name}_{axis}") for k, axis in enumerate("xyz")]
        )

    def matrix(self, mat: sp.MatrixBase, name: str) -> sp.ImmutableMatrix:
        """Record each entry of a matrix as ``name_<row><col>`` (1-based)."""
        rows, cols = mat.shape
        return sp.ImmutableMatrix(
            rows, cols, [self.scalar(mat[r, c], f"{name}_{r + 1}{c + 1}")
                         for r in range(rows) for c in range(cols)]
        )


@dataclass(frozen=True)
class Program:
    """Intermediate-variable form of a set of outputs.

    Attributes
    ----------
    assignments : tuple of (Symbol, Expr)
        Evaluation order; each right-hand side uses only earlier symbols, joint variables and
        parameters.
    outputs : sympy.ImmutableMatrix
        The outputs in terms of the intermediate symbols.
    """

    assignments: tuple[tuple[sp.Symbol, sp.Expr], ...]
    outputs: sp.ImmutableMatrix

    def expand(self) -> sp.ImmutableMatrix:
        """Outputs with every intermediate symbol substituted (products are not multiplied out)."""
        values = substitution_map(self.assignments)
        return sp.ImmutableMatrix(self.outputs.xreplace(values))

    def pruned(self) -> Program:
        """Drop assignments the outputs do not use."""
        needed = set(self.outputs.free_symbols)
        kept: list[tuple[sp.Symbol, sp.Expr]] = []
        for sym, expr in reversed(self.assignments):
            if sym in needed:
                kept.append((sym, expr))
                needed |= expr.free_symbols
        return Program(tuple(reversed(kept)), self.outputs)


def substitution_map(assignments: Sequence[tuple[sp.Symbol, sp.Expr]]) -> dict[sp.Symbol, sp.Expr]:
    """``{symbol: expression without intermediates}`` for a sequence of assignments."""
    values: dict[sp.Symbol, sp.Expr] = {}
    for sym, expr in assignments:
        values[sym] = expr.xreplace(values)
    return values


def eliminate_common_subexpressions(
        assignments: Sequence[tuple[sp.Symbol, sp.Expr]], outputs: Sequence[sp.Expr],
        prefix: str = "t") -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[sp.Expr]]:
    """``sympy.cse`` over a straight-line program, keeping a valid evaluation order.

    Each extracted subexpression is emitted just before the first assignment (or output) that
    uses it, after everything it uses.

    Parameters
    ----------
    assignments : sequence of (Symbol, Expr), length A
        The program's assignments in evaluation order.
    outputs : sequence of Expr, length K
        The program's outputs (scalars, in terms of the assigned symbols).
    prefix : str
        Names of the extracted subexpressions: ``prefix0``, ``prefix1``, ... skipping names the
        assignments already use.

    Returns
    -------
    body : list of (Symbol, Expr)
        The assignments (A of them) with the extracted ones interleaved, in evaluation order.
    outputs : list of Expr, length K
        The outputs in terms of the body's symbols.
    """
    taken = {s.name for s, _ in assignments}
    names = (sp.Symbol(f"{prefix}{k}", real=True) for k in range(10**9)
             if f"{prefix}{k}" not in taken)
    rhs = [e for _, e in assignments] + list(outputs)
    replacements, reduced = sp.cse(rhs, symbols=names, optimizations=None, order="none")
    extracted = dict(replacements)
    body: list[tuple[sp.Symbol, sp.Expr]] = []
    emitted: set[sp.Symbol] = set()

    def emit_needed(expr: sp.Expr) -> None:
        # depth-first: a subexpression's own subexpressions come first
        for s in sorted(expr.free_symbols & extracted.keys() - emitted, key=lambda s: s.name):
            if s in emitted:
                continue
            emit_needed(extracted[s])
            emitted.add(s)
            body.append((s, extracted[s]))

    for (sym, _), expr in zip(assignments, reduced, strict=False):
        emit_needed(expr)
        body.append((sym, expr))
    outs = list(reduced[len(assignments):])
    for o in outs:
        emit_needed(o)
    return body, outs
