"""Joints without data in the target: a recording's target column that is NaN in every row.

A :class:`~robodyn.measure.recording.Recording` marks a joint without a sensor by an all-NaN
column (a recording spec's ``missing: zero`` turns an all-zero column into one: the Kinova Gen3
logs in ``../shared`` have no torque-sensor data for joint 1). ``rd.identify`` fits such
recordings with the rows of the joints that have data:

* the stacked problems (the candidates' cross-validation, the linear step, the consistent
  program, drive gains from payload runs) leave out the rows of a joint in the recordings where
  it has no data (:func:`kept_rows`);
* the prior's per-joint fit (rotor inertia, friction, the drive gain of a current target) uses
  the recordings where the joint has data; where none has, the joint keeps the description's
  values (:func:`robodyn.identification.prior.joint_prior`);
* the terms fitted after the linear step (friction law, position ripple, prediction cut-off,
  drive modes) see in place of the missing column the model's own prediction of it
  (:func:`imputed_samples`, :func:`imputed_recordings`), which leaves them nothing to fit there.

Parameters seen only through such a joint's rows (its own rotor inertia and friction, the
inertial combinations that only its torque carries) are then not excited by the data: the
regularisation keeps them at the prior, and without it they are reported unexcited. The joint's
prediction is the identified model's, in the target's unit (for a current target, through the
description's drive gain, or 1 where the gains are absorbed: nothing measured it).
"""

from __future__ import annotations

import copy
import warnings
from collections.abc import Sequence
from dataclasses import is_dataclass, replace
from typing import Any

import numpy as np

from robodyn.identification.preprocess import Samples, preprocess
from robodyn.identification.prior import IdentificationWarning
from robodyn.identification.thermal import temperatures

__all__ = ["filled", "imputed_recordings", "imputed_samples", "kept_rows", "note_unobserved",
           "observed_joints", "seen_joints", "unobserved_names", "with_data"]


def observed_joints(recs: Sequence[Any], target: str) -> list[np.ndarray]:
    """Per recording, the joints (n,) bool whose ``target`` column has a finite value."""
    return [np.isfinite(np.asarray(getattr(r, target), float)).any(axis=0) for r in recs]


def seen_joints(observed: Sequence[np.ndarray]) -> np.ndarray:
    """The joints (n,) bool with target data in at least one recording."""
    return np.logical_or.reduce(list(observed))


def unobserved_names(observed: Sequence[np.ndarray], names: Sequence[str]) -> tuple[str, ...]:
    """The joints without data in every recording."""
    return tuple(name for name, s in zip(names, seen_joints(observed), strict=True) if not s)


def note_unobserved(observed: Sequence[np.ndarray], names: Sequence[str], target: str) -> None:
    """Warn about the joints without ``target`` data in every recording."""
    missing = unobserved_names(observed, names)
    if missing:
        warnings.warn(IdentificationWarning(
            f"{target}: no data for joint(s) {', '.join(missing)} in any recording (all-NaN "
            f"columns): their rows are not fitted, their rotor inertia, friction and drive gain "
            f"stay the description's, and their prediction is the model's"), stacklevel=3)


def filled(recs: Sequence[Any], target: str, observed: Sequence[np.ndarray]) -> list[Any]:
    """The recordings with each missing ``target`` column set to 0 (copies: the caller's
    recordings and arrays are left as they are); recordings without one are returned as given."""
    out = []
    for rec, obs in zip(recs, observed, strict=True):
        if obs.all():
            out.append(rec)
            continue
        y = np.asarray(getattr(rec, target), float)
        out.append(_with_target(rec, target, np.where(obs[None, :], y, 0.0)))
    return out


def _with_target(rec: Any, target: str, y: np.ndarray) -> Any:
    """A copy of ``rec`` (a Recording, or any object with its fields) whose ``target`` is ``y``."""
    if is_dataclass(rec):
        return replace(rec, **{target: y})
    out = copy.copy(rec)
    setattr(out, target, y)
    return out


def kept_rows(observed: Sequence[np.ndarray] | None, counts: Sequence[int]) -> np.ndarray | None:
    """Rows (sum N_k n,) bool of the stacked problems (sample-major, joint-minor) that have data;
    None when every row has (or ``observed`` is None)."""
    if observed is None or all(obs.all() for obs in observed):
        return None
    return np.concatenate([np.tile(obs, count) for obs, count in zip(observed, counts, strict=True)])


def with_data(a: np.ndarray, observed: Sequence[np.ndarray] | None, counts: Sequence[int]) -> np.ndarray:
    """The stacked rows ``a`` (sum N_k n, ...) of the joints with data (:func:`kept_rows`)."""
    keep = kept_rows(observed, counts)
    return a if keep is None else a[keep]


def imputed_samples(samples: Sequence[Samples], y_full: Sequence[np.ndarray], standard: np.ndarray,
                    gains: np.ndarray, observed: Sequence[np.ndarray]) -> list[Samples]:
    """``samples`` whose missing target columns hold the model's own prediction
    ``(Y p)_j / K_j`` (``y_full`` (N_k, n, 15 n) rows, ``standard`` (15 n,) parameters, ``gains``
    (n,)), in the convention of targets with the known loads already taken off."""
    out = []
    for s, rows, obs in zip(samples, y_full, observed, strict=True):
        if obs.all():
            out.append(s)
            continue
        own = (rows @ standard) / gains[None, :]
        out.append(replace(s, y=np.where(obs[None, :], s.y, own)))
    return out


def imputed_recordings(ident: Any, recs: Sequence[Any], pays: Sequence[Any], target: str,
                       observed: Sequence[np.ndarray]) -> list[Any]:
    """``recs`` whose missing target columns hold ``ident``'s own prediction of them at the
    prediction's processing, as the drive modes and the prediction cut-off compare it."""
    out = []
    for rec, pay, obs in zip(recs, pays, observed, strict=True):
        if obs.all():
            out.append(rec)
            continue
        temp = temperatures(rec, 0, ident.robot.dof) if ident.thermal_fit is not None else None
        own = ident.effort(preprocess(rec, ident.prediction_settings, None), temp, pay)
        y = np.asarray(getattr(rec, target), float)
        out.append(_with_target(rec, target, np.where(obs[None, :], y, own)))
    return out
