"""Preprocessing choices of ``rd.identify`` made from the identification data by cross-validation.

A setting left at ``"auto"`` (the velocity source, the Coulomb dead band, the cut-off, thermal
friction) is chosen among a few candidates by time-block cross-validation on the identification
data themselves: each recording is cut into ``FOLDS`` contiguous blocks, each block is predicted
by a fit on the others (for every Tikhonov weight of
:data:`robodyn.identification.estimate.LAMBDA_GRID`), and the candidate whose best held-out error is
lowest is kept. The fit uses the filtered regressor rows and the per-joint row weights of
weighted least squares, as the identification does; the held-out block is predicted as
:meth:`Identification.predict` predicts (the unfiltered rows with the candidate's dead band,
:func:`robodyn.identification.preprocess.prediction_rows`), so that what a candidate does to a
prediction (a Coulomb sign flipping with the noise of a joint at rest) is what is scored, and
compared with one target for all candidates (low-passed at the plain candidate's cut-off, not
each candidate's own filtered one, which differs between cut-offs), in torque units, rows
unweighted. The score is the relative held-out error
``sqrt(sum e^2 / sum y^2)`` over all blocks: a ratio over the same blocks of time, so that
candidates with other decimations (other cut-offs) compare like for like.
Held-out blocks, not the fit residual: a richer processing always fits its own data better, but
only a real gain survives a block it has not seen.

The first candidate (position differences, no dead band, the cut-off rule's value, no thermal
friction: the plain processing) is kept unless
another beats it by more than one standard error of the paired block differences (the
"one-standard-error rule" of cross-validation, Hastie, Tibshirani and Friedman, *The Elements
of Statistical Learning*, 7.10): differences within the blocks' own scatter are not evidence,
and a choice made on them would follow the noise of the particular recording.

:class:`Choices` records every candidate's score and why the winner was kept; it is
``Identification.choices``, printed by ``robodyn identify`` and shown in its HTML report.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from robodyn.identification.estimate import LAMBDA_GRID, candidate_cv_errors, paired_se
from robodyn.identification.preprocess import resolve_preprocess, slowest_rate
from robodyn.measure.filtering import lowpass

__all__ = ["CUTOFF_WIDER", "Candidate", "Choices", "Problem", "candidates", "choose",
           "cutoff_candidates", "reference_targets"]

#: The wider cut-off tried by cross-validation, as a multiple of the rule's (cutoff="auto").
CUTOFF_WIDER = 2.5


@dataclass(frozen=True)
class Candidate:
    """One preprocessing candidate and its cross-validated score.

    Attributes
    ----------
    velocity : {"position", "measured"}
    dead_band : float
        Coulomb dead band, rad/s.
    score : float
        Relative held-out error over the time blocks (best Tikhonov weight); NaN: not scored.
    lam : float
        The Tikhonov weight of that best held-out error.
    thermal : bool
        With temperature-dependent friction (:mod:`robodyn.identification.thermal`).
    cutoff : float, None or "auto"
        Low-pass cut-off, Hz, as passed to the preprocessing ("auto": its own rule).
    """

    velocity: str
    dead_band: float
    score: float = float("nan")
    lam: float = float("nan")
    thermal: bool = False
    cutoff: float | str | None = "auto"

    @property
    def key(self) -> tuple[str, float, bool, float | str | None]:
        """What identifies the candidate: (velocity, dead_band, thermal, cutoff)."""
        return (self.velocity, self.dead_band, self.thermal, self.cutoff)

    @property
    def label(self) -> str:
        """``velocity=..., dead_band=..., cutoff=..., thermal`` as printed."""
        cut = self.cutoff if isinstance(self.cutoff, str) or self.cutoff is None else f"{self.cutoff:.3g} Hz"
        return (f"velocity={self.velocity}, dead_band={self.dead_band:g} rad/s, cutoff={cut}"
                + (", thermal friction" if self.thermal else ""))


@dataclass(frozen=True)
class Choices:
    """What ``rd.identify`` chose from the data, and why.

    Attributes
    ----------
    velocity : {"position", "measured"}
        Velocity source used.
    dead_band : float
        Coulomb dead band used, rad/s.
    cutoff : float or None
        Low-pass cut-off used, Hz (its own rule: :mod:`robodyn.identification.preprocess`).
    regularization : float
        Tikhonov weight of the final fit (chosen by the same time-block cross-validation when
        ``regularization="auto"``).
    candidates : tuple of Candidate
        Every candidate tried with its score (one when nothing was left to choose).
    reason : str
        One sentence: how the winner was chosen.
    thermal : bool
        Whether temperature-dependent friction was used.
    chosen : Candidate or None
        The winning candidate (its entry of ``candidates``).
    friction : str or None
        The friction law chosen by ``friction="auto"`` (:mod:`robodyn.identification.friction_choice`),
        else None.
    friction_scores : tuple of (str, float)
        Each law's relative held-out error of the friction residual (``friction="auto"``;
        empty when thermal friction, which extends the linear law, keeps it).
    ripple : bool or None
        Whether ``ripple="auto"`` kept the position ripple (:mod:`robodyn.identification.ripple`),
        else None.
    ripple_scores : tuple of (str, float)
        Relative held-out error of the model's residual without and with the ripple; empty
        where no joint's travel separates a ripple from a constant.
    prediction_cutoff : float or None
        The cut-off of the states ``ident.predict`` uses, chosen by ``prediction_cutoff="auto"``
        (:mod:`robodyn.identification.bandwidth`), Hz; else None.
    prediction_scores : tuple of (str, float)
        Each candidate cut-off's relative error against the raw target of the identification
        recordings.
    resonance : bool or None
        Whether ``resonance="auto"`` (or True) kept a drive mode on some joint
        (:mod:`robodyn.identification.resonance`), else None.
    resonance_scores : tuple of (str, float)
        Relative held-out error of the target without and with the modes.
    resonance_modes : tuple of (str, float, float, float)
        Each kept mode: joint name, frequency (Hz), damping ratio, share.
    local : bool or None
        Whether ``local="auto"`` (or True) kept the local correction of the residual
        (:mod:`robodyn.identification.local_residual`), else None.
    local_scores : tuple of (str, float)
        Relative held-out error of the residual without and with the correction.
    local_setting : tuple of (float, float)
        The kept correction's kernel length (standard deviations) and ridge weight; empty when
        none is kept.
    velocity_scores : tuple of (str, float)
        With ``velocity="auto"`` and a recorded velocity: each source's relative residual of
        its finished model on the identification recordings' raw target
        (:mod:`robodyn.identification.velocity_choice`); empty otherwise.
    """

    velocity: str
    dead_band: float
    cutoff: float | None
    regularization: float
    candidates: tuple[Candidate, ...]
    reason: str
    thermal: bool = False
    chosen: Candidate | None = None
    friction: str | None = None
    friction_scores: tuple[tuple[str, float], ...] = ()
    ripple: bool | None = None
    ripple_scores: tuple[tuple[str, float], ...] = ()
    prediction_cutoff: float | None = None
    prediction_scores: tuple[tuple[str, float], ...] = ()
    resonance: bool | None = None
    resonance_scores: tuple[tuple[str, float], ...] = ()
    resonance_modes: tuple[tuple[str, float, float, float], ...] = ()
    local: bool | None = None
    local_scores: tuple[tuple[str, float], ...] = ()
    local_setting: tuple[tuple[float, float], ...] = ()
    velocity_scores: tuple[tuple[str, float], ...] = ()

    @property
    def friction_reason(self) -> str:
        """Why the friction law: its held-out scores, or the thermal friction that extends it."""
        if not self.friction_scores:
            return "with the thermal friction, which extends it"
        scores = ", ".join(f"{law} {score:.4f}" for law, score in self.friction_scores)
        return f"held-out blocks of the friction residual: {scores}"

    def summary(self) -> str:
        """A few lines for the terminal and the report."""
        cut = "none" if self.cutoff is None else f"{self.cutoff:g} Hz"
        lines = [f"velocity {self.velocity}, Coulomb dead band {self.dead_band:g} rad/s, cut-off "
                 f"{cut}, regularization {self.regularization:g}"
                 + (", thermal friction" if self.thermal else "") + f": {self.reason}"]
        if self.velocity_scores:
            scores = ", ".join(f"{k} {v:.4f}" for k, v in self.velocity_scores)
            lines.append(f"  velocity source {self.velocity} (residual of each source's model on "
                         f"the identification recordings: {scores})")
        if self.friction is not None:
            lines.append(f"  friction law {self.friction} ({self.friction_reason})")
        if self.ripple is not None and not self.ripple_scores:
            lines.append("  position ripple not kept (no joint travels far enough in the fit data "
                         "to tell a once-per-turn term from a constant)")
        elif self.ripple is not None:
            scores = ", ".join(f"{k} {v:.4f}" for k, v in self.ripple_scores)
            lines.append(f"  position ripple {'kept' if self.ripple else 'not kept'} (held-out "
                         f"blocks of the model's residual: {scores})")
        if self.resonance is not None:
            scores = ", ".join(f"{k} {v:.4f}" for k, v in self.resonance_scores)
            lines.append(f"  drive modes {'kept' if self.resonance else 'not kept'} (held-out "
                         f"blocks of the target: {scores})")
            lines += [f"    {name}: {f0:g} Hz, damping {zeta:g}, share {gain:.3g}"
                      for name, f0, zeta, gain in self.resonance_modes]
        if self.local is not None:
            scores = ", ".join(f"{k} {v:.4f}" for k, v in self.local_scores)
            kept = (f"kept, kernel length {self.local_setting[0][0]:g} sd, ridge "
                    f"{self.local_setting[0][1]:g}" if self.local else "not kept")
            lines.append(f"  local correction of the residual {kept} (held-out blocks of the "
                         f"residual: {scores})")
        if self.prediction_cutoff is not None:
            scores = ", ".join(f"{k} {v:.4f}" for k, v in self.prediction_scores)
            lines.append(f"  prediction cut-off {self.prediction_cutoff:g} Hz (raw target of the "
                         f"identification recordings: {scores})")
        if len(self.candidates) > 1:
            for c in self.candidates:
                mark = "*" if self.chosen is not None and c.key == self.chosen.key else " "
                lines.append(f"  {mark} {c.label}: held-out blocks {c.score:.4f} (lambda {c.lam:g})")
        return "\n".join(lines)


@dataclass(frozen=True, eq=False)
class Problem:
    """One candidate's identification problem, as :func:`choose` scores it (m rows).

    Attributes
    ----------
    phi : numpy.ndarray, shape (m, p)
        Filtered identification matrix (base columns, then any extra ones).
    y : numpy.ndarray, shape (m,)
        Filtered target in torque units.
    theta0 : numpy.ndarray, shape (p,)
        The prior.
    joint, blocks : numpy.ndarray of int, shape (m,)
        Joint and cross-validation block of each row.
    phi_test : numpy.ndarray, shape (m, p)
        Prediction rows of the same samples (unfiltered, :meth:`Identification.predict`'s).
    y_test : numpy.ndarray, shape (m,)
        The held-out target at the same samples, torque units (the same signal for every
        candidate).
    payload : Any
        Whatever the caller needs back for the winner.
    """

    phi: np.ndarray
    y: np.ndarray
    theta0: np.ndarray
    joint: np.ndarray
    blocks: np.ndarray
    phi_test: np.ndarray
    y_test: np.ndarray
    payload: Any


def candidates(velocity: str, dead_band: float | str, thermal: bool | str, measured_available: bool,
               temperatures_available: bool, default_band: float,
               cutoffs: tuple[float | str | None, ...] = ("auto",)) -> list[Candidate]:
    """The candidates of the ``"auto"`` settings (a fixed setting is its only candidate).

    ``velocity="auto"``: position differences, and the measured velocity when every recording
    has one (not estimated); ``dead_band="auto"``: none and ``default_band``;
    ``thermal="auto"``: without, and with when every recording has temperatures; ``cutoffs``:
    the cut-offs to try (the first is the plain one).
    """
    vels = (["measured", "position"] if measured_available else ["position"]) \
        if velocity == "auto" else [velocity]
    bands = [0.0, float(default_band)] if dead_band == "auto" else [float(dead_band)]
    therms = ([False, True] if temperatures_available else [False]) if thermal == "auto" \
        else [bool(thermal)]
    return [Candidate(v, b, thermal=th, cutoff=c) for c in cutoffs for th in therms for v in vels
            for b in bands]


def choose(cands: Sequence[Candidate], stacked: Callable[[Candidate], Problem]
           ) -> tuple[list[tuple[Candidate, Problem, list[Candidate]]], list[Candidate]]:
    """Score each candidate and return the best of each velocity source, and every one scored.

    Within the candidates of one velocity source, the first (plain) one is kept unless another
    predicts the held-out blocks better by more than one standard error of the paired block
    differences; between sources, :mod:`robodyn.identification.velocity_choice` decides on the
    finished models.

    Parameters
    ----------
    cands : sequence of Candidate
    stacked : callable
        ``stacked(candidate) -> Problem``; each winner's is returned so that the caller need not
        build it again.

    Returns
    -------
    (list of (Candidate, Problem, list of Candidate), list of Candidate)
        Per velocity source, in the order of ``cands``: its winner, the winner's problem and its
        scored candidates; and every scored candidate.
    """
    if len(cands) == 1:
        return [(cands[0], stacked(cands[0]), list(cands))], list(cands)
    scored: list[Candidate] = []
    # per velocity source: its best candidate so far (index, problem) and its plain candidate's
    # block errors; a losing candidate's problem is dropped at once (peak memory: two per source)
    best: dict[str, tuple[int, Problem]] = {}
    plain: dict[str, np.ndarray] = {}
    for i, cand in enumerate(cands):
        pr = stacked(cand)
        # the estimator's own row weights (per joint, from a first fit), the raw target held out;
        # squared error of each held-out block (K, L) relative to the whole target: candidates
        # with another decimation (another cut-off) have other rows, the same blocks of time
        per_block = candidate_cv_errors(pr.phi, pr.y, pr.theta0, pr.joint, pr.blocks, pr.phi_test,
                                        pr.y_test)
        per_block = per_block / max(float(pr.y_test @ pr.y_test), 1e-300)
        k = int(np.argmin(per_block.sum(axis=0)))  # each candidate at its best weight
        scored.append(replace(cand, score=float(np.sqrt(per_block[:, k].sum())),
                              lam=float(LAMBDA_GRID[k])))
        v = cand.velocity
        if v not in best:  # the source's first (plain) candidate
            best[v], plain[v] = (i, pr), per_block[:, k]
            continue
        # paired difference of the block errors against the source's plain candidate, its SE
        d = per_block[:, k] - plain[v]
        if d.sum() < -paired_se(d) and scored[i].score < scored[best[v][0]].score:
            best[v] = (i, pr)
        del pr
    out = [(scored[i], pr, [s for s, c in zip(scored, cands, strict=True) if c.velocity == v])
           for v, (i, pr) in best.items()]
    return out, scored


def cutoff_candidates(recs: list[Any], cutoff: float | str | None,
                       rule: float | None = None) -> tuple[float | str | None, ...]:
    """The cut-offs to try: a given one alone; for "auto" its rule's value and ``CUTOFF_WIDER``
    times it (below 0.2 x the slowest sampling rate), for a record whose torque holds more above
    the motion's own bandwidth (a stiff controller, a fast excitation) than its noise."""
    if cutoff != "auto":
        return (cutoff,)
    rule = resolve_preprocess(recs, "auto", "auto", auto=rule).cutoff
    fs = slowest_rate(recs)
    wide = min(CUTOFF_WIDER * rule, 0.2 * fs)
    return ("auto", wide) if wide > 1.01 * rule else ("auto",)


def reference_targets(recs: list[Any], target: str, cutoff: float | str | None,
                       rule: float | None = None) -> list[np.ndarray]:
    """The held-out target of the cross-validated choices, (N_k, n) per recording: each
    recording's target low-passed at the first (plain) candidate's cut-off, the same for every
    candidate, so that a wider cut-off wins only by better parameters, not by following the
    target's noise (the raw target when the plain candidate has no filter)."""
    cut = resolve_preprocess(recs, cutoff, 1, auto=rule).cutoff
    out = []
    for r in recs:
        y = np.asarray(getattr(r, target), float)
        out.append(y if cut is None else lowpass(np.asarray(r.t, float), y, cut, order=4))
    return out
