"""Analytic regressor derivatives and the excitation gradient built on them.

References: central finite differences of the compiled regressor (an independent code path:
the regressor kernel itself), central differences of the design criterion in the Fourier
coefficients, and the earlier finite-difference gradient of the design.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.studies.excitation import (
    _STEP_COLUMNS,
    _Layout,
    _null_bases,
    _Problem,
    base_columns,
    condition_number,
    excitation,
    excitation_limits,
    random_fourier,
)
from robodyn.symbolic.regressor import PER_JOINT

pytestmark = pytest.mark.tool("gcc|cc")


def _fd_regressor(model, q, qd, qdd, h=1e-6):
    """Central differences of Y in q, qd, qdd: three (N, n, 15 n, n) arrays."""
    out = []
    for which in range(3):
        d = np.empty(q.shape[:1] + (model.dof, 15 * model.dof, model.dof))
        for j in range(model.dof):
            plus = [q.copy(), qd.copy(), qdd.copy()]
            minus = [q.copy(), qd.copy(), qdd.copy()]
            plus[which][:, j] += h
            minus[which][:, j] -= h
            d[..., j] = (model.regressor(*plus) - model.regressor(*minus)) / (2 * h)
        out.append(d)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", ["planar", "puma"])
@pytest.mark.parametrize("count", [1, 7, 17])
def test_regressor_derivatives_match_central_differences(request, name, count):
    model = request.getfixturevalue(name)
    rng = np.random.default_rng(count)
    n = model.dof
    q, qdd = rng.uniform(-2, 2, (count, n)), rng.uniform(-3, 3, (count, n))
    # velocities away from 0: the Coulomb steps have no derivative there
    qd = rng.choice([-1.0, 1.0], (count, n)) * rng.uniform(0.2, 1.5, (count, n))
    analytic = model.regressor_derivatives(q, qd, qdd)
    for a, fd, what in zip(analytic, _fd_regressor(model, q, qd, qdd), ("q", "qd", "qdd"), strict=True):
        assert a.shape == (count, n, 15 * n, n)
        scale = np.max(np.abs(fd))
        assert np.max(np.abs(a - fd)) <= 1e-6 * scale, what
    # one state alone: the shapes drop the batch axis and the values are the same bits
    one = model.regressor_derivatives(q[0], qd[0], qdd[0])
    assert one[0].shape == (n, 15 * n, n)
    assert all(np.array_equal(o, a[0]) for o, a in zip(one, analytic, strict=True))


def test_regressor_derivatives_numpy_backend(planar):
    numpy_model = rd.compile_model(planar.robot, "numpy")
    rng = np.random.default_rng(3)
    q, qd, qdd = rng.normal(size=(3, 9, 2))
    for a, b in zip(numpy_model.regressor_derivatives(q, qd, qdd),
                    planar.regressor_derivatives(q, qd, qdd), strict=True):
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12 * np.max(np.abs(b)))


def _problem(model, gradient, harmonics=4, k=60, seed=0, smooth=False):
    f = 0.2
    lim = excitation_limits(model.robot)
    rng = np.random.default_rng(seed)
    cols = base_columns(model, rng)
    if smooth:
        # without the Coulomb/offset step columns: the criterion is then differentiable (with
        # them it jumps where a sample's qd, exactly 0 at the rest points, changes sign)
        cols = tuple(c for c in cols if c % PER_JOINT not in _STEP_COLUMNS)
    layout = _Layout(model.dof, harmonics, *_null_bases(harmonics, f))
    problem = _Problem(model, layout, f, k, cols, lim, "cond", gradient)
    x = layout.pack(random_fourier(lim, harmonics, f, rng, samples=k))
    return problem, x


@pytest.mark.parametrize("criterion", ["cond", "logdet"])
def test_excitation_gradient_analytic_equals_finite_differences(puma, criterion):
    analytic, x = _problem(puma, "analytic")
    fd, _ = _problem(puma, "finite_difference")
    analytic.criterion = fd.criterion = criterion
    v_a, g_a = analytic.objective(x)
    v_f, g_f = fd.objective(x)
    assert v_a == v_f
    scale = np.max(np.abs(g_a))
    assert np.max(np.abs(g_a - g_f)) <= 1e-5 * scale
    # and against central differences of the (smooth) criterion itself in a few coefficients
    analytic, x = _problem(puma, "analytic", smooth=True)
    analytic.criterion = criterion
    g_a = analytic.objective(x)[1]
    scale = np.max(np.abs(g_a))
    # (h = 1e-4: the criterion's rounding noise, through an eigendecomposition, swamps smaller
    # steps; the truncation error at 1e-4 is ~1e-8 relative)
    h = 1e-4
    for i in np.random.default_rng(1).choice(x.size, 8, replace=False):
        e = np.zeros_like(x)
        e[i] = h
        slope = (analytic.objective(x + e)[0] - analytic.objective(x - e)[0]) / (2 * h)
        assert slope == pytest.approx(g_a[i], rel=1e-4, abs=1e-6 * scale)


@pytest.mark.slow
def test_design_with_analytic_gradient_improves_on_its_starts(puma):
    # No optimiser guarantees that one gradient ends at least as low as another from the same
    # starts (that depends on the path, and so on the CPU's rounding). What holds on any CPU: the
    # design keeps the best feasible point it visits, the starts included, so its criterion is
    # at most the best start's (up to the final shrink onto the limits on a finer grid), and it
    # stays within the limits. The gradient itself is checked against differences above.
    harmonics, seed, starts = 4, 3, 2
    a = excitation(puma, gradient="analytic", harmonics=harmonics, seed=seed, starts=starts,
                   max_iterations=25)
    # the same random starts, drawn independently of the optimiser
    rng = np.random.default_rng(seed)
    cols = base_columns(puma, rng)
    assert cols == a.columns
    lim = excitation_limits(puma.robot)
    k = a.design_samples
    f = 1.0 / a.series.period
    t_d = np.arange(k) / (k * f)
    start_conds = []
    for _ in range(starts):
        start = random_fourier(lim, harmonics, f, rng, samples=k)
        start_conds.append(condition_number(puma, *start.evaluate(t_d), cols))
    print(f"PUMA design cond: starts {start_conds}, analytic-gradient design {a.condition_number:.3f}")
    assert np.isfinite(a.condition_number)
    assert a.condition_number <= min(start_conds) * (1 + 1e-2)
    assert lim.violation(a.q, a.qd, a.qdd) <= 1e-9


def test_unknown_gradient_is_refused(planar):
    with pytest.raises(ValueError, match="unknown gradient 'exact'"):
        excitation(planar, gradient="exact")
