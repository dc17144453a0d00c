"""The compiled zero-phase filter of many columns against SciPy's ``sosfiltfilt``."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from robodyn.measure import filtfilt_columns as ffc
from robodyn.measure.filtfilt_columns import COLUMN_BLOCK, filtfilt_columns

#: The kernel and SciPy run the same recursion; they differ only where the compiler fuses a
#: multiply and an add (one rounding instead of two). Measured: at most 4e-14 of the signal's
#: scale on the cases below (cut-offs of at least 1/200 of the rate); the bound leaves 25x for
#: other processors and compilers. Lower cut-offs lose more digits in either (see
#: test_as_accurate_as_sosfiltfilt).
RTOL = 1e-12


def _reference(sos: np.ndarray, x: np.ndarray, pad: int) -> np.ndarray:
    """sosfiltfilt of one column in extended precision (``np.longdouble``), the same recursion
    with the same double coefficients, odd extension and initial-state factors."""
    from scipy.signal._arraytools import odd_ext

    ld = np.longdouble
    sections = [[ld(v) for v in row] for row in sos]
    zi = signal.sosfilt_zi(sos)

    def run(seq):
        z = [[ld(zi[k][0]) * seq[0], ld(zi[k][1]) * seq[0]] for k in range(len(sections))]
        out = []
        for v in seq:
            for k, (b0, b1, b2, _, a1, a2) in enumerate(sections):
                y = b0 * v + z[k][0]
                z[k][0] = b1 * v - a1 * y + z[k][1]
                z[k][1] = b2 * v - a2 * y
                v = y
            out.append(v)
        return out

    ext = [ld(v) for v in (odd_ext(x, pad) if pad else x)]
    y = run(run(ext)[::-1])[::-1]
    return np.array(y[pad:pad + x.size], dtype=np.longdouble)


@pytest.mark.parametrize(("count", "fs", "cutoff"), [(20000, 4000.0, 2.0), (3000, 1000.0, 5.0)])
def test_as_accurate_as_sosfiltfilt(count, fs, cutoff):
    """Against the recursion in extended precision: the kernel's error is within 2x SciPy's
    (a cut-off at 1/2000 of the rate loses about 1e-12 of the scale in both); a constant stays
    as close to itself as SciPy keeps it."""
    rng = np.random.default_rng(5)
    sos = signal.butter(4, cutoff, fs=fs, output="sos")
    pad = min(count - 1, int(3 * fs / cutoff) + 3 * (2 * sos.shape[0] + 1))
    for x in (rng.standard_normal(count).cumsum() + 5.0, np.full(count, 2.5)):
        ref = _reference(sos, x, pad)
        got = filtfilt_columns(sos, pad, x[:, None], np.array([0]), np.empty((count, 1)))[:, 0]
        scipy_error = float(np.abs(signal.sosfiltfilt(sos, x, padlen=pad) - ref).max())
        scale = float(np.abs(x).max())
        assert float(np.abs(got - ref).max()) <= 2 * scipy_error + 1e-15 * scale


@pytest.mark.parametrize(("count", "fs", "cutoff", "order"),
                         [(3000, 1000.0, 5.0, 4), (400, 94.0, 10.0, 2), (5000, 1000.0, 150.0, 6),
                          (9, 100.0, 20.0, 4)])
def test_equals_sosfiltfilt(count, fs, cutoff, order):
    """Chosen columns (more than one block, in no particular order) of a matrix with an offset,
    every third sample kept: SciPy's result on each column, to rounding; the destination's other
    columns and the input are untouched."""
    rng = np.random.default_rng(count)
    cols = 2 * COLUMN_BLOCK + 5
    x = rng.standard_normal((count, cols)).cumsum(axis=0) + 5.0
    x.flags.writeable = False
    sos = signal.butter(order, cutoff, fs=fs, output="sos")
    pad = min(count - 1, int(3 * fs / cutoff) + 3 * (2 * sos.shape[0] + 1))
    chosen = rng.permutation(cols)[: cols - 7]
    out = np.full((-(-count // 3), cols), 7.0)
    assert filtfilt_columns(sos, pad, x, chosen, out, keep=3) is out
    want = signal.sosfiltfilt(sos, x[:, chosen], axis=0, padlen=pad)[::3]
    scale = np.abs(x).max()
    assert np.abs(out[:, chosen] - want).max() <= RTOL * scale
    rest = np.setdiff1d(np.arange(cols), chosen)
    assert np.all(out[:, rest] == 7.0)


def test_a_column_gets_the_same_bits_in_any_company():
    """Each column's recursion is its own: filtered alone, in a block, at another position of the
    block, or from a strided view, it gets the same bits (what lets rd.identify filter a few
    regressor columns again and splice them in)."""
    rng = np.random.default_rng(1)
    count, cols = 2000, COLUMN_BLOCK + 11
    x = rng.standard_normal((count, cols))
    sos = signal.butter(4, 8.0, fs=1000.0, output="sos")
    whole = filtfilt_columns(sos, 400, x, np.arange(cols), np.empty((count, cols)))
    for j in (0, 5, COLUMN_BLOCK, cols - 1):
        alone = filtfilt_columns(sos, 400, x, np.array([j]), np.zeros((count, cols)))
        np.testing.assert_array_equal(alone[:, j], whole[:, j])
    view = x[:, 3:]  # row stride of x, first element elsewhere
    part = filtfilt_columns(sos, 400, view, np.arange(cols - 3), np.empty((count, cols - 3)))
    np.testing.assert_array_equal(part, whole[:, 3:])


def test_the_compiled_kernel_is_built():
    """With the C compiler the suite needs anyway, the kernel (not the fallback) is what runs."""
    assert ffc._library() is not None


def test_without_a_compiler_sosfiltfilt_itself(monkeypatch):
    """No C compiler and no library built before: SciPy's ``sosfiltfilt``, the same bits."""
    monkeypatch.setattr(ffc, "_library", lambda: None)
    rng = np.random.default_rng(2)
    x = rng.standard_normal((500, 40))
    sos = signal.butter(4, 20.0, fs=1000.0, output="sos")
    out = filtfilt_columns(sos, 100, x, np.arange(0, 40, 3), np.zeros((250, 40)), keep=2)
    want = signal.sosfiltfilt(sos, x[:, ::3], axis=0, padlen=100)[::2]
    np.testing.assert_array_equal(out[:, ::3], want)


def test_zero_columns_stay_zero():
    """A structural zero of a regressor stays exactly zero (nothing to filter)."""
    count = 1000
    x = np.zeros((count, 2))
    x[:, 1] = np.sin(np.arange(count) * 0.01)
    sos = signal.butter(4, 5.0, fs=1000.0, output="sos")
    out = filtfilt_columns(sos, 600, x, np.arange(2), np.empty((count, 2)))
    assert np.all(out[:, 0] == 0.0)
    assert np.abs(out[:, 1]).max() > 0.5
