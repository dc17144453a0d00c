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
    norms, used, _, piv, rank = pivoted_columns(w)
    assert rank == 2 and list(used) == [0, 1, 2]
    np.testing.assert_allclose(norms, np.linalg.norm(w, axis=0))
    # excitation design takes its base columns through the same function
    assert excitation.pivoted_columns is pivoted_columns
