"""Test helper: evaluate symbolic equations of motion numerically with the robot's defaults."""

from __future__ import annotations

import numpy as np
import sympy as sp

from robodyn.symbolic.eom import EquationsOfMotion


def evaluator(eom: EquationsOfMotion, expr: sp.MatrixBase):
    """Return f(q, qd, qdd) -> ndarray of ``expr`` with parameters at their default values."""
    bound = sp.ImmutableMatrix(expr).xreplace(eom.numeric())
    fn = sp.lambdify([eom.q, eom.qd, eom.qdd], bound, modules="numpy", cse=True)

    def call(q, qd=None, qdd=None):
        n = eom.dof
        qd = np.zeros(n) if qd is None else qd
        qdd = np.zeros(n) if qdd is None else qdd
        return np.array(fn(q, qd, qdd), dtype=float)

    return call


def random_states(n: int, count: int, seed: int = 0):
    """``count`` random (q, qd, qdd) triples of size n, well away from zero velocity."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)


def program_evaluator(eom: EquationsOfMotion, program):
    """Evaluate a recursive :class:`Program` at one state by running its assignments in order."""
    fn_cache = []
    params = eom.numeric()
    states = list(eom.q) + list(eom.qd) + list(eom.qdd)
    for sym, expr in program.assignments:
        args = sorted(expr.free_symbols - set(params), key=lambda s: s.name)
        fn_cache.append((sym, args, sp.lambdify(args, expr.xreplace(params), modules="math")))
    out_args = sorted(program.outputs.free_symbols - set(params), key=lambda s: s.name)
    out_fn = sp.lambdify(out_args, program.outputs.xreplace(params), modules="numpy")

    def call(q, qd=None, qdd=None):
        n = eom.dof
        qd = np.zeros(n) if qd is None else qd
        qdd = np.zeros(n) if qdd is None else qdd
        vals = dict(zip(states, [*q, *qd, *qdd], strict=True))
        for sym, args, fn in fn_cache:
            vals[sym] = fn(*[vals[a] for a in args])
        return np.array(out_fn(*[vals[a] for a in out_args]), dtype=float)

    return call
