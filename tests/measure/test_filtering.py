"""Filtering and differentiation against analytic signals (sums of sines inside the passband)."""

import numpy as np
import pytest

from robodyn.measure.filtering import bandwidth_cutoff, differentiate, lowpass
from robodyn.robot.errors import RecordingError

F = np.array([0.5, 1.5, 2.0])  # Hz
A = np.array([0.5, 0.2, 0.3])  # rad
PH = np.array([0.0, 1.0, 2.0])


def _sines(t):
    w = 2 * np.pi * F
    arg = np.outer(t, w) + PH
    q = (A * np.sin(arg)).sum(axis=1)
    qd = (A * w * np.cos(arg)).sum(axis=1)
    qdd = (-A * w**2 * np.sin(arg)).sum(axis=1)
    return q, qd, qdd


def _rel(a, b, inner=slice(None)):
    return np.abs(a - b)[inner].max() / np.abs(b).max()


@pytest.mark.parametrize("method", ["butter", "savgol"])
def test_clean_sines_velocity_and_acceleration(method):
    t = np.arange(0.0, 4.0, 1e-3)
    q, qd, qdd = _sines(t)
    qf, v, a = differentiate(t, q, method=method)
    inner = slice(200, -200)  # 0.2 s from either end: filter edge transients excluded
    # measured: butter 2.6e-5 / 5.3e-5, savgol 1.7e-8 / 2.2e-4 (relative to the peak)
    assert _rel(qf, q) < 2e-5  # measured: butter 1.2e-5 (at the ends), savgol 3e-8
    assert _rel(v, qd, inner) < 1e-4
    assert _rel(a, qdd, inner) < 1e-3
    # whole record, ends included (the Butterworth's odd-extension edge transient shows there):
    # measured butter 3.0e-3, savgol 5.7e-7
    assert _rel(v, qd) < {"butter": 5e-3, "savgol": 1e-5}[method]


@pytest.mark.parametrize("method", ["butter", "savgol"])
def test_noisy_sines_bandwidth_cutoff(method):
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 4.0, 1e-3)
    q, qd, qdd = _sines(t)
    qn = q + 1e-4 * rng.standard_normal(t.size)
    cut = bandwidth_cutoff(t, qn)
    assert 2.0 < cut < 60.0  # above the 2 Hz content, far below Nyquist (500 Hz)
    _, v, a = differentiate(t, qn, method=method)
    inner = slice(200, -200)
    naive = np.gradient(qn, t)
    # the noise alone in a naive central difference is ~0.1 rad/s; filtered: below 0.2 % of peak
    assert _rel(v, qd, inner) < 2e-3
    assert _rel(naive, qd, inner) > 10 * _rel(v, qd, inner)
    assert _rel(a, qdd, inner) < 2e-2


def test_irregular_stamps_are_resampled_and_back():
    rng = np.random.default_rng(2)
    t = np.cumsum(1e-3 * (1 + 0.2 * rng.uniform(-1, 1, 4000)))
    q, qd, _ = _sines(t)
    qf, v, _ = differentiate(t, q)
    assert qf.shape == q.shape
    assert _rel(v, qd, slice(200, -200)) < 1e-3


def test_lowpass_same_cutoff_on_two_signals_and_columns():
    t = np.arange(0.0, 3.0, 1e-3)
    x = np.c_[np.sin(2 * np.pi * 1 * t), np.sin(2 * np.pi * 100 * t)]
    y = lowpass(t, x, cutoff=10.0)
    assert y.shape == x.shape
    assert _rel(y[:, 0], x[:, 0], slice(100, -100)) < 1e-5  # measured 2.3e-6
    # 100 Hz through 8th-order (4 forward + 4 backward) at 10 Hz: |H| = 1e-8 in steady state;
    # the odd extension keeps each end value, whose transient has decayed 1 s from the ends
    assert np.abs(y[1000:-1000, 1]).max() < 1e-7  # measured 7.3e-9


def test_input_is_not_modified():
    t = np.arange(0.0, 1.0, 1e-3)
    x = np.sin(t)
    x.flags.writeable = False
    lowpass(t, x)


def test_errors():
    t = np.arange(0.0, 1.0, 1e-3)
    with pytest.raises(RecordingError, match="cutoff: must be in"):
        lowpass(t, np.sin(t), cutoff=600.0)
    with pytest.raises(RecordingError, match="unknown filter 'kalman'"):
        lowpass(t, np.sin(t), method="kalman")
    bad = np.sin(t)
    bad[7] = np.nan
    with pytest.raises(RecordingError, match="non-finite value at row 7"):
        lowpass(t, bad)


def test_wide_matrix_is_filtered_as_sosfiltfilt_and_each_column_as_alone():
    """A wide matrix (a regressor's hundreds of columns, filtered side by side by the compiled
    kernel) gives SciPy's ``sosfiltfilt`` over the whole matrix to rounding
    (tests/measure/test_filtfilt_columns.py), and each column the bits of its own call."""
    from scipy import signal

    from robodyn.measure.filtfilt_columns import COLUMN_BLOCK

    count, cutoff, fs = 4000, 7.0, 1000.0
    t = np.arange(count) / fs
    cols = 3 * COLUMN_BLOCK + 5  # three blocks and a part
    x = np.random.default_rng(3).standard_normal((count, cols))
    sos = signal.butter(4, cutoff, fs=fs, output="sos")
    pad = min(count - 1, int(3 * fs / cutoff) + 3 * (2 * sos.shape[0] + 1))
    whole = signal.sosfiltfilt(sos, x, axis=0, padlen=pad)
    got = lowpass(t, x, cutoff)
    assert np.abs(got - whole).max() <= 1e-12 * np.abs(x).max()
    np.testing.assert_array_equal(lowpass(t, x[:, cols - 1], cutoff), got[:, -1])


@pytest.mark.parametrize("stamps", ["uniform", "irregular"])
def test_lowpass_columns_gives_each_column_the_bits_of_lowpass(stamps):
    """Chosen columns of a matrix wider than one block, filtered into a destination, every third
    sample kept: each equals ``lowpass`` of that column alone; the other columns of the
    destination and the input are untouched."""
    from robodyn.measure.filtering import CHUNK_BYTES, lowpass_columns

    rng = np.random.default_rng(4)
    count, cutoff = 3000, 9.0
    step = 1e-3 * (1 + 0.2 * rng.uniform(-1, 1, count)) if stamps == "irregular" else np.full(count, 1e-3)
    t = np.cumsum(step)
    cols = 2 * CHUNK_BYTES // (8 * count) + 9  # more than two blocks
    x = rng.standard_normal((count, cols))
    x.flags.writeable = False
    chosen = np.arange(1, cols, 2)
    out = np.full((-(-count // 3), cols), 7.0)
    got = lowpass_columns(t, x, cutoff, chosen, out, keep=3)
    assert got is out
    for j in (chosen[0], chosen[len(chosen) // 2], chosen[-1]):
        np.testing.assert_array_equal(out[:, j], lowpass(t, x[:, j], cutoff)[::3])
    assert np.all(out[:, ::2] == 7.0)  # the columns not chosen are left as they are


def test_lowpass_columns_errors_name_the_column_and_shape():
    from robodyn.measure.filtering import lowpass_columns

    t = np.arange(0.0, 1.0, 1e-3)
    x = np.zeros((t.size, 4))
    x[5, 2] = np.inf
    with pytest.raises(RecordingError, match="non-finite value at row 5, column 2"):
        lowpass_columns(t, x, 10.0, np.array([0, 2]), np.zeros_like(x))
    with pytest.raises(RecordingError, match=r"out must have shape \(500, 4\)"):
        lowpass_columns(t, x, 10.0, np.array([0]), np.zeros_like(x), keep=2)
    with pytest.raises(RecordingError, match="cutoff: must be in"):
        lowpass_columns(t, x, 600.0, np.array([0]), np.zeros_like(x))
