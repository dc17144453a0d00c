"""The parameter covariance from the column-scaled normal matrix against the SVD of ``J``."""

from __future__ import annotations

import numpy as np

from robodyn.calibration.solve import covariance


def test_covariance_matches_the_svd_of_the_jacobian():
    rng = np.random.default_rng(0)
    # columns spanning six decades (metres and radians side by side), mildly correlated
    j = rng.normal(size=(3000, 40)) @ (np.eye(40) + 0.3 * rng.normal(size=(40, 40)) / 40)
    j *= np.logspace(-3, 3, 40)
    _, sv, vt = np.linalg.svd(j, full_matrices=False)
    ref = (vt.T / sv**2) @ vt * 2.5
    cov = covariance(j, 2.5)
    np.testing.assert_allclose(cov, cov.T, rtol=0, atol=1e-12 * np.abs(ref).max())
    np.testing.assert_allclose(np.sqrt(np.diag(cov)), np.sqrt(np.diag(ref)), rtol=1e-8)
    assert np.abs(cov - ref).max() < 1e-8 * np.abs(ref).max()


def test_a_dependent_column_has_infinite_variance():
    rng = np.random.default_rng(1)
    j = rng.normal(size=(500, 5))
    j[:, 4] = j[:, 0] - 2 * j[:, 1]
    assert not np.all(np.isfinite(np.diag(covariance(j, 1.0))))


def test_compressed_rows_keep_the_column_geometry():
    from robodyn.calibration.identifiability import compress_rows, independent_columns, observability

    rng = np.random.default_rng(2)
    j = rng.normal(size=(2000, 12)) * np.logspace(-2, 2, 12)
    j[:, 5] = 0.5 * j[:, 1] - j[:, 7]  # a dependent column
    r = compress_rows(j)
    assert r.shape == (12, 12) and np.allclose(r, np.triu(r))
    g = np.einsum("ki,kj->ij", j, j)
    np.testing.assert_allclose(r.T @ r, g, rtol=0, atol=1e-12 * np.abs(g).max())
    order = list(range(12))
    # column 7 comes after 1 and 5 in the order: it is the one found dependent
    assert independent_columns(r, order) == independent_columns(j, order) == [k for k in order if k != 7]
    np.testing.assert_allclose(observability(j, 500).singular_values,
                               np.linalg.svd(j, compute_uv=False), rtol=1e-9, atol=1e-9)
