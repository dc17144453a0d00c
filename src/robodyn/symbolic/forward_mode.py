"""Forward-mode differentiation of a straight-line program (no expanded expressions).

A program ``s_1 = e_1(...), s_2 = e_2(...), ...`` with outputs ``y = f(s, x)`` is differentiated
assignment by assignment: each ``s_i`` gets, for every direction ``x_v`` it depends on, the new
assignment ``ds_i/dx_v = sum_a de_i/da * da/dx_v`` over the arguments ``a`` of ``e_i`` that depend
on ``x``. The local partials ``de_i/da`` are recorded once and shared by all directions, and a
symbol that does not depend on ``x_v`` carries no derivative at all, so the cost is a small
multiple of the program's length times the number of directions actually involved (a link's
quantities depend only on the joints before it). Nothing is ever expanded.

Points where the program is not differentiable are given the one-sided value a simulation or a
controller expects, and documented:

* steps (``Heaviside``, Coulomb friction's ``Piecewise`` of numbers): derivative 0, exact away
  from the switching point (``qd = 0``), where the step has no derivative;
* ``sqrt(s)`` at ``s = 0``: the partial ``1 / (2 sqrt(s))`` is taken as 0 there. For ``s = u . u``
  (the flow speed ``|u|`` of the hydrodynamic terms) ``ds = 2 u . du`` vanishes at ``u = 0``, so
  the derivative of ``|u| u`` (drag, lift) is exact, namely 0; ``|u|`` alone has no derivative at 0.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence

import sympy as sp

from robodyn.symbolic.program import Recorder

Assignment = tuple[sp.Symbol, sp.Expr]


def jacobian(assignments: Sequence[Assignment], outputs: Sequence[sp.Expr],
             variables: Sequence[sp.Symbol], rec: Recorder,
             constants: Collection[sp.Symbol] = ()) -> sp.ImmutableMatrix:
    """``d outputs / d variables`` of a straight-line program, as a program.

    Parameters
    ----------
    assignments : sequence of (Symbol, Expr)
        The program, in evaluation order.
    outputs : sequence of Expr, length m
        Expressions of the program's symbols and inputs.
    variables : sequence of Symbol, length k
        Input symbols to differentiate with respect to.
    rec : Recorder
        Receives the new assignments (local partials ``p_<s>_<a>`` and derivatives
        ``d<s>_d<v>``), after ``assignments`` in evaluation order.
    constants : collection of Symbol
        Program symbols held fixed (their derivative is taken as zero even when their
        assignment depends on ``variables``), e.g. an acceleration computed earlier in the same
        program that the derivative must treat as an input.

    Returns
    -------
    sympy.ImmutableMatrix, (m, k)
        Entry ``(i, v)`` is ``d outputs[i] / d variables[v]`` in terms of the program's symbols,
        the recorded derivative symbols and the inputs.
    """
    outputs = [sp.sympify(o) for o in outputs]
    index = {v: k for k, v in enumerate(variables)}
    fixed = set(constants)
    defined = {s: e for s, e in assignments}
    # only the assignments the outputs reach (not through the constants) need derivatives
    needed: set[sp.Symbol] = set()
    stack = [s for o in outputs for s in o.free_symbols]
    while stack:
        s = stack.pop()
        if s in needed or s in fixed or s not in defined:
            continue
        needed.add(s)
        stack.extend(defined[s].free_symbols)
    # deriv[s] = {k: ds/dx_k}, only the non-zero directions
    deriv: dict[sp.Symbol, dict[int, sp.Expr]] = {v: {k: sp.Integer(1)} for v, k in index.items()}
    for sym, expr in assignments:
        if sym not in needed or sym in index:
            continue
        total = _chain(expr, deriv, rec, sym.name)
        recorded = {}
        for k, d in total.items():
            # ds/dx_k = sum_a de/da da/dx_k
            r = rec.scalar(d, f"d{sym.name}_d{variables[k].name}")
            if r != 0:
                recorded[k] = r
        if recorded:
            deriv[sym] = recorded
    rows = []
    for i, out in enumerate(outputs):
        total = _chain(out, deriv, rec, f"y{i + 1}")
        rows.append([total.get(k, sp.Integer(0)) for k in range(len(variables))])
    return sp.ImmutableMatrix(len(outputs), len(variables), [e for row in rows for e in row])


def _chain(expr: sp.Expr, deriv: dict[sp.Symbol, dict[int, sp.Expr]], rec: Recorder,
           name: str) -> dict[int, sp.Expr]:
    """``{k: sum_a de/da da/dx_k}`` over the arguments ``a`` of ``expr`` that carry derivatives."""
    args = sorted((a for a in expr.free_symbols if a in deriv), key=sp.default_sort_key)
    terms: dict[int, list[sp.Expr]] = {}
    for a in args:
        # p = de/da, recorded once and shared by every direction
        p = rec.scalar(partial(expr, a), f"p_{name}_{a.name}")
        if p == 0:
            continue
        for k, da in deriv[a].items():
            terms.setdefault(k, []).append(p * da)
    return {k: sp.Add(*ts) for k, ts in sorted(terms.items())}


def partial(expr: sp.Expr, a: sp.Symbol) -> sp.Expr:
    """``d expr / d a`` with steps' derivatives 0 and ``1 / sqrt(s)`` taken as 0 at ``s = 0``."""
    d = sp.diff(expr, a)
    if d.has(sp.DiracDelta):
        # d Heaviside(x)/dx = 0 away from x = 0
        d = d.replace(lambda e: isinstance(e, sp.DiracDelta), lambda e: sp.Integer(0))
    if d.has(sp.Piecewise):
        # a step's derivative: Piecewise((0, c), (0, True)) left over
        d = d.replace(lambda e: isinstance(e, sp.Piecewise) and all(v == 0 for v, _ in e.args),
                      lambda e: sp.Integer(0))
    return d.replace(_is_inverse_sqrt, _guarded_inverse_sqrt)


def _is_inverse_sqrt(e: sp.Basic) -> bool:
    return bool(e.is_Pow and e.exp == sp.Rational(-1, 2) and not e.base.is_number)


def _guarded_inverse_sqrt(e: sp.Pow) -> sp.Expr:
    # 1/sqrt(s) for s > 0, 0 at s = 0 (no branch on a NaN): step / (sqrt(s) + (1 - step))
    s = e.base
    on = sp.Piecewise((sp.Integer(1), s > 0), (sp.Integer(0), True))
    off = sp.Piecewise((sp.Integer(0), s > 0), (sp.Integer(1), True))
    return on / (sp.sqrt(s) + off)


__all__ = ["jacobian", "partial"]
