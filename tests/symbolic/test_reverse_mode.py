"""Reverse-mode differentiation of straight-line programs (``robodyn.symbolic.reverse_mode``).

Checked against SymPy's derivative of the expanded expressions (independent of both modes), and
against forward mode, on random programs and on the PUMA 560's inverse dynamics; held constants,
steps and the guarded ``1 / sqrt`` as forward mode documents them.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from robodyn.symbolic import forward_mode, reverse_mode
from robodyn.symbolic.program import Recorder


def _evaluate(assignments, exprs, values):
    """Numbers for ``exprs`` after running the program on ``values`` ({Symbol: float})."""
    env = {k: sp.Float(v) for k, v in values.items()}
    for sym, expr in assignments:
        env[sym] = sp.Float(expr.xreplace(env).evalf(30))
    return np.array([float(sp.sympify(e).xreplace(env).evalf(30)) for e in exprs])


def _random_program(rng, x, length):
    """A program of products, sums, sines, cosines and roots of earlier values and inputs."""
    rec = Recorder({s.name for s in x})
    pool = list(x)
    for k in range(length):
        a, b = (pool[i] for i in rng.integers(0, len(pool), 2))
        kind = rng.integers(0, 5)
        expr = [a * b + 1, a - 2 * b, sp.sin(a) * b, sp.cos(a + b), sp.sqrt(a * a + 1) * b][kind]
        pool.append(rec.scalar(expr, f"s{k}"))
    outputs = [pool[-1] + pool[-2], pool[-3] * pool[len(x)], pool[-4]]
    return rec, outputs


@pytest.mark.parametrize("seed", range(4))
def test_adjoints_equal_the_derivative_of_the_expanded_outputs(seed):
    rng = np.random.default_rng(seed)
    x = sp.symbols("x1:5", real=True)
    rec, outputs = _random_program(rng, x, 25)
    program = list(rec.assignments)
    d = reverse_mode.jacobian(program, outputs, x, rec)
    values = dict(zip(x, rng.uniform(-1, 1, 4), strict=True))
    got = _evaluate(rec.assignments, list(d), values)
    # independent: expand the program into the outputs, then differentiate
    expand = {}
    for sym, expr in program:
        expand[sym] = expr.xreplace(expand)
    full = [sp.sympify(o).xreplace(expand) for o in outputs]
    expected = _evaluate([], [sp.diff(o, v) for o in full for v in x], values)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)
    fwd = forward_mode.jacobian(program, outputs, x, rec)
    np.testing.assert_allclose(_evaluate(rec.assignments, list(fwd), values), expected,
                               rtol=1e-12, atol=1e-12)


def test_a_held_constant_carries_no_derivative():
    x, y = sp.symbols("x y", real=True)
    rec = Recorder({"x", "y"})
    a = rec.scalar(x * y + x ** 2, "a")  # held: as an input computed earlier
    b = rec.scalar(sp.sin(x) * a, "b")
    d = reverse_mode.jacobian(list(rec.assignments), [b * y], [x, y], rec, constants=[a])
    values = {x: 0.3, y: -0.7}
    av = 0.3 * -0.7 + 0.09
    expected = [np.cos(0.3) * av * -0.7, np.sin(0.3) * av]
    np.testing.assert_allclose(_evaluate(rec.assignments, list(d), values), expected, rtol=1e-13)


def test_steps_have_derivative_zero_and_the_root_is_guarded_at_zero():
    x, y = sp.symbols("x y", real=True)
    rec = Recorder({"x", "y"})
    step = rec.scalar(sp.Heaviside(x) * y, "step")
    speed = rec.scalar(sp.sqrt(x * x + y * y), "speed")
    d = reverse_mode.jacobian(list(rec.assignments), [step, speed * x], [x, y], rec)
    # d(H(x) y)/dx = 0 (away from x = 0), d(H(x) y)/dy = H(x)
    np.testing.assert_allclose(_evaluate(rec.assignments, list(d[0, :]), {x: 0.5, y: 2.0}),
                               [0.0, 1.0])
    # |u| u at u = 0: derivative 0, not NaN
    np.testing.assert_array_equal(_evaluate(rec.assignments, list(d[1, :]), {x: 0.0, y: 0.0}),
                                  [0.0, 0.0])


def test_puma_inverse_dynamics_derivatives_agree_with_forward_mode():
    import warnings

    import robodyn as rd
    from robodyn.codegen.kernels import _tau_full
    from robodyn.symbolic.kinematics import joint_symbols

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    n = robot.dof
    q, qd, qdd = joint_symbols(n)
    rec = Recorder({s.name for s in (*q, *qd, *qdd)} | set(robot.parameters))
    tau = _tau_full(robot, q, qd, qdd, rec)
    program = list(rec.assignments)
    rev = reverse_mode.jacobian(program, tau, [*q, *qd], rec)
    fwd = forward_mode.jacobian(program, tau, [*q, *qd], rec)
    rng = np.random.default_rng(3)
    values = {sp.Symbol(k, real=True): float(v) for k, v in robot.parameters.items()}
    values.update(zip((*q, *qd, *qdd), rng.uniform(-1, 1, 3 * n), strict=True))
    a = _evaluate(rec.assignments, list(rev), values)
    b = _evaluate(rec.assignments, list(fwd), values)
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * np.abs(b).max())
