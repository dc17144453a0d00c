"""Added mass in a current against an independent strip-theory reference written here in NumPy.

The reference is the planar two-link arm ``underwater_2r`` (link 1 along ``(cos q1, sin q1)``,
link 2 along ``(cos(q1 + q2), sin(q1 + q2))``, current ``(vc, 0)``): the fluid's kinetic energy of
the motion relative to the water, ``T_r = 1/2 sum_links int m' |P (v(s) - c)|^2 ds`` (200
Gauss points), and Lagrange's equations of it taken by central differences. The model's
added-mass force is what its compiled inverse dynamics loses when ``Ca`` is set to 0 (drag,
buoyancy and the rigid body stay), so the compiled kernels, their derivatives and the symbolic
terms are all checked against the same reference.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd

PRM = dict(l1=1.0, l2=0.8, r1=0.06, r2=0.05, rho=1000.0)
H = 1e-6  # central-difference step


def _normal_velocities(q: np.ndarray, qd: np.ndarray, vc: float) -> list[tuple[float, np.ndarray]]:
    """Per link ``(m' w_k, u_n(s_k))``: the normal velocity relative to the current at 200 Gauss
    points ``s_k`` along the link, with its quadrature weight times the added mass per metre."""
    x, w = np.polynomial.legendre.leggauss(200)
    c = np.array([vc, 0.0])
    out, base_vel = [], np.zeros(2)
    for i, (length, r) in enumerate(((PRM["l1"], PRM["r1"]), (PRM["l2"], PRM["r2"]))):
        phi, phid = q[: i + 1].sum(), qd[: i + 1].sum()
        n = np.array([-np.sin(phi), np.cos(phi)])
        s = (x + 1) * length / 2
        # v(s) = v_base + s phid n; its normal part relative to the water
        u_n = (base_vel @ n - c @ n) + s * phid
        out.append((PRM["rho"] * np.pi * r**2 * w * length / 2, u_n))
        base_vel = base_vel + length * phid * n
    return out


def _strip_energy(q: np.ndarray, qd: np.ndarray, vc: float) -> float:
    """``T_r``: normal added mass (C_a = 1) on the velocity relative to the current, J."""
    return sum(0.5 * np.sum(mw * u**2) for mw, u in _normal_velocities(q, qd, vc))


def _momentum(q: np.ndarray, qd: np.ndarray, vc: float) -> np.ndarray:
    """``dT/dqd``, shape (2,): u_n is linear in qd, its gradient is u_n at a unit qd, no current."""
    rows = _normal_velocities(q, qd, vc)
    grads = [_normal_velocities(q, e, 0.0) for e in np.eye(len(q))]
    return np.array([sum(np.sum(mw * u * g[i][1]) for i, (mw, u) in enumerate(rows)) for g in grads])


def _lagrange(q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, vc: float) -> np.ndarray:
    """``d/dt dT/dqd - dT/dq``, shape (2,): the time and q derivatives by central differences."""
    eye = np.eye(len(q))
    # d/dt dT/dqd = d(dT/dqd)/dq qd + d(dT/dqd)/dqd qdd   (the second one is exact: linear)
    ddt = ((_momentum(q + H * qd, qd, vc) - _momentum(q - H * qd, qd, vc)) / (2 * H)
           + _momentum(q, qdd, 0.0))
    dtdq = np.array([(_strip_energy(q + H * e, qd, vc) - _strip_energy(q - H * e, qd, vc)) / (2 * H)
                     for e in eye])
    return ddt - dtdq


@pytest.fixture(scope="module")
def models() -> dict[str, rd.Model]:
    robot = rd.load("underwater_2r")
    return {name: rd.compile_model(robot, parameters={"vc": 0.5, "Ca": ca})
            for name, ca in (("wet", 1.0), ("no_added_mass", 0.0))}


def _states(seed: int, count: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-2, 2, (count, 3, 2))


def test_added_mass_force_in_a_current_equals_the_strip_theory_reference(models) -> None:
    for q, qd, qdd in _states(11, 6):
        ref = _lagrange(q, qd, qdd, vc=0.5)
        got = models["wet"].inverse_dynamics(q, qd, qdd) - models["no_added_mass"].inverse_dynamics(
            q, qd, qdd)
        np.testing.assert_allclose(got, ref, rtol=1e-8, atol=1e-7)
        # the current really enters: the still-water force differs
        assert np.abs(ref - _lagrange(q, qd, qdd, vc=0.0)).max() > 0.05


def test_arm_at_rest_at_45_degrees_to_the_flow_feels_the_munk_moment(models) -> None:
    q, zero = np.array([np.pi / 4, 0.0]), np.zeros(2)
    got = models["wet"].inverse_dynamics(q, zero, zero) - models["no_added_mass"].inverse_dynamics(
        q, zero, zero)
    # -1/2 dk/dq with k = sum m' L (c sin phi)^2: -1/2 m' L c^2 sin(2 phi) per link at phi = pi/4
    m1, m2 = (PRM["rho"] * np.pi * r**2 for r in (PRM["r1"], PRM["r2"]))
    munk2 = -0.5 * m2 * PRM["l2"] * 0.5**2
    np.testing.assert_allclose(got, [-0.5 * m1 * PRM["l1"] * 0.5**2 + munk2, munk2], rtol=1e-12)
    np.testing.assert_allclose(got, _lagrange(q, zero, zero, vc=0.5), rtol=1e-6, atol=1e-7)


def test_derivatives_of_the_added_mass_in_a_current_equal_the_reference(models) -> None:
    eye = np.eye(2)
    for q, qd, qdd in _states(12, 3):
        dq, dqd = (a - b for a, b in zip(models["wet"].inverse_dynamics_derivatives(q, qd, qdd),
                                         models["no_added_mass"].inverse_dynamics_derivatives(
                                             q, qd, qdd), strict=True))
        step = 1e-4
        ref_q = np.column_stack([(_lagrange(q + step * eye[k], qd, qdd, 0.5)
                                  - _lagrange(q - step * eye[k], qd, qdd, 0.5)) / (2 * step)
                                 for k in range(2)])
        ref_qd = np.column_stack([(_lagrange(q, qd + step * eye[k], qdd, 0.5)
                                   - _lagrange(q, qd - step * eye[k], qdd, 0.5)) / (2 * step)
                                  for k in range(2)])
        np.testing.assert_allclose(dq, ref_q, rtol=1e-5, atol=1e-4)
        np.testing.assert_allclose(dqd, ref_qd, rtol=1e-5, atol=1e-4)


def test_in_a_current_the_water_frame_energy_is_conserved_without_drag() -> None:
    # no drag, no lift: seen from the water the Lagrangian has no explicit time, so its Jacobi
    # integral K + V - 1/2 k(q) is conserved, k = sum m' L (c sin phi)^2 (normal added mass);
    # the simulated K + V alone is not (the current works on the arm through the Munk moment)
    model = rd.compile_model(rd.load("underwater_2r"), parameters={"vc": 0.5, "Cd": 0.0})
    run = rd.simulate(model, np.array([0.4, -0.8]), np.array([1.0, -0.5]), 3.0, 1e-3)
    phi = np.column_stack([run.q[:, 0], run.q.sum(axis=1)])
    m_prime = PRM["rho"] * np.pi * np.array([PRM["r1"], PRM["r2"]]) ** 2
    k = (m_prime * np.array([PRM["l1"], PRM["l2"]]) * (0.5 * np.sin(phi)) ** 2).sum(axis=1)
    jacobi = run.energy - k / 2
    assert np.ptp(jacobi) < 1e-7
    assert np.ptp(run.energy) > 1e-2
