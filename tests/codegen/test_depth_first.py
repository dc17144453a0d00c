"""The depth-first order of generated programs (codegen.optimize.depth_first): a valid order with
the values of the recorded one, and each output's chain computed together."""

import numpy as np
import sympy as sp

import robodyn as rd
from robodyn.codegen.kernels import build_kernels
from robodyn.codegen.optimize import depth_first


def _evaluate(body, outputs, inputs):
    env = dict(inputs)
    for sym, expr in body:
        assert expr.free_symbols <= env.keys(), f"{sym} uses a value not yet computed"
        env[sym] = float(expr.xreplace(env))
    return [float(sp.sympify(o).xreplace(env)) for o in outputs]


def test_interleaved_chains_come_out_one_after_the_other():
    """Two directions recorded assignment by assignment (a1, b1, a2, b2, ...), like forward mode,
    are emitted chain by chain, each just before its output; nothing else is kept."""
    x, y = sp.symbols("x y", real=True)
    a = sp.symbols("a1:5", real=True)
    b = sp.symbols("b1:5", real=True)
    unused = sp.Symbol("u", real=True)
    body = [(a[0], sp.sin(x)), (b[0], sp.cos(y)), (unused, x * y)]
    for k in range(1, 4):
        body += [(a[k], a[k - 1] * x + 1), (b[k], b[k - 1] * y + 2)]
    order = depth_first(body, [a[3], b[3]])
    assert [s for s, _ in order] == [*a, *b]


def test_depth_first_program_has_the_values_of_the_recorded_one(monkeypatch):
    """The AA300's forward-dynamics derivatives (forward mode, Cholesky solves): the generated body
    is a permutation of the body in recording order, a valid evaluation order (every value used
    after it is computed), and gives its outputs, both evaluated here at random inputs."""
    from robodyn.codegen import optimize

    robot = rd.load("aa300")
    names = ("forward_dynamics_derivatives",)
    kernel = build_kernels(robot, names=names)[names[0]]
    monkeypatch.setattr(optimize, "depth_first", lambda body, outputs: list(body))
    recorded = build_kernels(robot, names=names)[names[0]]
    assert [s for s, _ in kernel.body] != [s for s, _ in recorded.body]
    assert sorted(kernel.body, key=str) == sorted(recorded.body, key=str)
    rng = np.random.default_rng(5)
    inputs = {s: float(v) for a in kernel.inputs
              for s, v in zip(a.entries, rng.uniform(-1, 1, a.size), strict=True)}
    np.testing.assert_allclose(_evaluate(kernel.body, kernel.outputs[0].entries, inputs),
                               _evaluate(recorded.body, recorded.outputs[0].entries, inputs),
                               rtol=1e-12, atol=1e-12)
