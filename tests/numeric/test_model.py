"""Compiled models: C and NumPy backends against the symbolic equations and Pinocchio."""

from __future__ import annotations

import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn.codegen.build import CompilerNotFoundError
from robodyn.codegen.c import BLOCK
from robodyn.codegen.c_outputs import STREAM_MIN_BYTES
from robodyn.symbolic.regressor import reflected_rotor_inertia
from tests.numeric_eval import evaluator, program_evaluator
from tests.urdf_chains import pin_q, random_urdf

ROBOTS = ["puma560", "puma560_akb", "aa300", "planar_2r", "trolley_double_pendulum",
          pytest.param("kinova_gen3", marks=pytest.mark.slow)]


def load_quiet(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rd.load(name)


@pytest.fixture(scope="module", params=ROBOTS)
def compiled(request):
    robot = load_quiet(request.param)
    eom = rd.derive(robot, method="newton_euler")
    return robot, eom, rd.compile_model(robot), rd.compile_model(robot, backend="numpy")


def states(n, count=5, seed=3):
    rng = np.random.default_rng(seed)
    return rng.uniform(-2, 2, (count, n)), rng.uniform(-2, 2, (count, n)), rng.uniform(-2, 2, (count, n))


def close(a, b, rtol=1e-10):
    """Relative agreement, scaled by the largest entry (torques mix N m and N)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(1.0, float(np.abs(b).max()))
    np.testing.assert_allclose(a, b, rtol=0, atol=rtol * scale)


def test_backends_agree_with_the_symbolic_equations(compiled):
    robot, eom, c_model, np_model = compiled
    n = robot.dof
    f_m = program_evaluator(eom, eom.M_rigid_form)
    f_g = program_evaluator(eom, eom.g_form)
    f_rigid = program_evaluator(eom, eom.program)
    f_fric = evaluator(eom, eom.friction)
    f_fk = evaluator(eom, eom.fk)
    f_jac = evaluator(eom, eom.jacobian)
    rotor = np.diag([float(reflected_rotor_inertia(robot, j).xreplace(eom.numeric())) for j in range(n)])
    qs, qds, qdds = states(n)
    batch = {m: (m.inverse_dynamics(qs, qds, qdds), m.mass_matrix(qs), m.gravity(qs),
                 m.coriolis(qs, qds), m.forward_kinematics(qs), m.jacobian(qs))
             for m in (c_model, np_model)}
    for k, (q, qd, qdd) in enumerate(zip(qs, qds, qdds, strict=True)):
        m_ref = f_m(q) + rotor
        g_ref = f_g(q).ravel()
        tau_ref = f_rigid(q, qd, qdd).ravel() + rotor @ qdd + f_fric(q, qd).ravel()
        c_ref = f_rigid(q, qd, np.zeros(n)).ravel() - g_ref
        for model in (c_model, np_model):
            tau, mm, g, c, fk, jac = (out[k] for out in batch[model])
            close(tau, tau_ref)
            close(mm, m_ref)
            close(g, g_ref)
            close(c, c_ref)
            close(fk, f_fk(q))
            close(jac, f_jac(q))
            # one state gives the same numbers as the batch, with the batch axis dropped
            close(model.inverse_dynamics(q, qd, qdd), tau)
            assert model.mass_matrix(q).shape == (n, n)


def test_c_batches_across_blocks_large_angles_and_resting_joints(compiled):
    """The C batch loops run in blocks with vectorised sin/cos and friction switches: check
    counts around the block size, angles far outside [-pi, pi] (and beyond the polynomial's
    range), joints exactly at rest, and that one state alone gives the batch's numbers: the same
    operations, whose products the compiler may fuse (FMA) differently in the vector loop and in
    its scalar remainder, so equal to rounding (1e-14 of the output's largest entry), not always
    to the bit (the Kinova regressor at block width 8 differed in the last bits)."""
    robot, _, c_model, np_model = compiled
    n = robot.dof
    count = max(2 * BLOCK + 3, 12)  # any block width, 1 (scalar code) too
    rng = np.random.default_rng(11)
    q = rng.uniform(-np.pi, np.pi, (count, n))
    q[1] += 2e3
    q[2] -= 3e5
    q[3, :] = np.pi / 2 * np.arange(n)
    qd, qdd, tau = (rng.uniform(-2, 2, (count, n)) for _ in range(3))
    qd[4:9] = 0.0
    qd[10, 0] = -0.0
    args = {"inverse_dynamics": (q, qd, qdd), "mass_matrix": (q,), "gravity": (q,),
            "coriolis": (q, qd), "forward_dynamics": (q, qd, tau),
            "state_derivative": (np.hstack([q, qd]), tau), "forward_kinematics": (q,),
            "jacobian": (q,), "regressor": (q, qd, qdd)}
    for name, arrays in args.items():
        for m in sorted({1, max(BLOCK - 1, 1), BLOCK, BLOCK + 1, count}):
            part = [a[:m] for a in arrays]
            out = getattr(c_model, name)(*part)
            close(out, getattr(np_model, name)(*part))
        for k in (0, 2, BLOCK, count - 1):
            single = getattr(c_model, name)(*(a[k] for a in arrays))
            scale = max(1.0, float(np.max(np.abs(out[k]))))
            np.testing.assert_array_less(np.abs(single - out[k]), 1e-14 * scale, err_msg=name)


def test_streamed_regressor_keeps_the_bits():
    """A regressor batch large enough for streaming stores (reused out=, >= STREAM_MIN_BYTES),
    on 1 and 3 threads and with a destination that starts off 32-byte alignment, gives the same
    bits as the cached path (a fresh matrix) and as each state alone; the constant entries are
    written too (the out= buffer starts as NaN)."""
    robot = load_quiet("puma560")
    model = rd.compile_model(robot)
    n = robot.dof
    per_state = 8 * n * 15 * n
    count = -(-STREAM_MIN_BYTES // per_state) + 2 * BLOCK + 5
    rng = np.random.default_rng(21)
    q, qd, qdd = rng.uniform(-2, 2, (3, count, n))
    qd[7] = 0.0
    fresh = model.regressor(q, qd, qdd)
    for threads in (1, 3):
        # the buffer one double past a 32-byte boundary: the copy's scalar head is exercised
        raw = np.full(count * n * 15 * n + 4, np.nan)
        skip = (-(raw.ctypes.data // 8) % 4 + 1) % 4
        out = raw[skip:skip + count * n * 15 * n].reshape(count, n, 15 * n)
        assert out.nbytes >= STREAM_MIN_BYTES and out.ctypes.data % 32 != 0
        result = model.regressor(q, qd, qdd, threads=threads, out=out)
        assert np.shares_memory(result, out)
        np.testing.assert_array_equal(out, fresh)
    for k in (0, 7, BLOCK + 1, count - 1):
        np.testing.assert_array_equal(model.regressor(q[k], qd[k], qdd[k]), fresh[k])


def test_streamed_derivatives_keep_the_bits():
    """The six-joint forward-dynamics derivatives (108 entries per state, staged since
    2026-12-06): a reused out= array large enough for streaming stores, on 1 and 3 threads, gives
    the bits of a fresh array (the same block code, only the stores differ), constant entries
    included (NaN start); each state alone agrees to rounding (its scalar loop may fuse a multiply
    and an add that the block does not)."""
    robot = load_quiet("puma560")
    model = rd.compile_model(robot)
    n = robot.dof
    count = -(-STREAM_MIN_BYTES // (8 * 3 * n * n)) + 2 * BLOCK + 5
    rng = np.random.default_rng(22)
    q, qd, tau = rng.uniform(-2, 2, (3, count, n))
    fresh = np.concatenate(model.forward_dynamics_derivatives(q, qd, tau), axis=-1)
    assert np.all(fresh[:, :, 0] == 0.0)  # the first joint's angle moves nothing: constants
    for threads in (1, 3):
        out = np.full((count, n, 3 * n), np.nan)
        assert out.nbytes >= STREAM_MIN_BYTES
        model.forward_dynamics_derivatives(q, qd, tau, threads=threads, out=out)
        np.testing.assert_array_equal(out, fresh)
    for k in (0, BLOCK + 1, count - 1):
        one = np.concatenate(model.forward_dynamics_derivatives(q[k], qd[k], tau[k]), axis=-1)
        np.testing.assert_allclose(one, fresh[k], rtol=1e-12, atol=1e-12 * np.abs(fresh[k]).max())


def test_forward_dynamics_inverts_inverse_dynamics(compiled):
    robot, eom, c_model, np_model = compiled
    n = robot.dof
    qs, qds, qdds = states(n, seed=5)
    for model in (c_model, np_model):
        tau = model.inverse_dynamics(qs, qds, qdds)
        close(model.forward_dynamics(qs, qds, tau), qdds, rtol=1e-9)
        # and against a general solve of M qdd = tau - h
        h = model.inverse_dynamics(qs, qds, np.zeros_like(qs))
        ref = np.linalg.solve(model.mass_matrix(qs), (tau - h)[..., None])[..., 0]
        close(model.forward_dynamics(qs, qds, tau), ref, rtol=1e-9)
        xd = model.state_derivative(np.hstack([qs, qds]), tau)
        close(xd[:, :n], qds)
        close(xd[:, n:], qdds, rtol=1e-9)


def test_regressor_reproduces_inverse_dynamics(compiled):
    robot, eom, c_model, np_model = compiled
    params = np.array(eom.params.xreplace(eom.numeric()), dtype=float).ravel()
    qs, qds, qdds = states(robot.dof, seed=7)
    # friction columns are discontinuous at qd = 0: the random states never hit it
    for model in (c_model, np_model):
        close(model.regressor(qs, qds, qdds) @ params, model.inverse_dynamics(qs, qds, qdds))


def test_published_puma560_values_from_the_compiled_model():
    model = rd.compile_model(load_quiet("puma560"))
    qn = np.array([0, np.pi / 4, -np.pi, 0, np.pi / 4, 0])
    np.testing.assert_allclose(model.gravity(qn), [0, 31.6399, 6.0351, 0, 0.0283, 0], atol=5e-5)
    np.testing.assert_allclose(model.mass_matrix(qn)[0], [3.6594, -0.4044, 0.1006, -0.0025, 0, 0],
                               atol=5e-5)


@pytest.mark.slow
@pytest.mark.oracle("pinocchio")
@pytest.mark.parametrize("seed", range(4))
def test_random_chains_match_pinocchio(tmp_path, seed):
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(2, 7))
    path = tmp_path / f"chain{seed}.urdf"
    path.write_text(random_urdf(rng, n))
    robot = rd.load(path)
    model = rd.compile_model(robot)
    import pinocchio as pin

    pmodel = pin.buildModelFromUrdf(str(path))
    data = pmodel.createData()
    qs, qds, qdds = (rng.uniform(-2, 2, (4, n)) for _ in range(3))
    taus = model.inverse_dynamics(qs, qds, qdds)
    qdd_fd = model.forward_dynamics(qs, qds, taus)
    poses = model.forward_kinematics(qs)
    for k in range(4):
        pq = pin_q(pmodel, qs[k])
        close(taus[k], pin.rnea(pmodel, data, pq, qds[k], qdds[k]), rtol=1e-9)
        close(model.mass_matrix(qs[k]), pin.crba(pmodel, data, pq), rtol=1e-9)
        close(model.gravity(qs[k]), pin.computeGeneralizedGravity(pmodel, data, pq), rtol=1e-9)
        close(qdd_fd[k], pin.aba(pmodel, data, pq, qds[k], taus[k]), rtol=1e-8)
        pin.forwardKinematics(pmodel, data, pq)
        # the URDF has no tool: the end effector is the last link frame
        close(poses[k], data.oMi[pmodel.njoints - 1].homogeneous, rtol=1e-9)


def test_parameters_override_the_defaults():
    robot = load_quiet("trolley_pendulum")
    base = rd.compile_model(robot)
    heavier = rd.compile_model(robot, parameters={"m": 2 * robot.parameters["m"]})
    q = np.array([0.1, 0.4])
    assert not np.allclose(base.gravity(q), heavier.gravity(q))
    # the pendulum's gravity torque is m g l sin(theta): linear in m
    np.testing.assert_allclose(heavier.gravity(q)[1], 2 * base.gravity(q)[1], rtol=1e-12)
    with pytest.raises(ValueError, match="no parameter"):
        rd.compile_model(robot, parameters={"nonexistent": 1.0})


def test_a_replaced_copy_is_compiled_as_itself():
    # dataclasses.replace on a Robot recomputes its hash, so the model cache (keyed by it)
    # cannot hand back the original's model: once it did, silently
    import dataclasses

    robot = load_quiet("planar_2r")
    base = rd.compile_model(robot)
    heavier = dataclasses.replace(robot, links=(robot.links[0], dataclasses.replace(
        robot.links[1], mass=2 * robot.links[1].mass)))
    assert heavier.description_hash != robot.description_hash
    assert dataclasses.replace(robot).description_hash == robot.description_hash
    q = np.array([0.3, 0.2])
    g, g2 = base.gravity(q), rd.compile_model(heavier).gravity(q)
    # link 2's gravity torque is its mass times g times its lever arm: linear in its mass
    np.testing.assert_allclose(g2[1], 2 * g[1], rtol=1e-12)

def test_bad_shapes_and_backend_are_clear_errors():
    model = rd.compile_model(load_quiet("planar_2r"))
    with pytest.raises(ValueError, match=r"q must have shape \(2,\) or \(N, 2\)"):
        model.mass_matrix(np.zeros(3))
    with pytest.raises(ValueError, match="batch shape"):
        model.inverse_dynamics(np.zeros((4, 2)), np.zeros((3, 2)), np.zeros((4, 2)))
    with pytest.raises(ValueError, match="unknown backend"):
        rd.compile_model(load_quiet("planar_2r"), backend="fortran")


def test_missing_compiler_names_the_numpy_fallback(tmp_path, monkeypatch):
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.delenv("CC", raising=False)
    with pytest.raises(CompilerNotFoundError, match="backend='numpy'"):
        rd.compile_model(load_quiet("planar_2r"))
    # the fallback itself works without a compiler
    model = rd.compile_model(load_quiet("planar_2r"), backend="numpy")
    assert model.mass_matrix(np.zeros(2)).shape == (2, 2)


@pytest.mark.slow
def test_cache_is_reused_and_safe_across_processes(tmp_path):
    env = {**os.environ, "ROBODYN_CACHE": str(tmp_path)}
    script = ("import warnings, numpy as np, robodyn as rd; warnings.simplefilter('ignore');"
              "m = rd.compile_model(rd.load('planar_2r'));"
              "print(repr(float(m.gravity(np.array([0.3, 0.2]))[0])))")
    # two processes compiling the same model into an empty cache at the same time
    procs = [subprocess.Popen([sys.executable, "-c", script], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outs = [p.communicate(timeout=300) for p in procs]
    assert all(p.returncode == 0 for p in procs), [o[1] for o in outs]
    assert outs[0][0] == outs[1][0]
    libraries = sorted(tmp_path.glob("rd_*.so"))
    assert len(libraries) == 1
    # a rebuild replaces the file (os.replace): a new inode; a cache hit only touches its time
    stamp = libraries[0].stat().st_ino
    # a third run finds everything in the cache and compiles nothing
    third = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True,
                           timeout=300, check=True)
    assert third.stdout == outs[0][0]
    assert libraries[0].stat().st_ino == stamp
    assert not list(tmp_path.glob(".build-*"))
