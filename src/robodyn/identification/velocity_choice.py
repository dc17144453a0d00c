"""The velocity source, chosen by how well each source's finished model fits the data.

With ``velocity="auto"`` and a recorded velocity, :func:`robodyn.identify` can take the joint
velocity from the recorder or from differences of the positions. They differ in what the fit and
every later prediction see: a quantised encoder's differences are steps, a tachometer is noisy, a
recorder's velocity may be filtered or lag. Which is better shows in the model finished with
each: each source's cut-off and dead band chosen by the held-out time blocks among its own
candidates (:func:`robodyn.identification.choices.choose`), then the linear step, the estimator
and the terms of :func:`~robodyn.identification.prediction_terms.with_model_terms` (ripple,
prediction cut-off, drive modes). The friction law is chosen once, on
the first (plain) source's model, and the other source is fitted with the same law: both models
then have the same terms on the same samples and the same target, so their residuals on the
identification recordings carry the same fitting optimism and can be compared without held-out
data (a law chosen per source made the comparison one of the laws: on a KUKA LWR4+ run's first
half, position differences with the Stribeck law fitted it better than the recorder's velocity
with the linear law, and predicted the second half worse, 0.0215 against 0.0134).

The score of a source is its model's relative residual against the raw target, predicted as
:meth:`Identification.predict <robodyn.identification.result.Identification.predict>` does
(before the local correction, which is then fitted on the kept source alone); the smaller is
kept. Why not the time blocks for the
source as well, as before: their score is the linear step's (weighted least squares, no friction
law, no drive modes), against the target filtered at the plain cut-off; on the real recordings in
``../shared`` it disagreed with the finished models on three of the quality table's nine splits,
and the finished models picked the source whose held-out prediction was better on all eighteen
splits measured (docs/identification.md, "The velocity source").
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from robodyn.identification.choices import Candidate, Problem
from robodyn.identification.local_residual import model_residuals
from robodyn.identification.prediction_terms import as_predicted, with_corrections
from robodyn.identification.preprocess import target_signal

__all__ = ["chosen_velocity", "fit_residual", "kept_source", "same_law", "same_law_options"]

#: ``fit(opts, candidate, problem, scored) -> (Identification, recordings)``: a finished model.
ModelFit = Callable[[Any, Candidate, Problem, list[Candidate]], tuple[Any, list[Any]]]


def kept_source(winners: list[tuple[Candidate, Problem, list[Candidate]]], scored: list[Candidate],
                fit: ModelFit, opts: Any, pays: list[Any], target: str) -> Any:
    """The identification of the kept velocity source, with its corrections.

    Parameters
    ----------
    winners : list of (Candidate, Problem, list of Candidate)
        Each source's chosen candidate, its problem and its scored group
        (:func:`~robodyn.identification.choices.choose`); emptied as the models are fitted, so
        that each problem is freed once its model is.
    scored : list of Candidate
        Every candidate scored (all sources).
    fit : callable
        The finished model of one candidate (the pipeline's linear step, estimate and
        :func:`~robodyn.identification.prediction_terms.with_model_terms`).
    opts : IdentifyOptions
    pays : list of Payload or None
    target : {"tau", "current"}

    Returns
    -------
    Identification
        The model of the smaller :func:`fit_residual` (the only one with a single source),
        the local correction fitted on it alone.
    """
    fits = [fit(opts, *winners.pop(0))]
    if not winners:
        return with_corrections(*fits[0], pays, target, opts)
    # the other source with the friction law chosen on the first: the same terms compared
    law = same_law_options(opts, fits[0][0])
    while winners:
        fits.append(same_law(fit(law, *winners.pop(0)), fits[0][0]))
    # each source's model as it predicts: its residual on the fit data; the local correction
    # then fitted on the kept one (from the same residuals)
    res = [model_residuals(as_predicted(f, r, opts), r, pays, target) for f, r in fits]
    scores = [fit_residual(r, e[1], target) for (_, r), e in zip(fits, res, strict=True)]
    result, recs = chosen_velocity(fits, scores, scored)
    return with_corrections(result, recs, pays, target, opts, res[int(np.argmin(scores))])


def fit_residual(recs: Sequence[Any], residuals: Sequence[np.ndarray], target: str) -> float:
    """``||y - p|| / ||y||`` over the finite target entries of all joints and recordings: the
    raw target ``y`` of the identification recordings ``recs`` and ``residuals`` ``y - p``
    (:func:`~robodyn.identification.local_residual.model_residuals`, (N_k, n) each)."""
    num = den = 0.0
    for rec, e in zip(recs, residuals, strict=True):
        y = np.asarray(target_signal(rec, target), float)
        ok = np.isfinite(y)
        num += float(np.sum(e[ok] ** 2))
        den += float(np.sum(y[ok] ** 2))
    return float(np.sqrt(num / max(den, 1e-300)))


def same_law_options(opts: Any, first: Any) -> Any:
    """``opts`` with ``friction`` the law ``friction="auto"`` chose on the first source's model
    ``first`` (unchanged when the law was given)."""
    if opts.friction != "auto" or first.choices.friction is None:
        return opts
    return replace(opts, friction=first.choices.friction)


def same_law(fit: tuple[Any, list[Any]], first: Any) -> tuple[Any, list[Any]]:
    """``fit`` (an identification and its recordings) reporting the friction law and its scores
    as chosen on ``first``'s model, with which it was fitted."""
    ident, recs = fit
    if first.choices.friction is None:
        return fit
    choices = replace(ident.choices, friction=first.choices.friction,
                      friction_scores=first.choices.friction_scores)
    return replace(ident, choices=choices), recs


def chosen_velocity(fits: Sequence[tuple[Any, list[Any]]], scores: Sequence[float],
                    scored: Sequence[Candidate]) -> tuple[Any, list[Any]]:
    """The fit of the smallest score (the first on a tie), its choices extended.

    Parameters
    ----------
    fits : sequence of (Identification, list of Recording)
        Each velocity source's finished model (its ``choices`` those of its own candidates) and
        the recordings its later steps see.
    scores : sequence of float
        Each one's :func:`fit_residual`, computed as it predicts (Coulomb step smoothed).
    scored : sequence of Candidate
        Every candidate with its held-out block score (all sources).

    Returns
    -------
    (Identification, list of Recording)
        The kept one; its ``choices.candidates`` every source's scored candidates,
        ``velocity_scores`` each source's residual, and the reason saying how the source was
        chosen.
    """
    best = int(np.argmin(scores))
    ident, recs = fits[best]
    if len(fits) == 1:
        return ident, recs
    pairs = tuple((f.choices.velocity, float(s)) for (f, _), s in zip(fits, scores, strict=True))
    own = f"{ident.choices.reason}; " if len(ident.choices.candidates) > 1 else ""  # its source's
    reason = (f"{own}the velocity source: the smaller residual of each source's finished model "
              "on the identification recordings")
    return replace(ident, choices=replace(ident.choices, candidates=tuple(scored), velocity_scores=pairs,
                                          reason=reason)), recs
