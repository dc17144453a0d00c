"""Error metrics, noise floor and spectra against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.validation import error_metrics, noise_floor, residual_spectra


def test_metrics_of_a_constant_offset_are_its_closed_form():
    t = np.linspace(0.0, 1.0, 1001)
    y = np.column_stack([np.sin(2 * np.pi * t), 2.0 + 0.0 * t])
    c = np.array([0.1, -0.5])
    m = error_metrics(y, y + c)
    np.testing.assert_allclose(m.rms, np.abs(c), rtol=1e-12)
    np.testing.assert_allclose(m.max, np.abs(c), rtol=1e-12)
    # ||c 1|| / ||y||: sqrt(N) |c| / ||y||
    np.testing.assert_allclose(m.relative, np.sqrt(len(t)) * np.abs(c) / np.linalg.norm(y, axis=0),
                               rtol=1e-12)
    # NRMSE: |c| / range(y); the constant column has no range
    assert m.nrmse[0] == pytest.approx(0.1 / 2.0, rel=1e-6)
    assert np.isnan(m.nrmse[1])
    assert m.total_relative == pytest.approx(np.linalg.norm(np.broadcast_to(c, y.shape))
                                             / np.linalg.norm(y), rel=1e-12)


def test_scaled_prediction_has_relative_error_of_the_scale():
    rng = np.random.default_rng(1)
    y = rng.normal(size=(500, 3))
    m = error_metrics(y, 0.8 * y)
    np.testing.assert_allclose(m.relative, 0.2, rtol=1e-12)
    assert m.total_relative == pytest.approx(0.2, rel=1e-12)


def test_metrics_reject_bad_input_and_allow_a_missing_sensor():
    y = np.ones((10, 2))
    with pytest.raises(ValueError, match="must both be"):
        error_metrics(y, np.ones((10, 3)))
    bad = y.copy()
    bad[4, 1] = np.nan
    with pytest.raises(ValueError, match="measured is not finite at row 4, column 1"):
        error_metrics(bad, y)
    absent = y.copy()
    absent[:, 0] = np.nan
    m = error_metrics(absent, y + 1.0)
    assert np.isnan(m.rms[0]) and m.rms[1] == pytest.approx(1.0)
    assert m.total_relative == pytest.approx(1.0)


def test_noise_floor_and_spectrum_of_white_noise():
    rng = np.random.default_rng(2)
    n_samples, dt, sigma = 20000, 1e-3, 0.3
    noise = rng.normal(scale=sigma, size=(n_samples, 2))
    raw = 5.0 + noise
    floor = noise_floor(raw, np.full_like(raw, 5.0), cutoff=10.0)
    np.testing.assert_allclose(floor.rms, sigma, rtol=0.03)
    np.testing.assert_allclose(floor.relative, sigma / np.sqrt(25.0 + sigma**2), rtol=0.03)
    spec = residual_spectra(noise, noise, dt)
    # one-sided PSD of white noise: 2 sigma^2 dt
    inner = (spec.frequency > 5) & (spec.frequency < 490)
    np.testing.assert_allclose(spec.residual[inner].mean(axis=0), 2 * sigma**2 * dt, rtol=0.05)
    assert spec.frequency[-1] == pytest.approx(0.5 / dt)
