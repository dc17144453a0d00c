"""Prediction bandwidth: the cut-off of the states at which ``ident.predict`` evaluates the model.

The fit's cut-off (:mod:`robodyn.identification.preprocess`) trades the noise of the
differentiated states against the bias of a narrow band, for the *parameters*: target and
regressor are low-passed by the same filter (parallel filtering), so the parameters are fitted
on what lies below it. A prediction need not stop there. The identified model holds at every
frequency, and a recording's target carries the motion's content above the fit's cut-off (a fast
reversal, the acceleration peaks of a short stroke); evaluated on states low-passed at the fit's
cut-off, the prediction misses it. Too wide a band, and the encoder noise differentiated twice
enters the prediction instead.

``prediction_cutoff="auto"`` (an option of :func:`robodyn.identify`; ``"fit"`` keeps the fit's
cut-off, and the default ``"motion"`` widens it only for a predicted recording that moves faster
than the identification data, :meth:`Identification.recording_cutoff`) tries the fit's cut-off
``f_c`` and the wider :data:`FACTORS` ``x f_c`` (at most :data:`MAX_FRACTION` of the sampling
rate of the slowest recording), predicts the identification recordings with each, and scores each
against their *raw* target (no reference filter: only the raw target holds the band in
question; its noise adds the same amount to every candidate). The parameters are not refitted
per candidate, and were fitted below ``f_c``: the band above ``f_c`` is not fitted, so this
in-sample error is an honest estimate of that band's held-out error. A wider candidate replaces
the current one only when it is better by more than one standard error of the paired
differences of :data:`~robodyn.identification.estimate.FOLDS` time blocks per recording (the rule
of :mod:`robodyn.identification.choices`). ``ident.choices.prediction_cutoff`` and
``prediction_scores`` record the choice.

Why it is not the default: what it adds lies above the reference filter of every "against
filtered" figure (2.5 Hz, :mod:`robodyn.validation.heldout`), so it lowers the error against the
raw target and raises it against the filtered one. Measured on the Kinova rows of
``benchmarks/bench_identification_quality.py`` (one run): across runs 0.419 -> 0.378 raw and
0.151 -> 0.180 filtered; the 70/30 split 0.286 -> 0.293 raw and 0.176 -> 0.244 filtered (the
in-sample choice of 12.5 Hz did not carry over there); no change on the KUKA and virtual rows.
Use it where the raw signal is what a prediction must match (a feed-forward torque, a collision
detector's residual).

The prediction is scored on every ``stride``-th sample (at most :data:`SCORED_SAMPLES` in all):
the states are processed on the full grid, only the model is evaluated on fewer samples.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from robodyn.identification.estimate import FOLDS, paired_se
from robodyn.identification.preprocess import Samples, preprocess, slowest_rate, target_signal
from robodyn.identification.thermal import temperatures
from robodyn.robot.errors import IdentificationError

__all__ = ["FACTORS", "check_prediction_cutoff", "choose_prediction_cutoff", "prediction_candidates",
           "with_prediction_cutoff"]

#: Candidate prediction cut-offs, as multiples of the fit's cut-off (the first is the fit's).
FACTORS = (1.0, 1.6, 2.5, 4.0)
#: The widest prediction cut-off, as a fraction of the slowest recording's sampling rate.
MAX_FRACTION = 0.2
#: At most this many samples (all recordings) are predicted per candidate.
SCORED_SAMPLES = 20_000


def prediction_candidates(fit_cutoff: float, rate: float) -> list[float]:
    """The cut-offs tried (Hz): ``FACTORS x fit_cutoff`` up to ``MAX_FRACTION x rate``, the fit's
    first; ``rate`` is the slowest recording's sampling rate, Hz."""
    top = MAX_FRACTION * rate
    out = [float(fit_cutoff)]
    for f in FACTORS[1:]:
        c = min(f * fit_cutoff, top)
        if c > out[-1] * 1.05:
            out.append(float(c))
    return out


def _strided(s: Samples, stride: int) -> Samples:
    return Samples(s.t[::stride], s.q[::stride], s.qd[::stride], s.qdd[::stride], None, s.source)


def _block_errors(ident: Any, settings: Any, recordings: Sequence[Any], payloads: Sequence[Any],
                  target: str, stride: int) -> np.ndarray:
    """Squared raw-target error of each time block (FOLDS per recording), (FOLDS * R,)."""
    out = []
    for rec, pay in zip(recordings, payloads, strict=True):
        s = _strided(preprocess(rec, settings, None), stride)
        temp = (temperatures(rec, 0, ident.robot.dof)[::stride] if ident.thermal_fit is not None
                else None)
        e = np.asarray(target_signal(rec, target), float)[::stride] - ident.effort(s, temp, pay)
        sq = np.sum(e**2, axis=1)
        block = np.arange(sq.size) * FOLDS // max(sq.size, 1)
        out.append(np.bincount(block, weights=sq, minlength=FOLDS))
    return np.concatenate(out)


def choose_prediction_cutoff(ident: Any, recordings: Sequence[Any], payloads: Sequence[Any],
                             target: str) -> tuple[float, dict[str, float]]:
    """The prediction cut-off for ``ident`` (module docstring), and each candidate's score.

    Parameters
    ----------
    ident : Identification
        The identification (its ``preprocess.cutoff`` is the fit's).
    recordings : sequence of Recording
        The identification recordings, raw.
    payloads : sequence of Payload or None
        One per recording.
    target : {"tau", "current"}

    Returns
    -------
    (float, dict of str to float)
        The chosen cut-off, Hz, and for each candidate (``"<f> Hz"``) its relative error
        against the raw target ``sqrt(sum e^2 / sum y^2)``.
    """
    rate = slowest_rate(recordings)
    cands = prediction_candidates(ident.preprocess.cutoff, rate)
    total = sum(int(np.asarray(r.t).size) for r in recordings)
    stride = max(1, total // SCORED_SAMPLES)
    y2 = sum(float(np.sum(np.asarray(target_signal(r, target), float)[::stride] ** 2))
             for r in recordings)
    errs = [_block_errors(ident, replace(ident.preprocess, cutoff=c), recordings, payloads, target,
                          stride) for c in cands]
    best = 0
    for i in range(1, len(cands)):
        # paired block differences against the current choice, and their standard error
        d = errs[i] - errs[best]
        if d.sum() < -paired_se(d):
            best = i
    scores = {f"{c:g} Hz": float(np.sqrt(e.sum() / max(y2, 1e-300))) for c, e in zip(cands, errs,
                                                                                       strict=True)}
    return cands[best], scores


def check_prediction_cutoff(recordings: Sequence[Any], option: float | str) -> None:
    """Refuse a fixed prediction cut-off at or above the slowest recording's Nyquist frequency
    (before any fitting), naming the option."""
    if isinstance(option, str):
        return
    rate = slowest_rate(recordings)
    if not 0.0 < float(option) < 0.5 * rate:
        raise IdentificationError(f"prediction_cutoff: must lie in (0, {0.5 * rate:g}) Hz (the "
                                  f"Nyquist frequency of the slowest recording), got {option:g}")


def with_prediction_cutoff(ident: Any, recordings: Sequence[Any], payloads: Sequence[Any] | None,
                           target: str, option: float | str | None) -> Any:
    """``ident`` with the prediction cut-off of ``option`` set.

    Parameters
    ----------
    ident : Identification
    recordings : sequence of Recording
        The identification recordings, raw.
    payloads : sequence of Payload or None, optional
    target : {"tau", "current"}
    option : float, "motion", "auto" or "fit"
        A cut-off in Hz, chosen from the data ("auto"), or the fit's ("fit"; "motion": the fit's,
        widened per predicted recording by :meth:`Identification.predict`). Without a fit
        cut-off (``cutoff=None``: the recordings' own derivatives) there is nothing to choose.
    """
    fit_cut = ident.preprocess.cutoff
    if option in ("fit", "motion") or fit_cut is None:
        return ident
    pays = list(payloads) if payloads is not None else [None] * len(recordings)
    if option == "auto":
        cut, scores = choose_prediction_cutoff(ident, recordings, pays, target)
        ident = replace(ident, choices=replace(ident.choices, prediction_cutoff=cut,
                                               prediction_scores=tuple(scores.items())))
    else:
        cut = float(option)  # type: ignore[arg-type]
    if cut == fit_cut:
        return ident
    return replace(ident, prediction=replace(ident.preprocess, cutoff=cut))
