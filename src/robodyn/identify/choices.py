"""Preprocessing choices of ``rd.identify`` made from the identification data by cross-validation.

A setting left at ``"auto"`` (the velocity source, the Coulomb dead band) is chosen among a few
candidates by time-block cross-validation on the identification data themselves: each
recording is cut into ``FOLDS`` contiguous blocks, each block is predicted by a fit on the
others (for every Tikhonov weight of :data:`robodyn.identify.estimate.LAMBDA_GRID`), and the
candidate whose best held-out error is lowest is kept. The fit uses the filtered regressor rows
as the identification does; the held-out block is predicted as :meth:`Identification.predict`
predicts (the unfiltered rows with the candidate's dead band,
:func:`robodyn.identify.preprocess.prediction_rows`), so that what a candidate does to a
prediction (a Coulomb sign flipping with the noise of a joint at rest) is what is scored. The
score is the relative held-out error ``sqrt(sum e^2 / sum y^2)`` against the filtered target in
torque units, rows unweighted, so that candidates with the same target compare like for like.
Held-out blocks, not the fit residual: a richer processing always fits its own data better, but
only a real gain survives a block it has not seen.

The first candidate (position differences, no dead band: the plain processing) is kept unless
another beats it by more than one standard error of the paired block differences (the
"one-standard-error rule" of cross-validation, Hastie, Tibshirani and Friedman, *The Elements
of Statistical Learning*, 7.10): differences within the blocks' own scatter are not evidence,
and a choice made on them would follow the noise of the particular recording.

:class:`Choices` records every candidate's score and why the winner was kept; it is
``Identification.choices``, printed by ``robodyn identify`` and shown in its HTML report.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from robodyn.identify.estimate import LAMBDA_GRID, cv_errors_unweighted

__all__ = ["Candidate", "Choices", "choose"]


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
        With temperature-dependent friction (:mod:`robodyn.identify.thermal`).
    """

    velocity: str
    dead_band: float
    score: float = float("nan")
    lam: float = float("nan")
    thermal: bool = False

    @property
    def key(self) -> tuple[str, float, bool]:
        """What identifies the candidate: (velocity, dead_band, thermal)."""
        return (self.velocity, self.dead_band, self.thermal)

    @property
    def label(self) -> str:
        """``velocity=..., dead_band=..., thermal=...`` as printed."""
        return (f"velocity={self.velocity}, dead_band={self.dead_band:g} rad/s"
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
        Low-pass cut-off used, Hz (its own rule: :mod:`robodyn.identify.preprocess`).
    regularization : float
        Tikhonov weight of the final fit (chosen by the same time-block cross-validation when
        ``regularization="auto"``).
    candidates : tuple of Candidate
        Every candidate tried with its score (one when nothing was left to choose).
    reason : str
        One sentence: how the winner was chosen.
    thermal : bool
        Whether temperature-dependent friction was used.
    """

    velocity: str
    dead_band: float
    cutoff: float | None
    regularization: float
    candidates: tuple[Candidate, ...]
    reason: str
    thermal: bool = False

    def summary(self) -> str:
        """A few lines for the terminal and the report."""
        cut = "none" if self.cutoff is None else f"{self.cutoff:g} Hz"
        lines = [f"velocity {self.velocity}, Coulomb dead band {self.dead_band:g} rad/s, cut-off "
                 f"{cut}, regularization {self.regularization:g}"
                 + (", thermal friction" if self.thermal else "") + f": {self.reason}"]
        if len(self.candidates) > 1:
            for c in self.candidates:
                mark = "*" if c.key == (self.velocity, self.dead_band, self.thermal) else " "
                lines.append(f"  {mark} {c.label}: held-out blocks {c.score:.4f} (lambda {c.lam:g})")
        return "\n".join(lines)


def candidates(velocity: str, dead_band: float | str, thermal: bool | str, measured_available: bool,
               temperatures_available: bool, default_band: float) -> list[Candidate]:
    """The candidates of the ``"auto"`` settings (a fixed setting is its only candidate).

    ``velocity="auto"``: position differences, and the measured velocity when every recording
    has one (not estimated); ``dead_band="auto"``: none and ``default_band``;
    ``thermal="auto"``: without, and with when every recording has temperatures.
    """
    vels = (["position", "measured"] if measured_available else ["position"]) \
        if velocity == "auto" else [velocity]
    bands = [0.0, float(default_band)] if dead_band == "auto" else [float(dead_band)]
    therms = ([False, True] if temperatures_available else [False]) if thermal == "auto" \
        else [bool(thermal)]
    return [Candidate(v, b, thermal=th) for th in therms for v in vels for b in bands]


def choose(cands: Sequence[Candidate], stacked: Callable[[Candidate], tuple[Any, ...]]
           ) -> tuple[Candidate, tuple[Any, ...], list[Candidate]]:
    """Score each candidate and return the best, its stacked problem and every scored candidate.

    Parameters
    ----------
    cands : sequence of Candidate
    stacked : callable
        ``stacked(candidate) -> (phi (m, b), y (m,), theta0 (b,), blocks (m,), phi_test (m, b),
        *rest)``: the candidate's identification problem in torque units and the prediction
        rows of the same samples; the whole tuple of the winner is returned so that the caller
        need not build it again.

    Returns
    -------
    (Candidate, tuple, list of Candidate)
    """
    if len(cands) == 1:
        return cands[0], stacked(cands[0]), list(cands)
    scored, problems, blocks_err = [], [], []
    for cand in cands:
        problem = stacked(cand)
        phi, y, theta0, blocks, phi_test = problem[:5]
        per_block = cv_errors_unweighted(phi, y, theta0, blocks, phi_test)  # (K, L)
        k = int(np.argmin(per_block.sum(axis=0)))
        scored.append(Candidate(cand.velocity, cand.dead_band,
                                float(np.sqrt(per_block[:, k].sum() / max(float(y @ y), 1e-300))),
                                float(LAMBDA_GRID[k]), cand.thermal))
        blocks_err.append(per_block[:, k])
        problems.append(problem)
    best = 0
    for i in range(1, len(scored)):
        # paired difference of the summed block errors against the plain candidate, and its SE
        d = blocks_err[i] - blocks_err[0]
        se = float(np.std(d, ddof=1) * np.sqrt(d.size)) if d.size > 1 else 0.0
        if d.sum() < -se and scored[i].score < scored[best].score:
            best = i
    return scored[best], problems[best], scored
