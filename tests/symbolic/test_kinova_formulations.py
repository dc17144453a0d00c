"""The three formulations agree on the Kinova Gen3 (7 joints, general URDF origins).

Its equations are kept in intermediate-variable form; expanded, they share subexpressions
heavily, so ``lambdify`` (which walks them as trees) is far too slow here. They are evaluated
instead by visiting each distinct subexpression once, for all states at a time.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.symbolic.kinematics import joint_symbols
from tests.numeric_eval import random_states

NAME = "kinova_gen3"

_NUMPY = {sp.cos: np.cos, sp.sin: np.sin}


def _apply(node: sp.Basic, args: list) -> np.ndarray | float:
    if node.is_Add:
        return sum(args[1:], args[0])
    if node.is_Mul:
        out = args[0]
        for a in args[1:]:
            out = out * a
        return out
    if node.is_Pow:
        return args[0] ** args[1]
    fn = _NUMPY.get(node.func)
    if fn is None:
        fn = sp.lambdify(list(sp.symbols(f"a:{len(args)}")), node.func(*sp.symbols(f"a:{len(args)}")),
                         modules="numpy")
    return fn(*args)


def evaluate(exprs: Sequence[sp.Expr], env: dict[sp.Symbol, np.ndarray], count: int) -> np.ndarray:
    """Values of ``exprs`` at ``count`` states, each distinct subexpression computed once.

    ``env`` maps every free symbol to its values, shape (count,). Returns shape (len(exprs), count).
    """
    memo: dict[int, np.ndarray | float] = {}
    stack: list[tuple[sp.Basic, bool]] = [(e, False) for e in exprs]
    while stack:
        node, ready = stack.pop()
        key = id(node)
        if key in memo:
            continue
        if not node.args:
            memo[key] = env[node] if node.is_Symbol else float(node)
        elif ready:
            memo[key] = _apply(node, [memo[id(a)] for a in node.args])
        else:
            stack.append((node, True))
            stack.extend((a, False) for a in node.args if id(a) not in memo)
    return np.array([np.broadcast_to(memo[id(e)], (count,)) for e in exprs], dtype=float)


@cache
def quantities(method: str) -> tuple[sp.ImmutableMatrix, ...]:
    """``M``, ``g``, ``tau``, ``C`` of the Gen3 (no drives, no friction: all rigid-body)."""
    eom = rd.derive(rd.load(NAME), method=method)
    assert eom.rotor == sp.zeros(7, 1) and eom.friction == sp.zeros(7, 1)
    return eom.M, eom.g, eom.tau, eom.C


@pytest.mark.slow
def test_formulations_agree_numerically_on_kinova_gen3():
    count = 4
    states = list(random_states(7, count, seed=2))
    env = {sym: np.array([state[part][j] for state in states])
           for part, syms in enumerate(joint_symbols(7)) for j, sym in enumerate(syms)}
    values = {method: evaluate([e for mat in quantities(method) for e in mat], env, count)
              for method in ("newton_euler", "lagrange", "kane")}
    ref = values["newton_euler"]
    bounds = np.cumsum([0, 49, 7, 7, 49])  # rows of M, g, tau, C
    for method in ("lagrange", "kane"):
        for name, lo, hi in zip(("M", "g", "tau", "C"), bounds[:-1], bounds[1:], strict=True):
            for s in range(count):
                r, v = ref[lo:hi, s], values[method][lo:hi, s]
                np.testing.assert_allclose(v, r, rtol=0, atol=1e-10 * max(np.abs(r).max(), 1.0),
                                           err_msg=f"{name}: newton_euler vs {method}")
