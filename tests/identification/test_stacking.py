"""The stacked identification matrix: the batched regressor, sample-major, with or without a column
selection (chunked), against per-sample regressor calls."""

from __future__ import annotations

import numpy as np

import robodyn as rd
from robodyn.identification import stacking
from robodyn.identification.stacking import identification_matrix


def _model_and_states(count: int):
    model = rd.compile_model(rd.load("puma560"))
    rng = np.random.default_rng(7)
    q, qd, qdd = rng.uniform(-2, 2, (3, count, model.dof))
    return model, q, qd, qdd


def test_rows_are_the_per_sample_regressors():
    model, q, qd, qdd = _model_and_states(40)
    n = model.dof
    w = identification_matrix(model, q, qd, qdd)
    assert w.shape == (40 * n, 15 * n)
    for k in (0, 17, 39):
        one = model.regressor(q[k], qd[k], qdd[k])
        # the single-state entry point may contract to FMA differently from the batched one
        np.testing.assert_allclose(w[k * n:(k + 1) * n], one, rtol=0, atol=1e-12 * np.abs(one).max())


def test_column_selection_across_chunks(monkeypatch):
    monkeypatch.setattr(stacking, "CHUNK", 16)  # 40 samples: three chunks, the last partial
    model, q, qd, qdd = _model_and_states(40)
    cols = [0, 9, 14, 33, 89]
    full = identification_matrix(model, q, qd, qdd)
    picked = identification_matrix(model, q, qd, qdd, columns=cols)
    assert picked.shape == (40 * model.dof, len(cols))
    np.testing.assert_array_equal(picked, full[:, cols])


def test_inputs_are_not_modified():
    model, q, qd, qdd = _model_and_states(5)
    before = [a.copy() for a in (q, qd, qdd)]
    identification_matrix(model, q, qd, qdd)
    for a, b in zip((q, qd, qdd), before, strict=True):
        np.testing.assert_array_equal(a, b)


def test_threads_do_not_change_the_matrix():
    model, q, qd, qdd = _model_and_states(50)
    np.testing.assert_array_equal(identification_matrix(model, q, qd, qdd, threads=2),
                                  identification_matrix(model, q, qd, qdd))


def test_pivoted_columns_is_the_one_base_column_rule():
    from robodyn.identification.base import pivoted_columns
    from robodyn.studies import excitation

    rng = np.random.default_rng(0)
    a = rng.standard_normal((50, 2))
    # columns: a0, 1e6 a1 (units must not decide), a0 - 1e6 a1 (dependent), a structural zero
    w = np.column_stack([a[:, 0], 1e6 * a[:, 1], a[:, 0] - 1e6 * a[:, 1], np.zeros(50)])
    scales, used, _, piv, rank = pivoted_columns(w)
    assert rank == 2 and list(used) == [0, 1, 2]
    # the column norms, the earlier columns' shortened by at most 1e-6 (the tie preference)
    norms = np.linalg.norm(w, axis=0)
    assert np.all(scales <= norms) and np.all(scales >= norms * (1 - 1e-6))
    assert scales[0] < scales[2] / norms[2] * norms[0]
    # excitation design takes its base columns through the same function
    assert excitation.pivoted_columns is pivoted_columns


def test_regressor_rows_of_writes_into_a_given_array():
    """``out=`` (N, n, 15 n) receives the rows that a fresh call returns; a wrong shape is refused."""
    import pytest

    from robodyn.identification.stacking import regressor_rows_of
    from robodyn.robot.errors import InputError

    model, q, qd, qdd = _model_and_states(30)
    buf = np.full((30, model.dof, 15 * model.dof), np.nan)
    got = regressor_rows_of(model, q, qd, qdd, out=buf)
    assert got.base is buf or got is buf or np.shares_memory(got, buf)
    np.testing.assert_array_equal(buf, regressor_rows_of(model, q, qd, qdd))
    with pytest.raises(InputError, match="regressor_rows_of"):
        regressor_rows_of(model, q, qd, qdd, out=buf[:, :, :-1])


def test_effort_in_chunks_equals_the_effort_of_the_whole_regressor(monkeypatch):
    """``Identification.effort`` evaluates the regressor a chunk of samples at a time into one
    buffer; with a chunk smaller than the run (three chunks and a part) it equals ``Y p / K``
    of the whole run's prediction rows, computed here from the fitted parameters."""
    from robodyn.identification import result
    from robodyn.identification.preprocess import prediction_rows, preprocess
    from tests.identification.helpers import fourier

    robot = rd.load("puma560")
    model = rd.compile_model(robot)
    rng = np.random.default_rng(3)
    t = np.arange(3000) * 2e-3
    q, qd, qdd = fourier(t, robot.dof, rng, f0=0.2)
    rec = rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=model.inverse_dynamics(q, qd, qdd),
                       joint_names=robot.joint_names, source="simulated")
    ident = rd.identify(robot, rec, target="tau", model=model, cutoff=None, method="ols",
                        friction="linear", resonance=False, ripple=False)
    s = preprocess(rec, ident.preprocess, None)
    whole = prediction_rows(model, s, ident.preprocess) @ ident.standard / ident.gains
    monkeypatch.setattr(result, "EFFORT_CHUNK", 700)
    np.testing.assert_allclose(ident.effort(s), whole, rtol=0, atol=1e-12 * np.abs(whole).max())


def test_pivoted_columns_gives_exact_ties_to_the_earlier_column():
    """Of two exactly collinear columns (the first joint's ZZ and Ia), the earlier one is the base
    column whatever the last bits say: round-off, which differs between BLAS builds, vector
    widths and statement orders, must not choose between them."""
    from robodyn.identification.base import pivoted_columns

    rng = np.random.default_rng(1)
    for trial in range(40):
        a, b = rng.standard_normal((2, 60))
        scale = rng.uniform(0.1, 10.0)
        # columns 1 and 3 exactly collinear up to a last-bit wobble either way
        wobble = 1.0 + rng.choice([-1, 1]) * np.finfo(float).eps * rng.integers(1, 8, 60)
        w = np.column_stack([b, scale * a, a + b, a * wobble])
        _, used, _, piv, rank = pivoted_columns(w)
        base = set(used[piv[:rank]].tolist())
        assert rank == 2, trial
        # {b, scale a} span everything: columns 2 (a + b) and 3 (a) depend on them
        assert base == {0, 1}, (trial, base)
        # the same columns in the other order: now column 1 is the later twin
        w2 = np.column_stack([b, a * wobble, a + b, scale * a])
        _, used2, _, piv2, rank2 = pivoted_columns(w2)
        assert set(used2[piv2[:rank2]].tolist()) == {0, 1}, trial
