"""Link-frame hydrodynamics on a SPATIAL arm (twisted axes, URDF-style origins, a 3-D current)
against the world-frame strip formulas evaluated numerically here (the added mass in the
current by Lagrange's equations of the relative kinetic energy, differentiated numerically)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn import spatial as S
from robodyn.robot.yaml_loader import load_yaml_text
from robodyn.symbolic.hydro.geometry import link_frame_jacobian
from robodyn.symbolic.hydro.quadrature import gauss_legendre
from robodyn.symbolic.hydro.terms import hydro_terms
from robodyn.symbolic.kinematics import forward_kinematics, point_jacobian

# three revolute joints: z, then a 90-degree twisted axis, then an origin with rpy and an
# oblique cylinder; a current with all three components
SPATIAL = """\
name: spatial_wet
gravity: [0, 0, -9.81]
fluid: {density: 1025, current: [0.3, -0.2, 0.1]}
joints:
  - name: j1
    type: revolute
    dh: {a: 0.1, alpha: pi/2, d: 0.3, theta: 0}
    link:
      mass: 4
      com: [0, 0, 0]
      inertia: {ixx: 0.05, iyy: 0.05, izz: 0.05}
      hydro:
        cylinders: [{radius: 0.05, length: 0.3, axis: [0, 0, -1], start: [0, 0, 0]}]
        drag: 1.1
        skin_friction: 0.02
  - name: j2
    type: revolute
    origin: {xyz: [0.05, 0, 0.1], rpy: [0.3, 0, 0]}
    axis: [0, 1, 0]
    link:
      mass: 3
      com: [0.3, 0, 0]
      inertia: {ixx: 0.02, iyy: 0.1, izz: 0.1}
      hydro:
        cylinders: [{radius: 0.04, length: 0.6, axis: [1, 0, 0], start: [0, 0, 0]}]
        drag: 1.2
        lift: 0.3
        axial_added_mass: 0.2
  - name: j3
    type: revolute
    origin: {xyz: [0.6, 0, 0], rpy: [0, 0.2, 0.4]}
    axis: [0, 0.6, 0.8]
    link:
      mass: 2
      com: [0.2, 0.1, 0]
      inertia: {ixx: 0.01, iyy: 0.05, izz: 0.05}
      hydro:
        cylinders:
          - {radius: 0.03, length: 0.4, axis: [0.8, 0.6, 0], start: [0, 0, 0]}
          - {radius: 0.02, length: 0.2, axis: [0, 0, 1], start: [0.1, 0, 0]}
        drag: 1.0
"""


def test_link_frame_jacobian_is_the_rotated_world_jacobian() -> None:
    robot = load_yaml_text(SPATIAL, source="spatial.yaml")
    q = sp.symbols("q1:4", real=True)
    kin = forward_kinematics(robot, q)
    rng = np.random.default_rng(5)
    for link in range(3):
        point = sp.Matrix([0.1, -0.2, 0.3])
        local = link_frame_jacobian(robot, q, link, point)
        t = kin.links[link]
        world = point_jacobian(robot, kin, S.translation(t) + S.rotation(t) * point, link + 1)
        rot = S.rotation(t)
        rotated = sp.Matrix.vstack(rot.T * world[:3, :], rot.T * world[3:, :])
        f = sp.lambdify([q], local - rotated)
        for x in rng.uniform(-3, 3, (5, 3)):
            assert np.abs(np.array(f(x), dtype=float)).max() < 1e-13


def _world_functions(robot: rd.Robot) -> list:
    """Per cylinder: (link, cylinder data, f(q) -> R, f(q, xi) -> world J of the point at xi)."""
    q = sp.symbols("q1:4", real=True)
    xi = sp.Symbol("xi", real=True)
    kin = forward_kinematics(robot, q)
    out = []
    for link, lk in enumerate(robot.links):
        t = kin.links[link]
        for cyl in lk.hydro.cylinders:
            pt = S.translation(t) + S.rotation(t) * (cyl.start + xi * cyl.axis)
            out.append((link, cyl, sp.lambdify([q], S.rotation(t)),
                        sp.lambdify([q, xi], point_jacobian(robot, kin, pt, link + 1)[:3, :])))
    return out


def _world_reference(functions: list, qv: np.ndarray, qdv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Added mass and normal drag + lift + skin friction from world-frame strip formulas."""
    rho, current = 1025.0, np.array([0.3, -0.2, 0.1])
    coeffs = [dict(cd=1.1, cl=0.0, cf=0.02, cax=0.0), dict(cd=1.2, cl=0.3, cf=0.0, cax=0.2),
              dict(cd=1.0, cl=0.0, cf=0.0, cax=0.0)]
    m_a, tau = np.zeros((3, 3)), np.zeros(3)
    for link, cyl, rot_fn, jac_fn in functions:
        a = np.array(cyl.axis, float).ravel()  # unit axis (normalised when the file was read)
        r, length = float(cyl.radius), float(cyl.length)
        c = coeffs[link]
        e = np.array(rot_fn(qv), float) @ a
        p = np.eye(3) - np.outer(e, e)
        for xi, w in gauss_legendre(6, sp.Float(length)):  # the model's rule
            xi, w = float(xi), float(w)
            jac = np.array(jac_fn(qv, xi), float)
            u = p @ (jac @ qdv - current)
            # M_a += w C_a rho pi r^2 (P J)^T (P J)   (C_a = 1)
            m_a += w * rho * np.pi * r**2 * (p @ jac).T @ (p @ jac)
            # tau += w J^T (rho C_d r |u| u - rho C_L r |u| (e x u))
            tau += w * jac.T @ (rho * c["cd"] * r * np.linalg.norm(u) * u
                                - rho * c["cl"] * r * np.linalg.norm(u) * np.cross(e, u))
        j0 = np.array(jac_fn(qv, 0.0), float)
        u_a = e @ (j0 @ qdv - current)
        # skin friction and axial added mass, uniform along the cylinder
        tau += length * j0.T @ e * rho * c["cf"] * np.pi * r * abs(u_a) * u_a
        m_a += c["cax"] * rho * np.pi * r**2 * length * np.outer(j0.T @ e, j0.T @ e)
    return m_a, tau


def _added_energy(functions: list, qv: np.ndarray, qdv: np.ndarray,
                  current: np.ndarray) -> tuple[float, np.ndarray]:
    """``(T_r, dT_r/dqd)``: the added mass's kinetic energy of the motion relative to the water
    (world-frame strips, the model's rule) and its momentum, shape (3,)."""
    cax = (0.0, 0.2, 0.0)
    energy, momentum = 0.0, np.zeros(3)
    for link, cyl, rot_fn, jac_fn in functions:
        a = np.array(cyl.axis, float).ravel()  # unit axis (normalised when the file was read)
        r, length = float(cyl.radius), float(cyl.length)
        e = np.array(rot_fn(qv), float) @ a
        p = np.eye(3) - np.outer(e, e)
        m_n = 1025.0 * np.pi * r**2
        for xi, w in gauss_legendre(6, sp.Float(length)):
            jac = p @ np.array(jac_fn(qv, float(xi)), float)
            u = jac @ qdv - p @ current
            # T += w m' |P (v - c)|^2 / 2,  p += w m' (P J)^T P (v - c)
            energy += float(w) * m_n * (u @ u) / 2
            momentum += float(w) * m_n * jac.T @ u
        j0 = np.array(jac_fn(qv, 0.0), float)
        u_a = e @ (j0 @ qdv - current)
        energy += cax[link] * m_n * length * u_a**2 / 2
        momentum += cax[link] * m_n * length * u_a * (j0.T @ e)
    return energy, momentum


def _current_added_mass(functions: list, qv: np.ndarray, qdv: np.ndarray) -> np.ndarray:
    """Lagrange's equations of T_r at qdd = 0 with the current less those without it, by central
    differences in q: the added mass's terms that the current brings, shape (3,)."""
    h, eye = 1e-6, np.eye(3)
    out = np.zeros(3)
    for sign, current in ((1.0, np.array([0.3, -0.2, 0.1])), (-1.0, np.zeros(3))):
        # d/dt dT/dqd - dT/dq  with qdd = 0
        ddt = (_added_energy(functions, qv + h * qdv, qdv, current)[1]
               - _added_energy(functions, qv - h * qdv, qdv, current)[1]) / (2 * h)
        dtdq = np.array([_added_energy(functions, qv + h * e, qdv, current)[0]
                         - _added_energy(functions, qv - h * e, qdv, current)[0] for e in eye]) / (2 * h)
        out += sign * (ddt - dtdq)
    return out


@pytest.mark.slow
def test_spatial_hydro_terms_equal_world_frame_strip_formulas() -> None:
    robot = load_yaml_text(SPATIAL, source="spatial.yaml")
    q, qd = sp.symbols("q1:4", real=True), sp.symbols("qd1:4", real=True)
    h = hydro_terms(robot, q, qd, sp.symbols("qdd1:4", real=True))
    f_m = sp.lambdify([q], h.mass_matrix, cse=True)
    f_v = sp.lambdify([q, qd], h.drag + h.skin_friction + h.lift, cse=True)
    f_c = sp.lambdify([q, qd], h.current_added_mass, cse=True)
    functions = _world_functions(robot)
    rng = np.random.default_rng(6)
    for qv, qdv in rng.uniform(-2, 2, (3, 2, 3)):
        m_ref, tau_ref = _world_reference(functions, qv, qdv)
        np.testing.assert_allclose(np.array(f_m(qv), float), m_ref, rtol=1e-11, atol=1e-13)
        np.testing.assert_allclose(np.ravel(f_v(qv, qdv)), tau_ref, rtol=1e-10, atol=1e-12)
        # the added mass in the current: Lagrange's equations of the relative kinetic energy
        c_ref = _current_added_mass(functions, qv, qdv)
        assert np.abs(c_ref).max() > 1e-2
        np.testing.assert_allclose(np.ravel(f_c(qv, qdv)), c_ref, rtol=1e-7, atol=1e-8)
