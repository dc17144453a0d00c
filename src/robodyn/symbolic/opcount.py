"""Operation counts of equations after common-subexpression elimination."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import sympy as sp


@dataclass(frozen=True)
class OpCount:
    """Arithmetic cost of evaluating a set of equations once.

    Attributes
    ----------
    additions : int
        Additions and subtractions.
    multiplications : int
        Multiplications and divisions (a negation is free: it folds into an addition).
    functions : int
        Calls of sin, cos, sqrt and other functions.
    """

    additions: int
    multiplications: int
    functions: int

    @property
    def total(self) -> int:
        """All operations."""
        return self.additions + self.multiplications + self.functions

    def __add__(self, other: OpCount) -> OpCount:
        return OpCount(self.additions + other.additions, self.multiplications + other.multiplications,
                       self.functions + other.functions)


def _count(expr: sp.Expr) -> OpCount:
    adds = muls = funcs = 0
    stack = [expr]
    while stack:
        e = stack.pop()
        if e.is_Atom:
            continue
        if e.is_Add:
            adds += len(e.args) - 1
        elif e.is_Mul:
            coeff, factors = e.as_coeff_mul()
            muls += len(factors) - 1
            if coeff not in (1, -1):
                muls += 1
            stack.extend(factors)
            continue
        elif e.is_Pow:
            base, exp = e.args
            if exp.is_Integer:
                muls += abs(int(exp)) - 1 if exp > 0 else abs(int(exp))
            else:
                funcs += 1
            stack.append(base)
            continue
        elif isinstance(e, sp.Function | sp.Heaviside):
            funcs += 1
        stack.extend(e.args)
    return OpCount(adds, muls, funcs)


def count_ops(exprs: Iterable[sp.Expr]) -> OpCount:
    """Operations in a list of expressions, counted as trees (no sharing)."""
    total = OpCount(0, 0, 0)
    for e in exprs:
        total = total + _count(sp.sympify(e))
    return total


def cse_op_count(exprs: Sequence[sp.Expr],
                 assignments: Sequence[tuple[sp.Symbol, sp.Expr]] = ()) -> OpCount:
    """Operations after ``sympy.cse`` of ``assignments`` (a straight-line program) and ``exprs``."""
    rhs = [e for _, e in assignments] + list(exprs)
    replacements, reduced = sp.cse(rhs, optimizations=None, order="none")
    return count_ops([e for _, e in replacements]) + count_ops(reduced)
