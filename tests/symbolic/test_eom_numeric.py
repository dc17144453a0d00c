"""``EquationsOfMotion.numeric_function``: each formulation's own straight-line form, numerically.

References: the planar 2R arm's closed forms (Spong, sec. 7.4), the compiled model (generated from
the Newton-Euler and composite-rigid-body programs), and the three formulations against each other.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn as rd

METHODS = ("newton_euler", "lagrange", "kane")


def _planar_closed_form(q, qd, qdd, m1=1.0, m2=1.0, l1=1.0, l2=1.0, g=9.81):
    """M, C qd, g and tau of the uniform-rod 2R arm in a vertical plane (planar_2r.yaml)."""
    lc1, lc2, i1, i2 = l1 / 2, l2 / 2, m1 * l1**2 / 12, m2 * l2**2 / 12
    c2 = np.cos(q[1])
    m11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + i1 + i2
    m12 = m2 * (lc2**2 + l1 * lc2 * c2) + i2
    mass = np.array([[m11, m12], [m12, m2 * lc2**2 + i2]])
    h = -m2 * l1 * lc2 * np.sin(q[1])
    cqd = np.array([h * qd[1] * (2 * qd[0] + qd[1]), -h * qd[0] ** 2])
    grav = np.array([(m1 * lc1 + m2 * l1) * g * np.cos(q[0]) + m2 * lc2 * g * np.cos(q[0] + q[1]),
                     m2 * lc2 * g * np.cos(q[0] + q[1])])
    return mass, cqd, grav, mass @ qdd + cqd + grav


@pytest.fixture(scope="module")
def planar_eoms():
    robot = rd.load("planar_2r")
    return [rd.derive(robot, m) for m in METHODS]


def test_each_formulation_matches_the_closed_form(planar_eoms):
    rng = np.random.default_rng(3)
    for eom in planar_eoms:
        f = {k: eom.numeric_function(k) for k in ("M", "C", "g", "tau")}
        for _ in range(5):
            q, qd, qdd = (rng.uniform(-3, 3, 2) for _ in range(3))
            for values in (None, {"m2": 2.5, "l1": 0.7}):
                ref = _planar_closed_form(q, qd, qdd, **(values or {}))
                got = (f["M"](q, values=values), f["C"](q, qd, values=values) @ qd,
                       f["g"](q, values=values), f["tau"](q, qd, qdd, values=values))
                for name, a, b in zip(("M", "C qd", "g", "tau"), got, ref, strict=True):
                    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * max(1, np.abs(b).max()),
                                               err_msg=f"{eom.method} {name} {values}")


def test_shapes_batches_and_errors(planar_eoms):
    eom = planar_eoms[0]
    q = np.array([[0.1, 0.2], [0.3, -0.4], [1.0, 2.0]])
    mass, tau = eom.numeric_function("M"), eom.numeric_function("tau")
    assert mass(q[0]).shape == (2, 2) and mass(q).shape == (3, 2, 2)
    assert eom.numeric_function("g")(q).shape == (3, 2)
    assert tau(q, q, q).shape == (3, 2)
    np.testing.assert_array_equal(mass(q)[1], mass(q[1]))
    # the same function object each time (built once per quantity)
    assert eom.numeric_function("M") is mass
    with pytest.raises(ValueError, match="unknown quantity 'D'"):
        eom.numeric_function("D")
    with pytest.raises(ValueError, match=r"qd must be \(2,\) or \(N, 2\)"):
        tau(q, q[:2], q)
    with pytest.raises(TypeError, match=r"tau\(q, qd, qdd, values=None\)"):
        tau(q)
    # symbolic inertia: the barycentric parameters must be given
    sym = rd.derive(rd.load("planar_2r"), symbolic_inertia=True)
    with pytest.raises(ValueError, match="no value for the parameter.*MX1"):
        sym.numeric_function("g")(q[0])


@pytest.fixture(scope="module")
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    return robot, rd.compile_model(robot)


@pytest.mark.slow
def test_the_three_formulations_agree_with_each_other_and_the_compiled_puma(puma):
    """Rotor inertia and friction included: the full tau of each formulation."""
    robot, model = puma
    rng = np.random.default_rng(7)
    q, qd, qdd = (rng.uniform(-np.pi, np.pi, (8, 6)), rng.uniform(-2, 2, (8, 6)),
                  rng.uniform(-3, 3, (8, 6)))
    ref = {"M": model.mass_matrix(q), "g": model.gravity(q), "tau": model.inverse_dynamics(q, qd, qdd),
           "C qd": model.coriolis(q, qd)}
    values = {}
    for method in METHODS:
        eom = rd.derive(robot, method)
        values[method] = {"M": eom.numeric_function("M")(q), "g": eom.numeric_function("g")(q),
                          "tau": eom.numeric_function("tau")(q, qd, qdd),
                          "C qd": np.einsum("kij,kj->ki", eom.numeric_function("C")(q, qd), qd)}
    # measured: at most 6e-16 relative (rounding)
    for method, got in values.items():
        for name, r in ref.items():
            scale = np.abs(r).max()
            assert np.abs(got[name] - r).max() < 1e-10 * scale, (method, name)
            assert np.abs(got[name] - values["newton_euler"][name]).max() < 1e-10 * scale
