"""PUMA 560 against the Robotics Toolbox: published values and the toolbox itself (test oracle)."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

import robodyn as rd
from tests.numeric_eval import evaluator, random_states

QN = np.array([0, np.pi / 4, -np.pi, 0, np.pi / 4, 0])


@cache
def puma():
    return rd.derive(rd.load("puma560"), method="newton_euler")


def test_gravity_load_at_qn_matches_published_values():
    eom = puma()
    g = evaluator(eom, eom.g)(QN).ravel()
    # Robotics Toolbox documentation: p560.gravload(qn)
    np.testing.assert_allclose(g, [0, 31.6399, 6.0351, 0, 0.0283, 0], atol=5e-5)


def test_inertia_matrix_first_row_at_qn_matches_published_values():
    eom = puma()
    m = evaluator(eom, eom.M)(QN)
    # Robotics Toolbox documentation: p560.inertia(qn), rotor inertia G^2 Jm included
    np.testing.assert_allclose(m[0], [3.6594, -0.4044, 0.1006, -0.0025, 0, 0], atol=5e-5)


@pytest.mark.oracle("roboticstoolbox")
def test_full_inverse_dynamics_matches_robotics_toolbox_rne():
    import roboticstoolbox as rtb

    p560 = rtb.models.DH.Puma560()
    eom = puma()
    f_tau, f_m, f_c = evaluator(eom, eom.tau), evaluator(eom, eom.M), evaluator(eom, eom.C)
    for q, qd, qdd in random_states(6, 5, seed=7):
        # RTB rne includes motor inertia G^2 Jm and friction (B and Tc reflected, Coulomb by sign)
        ref = p560.rne(q, qd, qdd)
        np.testing.assert_allclose(f_tau(q, qd, qdd).ravel(), ref, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(f_m(q), p560.inertia(q), rtol=1e-9, atol=1e-10)
        np.testing.assert_allclose(f_c(q, qd) @ qd, p560.coriolis(q, qd) @ qd, rtol=1e-9,
                                   atol=1e-10)
