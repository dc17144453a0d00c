"""SciPy ``solve_ivp`` peers at matched accuracy (issue 22, item 1d).

Two routes, each swept over tolerances from loose to tight until its error against a fine
reference is within :data:`MATCH_FACTOR` of robodyn's own error (the loosest matching
tolerance is the peer's setting; "matched accuracy"; where no tolerance of the sweep gets
there, the most accurate trial is timed instead and labelled as not matched):

* the usual Python route: RK45 over ``sympy.lambdify`` of robodyn's own M(q) and h(q, qd),
  ``np.linalg.solve`` per call (``peers.lambdified_rhs``);
* SciPy at its best: DOP853 (8th order) over robodyn's compiled right-hand side,
  ``Model.state_derivative`` called by ``solve_ivp`` once per stage (one state per call from
  Python: solve_ivp's explicit methods evaluate one state at a time).

Each sweep point runs once (its time is printed, "one run"); the matched settings are then timed
in rounds with the other rows of the benchmark. Run by ``bench_simulation.py`` and
``bench_hydro.py``; nothing here is a unit test.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

import robodyn as rd

#: A peer matches when its max error is at most this many times robodyn's.
MATCH_FACTOR = 2.0
#: Relative tolerances tried, loose to tight; ``atol = rtol * ATOL_RATIO``.
RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13)
ATOL_RATIO = 1e-2

Rhs = Callable[[float, np.ndarray], np.ndarray]


def compiled_rhs(model: rd.Model) -> Rhs:
    """``f(t, x) = Model.state_derivative(x, 0)``: robodyn's generated C, one state per call."""
    zero = np.zeros(model.dof)

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        return model.state_derivative(x, zero)

    return rhs


@dataclass
class Trial:
    """One ``solve_ivp`` run of a sweep.

    Attributes
    ----------
    rtol, atol : float
        Tolerances.
    ms : float
        Wall time of the run, ms (one run).
    rhs_calls : int
        ``nfev``.
    max_error : float
        Max |x - x_ref| over the output times and states.
    """

    rtol: float
    atol: float
    ms: float
    rhs_calls: int
    max_error: float


def solver(rhs: Rhs, method: str, x0: np.ndarray, t_eval: np.ndarray, rtol: float,
           ) -> Callable[[], Any]:
    """A callable running ``solve_ivp`` over ``[0, t_eval[-1]]`` with output at ``t_eval``."""
    from scipy.integrate import solve_ivp

    def run() -> Any:
        return solve_ivp(rhs, (0.0, float(t_eval[-1])), x0, method=method, t_eval=t_eval,
                         rtol=rtol, atol=rtol * ATOL_RATIO)

    return run


def sweep(rhs: Rhs, method: str, x0: np.ndarray, t_eval: np.ndarray, reference: np.ndarray,
          target: float, rtols: Sequence[float] = RTOLS, log: Callable[[str], None] = print,
          label: str = "") -> tuple[list[Trial], Trial | None]:
    """Tolerances from loose to tight until the error is at most ``target``.

    Parameters
    ----------
    rhs : callable
        ``f(t, x)``.
    method : str
        ``solve_ivp`` method.
    x0 : ndarray
        Initial state.
    t_eval : ndarray
        Output times (from 0).
    reference : ndarray (len(t_eval), len(x0))
        The fine reference at ``t_eval``.
    target : float
        Error to reach (``MATCH_FACTOR`` times robodyn's).
    rtols : sequence of float
        Tolerances to try, loose to tight.
    log : callable
        Receives one line per trial.
    label : str
        Printed before each trial.

    Returns
    -------
    trials : list of Trial
    matched : Trial or None
        The first (loosest) trial within ``target``; None if none was.
    """
    trials = []
    for rtol in rtols:
        start = time.perf_counter()
        sol = solver(rhs, method, x0, t_eval, rtol)()
        elapsed = time.perf_counter() - start
        err = float(np.max(np.abs(sol.y.T - reference))) if sol.success else float("inf")
        trial = Trial(rtol, rtol * ATOL_RATIO, round(elapsed * 1e3, 2), int(sol.nfev), err)
        trials.append(trial)
        log(f"  {label} rtol {rtol:.0e}: {trial.ms:9.1f} ms (one run), {trial.rhs_calls} rhs "
            f"calls, max |x - x_ref| = {err:.1e}")
        if err <= target:
            return trials, trial
    return trials, None


def timed_setting(trials: list[Trial], matched: Trial | None) -> tuple[Trial, str]:
    """The trial to time and how to label it: the matched one, else the most accurate one.

    Returns
    -------
    trial : Trial
    label : str
        ``"matched"`` or, e.g., ``"not matched: its least error of the sweep, 5.8e-10"``.
    """
    if matched is not None:
        return matched, "matched"
    best = min(trials, key=lambda t: t.max_error)
    return best, f"not matched: its least error of the sweep, {best.max_error:.1e}"


def describe(method: str, trial: Trial, matched: bool) -> str:
    """What a timed ``solve_ivp`` row runs: method, tolerances, how they were chosen, rhs calls."""
    import scipy

    how = (f"the loosest of the sweep within {MATCH_FACTOR:g}x robodyn's error" if matched else
           f"NOT matched: no rtol down to {RTOLS[-1]:.0e} came within {MATCH_FACTOR:g}x "
           "robodyn's error, its most accurate trial")
    return (f"SciPy {scipy.__version__} solve_ivp {method}, adaptive steps, rtol {trial.rtol:.0e} "
            f"(atol {trial.atol:.0e}; {how}), output on robodyn's time grid (t_eval, from its "
            f"dense output), {trial.rhs_calls} right-hand sides")


def sweep_record(trials: list[Trial], matched: Trial | None, method: str, rhs: str,
                 target: float) -> dict[str, Any]:
    """The results-file form of a sweep: every trial, the timed one, and what it compares.

    ``timed`` is the matched trial, or the most accurate one with ``matched`` None.
    """
    timed, _ = timed_setting(trials, matched)
    return {"method": method, "rhs": rhs, "target_error": target,
            "atol": f"rtol * {ATOL_RATIO:g}", "trials": [asdict(t) for t in trials],
            "matched": asdict(matched) if matched is not None else None,
            "timed": asdict(timed)}
