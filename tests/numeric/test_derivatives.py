"""Analytic derivatives of the inverse and forward dynamics against independent references.

References: central finite differences of the compiled dynamics (relative 1e-6), the inverse of
the mass matrix, and Pinocchio's ``computeRNEADerivatives`` / ``computeABADerivatives`` on random
URDF chains (1e-9; those chains have no friction and no rotor inertia, which Pinocchio lacks).
"""

from __future__ import annotations

import warnings
from functools import partial

import numpy as np
import pytest

import robodyn as rd
from robodyn.codegen.emit import LANGUAGES, generate
from robodyn.codegen.kernels import DERIVATIVE_KERNEL_NAMES, build_kernels
from tests.urdf_chains import pin_q, random_urdf

try:  # test-only oracle: the tests that use it are marked and skip alone (see tests/conftest.py)
    import pinocchio as pin
except ImportError:
    pin = None

H = 1e-6


def load_quiet(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rd.load(name)


_MODELS: dict[tuple[str, str], rd.Model] = {}


def model_of(name: str, backend: str):
    if (name, backend) not in _MODELS:
        _MODELS[name, backend] = rd.compile_model(load_quiet(name), backend=backend)
    return _MODELS[name, backend]


def central(f, x, h=H):
    """(m, n) central differences of f: R^n -> R^m at x."""
    cols = [(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(x.size)]
    return np.array(cols).T


def central_q_qd(f, q, qd, third):
    """Central differences of ``f(q, qd, third)`` in ``q`` and in ``qd``."""
    return central(lambda x: f(x, qd, third), q), central(lambda x: f(q, x, third), qd)


def assert_relative(actual, expected, rtol):
    """max |actual - expected| <= rtol * max |expected| (the matrix's own scale)."""
    scale = max(np.max(np.abs(expected)), 1e-300)
    err = np.max(np.abs(actual - expected))
    assert err <= rtol * scale, f"relative error {err / scale:.3g} > {rtol:g}"


def random_state(n, seed):
    rng = np.random.default_rng(seed)
    q, qd, qdd = rng.uniform(-2, 2, (3, n))
    # |qd| >= 0.1: the Coulomb steps stay constant across the differences
    qd = np.where(np.abs(qd) < 0.1, 0.1 * np.sign(qd + 1e-12), qd)
    return q, qd, qdd


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["c", "numpy"])
@pytest.mark.parametrize("name", ["planar_2r", "puma560"])
def test_inverse_dynamics_derivatives_match_central_differences(name, backend):
    model = model_of(name, backend)
    n = model.dof
    for seed in range(3):
        q, qd, qdd = random_state(n, seed)
        dq, dqd = model.inverse_dynamics_derivatives(q, qd, qdd)
        assert dq.shape == dqd.shape == (n, n)
        ref_q, ref_qd = central_q_qd(model.inverse_dynamics, q, qd, qdd)
        assert_relative(dq, ref_q, 1e-6)
        assert_relative(dqd, ref_qd, 1e-6)


@pytest.mark.parametrize("backend", ["c", "numpy"])
@pytest.mark.parametrize("name", ["planar_2r", "puma560"])
def test_forward_dynamics_derivatives_match_central_differences(name, backend):
    model = model_of(name, backend)
    n = model.dof
    for seed in range(3):
        q, qd, qdd = random_state(n, 10 + seed)
        tau = model.inverse_dynamics(q, qd, qdd)
        dq, dqd, dtau = model.forward_dynamics_derivatives(q, qd, tau)
        assert dq.shape == dqd.shape == dtau.shape == (n, n)
        ref_q, ref_qd = central_q_qd(model.forward_dynamics, q, qd, tau)
        assert_relative(dq, ref_q, 1e-6)
        assert_relative(dqd, ref_qd, 1e-6)
        # d qdd/d tau = M^-1 (rotor inertia included)
        m = model.mass_matrix(q)
        np.testing.assert_allclose(dtau @ m, np.eye(n), atol=1e-10)
        # and it is exact: qdd is affine in tau
        assert_relative(dtau, central(partial(model.forward_dynamics, q, qd), tau, h=1.0), 1e-8)


def test_forward_derivatives_are_minus_m_inverse_times_inverse_derivatives():
    model = model_of("puma560", "c")
    q, qd, _ = random_state(6, 21)
    tau = np.array([3.0, -20.0, 5.0, 0.5, -0.3, 0.1])
    qdd = model.forward_dynamics(q, qd, tau)
    dq, dqd = model.inverse_dynamics_derivatives(q, qd, qdd)
    fq, fqd, ftau = model.forward_dynamics_derivatives(q, qd, tau)
    m = model.mass_matrix(q)
    np.testing.assert_allclose(m @ fq, -dq, rtol=1e-10, atol=1e-10 * np.max(np.abs(dq)))
    np.testing.assert_allclose(m @ fqd, -dqd, rtol=1e-10, atol=1e-10 * np.max(np.abs(dqd)))


def test_viscous_friction_is_in_d_tau_d_qd_and_the_coulomb_step_is_not():
    model = model_of("puma560", "c")
    n = model.dof
    q, _, qdd = random_state(n, 5)
    qd = np.full(n, 0.7)
    _, dqd_pos = model.inverse_dynamics_derivatives(q, qd, qdd)
    _, dqd_neg = model.inverse_dynamics_derivatives(q, -qd, qdd)
    # C(q, qd) qd is quadratic in qd, so its d/dqd is odd in qd; the viscous part is even:
    # (dtau/dqd(qd) + dtau/dqd(-qd)) / 2 = diag(Fv) (joint-side viscous friction), nothing else
    even = 0.5 * (dqd_pos + dqd_neg)
    np.testing.assert_allclose(even - np.diag(np.diag(even)), 0.0, atol=1e-9 * np.max(np.abs(even)))
    # the viscous coefficients: tau_f(qd) - tau_f(-qd) = 2 Fv qd + Coulomb levels, at qdd = 0, q fixed
    t1 = model.inverse_dynamics(q, 2 * qd, qdd) - model.inverse_dynamics(q, -2 * qd, qdd)
    t2 = model.inverse_dynamics(q, qd, qdd) - model.inverse_dynamics(q, -qd, qdd)
    # C(q, qd) qd is even in qd (cancels); friction gives 2 Fv x + the Coulomb levels' sum
    fv = (t1 - t2) / (2 * qd)
    assert np.all(fv > 0)
    np.testing.assert_allclose(np.diag(even), fv, rtol=1e-9)
    # at qd = 0 exactly the step has no derivative; the kernel gives the viscous value there
    _, at_rest = model.inverse_dynamics_derivatives(q, np.zeros(n), qdd)
    np.testing.assert_allclose(at_rest, np.diag(fv), rtol=1e-9, atol=1e-12)


def test_single_state_and_batch_shapes_and_values():
    model = model_of("puma560", "c")
    n, count = model.dof, 37
    rng = np.random.default_rng(2)
    q, qd, qdd = rng.uniform(-2, 2, (3, count, n))
    dq, dqd = model.inverse_dynamics_derivatives(q, qd, qdd)
    assert dq.shape == dqd.shape == (count, n, n)
    tau = model.inverse_dynamics(q, qd, qdd)
    fd = model.forward_dynamics_derivatives(q, qd, tau)
    assert [a.shape for a in fd] == [(count, n, n)] * 3
    for k in (0, 16, 36):
        one = model.inverse_dynamics_derivatives(q[k], qd[k], qdd[k])
        np.testing.assert_allclose(one[0], dq[k], rtol=1e-13, atol=1e-13)
        np.testing.assert_allclose(one[1], dqd[k], rtol=1e-13, atol=1e-13)
        for a, b in zip(model.forward_dynamics_derivatives(q[k], qd[k], tau[k]), fd, strict=True):
            np.testing.assert_allclose(a, b[k], rtol=1e-13, atol=1e-13)
    # a batch of one keeps its leading axis
    assert model.inverse_dynamics_derivatives(q[:1], qd[:1], qdd[:1])[0].shape == (1, n, n)
    # non-contiguous inputs are read correctly; inputs are not modified
    qs = np.asfortranarray(q)
    before = qs.copy()
    np.testing.assert_allclose(model.inverse_dynamics_derivatives(qs, qd, qdd)[0], dq, rtol=1e-13)
    np.testing.assert_array_equal(qs, before)


def test_c_and_numpy_backends_agree():
    c, py = model_of("puma560", "c"), model_of("puma560", "numpy")
    rng = np.random.default_rng(4)
    q, qd, u = rng.uniform(-2, 2, (3, 9, 6))
    for a, b in zip(c.inverse_dynamics_derivatives(q, qd, u), py.inverse_dynamics_derivatives(q, qd, u),
                    strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10 * np.max(np.abs(b)))
    for a, b in zip(c.forward_dynamics_derivatives(q, qd, u), py.forward_dynamics_derivatives(q, qd, u),
                    strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10 * np.max(np.abs(b)))


def test_bad_shapes_are_refused_with_the_argument_named():
    model = model_of("planar_2r", "c")
    with pytest.raises(ValueError, match="qd must have shape"):
        model.inverse_dynamics_derivatives(np.zeros(2), np.zeros(3), np.zeros(2))
    with pytest.raises(ValueError, match="tau has shape"):
        model.forward_dynamics_derivatives(np.zeros((4, 2)), np.zeros((4, 2)), np.zeros((5, 2)))


@pytest.mark.parametrize("current", [0.0, 0.4])
def test_underwater_derivatives_include_the_hydrodynamic_terms(current):
    robot = load_quiet("underwater_2r")
    model = rd.compile_model(robot, backend="numpy", parameters={"vc": current})
    dry = rd.compile_model(robot, backend="numpy", parameters={"vc": current, "rho": 0.0})
    n = model.dof
    for seed in range(3):
        q, qd, qdd = random_state(n, 30 + seed)
        dq, dqd = model.inverse_dynamics_derivatives(q, qd, qdd)
        ref_q, ref_qd = central_q_qd(model.inverse_dynamics, q, qd, qdd)
        assert_relative(dq, ref_q, 1e-6)
        assert_relative(dqd, ref_qd, 1e-6)
        tau = model.inverse_dynamics(q, qd, qdd)
        fq, fqd, _ = model.forward_dynamics_derivatives(q, qd, tau)
        ref_q, ref_qd = central_q_qd(model.forward_dynamics, q, qd, tau)
        assert_relative(fq, ref_q, 1e-6)
        assert_relative(fqd, ref_qd, 1e-6)
        # the water matters: the dry arm's derivatives differ
        assert np.max(np.abs(dqd - dry.inverse_dynamics_derivatives(q, qd, qdd)[1])) > 1e-3
    # at rest in still water the flow speed is zero: |u| u has derivative 0, no NaN
    q = np.array([0.3, -0.4])
    dq, dqd = model.inverse_dynamics_derivatives(q, np.zeros(n), np.zeros(n))
    assert np.all(np.isfinite(dq)) and np.all(np.isfinite(dqd))
    if current == 0.0:
        # no drag or lift derivative at rest, only the added mass's Coriolis terms (zero at rest)
        np.testing.assert_allclose(dqd, 0.0, atol=1e-12)
        np.testing.assert_allclose(dq, central(lambda x: model.inverse_dynamics(x, np.zeros(n),
                                                                              np.zeros(n)), q),
                                   rtol=1e-6, atol=1e-6 * np.max(np.abs(dq)))


@pytest.mark.parametrize("lang", LANGUAGES)
def test_every_code_target_prints_the_derivative_kernels(tmp_path, lang):
    kset = build_kernels(load_quiet("planar_2r"), names=DERIVATIVE_KERNEL_NAMES)
    paths = generate(kset, lang, tmp_path)
    text = "\n".join(p.read_text() for p in paths)
    for kernel in kset.kernels:
        # LaTeX titles its sections "Inverse dynamics derivatives"
        name = kernel.name.replace("_", " ").capitalize() if lang == "latex" else kernel.name
        assert name in text
        # every output entry is written (the last one, e.g. dqdd[1, 5] / dqdd(2, 6))
        assert len(kernel.outputs[0].entries) == 2 * 2 * (2 if "inverse" in kernel.name else 3)


def test_generated_numpy_module_of_the_derivatives_runs(tmp_path):
    robot = load_quiet("planar_2r")
    kset = build_kernels(robot, names=DERIVATIVE_KERNEL_NAMES)
    (path,) = generate(kset, "python", tmp_path)
    scope: dict = {}
    exec(compile(path.read_text(), str(path), "exec"), scope)  # noqa: S102 - our generated file
    model = model_of("planar_2r", "c")
    q, qd, qdd = random_state(2, 3)
    d = scope["inverse_dynamics_derivatives"](q, qd, qdd)
    np.testing.assert_allclose(d[:, :2], model.inverse_dynamics_derivatives(q, qd, qdd)[0], rtol=1e-12)


@pytest.mark.slow
@pytest.mark.oracle("pinocchio")
@pytest.mark.parametrize("seed", range(4))
def test_random_chain_derivatives_match_pinocchio(tmp_path, seed):
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(2, 6))
    path = tmp_path / f"random_{seed}.urdf"
    path.write_text(random_urdf(rng, n))
    robot = rd.load(path)
    model = rd.compile_model(robot, backend="numpy")
    pmodel = pin.buildModelFromUrdf(str(path))
    data = pmodel.createData()
    for _ in range(3):
        q, qd, qdd = rng.uniform(-2, 2, (3, n))
        pq = pin_q(pmodel, q)
        rq, rv, _ = pin.computeRNEADerivatives(pmodel, data, pq, qd, qdd)
        dq, dqd = model.inverse_dynamics_derivatives(q, qd, qdd)
        np.testing.assert_allclose(dq, rq, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(dqd, rv, rtol=1e-9, atol=1e-9)
        tau = pin.rnea(pmodel, data, pq, qd, qdd)
        aq, av, atau = pin.computeABADerivatives(pmodel, data, pq, qd, tau)
        fq, fqd, ftau = model.forward_dynamics_derivatives(q, qd, tau)
        np.testing.assert_allclose(fq, aq, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(fqd, av, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(ftau, np.triu(atau) + np.triu(atau, 1).T, rtol=1e-9, atol=1e-9)
