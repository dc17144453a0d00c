"""What a prediction adds to the linear fit, each term chosen on the identification data.

After the linear step (:func:`robodyn.identification.identify`: base parameters, drive gains,
linear friction), in this order:

1. the friction law (:mod:`robodyn.identification.friction_choice`; a nonlinear law fitted by
   :mod:`robodyn.identification.friction`);
2. the position ripple (:mod:`robodyn.identification.ripple`);
3. the prediction's cut-off (:mod:`robodyn.identification.bandwidth`);
4. the drive modes (:mod:`robodyn.identification.resonance`);
5. the smoothed Coulomb step (:mod:`robodyn.identification.coulomb_width`): the fit and every
   choice above are made with the step;
6. last, the local correction of what the whole prediction leaves
   (:mod:`robodyn.identification.local_residual`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from robodyn.identification.bandwidth import with_prediction_cutoff
from robodyn.identification.coulomb_width import auto_coulomb_width
from robodyn.identification.friction import NONLINEAR, fit_friction_samples
from robodyn.identification.friction_choice import choose_friction_law
from robodyn.identification.local_residual import with_local_residual
from robodyn.identification.options import IdentifyOptions
from robodyn.identification.preprocess import Preprocess, Samples
from robodyn.identification.resonance import with_resonance
from robodyn.identification.result import Identification
from robodyn.identification.ripple import gravity_free_joints, with_ripple
from robodyn.identification.unobserved import imputed_recordings

__all__ = ["as_predicted", "with_corrections", "with_model_terms"]


def with_model_terms(result: Identification, recs: Sequence[Any], pays: Sequence[Any],
                     target: str, opts: IdentifyOptions, samples: Sequence[Samples],
                     y_full: Sequence[np.ndarray], full: Sequence[Samples], settings: Preprocess,
                     observed: Sequence[np.ndarray] | None = None
                     ) -> tuple[Identification, list[Any]]:
    """``result`` (the linear step, its choices set) with steps 1-4 of the module docstring.

    Parameters
    ----------
    result : Identification
        The linear step's identification.
    recs, pays : sequence
        The fit's recordings and their payloads (None: none).
    target : {"tau", "current"}
    opts : IdentifyOptions
        The run's options (``friction``, ``ripple``, ``prediction_cutoff``, ``resonance``).
    samples : sequence of Samples
        The fit's processed, decimated samples, (N_k, n).
    y_full : sequence of numpy.ndarray, shape (N_k, n, 15 n)
        Their filtered regressor rows.
    full : sequence of Samples
        The processed samples before decimation.
    settings : Preprocess
        The fit's processing.
    observed : sequence of numpy.ndarray of bool, shape (n,), optional
        The joints with target data in each recording (default: all). ``samples`` already hold
        the model's prediction in place of the others; the recordings' are filled here, before
        the prediction cut-off and the drive modes (:mod:`robodyn.identification.unobserved`).

    Returns
    -------
    (Identification, list of Recording)
        The identification and the recordings the later steps see (``recs``, a joint without
        data filled with the model's prediction).
    """
    law = opts.friction
    if opts.friction == "auto":
        # thermal friction scales the linear law's columns: with it the linear law stays
        law, scores = (("linear", {}) if result.thermal_fit is not None
                       else choose_friction_law(result, samples, y_full))
        result = replace(result, choices=replace(result.choices, friction=law,
                                                 friction_scores=tuple(scores.items())))
    if law in NONLINEAR:
        result = replace(result, friction_fit=fit_friction_samples(result, samples, y_full, law))
    model = result._model
    revolute = np.array([j.type == "revolute" for j in result.robot.joints])
    result = with_ripple(result, full, samples, y_full, settings,
                         gravity_free_joints(model, revolute), opts.ripple)
    recs = list(recs)
    if observed is not None:
        recs = imputed_recordings(result, recs, pays, target, observed)
    result = with_prediction_cutoff(result, recs, pays, target, opts.prediction_cutoff)
    return with_resonance(result, recs, pays, target, opts.resonance), recs


def as_predicted(result: Identification, recs: Sequence[Any], opts: IdentifyOptions
                 ) -> Identification:
    """``result`` with the run's options and the smoothed Coulomb step (step 5) set: how
    :meth:`~robodyn.identification.result.Identification.predict` uses it."""
    width = (auto_coulomb_width(recs, result.preprocess) if opts.coulomb_width == "auto"
             else float(opts.coulomb_width))
    return replace(result, options=opts, coulomb_width=width)


def with_corrections(result: Identification, recs: Sequence[Any], pays: Sequence[Any],
                     target: str, opts: IdentifyOptions,
                     residuals: tuple[list[np.ndarray], list[np.ndarray]] | None = None
                     ) -> Identification:
    """``result`` (:func:`with_model_terms`'s, ``recs`` its recordings) with steps 5 and 6 of
    the module docstring (``opts``: ``coulomb_width``, ``local``); stored as
    ``result.options``; ``residuals``: its
    :func:`~robodyn.identification.local_residual.model_residuals`, when the caller has them."""
    # the prediction's Coulomb step smoothed (the fit and every choice made with the step)
    result = as_predicted(result, recs, opts)
    return with_local_residual(result, recs, pays, target, opts.local, residuals)
