"""A singular mass matrix is a clear error wherever the forward dynamics is needed."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import SimulationError, SingularMassMatrixError

MASSLESS_TIP = """
name: massless_tip
parameters: {m: 1.0, l: 1.0, g: 9.81}
gravity: [0, -g, 0]
joints:
  - name: q1
    type: revolute
    dh: {a: l, alpha: 0, d: 0, theta: 0}
    link:
      name: rod
      mass: m
      com: [-l/2, 0, 0]
      inertia: {ixx: 0, iyy: m*l**2/12, izz: m*l**2/12, ixy: 0, ixz: 0, iyz: 0}
  - name: wrist
    type: revolute
    dh: {a: 0.1, alpha: 0, d: 0, theta: 0}
    link:
      name: tip
      mass: 0
      com: [0, 0, 0]
      inertia: {ixx: 0, iyy: 0, izz: 0, ixy: 0, ixz: 0, iyz: 0}
"""

# link 1 massless, link 2 a point mass at its tip: M = m J^T J is singular wherever the arm is
# stretched or folded (q2 = 0, pi), regular elsewhere
POINT_MASS = """
name: point_mass_rr
parameters: {m: 1.0, g: 9.81}
gravity: [0, -g, 0]
joints:
  - name: shoulder
    type: revolute
    dh: {a: 1.0, alpha: 0, d: 0, theta: 0}
    link:
      name: bare
      mass: 0
      com: [0, 0, 0]
      inertia: {ixx: 0, iyy: 0, izz: 0, ixy: 0, ixz: 0, iyz: 0}
  - name: elbow
    type: revolute
    dh: {a: 1.0, alpha: 0, d: 0, theta: 0}
    link:
      name: ball
      mass: m
      com: [0, 0, 0]
      inertia: {ixx: 0, iyy: 0, izz: 0, ixy: 0, ixz: 0, iyz: 0}
"""


@pytest.fixture
def massless(tmp_path):
    path = tmp_path / "massless_tip.yaml"
    path.write_text(MASSLESS_TIP)
    return path


WHY = (r"massless_tip.yaml: the mass matrix .* singular in every configuration .* joint 'wrist' "
       r".* link 'tip'")


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_a_massless_final_link_has_no_forward_dynamics_naming_the_joint(massless, backend):
    # before: KeyError 'ComplexInfinity' (NumPy) or a printer error (C) from inside code
    # generation; then a refusal at compile time, which also refused the kinematics of every
    # kinematics-only description (a calibration's). Now the model compiles, its kinematics and
    # inverse dynamics work, and forward dynamics and simulation say why they cannot.
    robot = rd.load(massless)
    for _ in range(2):  # freshly generated, then from the cache
        model = rd.compile_model(robot, backend=backend)
        assert "joint 'wrist'" in model.singular
        q = np.array([0.4, -0.2])
        pose = model.forward_kinematics(q)
        assert pose.shape == (4, 4) and np.all(np.isfinite(pose))
        assert np.all(np.isfinite(model.inverse_dynamics(q, np.ones(2), np.ones(2))))
        calls = (("forward_dynamics", (q, np.zeros(2), np.zeros(2))),
                 ("state_derivative", (np.zeros(4), np.zeros(2))))
        for name, args in calls:
            with pytest.raises(SingularMassMatrixError, match=WHY):
                getattr(model, name)(*args)
        with pytest.raises(SingularMassMatrixError, match=WHY):
            rd.simulate(model, q, None, 0.1, 1e-3)


def test_the_cli_says_so_in_one_line(massless, capsys, tmp_path):
    from robodyn.cli import main

    code = main(["simulate", str(massless), "--backend", "numpy", "-o", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2
    # (the loader may warn first, one line too)
    errors = [line for line in err.splitlines() if line.startswith("robodyn: error:")]
    assert len(errors) == 1 and "singular" in errors[0] and "Traceback" not in err


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_forward_dynamics_and_simulate_where_the_mass_matrix_is_singular(tmp_path, backend):
    path = tmp_path / "point_mass_rr.yaml"
    path.write_text(POINT_MASS)
    model = rd.compile_model(rd.load(path), backend=backend)
    stretched = np.array([0.3, 0.0])
    # M = [[4, 2], [2, 1]]: the null direction (1, -2)/sqrt(5), mostly the elbow
    with pytest.raises(SingularMassMatrixError,
                       match=r"singular at q = \[0\.3 0\. *\] .* mostly joint 'elbow'"):
        model.forward_dynamics(stretched, np.zeros(2), np.zeros(2))
    states = np.array([[0.3, 1.0, 0, 0], [0.3, 0.0, 0, 0]])
    with pytest.raises(SingularMassMatrixError):
        model.state_derivative(states, np.zeros((2, 2)))
    with pytest.raises(SingularMassMatrixError):
        rd.simulate(model, stretched, None, 0.1, 1e-3)
    # a SimulationError: a ValueError for the command line (exit 2), a FloatingPointError as before
    assert issubclass(SingularMassMatrixError, SimulationError)
    assert issubclass(SimulationError, ValueError) and issubclass(SimulationError, FloatingPointError)
    # bent, the same arm is regular: M^-1 exists and the call returns
    bent = np.array([0.3, 1.0])
    qdd = model.forward_dynamics(bent, np.zeros(2), np.zeros(2))
    np.testing.assert_allclose(model.mass_matrix(bent) @ qdd, -model.gravity(bent), atol=1e-12)


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_forward_dynamics_derivatives_refuse_a_singular_state_anywhere_in_the_batch(tmp_path,
                                                                                   backend):
    # since 2026-12-06 only the diagonal of the d qdd/d tau block (M^-1) is checked for
    # finiteness, not all 3 n^2 entries: a singular M must still be caught in any row
    path = tmp_path / "point_mass_rr.yaml"
    path.write_text(POINT_MASS)
    model = rd.compile_model(rd.load(path), backend=backend)
    q = np.array([[0.3, 1.0], [0.3, 0.5], [0.3, 0.0], [0.3, -1.0]])  # row 2 stretched: singular
    zeros = np.zeros_like(q)
    with pytest.raises(SingularMassMatrixError, match=r"singular at q = \[0\.3 0\. *\]"):
        model.forward_dynamics_derivatives(q, zeros, zeros)
    dq, dqd, dtau = model.forward_dynamics_derivatives(q[[0, 1, 3]], zeros[:3], zeros[:3])
    np.testing.assert_allclose(dtau, np.linalg.inv(model.mass_matrix(q[[0, 1, 3]])), rtol=1e-12)


@pytest.mark.parametrize("lang", ["c", "python"])
def test_codegen_refuses_a_robot_without_forward_dynamics(massless, capsys, tmp_path, lang):
    from robodyn.cli import main

    # before: SymPy's zoo reached the printer (a traceback from the C printer, KeyError
    # 'ComplexInfinity' from the Python one)
    code = main(["codegen", str(massless), "--lang", lang, "-o", str(tmp_path / "gen")])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    errors = [line for line in err.splitlines() if line.startswith("robodyn: error:")]
    assert len(errors) == 1 and "singular in every configuration" in errors[0]
    assert "joint 'wrist'" in errors[0]


@pytest.mark.parametrize("threads", [1, 2])
def test_the_compiled_batches_count_the_blocks_with_a_non_finite_output(tmp_path, threads):
    # the C batches of the kernels a singular M breaks count the blocks whose checked outputs
    # are not finite (codegen.c_outputs.FINITE_CHECKED), so that finite results are not read
    # back; a count of 0 must mean finite, wherever the singular state sits (first block, a
    # middle one, the last, partial one) and on any number of threads
    from robodyn.codegen.cpu import BLOCK

    path = tmp_path / "point_mass_rr.yaml"
    path.write_text(POINT_MASS)
    model = rd.compile_model(rd.load(path))
    count = 3 * BLOCK + 3  # three full blocks and a partial one at any block width
    rng = np.random.default_rng(7)
    q = np.column_stack([rng.uniform(-1, 1, count), rng.uniform(0.3, 2.5, count)])  # bent: regular
    qd, tau = rng.normal(size=(count, 2)), rng.normal(size=(count, 2))
    d = model._derivative_model
    calls = {"forward_dynamics": lambda q: model._call_counted(
                 "forward_dynamics", q, qd, tau, threads=threads),
             "state_derivative": lambda q: model._call_counted(
                 "state_derivative", np.hstack([q, qd]), tau, threads=threads),
             "forward_dynamics_derivatives": lambda q: d._call_counted(
                 "forward_dynamics_derivatives", q, qd, tau, threads=threads)}
    for name, call in calls.items():
        out, bad = call(q)
        assert bad == 0 and np.all(np.isfinite(out)), name
        for k in (0, BLOCK + 1, count - 1):
            stretched = q.copy()
            stretched[k, 1] = 0.0  # M singular at state k only
            out, bad = call(stretched)
            assert bad == 1, (name, k)
            assert not np.all(np.isfinite(out[k])) and np.all(np.isfinite(np.delete(out, k, 0))), name
    with pytest.raises(SingularMassMatrixError):
        model.forward_dynamics_derivatives(stretched, qd, tau, threads=threads)
