"""Zero-phase low-pass filtering and differentiation of sampled signals.

Two filters, both zero-phase so that a filtered velocity is not delayed against the position or
the torque it is fitted to:

- ``"butter"``: a Butterworth low-pass run forward and backward (``scipy.signal.sosfiltfilt``),
  so the effective order doubles and the phase is zero; derivatives by second-order central
  differences (``numpy.gradient``) of the filtered signal.
- ``"savgol"``: Savitzky-Golay local polynomial fits (``scipy.signal.savgol_filter``) whose
  window is chosen so that its -3 dB frequency matches the cut-off (Schafer 2011:
  ``f_c ~ (p + 1) / (3.2 L - 4.6) * f_s`` for polynomial order ``p`` and window length ``L``);
  the derivatives are those of the fitted polynomials.

Cut-off rule when none is given (:func:`bandwidth_cutoff`): the bandwidth of a column is the
highest frequency at which its power spectral density (Welch, Hann windows, linear trend
removed) stands 20 dB (x100) above its noise floor, taken as the median density over the upper
half of the band ``[f_s/4, f_s/2]``; the cut-off is that bandwidth, kept within
``[4 / T, 0.4 f_s]`` (T the duration). With several columns the largest cut-off among the
columns that move (variance at least 1e-4 of the largest column's) is used, so one filter serves
all joints and a joint held still (whose tiny noisy motion has no bandwidth to speak of) does not
set it. The same cut-off can be applied to torque or current (:func:`lowpass` with ``cutoff=``)
so that a fit of filtered torque on filtered motion is not biased by different filter gains.

Irregular time stamps are handled by resampling onto a uniform grid at the median period
(cubic interpolation), filtering there, and interpolating the results back onto the original
stamps.
"""

from __future__ import annotations

import numpy as np
from scipy import signal
from scipy.interpolate import make_interp_spline

from robodyn.measure.filtfilt_columns import filtfilt_columns
from robodyn.robot.errors import RecordingError

__all__ = ["CHUNK_BYTES", "METHODS", "bandwidth_cutoff", "differentiate", "is_uniform", "lowpass",
           "lowpass_columns"]

METHODS = ("butter", "savgol")
_UNIFORM_RTOL = 1e-3  # relative spread of the sample period still treated as uniform


def is_uniform(t: np.ndarray, rtol: float = _UNIFORM_RTOL) -> bool:
    """True when the steps of ``t`` (N,) differ from their median by at most ``rtol``."""
    dt = np.diff(np.asarray(t, dtype=float))
    med = np.median(dt)
    return bool(np.all(np.abs(dt - med) <= rtol * med))


def _check_stamps(t: np.ndarray, what: str) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise RecordingError(f"{what}: t must be a 1-D array of at least 2 times, got shape {t.shape}")
    if not np.all(np.diff(t) > 0):
        k = int(np.argmin(np.diff(t) > 0)) + 1
        raise RecordingError(f"{what}: t not strictly increasing at row {k}")
    return t


def _check_finite(x: np.ndarray, what: str, columns: np.ndarray | None = None) -> None:
    """Raise naming the first non-finite value of ``x`` (N,) or (N, c); ``columns`` (c,): the
    column numbers the message gives for the columns of ``x``."""
    if not np.all(np.isfinite(x)):
        row, *col = np.argwhere(~np.isfinite(x))[0]
        if col and columns is not None:
            col = [columns[col[0]]]
        where = f"row {row}" + (f", column {col[0]}" if col else "")
        raise RecordingError(f"{what}: non-finite value at {where}")


def _check(t: np.ndarray, x: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray]:
    t = _check_stamps(t, what)
    x = np.asarray(x, dtype=float)
    if x.ndim not in (1, 2) or x.shape[0] != t.size:
        raise RecordingError(f"{what}: x must have shape (N,) or (N, n) with N = {t.size} (len(t)), "
                             f"got {x.shape}")
    _check_finite(x, what)
    return t, x


def bandwidth_cutoff(t: np.ndarray, x: np.ndarray, snr: float = 100.0) -> float:
    """Cut-off frequency (Hz) for filtering and differentiating ``x`` (the module's rule).

    Parameters
    ----------
    t : (N,) ndarray
        Sample times, s (the median period sets the sampling rate).
    x : (N,) or (N, n) ndarray
        Signal(s); constant columns and columns with under 1e-4 of the largest variance are
        ignored.
    snr : float
        Power ratio above the noise floor that still counts as signal (100 = 20 dB).

    Returns
    -------
    float
        ``clip(f_b, 4 / T, 0.4 f_s)``, Hz, with ``f_b`` the largest bandwidth of the columns.
    """
    t, x = _check(t, x, "bandwidth_cutoff")
    fs = 1.0 / float(np.median(np.diff(t)))
    lo, hi = min(4.0 / float(t[-1] - t[0]), 0.4 * fs), 0.4 * fs
    cols = x.reshape(x.shape[0], -1)
    var = signal.detrend(cols, axis=0).var(axis=0)
    nper = int(min(cols.shape[0], max(256, 2 ** int(np.log2(max(cols.shape[0] // 4, 1))))))
    best = lo
    for k in np.nonzero(var >= 1e-4 * var.max())[0] if var.max() > 0 else ():
        # Welch power spectral density of the linearly detrended column
        f, p = signal.welch(cols[:, k], fs=fs, nperseg=nper, detrend="linear")
        floor = np.median(p[f >= fs / 4])
        # bandwidth: the highest frequency still snr above the noise floor
        above = np.nonzero(p > snr * floor)[0]
        if above.size:
            best = max(best, float(f[above[-1]]))
    return float(np.clip(best, lo, hi))


#: At most this many times the recorded samples on the uniform grid of the filter (gaps are
#: interpolated; a longer grid means a gap far longer than the run, or a corrupt stamp).
UNIFORM_GROWTH = 10.0


def _grid(t: np.ndarray) -> tuple[np.ndarray, bool]:
    """``(t_u, resampled)``: ``t`` itself when uniform, else a uniform grid at its median period."""
    if is_uniform(t):
        return t, False
    steps = np.diff(t)
    dt = float(np.median(steps))
    count = (t[-1] - t[0]) / dt + 1.0
    if count > UNIFORM_GROWTH * t.size + 1000:
        # a gap (or a corrupt stamp) that a uniform grid would fill with interpolated samples
        k = int(np.argmax(steps))
        raise RecordingError(f"t: a step of {steps[k]:.6g} s after row {k} (median period {dt:.6g} s) "
                             f"would need {count:.3g} samples on the uniform grid that filtering "
                             f"uses, for {t.size} samples recorded; check that time stamp, or split "
                             "the recording at the gap (Recording.slice)")
    return t[0] + dt * np.arange(int(np.floor((t[-1] - t[0]) / dt + 1e-9)) + 1), True


def _uniform(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    """``(t_u, x_u, resampled)``: x on a uniform grid at the median period (cubic)."""
    tu, resampled = _grid(t)
    return tu, (make_interp_spline(t, x, k=3, axis=0)(tu) if resampled else x), resampled


def _savgol_window(cutoff: float, fs: float, polyorder: int, n: int) -> int:
    # Schafer 2011: f_c = (p + 1) / (3.2 L - 4.6) * f_s  ->  L = ((p + 1) f_s / f_c + 4.6) / 3.2
    length = int(round(((polyorder + 1) * fs / cutoff + 4.6) / 3.2))
    length = max(length, polyorder + 2 + (polyorder % 2 == 0))
    length += 1 - length % 2  # odd
    if length > n:
        raise RecordingError(f"savgol: window of {length} samples for a {cutoff:g} Hz cut-off is "
                             f"longer than the signal ({n} samples)")
    return length


#: Bytes of the columns resampled onto the uniform grid at a time in :func:`lowpass_columns`
#: (irregular stamps).
CHUNK_BYTES = 2 << 20


def _block_columns(count: int, padlen: int) -> int:
    """Columns of ``count`` samples (padded by ``padlen`` at both ends) in one block."""
    return max(1, CHUNK_BYTES // (8 * (count + 2 * padlen)))


def _sosfiltfilt_columns(sos: np.ndarray, xu: np.ndarray, padlen: int) -> np.ndarray:
    """``sosfiltfilt`` along axis 0 of ``xu`` (N,) or (N, c): every column, by
    :func:`robodyn.measure.filtfilt_columns.filtfilt_columns` (the columns side by side)."""
    x2 = xu.reshape(xu.shape[0], -1)
    out = np.empty(x2.shape)
    filtfilt_columns(sos, padlen, x2, np.arange(x2.shape[1]), out)
    return out.reshape(xu.shape)


def _butter(cutoff: float, fs: float, order: int, count: int) -> tuple[np.ndarray, int]:
    """Second-order sections of the Butterworth low-pass and the padding of its zero-phase run
    over ``count`` samples at ``fs`` Hz."""
    if not 0.0 < cutoff < 0.5 * fs:
        raise RecordingError(f"cutoff: must be in (0, {0.5 * fs:g}) Hz (the Nyquist frequency), "
                             f"got {cutoff:g}")
    sos = signal.butter(order, cutoff, btype="low", fs=fs, output="sos")
    # odd extension over ~3 filter time constants keeps value and slope at the ends
    return sos, min(count - 1, int(3 * fs / cutoff) + 3 * (2 * sos.shape[0] + 1))


def _filter(tu: np.ndarray, xu: np.ndarray, cutoff: float, order: int, method: str,
            polyorder: int, derivs: int) -> list[np.ndarray]:
    """Filtered signal and its first ``derivs`` derivatives on the uniform grid."""
    dt = float(tu[1] - tu[0])
    fs = 1.0 / dt
    if method == "butter":
        sos, padlen = _butter(cutoff, fs, order, xu.shape[0])
        out = [_sosfiltfilt_columns(sos, xu, padlen)]
        for _ in range(derivs):
            out.append(np.gradient(out[-1], dt, axis=0, edge_order=2))  # central differences
        return out
    if method == "savgol":
        if not 0.0 < cutoff < 0.5 * fs:
            raise RecordingError(f"cutoff: must be in (0, {0.5 * fs:g}) Hz (the Nyquist "
                                 f"frequency), got {cutoff:g}")
        length = _savgol_window(cutoff, fs, polyorder, xu.shape[0])
        return [signal.savgol_filter(xu, length, polyorder, deriv=d, delta=dt, axis=0, mode="interp")
                for d in range(derivs + 1)]
    raise RecordingError(f"method: unknown filter {method!r} (expected one of {', '.join(METHODS)})")


def _run(t, x, cutoff, order, method, polyorder, derivs, what):
    t, x = _check(t, x, what)
    if x.shape[0] < 8:
        raise RecordingError(f"{what}: at least 8 samples are needed, got {x.shape[0]}")
    if cutoff is None:
        cutoff = bandwidth_cutoff(t, x)
    tu, xu, resampled = _uniform(t, x)
    outs = _filter(tu, xu, float(cutoff), order, method, polyorder, derivs)
    if resampled:
        outs = [make_interp_spline(tu, y, k=3, axis=0)(np.clip(t, tu[0], tu[-1])) for y in outs]
    return outs


def lowpass(t: np.ndarray, x: np.ndarray, cutoff: float | None = None, *, order: int = 4,
            method: str = "butter", polyorder: int = 3) -> np.ndarray:
    """Zero-phase low-pass filter.

    Parameters
    ----------
    t : (N,) ndarray
        Sample times, s, strictly increasing (irregular stamps are resampled, see module notes).
    x : (N,) or (N, n) ndarray
        Signal(s): positions, torques, currents, ...
    cutoff : float, optional
        -3 dB frequency of one pass, Hz; :func:`bandwidth_cutoff` of ``x`` when None. Pass the
        cut-off used for the positions to filter torque or current identically.
    order : int
        Butterworth order of one pass (forward-backward doubles it).
    method : {"butter", "savgol"}
    polyorder : int
        Savitzky-Golay polynomial order.

    Returns
    -------
    (N,) or (N, n) ndarray
        Filtered signal, same shape as ``x``; ``x`` is not modified.
    """
    return _run(t, x, cutoff, order, method, polyorder, 0, "lowpass")[0]


def differentiate(t: np.ndarray, x: np.ndarray, cutoff: float | None = None, *, order: int = 4,
                  method: str = "butter", polyorder: int = 3
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Zero-phase low-pass filter with first and second derivatives.

    Parameters
    ----------
    t : (N,) ndarray
        Sample times, s, strictly increasing.
    x : (N,) or (N, n) ndarray
        Signal(s), e.g. joint positions in rad.
    cutoff, order, method, polyorder
        As in :func:`lowpass`.

    Returns
    -------
    x_f, xd, xdd : (N,) or (N, n) ndarray
        Filtered signal, its first derivative (unit/s) and second derivative (unit/s^2).
    """
    x_f, xd, xdd = _run(t, x, cutoff, order, method, polyorder, 2, "differentiate")
    return x_f, xd, xdd


def lowpass_columns(t: np.ndarray, x: np.ndarray, cutoff: float, columns: np.ndarray,
                    out: np.ndarray, *, order: int = 4, keep: int = 1) -> np.ndarray:
    """Zero-phase Butterworth low-pass of some columns of a wide matrix, into a destination.

    The columns are filtered a block at a time (:data:`CHUNK_BYTES`); the stamps are checked,
    the filter designed and (for irregular stamps) the uniform grid built once for all blocks.
    Each column gets the bits of :func:`lowpass` on that column.

    Parameters
    ----------
    t : (N,) ndarray
        Sample times, s, strictly increasing (irregular stamps: see the module notes).
    x : (N, c) ndarray
        Signals (a regressor's columns, say); not modified.
    cutoff : float
        -3 dB frequency of one pass, Hz.
    columns : (k,) ndarray of int
        The columns of ``x`` to filter.
    out : (ceil(N / keep), c) ndarray
        Destination: its ``columns`` receive every ``keep``-th filtered sample; its other columns
        are left as they are.
    order : int
        Butterworth order of one pass (forward-backward doubles it).
    keep : int
        Keep every ``keep``-th filtered sample (1: all).

    Returns
    -------
    (ceil(N / keep), c) ndarray
        ``out``.
    """
    what = "lowpass_columns"
    t = _check_stamps(t, what)
    if x.ndim != 2 or x.shape[0] != t.size:
        raise RecordingError(f"{what}: x must have shape (N, c) with N = {t.size} (len(t)), got {x.shape}")
    rows = -(-t.size // keep)
    if out.shape != (rows, x.shape[1]):
        raise RecordingError(f"{what}: out must have shape {(rows, x.shape[1])}, got {out.shape}")
    columns = np.asarray(columns, dtype=np.intp)
    if t.size < 8:
        raise RecordingError(f"{what}: at least 8 samples are needed, got {t.size}")
    tu, resampled = _grid(t)
    sos, padlen = _butter(float(cutoff), 1.0 / float(tu[1] - tu[0]), order, tu.size)
    if not resampled:
        filtfilt_columns(sos, padlen, x, columns, out, keep)
        # a non-finite input spreads through its column's recursion (both passes)
        bad = np.flatnonzero(~np.isfinite(out[:, columns]).all(axis=0))
        if bad.size:
            _check_finite(x[:, columns[bad]], what, columns[bad])
        return out
    step = _block_columns(tu.size, padlen)
    for a in range(0, columns.size, step):
        cols = columns[a:a + step]
        block = x[:, cols]
        _check_finite(block, what, cols)
        # cubic onto the uniform grid, filtered there, cubic back onto the stamps
        filtered = _sosfiltfilt_columns(sos, make_interp_spline(t, block, k=3, axis=0)(tu), padlen)
        out[:, cols] = make_interp_spline(tu, filtered, k=3, axis=0)(np.clip(t, tu[0], tu[-1]))[::keep]
    return out
