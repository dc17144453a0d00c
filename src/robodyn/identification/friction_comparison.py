"""Held-out comparison of the friction laws: one identification per law, one row per law."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from robodyn.identification.friction import FRICTION_MODELS
from robodyn.identification.pipeline import identify
from robodyn.robot.errors import IdentificationError
from robodyn.validation.heldout import held_out_error

__all__ = ["friction_table"]


def friction_table(robot: Any, train: Any, test: Sequence[Any], models: Sequence[str] = FRICTION_MODELS,
                   *, like: Any = None, **options: Any) -> Any:
    """Held-out error of each friction model.

    Each model is identified on ``train`` (``rd.identify(robot, train, friction=model,
    **options)``) and predicts every recording of ``test``. With ``like`` (an identification of
    the same data), every model is identified with its velocity source, cut-off, Coulomb dead band
    and Tikhonov weight, so that the law alone differs (and no fit repeats their cross-validation).

    Parameters
    ----------
    robot : Robot
    train : Recording or sequence of Recording
    test : sequence of Recording
    models : sequence of str
        Among ``FRICTION_MODELS``.
    like : Identification, optional
        Sets ``velocity``, ``cutoff``, ``dead_band`` and ``regularization`` to ``like``'s (its
        ``preprocess.velocity``, ``.cutoff`` and ``.dead_band``, and ``regularization``).
    **options
        Passed to :func:`robodyn.identification` (target, method, cutoff, ...).

    Returns
    -------
    pandas.DataFrame
        One row per model: ``relative_error`` (``||e|| / ||y||`` against the raw target over all
        test samples and joints), ``relative_error_filtered`` (against the target low-passed with
        the reference filter of :mod:`robodyn.validation.heldout`), ``noise_floor``
        (``||y - y_f|| / ||y||``) and
        ``relative_error_<joint>`` per joint (raw).

    Raises
    ------
    IdentificationError
        ``like`` together with an option it sets.
    """
    import pandas as pd

    if like is not None:
        pre = like.preprocess
        same = {"velocity": pre.velocity, "cutoff": pre.cutoff, "dead_band": pre.dead_band,
                "regularization": like.regularization}
        clash = sorted(set(same) & set(options))
        if clash:
            raise IdentificationError(f"friction_table: like= sets {', '.join(clash)}; pass "
                                      "either like= or those options")
        options = {**options, **same}
    rows = []
    for model in models:
        ident = identify(robot, train, friction=model, **options)
        preds = [ident.predict(r) for r in test]
        ys = [np.asarray(getattr(r, ident.target), float) for r in test]
        fig = held_out_error([np.asarray(r.t, float) for r in test], ys, preds, robot.joint_names)
        pred, y = np.vstack(preds), np.vstack(ys)
        row = {"model": model, "relative_error": fig.raw, "relative_error_filtered": fig.filtered,
               "noise_floor": fig.noise_floor}
        for j, name in enumerate(robot.joint_names):
            row[f"relative_error_{name}"] = float(np.linalg.norm(pred[:, j] - y[:, j])
                                                  / np.linalg.norm(y[:, j]))
        rows.append(row)
    return pd.DataFrame(rows)
