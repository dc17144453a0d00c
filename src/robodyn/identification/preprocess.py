"""From a raw recording to the samples an identification fits: filter, differentiate, decimate.

One rule, used by :func:`robodyn.identification` and again by :meth:`Identification.predict`, so that a
prediction processes a new recording exactly as the fit processed its data:

* positions ``q`` are low-passed with a zero-phase Butterworth filter (order 4 per pass, run
  forward and backward: :func:`robodyn.measure.filtering.differentiate`), and ``qd``, ``qdd`` are
  the derivatives of the filtered positions (measured velocities are used, filtered the same
  way, only with ``velocity="measured"``; their spikes make position differences the safer
  default); a joint whose position spans less than 1 mrad (1 mm) is held still: its ``qd`` and
  ``qdd`` are exactly zero;
* the target (torque or current) is low-passed with the SAME filter, so that the fit of a
  filtered target on filtered motion is not biased by different filter gains;
* for fitting only, the filtered samples are then decimated by an integer factor (keeping every
  ``decimate``-th sample), which thins the strongly correlated neighbouring rows the filter
  leaves; :meth:`Identification.predict` returns every sample.

The regressor rows of a prediction (:func:`prediction_rows`) are the compiled regressor of the
processed states with its Coulomb columns set to zero wherever ``|qd_j|`` is below the dead band
(``dead_band``, 0 or ``DEAD_BAND`` = 1e-3 rad/s chosen from the data: a joint at rest, or
creeping within its velocity noise, carries no Coulomb step and only the friction offset ``Fo``,
a base parameter of its own, :mod:`robodyn.identification.base`); the fit's rows
(:func:`regressor_rows`) are the same rows low-passed column by column with the target's filter
(parallel filtering), so that the fit of the filtered target estimates the parameters of the
unfiltered model ``Y p`` that ``predict`` returns: the Coulomb sign is handled the same way in
both.

A logged angle that jumps by nearly a whole turn between two samples (a continuous joint
reported within ``[-pi, pi)`` or ``[0, 2 pi)``) is unwrapped first: no arm
turns half a revolution between two samples, and filtered and differentiated such a step would
be a burst of velocity; the regressor's sines and cosines do not change
(:func:`robodyn.measure.angles.unwrap_turns`).

``cutoff=None`` turns all filtering off: the recording's own ``qd`` and ``qdd`` (measured or
estimated when the recording was built) and its raw target are used (simulated data).

Default cut-off (``cutoff="auto"``): the largest bandwidth of the moving joints' positions
(:func:`robodyn.measure.filtering.bandwidth_cutoff`) over the recordings, clamped to
``[AUTO_MIN_HZ, AUTO_MAX_HZ]`` = [2, 5] Hz and to 0.2 x the sampling rate: manipulator motion
(and with it the rigid-body torque) lives below a few hertz, while the second derivative of
encoder noise grows with the square of frequency. Default decimation (``decimate="auto"``): the
largest integer not above ``fs / (5 cutoff)``, i.e. about five samples per cut-off period.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from robodyn.identification.stacking import regressor_rows_of
from robodyn.measure.angles import unwrap_turns
from robodyn.measure.filtering import bandwidth_cutoff, differentiate, lowpass, lowpass_columns
from robodyn.robot.errors import IdentificationError
from robodyn.symbolic.regressor import PER_JOINT, joint_columns

__all__ = ["AUTO_MAX_HZ", "AUTO_MIN_HZ", "DEAD_BAND", "MID_RATE", "MOVING_RAD", "Preprocess",
           "Samples", "SharedRows", "UnbandedRows", "auto_cutoff", "banded_rows",
           "coulomb_dead_band", "coulomb_smoothing", "evaluation_step", "filtered_rows",
           "prediction_rows", "preprocess", "regressor_rows", "resolve_preprocess",
           "slowest_rate", "unbanded_rows"]

AUTO_MIN_HZ = 2.0
AUTO_MAX_HZ = 5.0
#: A joint whose position spans less than this never moves (rad or m).
MOVING_RAD = 1e-3
#: Coulomb dead band, rad/s (m/s): below it a joint's Coulomb columns are zero.
DEAD_BAND = 1e-3
#: Samples per cut-off period kept for the parallel filtering of the regressor.
MID_RATE = 100
#: Most bytes of regressor rows held at once before filtering (:func:`unbanded_rows`): longer
#: logs are evaluated a group of columns at a time (each column is filtered on its own, so the
#: rows are the same bits), and the groups' regressor a block of samples at a time.
ROWS_BYTES = 2**30


@dataclass(frozen=True)
class Preprocess:
    """The frozen preprocessing settings of an identification.

    Attributes
    ----------
    cutoff : float or None
        -3 dB frequency of one pass of the zero-phase Butterworth filter, Hz; None: no filtering.
    order : int
        Butterworth order of one pass.
    decimate : int
        Keep every ``decimate``-th filtered sample for fitting (1: all).
    velocity : {"position", "measured"}
        Whether ``qd`` is the derivative of the filtered positions or the filtered measured one.
    dead_band : float
        Coulomb dead band, rad/s (m/s); 0: the sign of ``qd`` everywhere.
    """

    cutoff: float | None
    order: int = 4
    decimate: int = 1
    velocity: Literal["position", "measured"] = "position"
    dead_band: float = DEAD_BAND


@dataclass(frozen=True, eq=False)
class Samples:
    """Processed samples of one recording, all (N, n) at the recording's own times.

    Attributes
    ----------
    t : numpy.ndarray, shape (N,)
    q, qd, qdd : numpy.ndarray, shape (N, n)
        rad, rad/s, rad/s^2 (m for prismatic joints).
    y : numpy.ndarray or None, shape (N, n)
        The (filtered) target: N m (N) or A; None when the recording has no such signal.
    source : str
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    y: np.ndarray | None
    source: str


def _source(rec: Any) -> str:
    return str(getattr(rec, "source", "") or "Recording")


def target_signal(rec: Any, target: str) -> np.ndarray | None:
    """The recording's raw target (N, n) (``tau`` or ``current``), or None when absent."""
    return getattr(rec, target, None)


def slowest_rate(recordings: Sequence[Any]) -> float:
    """The sampling rate of the slowest recording, Hz (from its median stamp step)."""
    return min(1.0 / float(np.median(np.diff(np.asarray(r.t, float)))) for r in recordings)


def auto_cutoff(recordings: Sequence[Any]) -> float:
    """The cut-off of ``cutoff="auto"`` for these recordings, Hz (the module docstring's rule)."""
    bands = []
    for r in recordings:
        q = unwrap_turns(r.q)
        moving = np.ptp(q, axis=0) > MOVING_RAD
        if np.any(moving) and q.shape[0] >= 16:
            bands.append(bandwidth_cutoff(np.asarray(r.t, float), q[:, moving]))
    band = max(bands) if bands else AUTO_MIN_HZ
    return min(float(np.clip(band, AUTO_MIN_HZ, AUTO_MAX_HZ)), 0.2 * slowest_rate(recordings))


def resolve_preprocess(recordings: list[Any], cutoff: float | str | None, decimate: int | str,
                       velocity: str = "position", order: int = 4,
                       dead_band: float = DEAD_BAND, auto: float | None = None) -> Preprocess:
    """Settings for these recordings: the ``"auto"`` rules of the module docstring resolved
    (``auto``: :func:`auto_cutoff` of the recordings when already computed, Hz)."""
    if velocity not in ("position", "measured"):
        raise IdentificationError(f"velocity: expected 'position' or 'measured', got {velocity!r}")
    if not (isinstance(dead_band, (int, float)) and np.isfinite(dead_band) and 0 <= dead_band < 1e3):
        raise IdentificationError(f"dead_band: expected a velocity in [0, 1000) rad/s, got {dead_band!r}")
    fs = slowest_rate(recordings)
    if isinstance(cutoff, str):
        if cutoff != "auto":
            raise IdentificationError(f"cutoff: expected a frequency in Hz, None or 'auto', got {cutoff!r}")
        cut = auto_cutoff(recordings) if auto is None else float(auto)
    elif cutoff is None:
        cut = None
    else:
        cut = float(cutoff)
        if not 0.0 < cut < 0.5 * fs:
            raise IdentificationError(f"cutoff: must lie in (0, {0.5 * fs:g}) Hz (the Nyquist "
                                      f"frequency of the slowest recording), got {cut:g}")
    if isinstance(decimate, str):
        if decimate != "auto":
            raise IdentificationError(f"decimate: expected a positive integer or 'auto', got {decimate!r}")
        dec = 1 if cut is None else max(1, int(np.floor(fs / (5.0 * cut))))
        if cut is not None:
            # a multiple of the step at which regressor_rows evaluates and filters the regressor
            step = max(1, int(fs / (MID_RATE * cut)))
            dec = max(dec // step * step, 1)
    else:
        dec = int(decimate)
        if dec < 1 or dec != decimate:
            raise IdentificationError(f"decimate: expected a positive integer, got {decimate!r}")
    return Preprocess(cutoff=cut, order=order, decimate=dec, velocity=velocity,  # type: ignore[arg-type]
                      dead_band=float(dead_band))


def preprocess(rec: Any, settings: Preprocess, target: str | None) -> Samples:
    """Process one recording (not decimated; see the module docstring).

    Parameters
    ----------
    rec : Recording
        Raw recording: ``t`` (N,) s, ``q`` (N, n), optional ``qd``/``qdd``/``tau``/``current``.
    settings : Preprocess
    target : {"tau", "current"} or None
        Which signal to filter as the target (None: none).

    Returns
    -------
    Samples
    """
    t = np.asarray(rec.t, dtype=float)
    q = unwrap_turns(rec.q)
    raw_y = target_signal(rec, target) if target is not None else None
    y = None if raw_y is None else np.asarray(raw_y, dtype=float)
    if settings.cutoff is None:
        if rec.qd is None or rec.qdd is None:
            raise IdentificationError(f"{_source(rec)}: qd/qdd: cutoff=None uses the recording's own "
                                      f"velocities and accelerations, but it has none")
        return Samples(t, q, np.asarray(rec.qd, float), np.asarray(rec.qdd, float), y, _source(rec))
    cut, order = settings.cutoff, settings.order
    # q_f = H q (zero-phase low-pass), qd = d q_f / dt, qdd = d^2 q_f / dt^2
    q_f, qd, qdd = differentiate(t, q, cut, order=order)
    estimated = getattr(rec, "estimated", frozenset())
    if settings.velocity == "measured" and rec.qd is not None and "qd" not in estimated:
        # qd = H qd_measured, qdd = d qd / dt
        qd_f, qdd, _ = differentiate(t, np.asarray(rec.qd, float), cut, order=order)
        qd = qd_f
    held = np.ptp(q, axis=0) < MOVING_RAD
    qd[:, held] = 0.0  # a joint held still: its filtered encoder noise is no motion
    qdd[:, held] = 0.0
    y_f = None if y is None else lowpass(t, y, cut, order=order)  # the same H on the target
    return Samples(t, q_f, qd, qdd, y_f, _source(rec))


def coulomb_dead_band(y: np.ndarray, qd: np.ndarray, band: float) -> np.ndarray:
    """The regressor ``y`` (N, n, 15 n) with joint j's Coulomb columns (``Fcp``, ``Fcn``) zero
    wherever ``|qd_j| < band`` (``qd`` (N, n), rad/s); ``y`` is changed in place and returned."""
    if band <= 0:
        return y
    for j in range(qd.shape[1]):
        still = np.abs(qd[:, j]) < band
        if np.any(still):
            y[still, j, joint_columns(j, "Fcp", "Fcn")] = 0.0
    return y


def coulomb_smoothing(y: np.ndarray, qd: np.ndarray, width: float | np.ndarray) -> np.ndarray:
    """The regressor ``y`` (N, n, 15 n) with joint j's Coulomb steps smoothed over ``w_j``.

    Where a joint moves (its Coulomb columns ``H(qd)``, ``-H(-qd)`` not both zero: ``qd != 0``
    and outside the dead band) they become ``(1 + s) / 2`` and ``-(1 - s) / 2`` with
    ``s = tanh(qd / w)``: the probabilities that the velocity is positive or negative when its
    estimate is ``qd`` (:mod:`robodyn.identification.coulomb_width`), so that the Coulomb torque
    passes through the mean of its two levels at ``qd = 0``; a joint at rest keeps the offset
    alone. ``qd`` (N, n), rad/s; ``width`` rad/s: one for all joints, (n,), or (N, n) per
    sample; 0: the step. ``y`` is changed in place and returned."""
    widths = np.broadcast_to(np.asarray(width, float), qd.shape)
    for j in np.flatnonzero(np.any(widths > 0, axis=0)):
        cols = joint_columns(j, "Fcp", "Fcn")
        moving = y[:, j, cols.start] - y[:, j, cols.start + 1]  # 1 where moving, else 0
        w = widths[:, j]
        s = np.where(w > 0, np.tanh(qd[:, j] / np.where(w > 0, w, 1.0)), np.sign(qd[:, j]))
        # H(qd) -> (1 + s) / 2, -H(-qd) -> -(1 - s) / 2: the expected step given the estimate
        y[:, j, cols.start] = moving * 0.5 * (1.0 + s)
        y[:, j, cols.start + 1] = -moving * 0.5 * (1.0 - s)
    return y


def prediction_rows(model: Any, s: Samples, settings: Preprocess, out: np.ndarray | None = None,
                    coulomb_width: float | np.ndarray = 0.0) -> np.ndarray:
    """Regressor (N, n, 15 n) of processed samples for a prediction: the compiled regressor of
    ``model`` at ``(s.q, s.qd, s.qdd)`` with the Coulomb dead band (:func:`coulomb_dead_band`)
    and the Coulomb steps smoothed over ``coulomb_width`` rad/s (scalar, (n,) or (N, n),
    :func:`coulomb_smoothing`);
    written into ``out`` (N, n, 15 n), C-contiguous, when given."""
    y = regressor_rows_of(model, s.q, s.qd, s.qdd, out=out)
    return coulomb_smoothing(coulomb_dead_band(y, s.qd, settings.dead_band), s.qd, coulomb_width)


def regressor_rows(model: Any, s: Samples, settings: Preprocess, decimate: bool = True) -> np.ndarray:
    """Full regressor (N / decimate, n, 15 n) of processed samples for a fit or a prediction.

    The compiled regressor of ``model`` at ``(s.q, s.qd, s.qdd)`` with the Coulomb dead band
    (:func:`coulomb_dead_band`), low-passed column by column with the target's filter before
    decimation (parallel filtering, Gautier 1997): the filter is linear, so ``H(Y p) = H(Y) p``
    holds exactly, and the fit of the filtered target is not biased by terms the filter smooths
    (Coulomb steps at velocity reversals). ``decimate=False``: every sample (a prediction).

    To bound memory and time on long fast logs, ``Y`` is evaluated and filtered on every
    ``m``-th sample, ``m`` the largest divisor of the decimation factor with at least
    ``MID_RATE`` samples per cut-off period left (the filtered states are smooth there; only the
    timing of a Coulomb step moves, by less than ``1 / (MID_RATE cutoff)``).

    The rows are built without the dead band (:func:`unbanded_rows`), then the band is applied
    to the Coulomb columns alone (:func:`banded_rows`): each column is filtered on its own, so
    the result is the filtered rows of the banded regressor, and settings that differ only in
    the band can share the first step.
    """
    return banded_rows(unbanded_rows(model, s, settings, decimate), settings)


@dataclass(frozen=True, eq=False)
class UnbandedRows:
    """A recording's fit rows without the Coulomb dead band, and what a dead band changes.

    Attributes
    ----------
    rows : numpy.ndarray, shape (N / decimate, n, 15 n)
        :func:`regressor_rows` of the samples with no dead band.
    t : numpy.ndarray, shape (M,)
        Times of the samples the regressor was evaluated at (every ``m``-th, see
        :func:`evaluation_step`), s.
    qd : numpy.ndarray, shape (M, n)
        Velocities at those samples, rad/s (m/s).
    coulomb : numpy.ndarray, shape (M, n, 2)
        Joint j's unfiltered Coulomb columns (``Fcp``, ``Fcn``) of its own row, at those samples.
    keep : int
        ``rows`` keeps every ``keep``-th of the M samples after filtering.
    """

    rows: np.ndarray
    t: np.ndarray
    qd: np.ndarray
    coulomb: np.ndarray
    keep: int


def unbanded_rows(model: Any, s: Samples, settings: Preprocess, decimate: bool = True,
                  scratch: Any = None) -> UnbandedRows:
    """:func:`regressor_rows` of samples ``s`` without the dead band (``settings.dead_band`` is
    not used), with the Coulomb columns :func:`banded_rows` needs; at most about
    :data:`ROWS_BYTES` of unfiltered rows held at once. ``scratch(size)``, optional: a flat
    float64 buffer of at least ``size`` elements for the unfiltered rows (reused by the caller
    across calls: fresh memory of this size costs more to first touch than to compute)."""
    d = settings.decimate if decimate else 1
    m = evaluation_step(s.t, settings, d)
    t, q, qd, qdd = s.t[::m], s.q[::m], s.qd[::m], s.qdd[::m]
    count, n = q.shape
    width = PER_JOINT * n  # the regressor's columns (regressor_rows_of)
    coulomb_cols = [joint_columns(j, "Fcp", "Fcn") for j in range(n)]
    groups = -(-count * n * width * 8 // ROWS_BYTES)
    if groups <= 1:
        buf = None if scratch is None else scratch(count * n * width)[:count * n * width]
        y = regressor_rows_of(model, q, qd, qdd,
                              out=None if buf is None else buf.reshape(count, n, width))
        coulomb = np.stack([y[:, j, coulomb_cols[j]] for j in range(n)], axis=1)
        rows = filtered_rows(t, y, settings, d // m)
        if buf is not None and np.shares_memory(rows, buf):  # unfiltered: a view of the scratch
            rows = rows.copy()
        return UnbandedRows(rows, t, qd, coulomb, d // m)
    rows = np.empty((-(-count // (d // m)), n, width))
    coulomb = np.empty((count, n, 2))
    block = max(1, ROWS_BYTES // (4 * 8 * n * width))  # samples of regressor evaluated at once
    buf = np.empty((min(block, count), n, width))
    for g, cols in enumerate(np.array_split(np.arange(width), groups)):
        cols = slice(int(cols[0]), int(cols[-1]) + 1)  # contiguous: a plain copy
        part = np.empty((count, n, cols.stop - cols.start))
        for a in range(0, count, block):
            b = min(a + block, count)
            # Y of samples a..b into the reused buffer; this group's columns kept
            y = regressor_rows_of(model, q[a:b], qd[a:b], qdd[a:b], out=buf[:b - a])
            part[a:b] = y[:, :, cols]
            if g == 0:
                for j in range(n):
                    coulomb[a:b, j] = y[:, j, coulomb_cols[j]]
        rows[:, :, cols] = filtered_rows(t, part, settings, d // m)
    return UnbandedRows(rows, t, qd, coulomb, d // m)


def banded_rows(u: UnbandedRows, settings: Preprocess) -> np.ndarray:
    """The fit rows (N / decimate, n, 15 n) with the dead band ``settings.dead_band``: ``u.rows``
    itself when no sample is inside the band (not a copy: do not modify it), else a copy whose
    Coulomb columns of the joints with samples inside are zeroed there, then filtered and
    decimated as the other columns were (:func:`filtered_rows`)."""
    still = np.abs(u.qd) < settings.dead_band
    joints = np.flatnonzero(still.any(axis=0))
    if joints.size == 0:
        return u.rows
    cols = u.coulomb[:, joints, :].copy()
    cols[still[:, joints]] = 0.0  # |qd_j| < band: joint j's Coulomb terms are zero
    cols = filtered_rows(u.t, cols, settings, u.keep)
    out = u.rows.copy()
    for i, j in enumerate(joints):
        out[:, j, joint_columns(j, "Fcp", "Fcn")] = cols[:, i]
    return out


def evaluation_step(t: np.ndarray, settings: Preprocess, d: int) -> int:
    """The step ``m`` (a divisor of the decimation ``d``) at which rows are evaluated and filtered:
    the largest with at least ``MID_RATE`` samples per cut-off period (:func:`regressor_rows`);
    ``d`` itself without a filter."""
    if settings.cutoff is None:
        return d
    fs = 1.0 / float(np.median(np.diff(t)))
    limit = max(1, int(fs / (MID_RATE * settings.cutoff)))
    return max(k for k in range(1, d + 1) if d % k == 0 and k <= limit)


def filtered_rows(t: np.ndarray, y: np.ndarray, settings: Preprocess, keep: int) -> np.ndarray:
    """Rows ``y`` (N, ...) at times ``t`` (N,) low-passed along time with the target's filter,
    then every ``keep``-th kept (N / keep, ...)."""
    count = y.shape[0]
    flat = y.reshape(count, -1)
    if settings.cutoff is None:
        return flat[::keep].reshape((-1,) + y.shape[1:])
    # H Y: the same zero-phase low-pass as the target, along time, on the columns that vary (a
    # constant column, most of them structural zeros, is its own low-pass)
    varying = np.flatnonzero(np.ptp(flat, axis=0) > 0)
    out = lowpass_columns(t, flat, settings.cutoff, varying, flat[::keep].copy(),
                          order=settings.order, keep=keep)
    return out.reshape((-1,) + y.shape[1:])


class SharedRows:
    """Processed samples and fit rows of the recordings of one identification, per setting.

    The candidates of ``rd.identify``'s choices that differ only in the dead band (or in thermal
    friction, which adds columns of its own) have the same samples and the same rows but for
    the Coulomb columns: the samples and the unbanded rows are made once per velocity source
    and cut-off (:func:`unbanded_rows`), and each candidate gets its band applied
    (:func:`banded_rows`). The memo holds those arrays until :meth:`clear`.

    Parameters
    ----------
    model : Model
        The compiled model whose regressor is evaluated.
    """

    def __init__(self, model: Any) -> None:
        self._model = model
        self._memo: dict[tuple[Any, ...], tuple[list[Samples], list[UnbandedRows]]] = {}
        self._scratch = np.empty(0)

    def get(self, recs: Sequence[Any], settings: Preprocess, target: str | None
            ) -> tuple[list[Samples], list[np.ndarray]]:
        """:func:`preprocess` of each recording and its :func:`regressor_rows`."""
        key = (settings.cutoff, settings.order, settings.decimate, settings.velocity, target)
        if key not in self._memo:
            full = [preprocess(r, settings, target) for r in recs]
            self._memo[key] = (full, [unbanded_rows(self._model, s, settings, scratch=self._buffer)
                                      for s in full])
        full, base = self._memo[key]
        return full, [banded_rows(u, settings) for u in base]

    def _buffer(self, size: int) -> np.ndarray:
        """The unfiltered rows' scratch buffer, at least ``size`` float64: grown to twice the
        request when needed, within :data:`ROWS_BYTES` (memory never written costs nothing on
        Linux, a reservation elsewhere; a candidate evaluated at twice the rate, a wider
        cut-off's, then touches only the second half)."""
        if self._scratch.size < size:
            self._scratch = np.empty(max(size, min(2 * size, ROWS_BYTES // 8)))
        return self._scratch

    def clear(self) -> None:
        """Forget every setting's arrays."""
        self._memo.clear()
        self._scratch = np.empty(0)
