"""``eom.numeric_function`` (each formulation's straight-line form) includes the hydro terms."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn as rd

WET = {"vc": 0.3, "CL": 0.2}


@pytest.mark.parametrize("method", ["newton_euler", "lagrange", "kane"])
def test_numeric_function_equals_the_expanded_terms_under_water(method: str) -> None:
    robot = rd.load("underwater_2r")
    eom = rd.derive(robot, method=method)
    subs = eom.numeric(WET)
    states = np.random.default_rng(7).uniform(-2, 2, (6, 3, 2))
    q, qd, qdd = states[:, 0], states[:, 1], states[:, 2]
    for name, args in (("M", (q,)), ("C", (q, qd)), ("g", (q,)), ("tau", (q, qd, qdd))):
        expr = getattr(eom, name).xreplace(subs)
        ref_fn = sp.lambdify([eom.q, eom.qd, eom.qdd], expr, "numpy")
        got = eom.numeric_function(name)(*args, values=WET)
        for k in range(len(q)):
            ref = np.array(ref_fn(q[k], qd[k], qdd[k]), dtype=float)
            np.testing.assert_allclose(got[k], ref.reshape(got[k].shape), rtol=1e-12, atol=1e-10)
    # and the fluid is really in it: the dry robot's tau differs by the hydro terms
    hydro = sp.lambdify([eom.q, eom.qd, eom.qdd], eom.hydro.tau.xreplace(subs), "numpy")
    h = np.ravel(np.array(hydro(q[0], qd[0], qdd[0]), dtype=float))
    assert np.abs(h).max() > 1.0


def test_numeric_tau_matches_the_compiled_model_with_a_current() -> None:
    robot = rd.load("underwater_2r")
    tau = rd.derive(robot, method="lagrange").numeric_function("tau")
    model = rd.compile_model(robot, parameters=WET)
    x = np.random.default_rng(8).uniform(-2, 2, (3, 20, 2))
    np.testing.assert_allclose(tau(*x, values=WET), model.inverse_dynamics(*x), rtol=1e-11,
                               atol=1e-9)
