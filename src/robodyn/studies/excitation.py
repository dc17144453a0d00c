"""Optimal excitation trajectories for dynamic parameter identification (Swevers et al. 1997).

Each joint follows a finite Fourier series with ``L`` harmonics of the base frequency
``w_f = 2 pi f`` about an offset ``q0_i``::

    q_i(t)   = q0_i + sum_l  a_il / (w_f l) sin(w_f l t) - b_il / (w_f l) cos(w_f l t)
    qd_i(t)  =        sum_l  a_il cos(w_f l t) + b_il sin(w_f l t)
    qdd_i(t) =        sum_l -a_il w_f l sin(w_f l t) + b_il w_f l cos(w_f l t)

The motion is periodic with period ``T = 1 / f``, so it starts and ends at rest at the offset when,
at ``t = 0``::

    q_i(0) - q0_i = -sum_l b_il / (w_f l) = 0,   qd_i(0) = sum_l a_il = 0,
    qdd_i(0) = sum_l b_il w_f l = 0.

These three linear equalities are imposed *exactly by construction*: the coefficients are written
as ``a_i = N_a z_a``, ``b_i = N_b z_b`` with ``N_a``, ``N_b`` orthonormal bases of the null spaces of
the constraints (``L - 1`` free sine-side and ``L - 2`` free cosine-side numbers per joint), so no
polynomial correction is added and every period (and the whole run, ``duration`` a whole number of
periods) starts and ends with ``q = q0``, ``qd = qdd = 0``.

The design maximises the information in the identification matrix ``W``: the compiled regressor
``Y(q, qd, qdd)`` (``(n, 15 n)`` per sample, :meth:`robodyn.numeric.model.Model.regressor`) stacked
over ``K`` samples of one period, restricted to the *base columns* (a maximal linearly independent
set, found by QR with column pivoting on random states, :func:`base_columns`). The criterion is the
condition number ``cond(W) = sigma_max / sigma_min`` (``criterion="cond"``; minimised as
``log cond``) or ``-log det(W^T W)`` (``criterion="logdet"``, D-optimality). Both are minimised by
SciPy's SLSQP under the *linear* joint position, velocity and acceleration limits on the ``K``
samples, from several random feasible starts. The gradient is analytic in the Fourier
coefficients (chain rule). In the joint states it is, by default
(``gradient="finite_difference"``), central differences of the regressor (``5 n`` perturbed
copies of the samples in one batched regressor call; no extra compilation); with
``gradient="analytic"`` the compiled regressor derivatives
(:meth:`robodyn.numeric.model.Model.regressor_derivatives`, forward-mode differentiation of the
regressor's program, one batched call per gradient), 2.6-2.8x faster per gradient on the PUMA 560
(``benchmarks/bench_excitation.py``) but compiled once per robot first (about 3 minutes for the
PUMA 560 on this project's 2-core machine, then cached): worth it for repeated designs on one
robot, not for a single design of a new one. Coulomb and offset friction columns are steps in
``qd``: their derivative is zero wherever it exists, and it is taken as zero.

Limits are enforced exactly on the returned samples: after optimisation, the oscillating part is
shrunk about the offset (a scale factor <= 1) until the finely sampled trajectory is within every
limit.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import scipy.linalg
from scipy.interpolate import BPoly, PPoly
from scipy.optimize import minimize

from robodyn.identification.base import pivoted_columns
from robodyn.identification.stacking import identification_matrix as stacked_matrix
from robodyn.measure.csv_io import write_csv
from robodyn.measure.recording import Recording
from robodyn.numeric.model import Model, compile_model
from robodyn.robot.errors import InputError
from robodyn.robot.model import Robot
from robodyn.robot.sizes import time_grid_steps
from robodyn.simulation.trajectory import JointTrajectory
from robodyn.studies.excitation_limits import (
    DEFAULT_ACCELERATION,
    DEFAULT_VELOCITY,
    ExcitationLimits,
    excitation_limits,
)
from robodyn.studies.fourier_trajectory import (
    FourierTrajectory,
    _basis,
    _fit_to_limits,
    _Layout,
    _null_bases,
    random_fourier,
)
from robodyn.symbolic.regressor import JOINT_NAMES, PER_JOINT, parameter_names

Criterion = Literal["cond", "logdet"]


# Regressor columns with zero derivative almost everywhere (Coulomb +/- and offset friction).
_STEP_COLUMNS = tuple(PER_JOINT - len(JOINT_NAMES) + k for k in (2, 3, 4))


# ----------------------------------------------------------------------------------------------
# base columns and criteria
# ----------------------------------------------------------------------------------------------
def base_columns(model: Model, rng: np.random.Generator | int | None = 0, *, samples: int | None = None,
                 rtol: float = 1e-8) -> tuple[int, ...]:
    """Indices of a maximal set of linearly independent regressor columns (the base columns).

    The regressor is evaluated at ``samples`` random states (positions uniform within the joint
    limits or ``+-pi``, velocities and accelerations standard normal) and stacked; QR with column
    pivoting picks the columns, and the rank is the number of ``|R_kk| > rtol |R_00|`` after the
    columns are scaled to unit norm (so the units of the parameters do not decide the rank): the
    rule of :func:`robodyn.identification.base.pivoted_columns`, the one identification uses.

    Parameters
    ----------
    model : Model
    rng : numpy Generator or int seed or None
    samples : int, optional
        Random states, each adding n rows (default ``max(60, 30 n)``).
    rtol : float
        Rank tolerance relative to the largest pivot.

    Returns
    -------
    tuple of int
        Sorted column indices into the ``15 n`` columns of :meth:`Model.regressor`
        (names in :func:`robodyn.symbolic.regressor.parameter_names`).
    """
    gen = np.random.default_rng(rng)
    n = model.dof
    samples = max(60, 30 * n) if samples is None else int(samples)
    lo = np.array([-np.pi if j.lower is None else float(j.lower) for j in model.robot.joints])
    hi = np.array([np.pi if j.upper is None else float(j.upper) for j in model.robot.joints])
    q = gen.uniform(lo, hi, (samples, n))
    y = model.regressor(q, gen.standard_normal((samples, n)), gen.standard_normal((samples, n)))
    _, used, _, piv, rank = pivoted_columns(y.reshape(samples * n, -1), rtol)
    return tuple(sorted(int(c) for c in used[piv[:rank]]))


def identification_matrix(model: Model, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                          columns: Sequence[int]) -> np.ndarray:
    """Stacked regressor ``W`` restricted to ``columns``: (N n, p) for samples (N, n); the one
    stacking of :func:`robodyn.identification.stacking.identification_matrix`."""
    return stacked_matrix(model, q, qd, qdd, list(columns))


def condition_number(model: Model, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                     columns: Sequence[int]) -> float:
    """``sigma_max / sigma_min`` of :func:`identification_matrix` (inf when rank-deficient)."""
    s = _singular_values(identification_matrix(model, q, qd, qdd, columns))
    return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")


def _singular_values(w: np.ndarray) -> np.ndarray:
    """Singular values of a tall ``w``, largest first, from the eigenvalues of ``w^T w``.

    Relative accuracy of ``sigma_min`` about ``eps cond(w)^2``: ample below cond ~ 1e6. SciPy's
    LAPACK on the small Gram matrix stays fast where a threaded SVD of the tall matrix competes
    for busy cores (measured 100x slower on a loaded 2-core machine).
    """
    lam = scipy.linalg.eigh(w.T @ w, eigvals_only=True, driver="evr")
    return np.sqrt(np.clip(lam[::-1], 0.0, None))


# ----------------------------------------------------------------------------------------------
# result
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Excitation:
    """An optimised excitation trajectory.

    Attributes
    ----------
    series : FourierTrajectory
        The Fourier coefficients ``a``, ``b`` (n, L), offsets and base frequency.
    t : (N,) ndarray
        Sample times from 0 to ``duration``, s (step ``dt``).
    q, qd, qdd : (N, n) ndarray
        The trajectory at ``t``: rad, rad/s, rad/s^2 (m, m/s, m/s^2 for prismatic joints).
    duration : float
        s; a whole number of periods.
    condition_number : float
        ``cond(W)`` on the base columns over ``design_samples`` samples of one period.
    criterion : {"cond", "logdet"}
        What was optimised.
    logdet : float
        ``log det(W^T W / K)`` of the same matrix (``K`` samples).
    limits : ExcitationLimits
        The limits used; every sample respects them.
    columns : tuple of int
        Base columns of the regressor used in ``W``.
    column_names : tuple of str
        Their parameter names.
    joint_names : tuple of str
    starts : int
        Optimiser starts.
    history : tuple of float
        Final condition number of each start.
    elapsed : float
        Wall time of the design, s.
    """

    series: FourierTrajectory
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    duration: float
    condition_number: float
    criterion: str
    logdet: float
    limits: ExcitationLimits
    columns: tuple[int, ...]
    column_names: tuple[str, ...]
    joint_names: tuple[str, ...]
    starts: int
    history: tuple[float, ...]
    elapsed: float
    design_samples: int = 0
    _dt: float = field(default=1e-3, repr=False)

    @property
    def coefficients(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(a, b, offset)``: (n, L), (n, L), (n,)."""
        return self.series.a, self.series.b, self.series.offset

    @property
    def dof(self) -> int:
        """Number of joints n."""
        return self.q.shape[1]

    def at(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, qd, qdd)`` at any time(s), exact (the series); (n,) each for a scalar t."""
        tt = np.atleast_1d(np.asarray(t, dtype=float))
        q, qd, qdd = self.series.evaluate(tt)
        if np.ndim(t) == 0:
            return q[0], qd[0], qdd[0]
        return q, qd, qdd

    def trajectory(self, knot_step: float = 0.01) -> JointTrajectory:
        """The motion as a :class:`~robodyn.simulation.trajectory.JointTrajectory` (a reference
        for :func:`robodyn.simulation` controllers): quintic Hermite pieces matching q, qd, qdd of
        the series exactly at knots every ``knot_step`` s."""
        steps = max(1, int(np.ceil(self.duration / knot_step - 1e-9)))
        tk = np.linspace(0.0, self.duration, steps + 1)
        q, qd, qdd = self.series.evaluate(tk)
        y = np.stack([q, qd, qdd], axis=1)  # (K, 3, n)
        pp = PPoly.from_bernstein_basis(BPoly.from_derivatives(tk, y))
        return JointTrajectory(self.t, self.q, self.qd, self.qdd, duration=self.duration,
                               kind="fourier excitation", _pp=pp)

    def to_csv(self, path: str | Path) -> Path:
        """Write ``t, q[joint]..., qd[joint]..., qdd[joint]...`` (s, rad, rad/s, rad/s^2), one
        row per sample, for a controller to play. Returns the path."""
        return write_trajectory_csv(path, self.t, self.q, self.qd, self.qdd, self.joint_names)


def write_trajectory_csv(path: str | Path, t: np.ndarray, q: np.ndarray, qd: np.ndarray,
                         qdd: np.ndarray, joint_names: Sequence[str]) -> Path:
    """Write a sampled joint trajectory (each array (N, n), ``t`` (N,)) in robodyn's recording
    layout: ``t, q[NAME]..., qd[NAME]..., qdd[NAME]...``; SI units (s, rad, rad/s, rad/s^2), 17
    significant digits. It reads back with :func:`robodyn.read_recording` (``robodyn record``) as the
    same numbers (:func:`robodyn.measure.csv_io.write_csv`)."""
    rec = Recording(t=np.asarray(t, float), q=np.asarray(q, float), qd=np.asarray(qd, float),
                    qdd=np.asarray(qdd, float), joint_names=tuple(joint_names), source=str(path))
    return write_csv(rec, path)


# ----------------------------------------------------------------------------------------------
# design
# ----------------------------------------------------------------------------------------------
def _starts(starts: int, progress: bool) -> Any:
    """``range(starts)``, with a progress bar on stderr when asked."""
    if not progress:
        return range(starts)
    from tqdm import tqdm

    return tqdm(range(starts), desc="optimising the excitation", unit="start", leave=False)


#: Accepted base frequencies of an excitation, Hz: a period of 0.01 s to 10^4 s (2.8 h).
BASE_FREQUENCY = (1e-4, 100.0)


def _checked_frequency(base_frequency: float, harmonics: int, dt: float) -> float:
    """The base frequency, Hz, within :data:`BASE_FREQUENCY` and with its highest harmonic
    sampled at least 4 times per period by ``dt`` (s), else :class:`InputError`."""
    f = float(base_frequency)
    if not np.isfinite(f) or not BASE_FREQUENCY[0] <= f <= BASE_FREQUENCY[1]:
        raise InputError(f"excitation: base_frequency must be a number of Hz in "
                         f"[{BASE_FREQUENCY[0]:g}, {BASE_FREQUENCY[1]:g}] (a period of 0.01 s to "
                         f"{1 / BASE_FREQUENCY[0]:g} s), got {base_frequency!r}")
    if isinstance(dt, int | float) and not isinstance(dt, bool) and np.isfinite(dt) and dt > 0 \
            and harmonics * f * dt > 0.25:
        raise InputError(f"excitation: dt {dt:g} s samples the highest harmonic ({harmonics} x "
                         f"{f:g} Hz) fewer than 4 times per period; use dt <= "
                         f"{0.25 / (harmonics * f):.3g} s")
    return f


def excitation(robot: Robot | Model, harmonics: int = 5, base_frequency: float = 0.1,
               duration: float | None = None, limits: ExcitationLimits | None = None, *,
               criterion: Criterion = "cond", starts: int = 6, seed: int = 0, dt: float = 1e-3,
               design_samples: int | None = None, max_iterations: int = 40,
               columns: Sequence[int] | None = None,
               gradient: Literal["analytic", "finite_difference"] = "finite_difference",
               progress: bool = False) -> Excitation:
    """Design an optimal periodic excitation trajectory (finite Fourier series, Swevers 1997).

    Parameters
    ----------
    robot : Robot or Model
        A description (compiled with :func:`robodyn.compile_model`) or a compiled model.
    harmonics : int
        Harmonics L per joint (>= 3: the rest-to-rest constraints use three of the 2 L + 1
        numbers per joint).
    base_frequency : float
        ``f``, Hz, in :data:`BASE_FREQUENCY`; the period is ``1 / f`` and the highest frequency
        ``L f`` (sampled at least 4 times per period by ``dt``).
    duration : float, optional
        Length of the returned trajectory, s: a whole number of periods (default one period).
    limits : ExcitationLimits, optional
        Default :func:`excitation_limits` of the robot.
    criterion : {"cond", "logdet"}
        Minimise ``log cond(W)`` or ``-log det(W^T W)``.
    starts : int
        Random feasible starts of the optimiser (multi-start); the best result is kept.
    seed : int
        Seed of the starts and of the base-column search.
    dt : float
        Sampling step of the returned arrays, s.
    design_samples : int, optional
        Samples of one period in ``W`` and in the limit constraints (default ``20 L``).
    max_iterations : int
        SLSQP iterations per start.
    columns : sequence of int, optional
        Regressor columns to use (default :func:`base_columns`).
    gradient : {"finite_difference", "analytic"}
        How the criterion's gradient is differentiated in the joint states: central
        differences of the regressor (default), or the compiled regressor derivatives (the first
        design for a robot compiles them, which takes minutes for a six-joint arm, then cached).
    progress : bool
        A progress bar over the starts on stderr (the command line's).

    Returns
    -------
    Excitation

    Raises
    ------
    ValueError
        On a bad argument (non-positive frequency, duration not a whole number of periods,
        limits for another number of joints, unknown criterion).
    """
    t_start = time.perf_counter()
    model = robot if isinstance(robot, Model) else compile_model(robot)
    n = model.dof
    if not isinstance(harmonics, int | np.integer) or harmonics < 3:
        raise InputError(f"excitation: harmonics must be an integer >= 3, got {harmonics!r}")
    f = _checked_frequency(base_frequency, harmonics, dt)
    period = 1.0 / f
    total = period if duration is None else float(duration)
    periods = total / period
    if not np.isfinite(periods) or periods < 1 - 1e-9 or abs(periods - round(periods)) > 1e-6:
        raise InputError(f"excitation: duration {duration!r} s must be a whole number of periods "
                         f"(1 / base_frequency = {period:g} s)")
    # t, q, qd, qdd evaluated and written: bounded before the design starts
    time_grid_steps(total, dt, "excitation", duration_name="duration (whole periods)",
                    values_per_sample=1 + 3 * n)
    if criterion not in ("cond", "logdet"):
        raise InputError(f"excitation: unknown criterion {criterion!r}; choose 'cond' or 'logdet'")
    if starts < 1:
        raise InputError(f"excitation: starts must be >= 1, got {starts!r}")
    if gradient not in ("analytic", "finite_difference"):
        raise InputError(f"excitation: unknown gradient {gradient!r}; choose 'analytic' or "
                         "'finite_difference'")
    lim = excitation_limits(model.robot) if limits is None else limits
    if lim.dof != n:
        raise InputError(f"excitation: limits are for {lim.dof} joints, the robot has {n}")
    rng = np.random.default_rng(seed)
    cols = base_columns(model, rng) if columns is None else tuple(int(c) for c in columns)
    k = int(design_samples or 20 * harmonics)
    na, nb = _null_bases(harmonics, f)
    layout = _Layout(n, harmonics, na, nb)
    problem = _Problem(model, layout, f, k, cols, lim, criterion, gradient)
    best: tuple[float, FourierTrajectory] | None = None
    history = []
    for _ in _starts(starts, progress):
        x0 = layout.pack(random_fourier(lim, harmonics, f, rng, samples=k))
        problem.best = (np.inf, x0)
        minimize(problem.objective, x0, jac=True, method="SLSQP",
                 constraints=[{"type": "ineq", "fun": problem.slack, "jac": problem.slack_jacobian}],
                 options={"maxiter": max_iterations, "ftol": 1e-9})
        # the best feasible point visited: the criterion is not smooth where the extreme singular
        # values cross, and SLSQP's last iterate is not always its best
        res_x = problem.best[1]
        # keep the result inside the limits on a fine grid (SLSQP may end slightly outside)
        traj = _fit_to_limits(layout.series(res_x, f), lim, 20 * k, shrink_only=True)
        t_d = np.arange(k) * period / k
        c = condition_number(model, *traj.evaluate(t_d), cols)
        score = c if criterion == "cond" else -_logdet(model, traj, t_d, cols)
        history.append(c)
        if best is None or score < best[0]:
            best = (score, traj)
    assert best is not None
    traj = best[1]
    steps = int(round(total / dt))
    t = np.linspace(0.0, steps * dt, steps + 1)
    # the continuous motion, checked on a grid 10x finer than the output, must stay within the
    # limits: shrink the oscillation about the offset where needed, with a 1e-6 relative margin
    # (far above the excess possible between those check points)
    t_check = np.linspace(0.0, period, 10 * max(1, int(round(period / dt))) + 1)
    s_fit = _shrink_factor(*traj.evaluate(t_check), traj.offset, lim)
    if s_fit < 1.0:
        traj = traj.scaled(s_fit * (1.0 - 1e-6))
    q, qd, qdd = traj.evaluate(t)
    # rest at both ends (exact in the series; remove rounding of the sines)
    for arr, ref in ((q, traj.offset), (qd, 0.0), (qdd, 0.0)):
        arr[0] = arr[-1] = ref
    t_d = np.arange(k) * period / k
    cond = condition_number(model, *traj.evaluate(t_d), cols)
    names = parameter_names(n)
    for arr in (t, q, qd, qdd):
        arr.flags.writeable = False  # read-only in place: no second copy of the samples
    return Excitation(series=traj, t=t, q=q, qd=qd, qdd=qdd,
                      duration=float(steps * dt), condition_number=cond, criterion=criterion,
                      logdet=_logdet(model, traj, t_d, cols), limits=lim, columns=cols,
                      column_names=tuple(names[c] for c in cols), joint_names=model.robot.joint_names,
                      starts=starts, history=tuple(history), elapsed=time.perf_counter() - t_start,
                      design_samples=k, _dt=dt)


def _shrink_factor(q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, off: np.ndarray,
                   lim: ExcitationLimits) -> float:
    dq = q - off
    ratio = max(np.max(np.where(dq > 0, dq / (lim.upper - off), -dq / (off - lim.lower))),
                np.max(np.abs(qd) / lim.velocity), np.max(np.abs(qdd) / lim.acceleration))
    return min(1.0, 1.0 / ratio)


def _logdet(model: Model, traj: FourierTrajectory, t: np.ndarray, cols: Sequence[int]) -> float:
    s = _singular_values(identification_matrix(model, *traj.evaluate(t), cols))
    # log det(W^T W / K) = 2 sum log sigma - p log K
    return float(2.0 * np.sum(np.log(s)) - s.size * np.log(t.size))


class _Problem:
    """Objective, gradient and linear limit constraints of one design (x as in :class:`_Layout`)."""

    def __init__(self, model: Model, layout: _Layout, f: float, k: int, cols: Sequence[int],
                 lim: ExcitationLimits, criterion: str, gradient: str = "analytic") -> None:
        self.model, self.layout, self.cols, self.criterion = model, layout, list(cols), criterion
        self.gradient = gradient
        n, m = layout.n, layout.per_joint
        t = np.arange(k) / (k * f)
        sq, sqd, sqdd = _basis(t, layout.harmonics, f)
        jm = layout.joint_map()
        # d(q_i, qd_i, qdd_i)(t_k) / d x_i: (K, per_joint) each; the offset enters q only
        self.dq = np.hstack([np.ones((k, 1)), sq @ jm])
        self.dqd = np.hstack([np.zeros((k, 1)), sqd @ jm])
        self.dqdd = np.hstack([np.zeros((k, 1)), sqdd @ jm])
        self.n, self.m, self.k = n, m, k
        self.step_cols = np.array([c for c in range(PER_JOINT * n) if c % PER_JOINT in _STEP_COLUMNS])
        # constraints g(x) >= 0, linear: rows for upper/lower q, +-qd, +-qdd per joint and sample
        blocks = []
        consts = []
        for i in range(n):
            for d, bound in ((self.dq, None), (self.dqd, lim.velocity[i]), (self.dqdd, lim.acceleration[i])):
                jac = np.zeros((2 * k, n * m))
                jac[:k, i * m:(i + 1) * m] = -d
                jac[k:, i * m:(i + 1) * m] = d
                blocks.append(jac)
                if bound is None:
                    consts.append(np.concatenate([np.full(k, lim.upper[i]), np.full(k, -lim.lower[i])]))
                else:
                    consts.append(np.full(2 * k, bound))
        self.g_jac = np.vstack(blocks)
        self.g_const = np.concatenate(consts)
        self.g_scale = float(np.max(np.abs(self.g_const)))
        self.best: tuple[float, np.ndarray] = (np.inf, np.zeros(n * m))

    def states(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        xs = x.reshape(self.n, self.m)
        return self.dq @ xs.T, self.dqd @ xs.T, self.dqdd @ xs.T

    def slack(self, x: np.ndarray) -> np.ndarray:
        return self.g_const + self.g_jac @ x

    def slack_jacobian(self, x: np.ndarray) -> np.ndarray:
        return self.g_jac

    def objective(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """Criterion value and its gradient with respect to x."""
        states = self.states(x)
        y = self.model.regressor(*states)  # (K, n, P)
        feasible = np.min(self.slack(x)) >= -1e-9 * self.g_scale
        w = y.reshape(-1, y.shape[-1])[:, self.cols]
        # eigen-decomposition of the Gram matrix W^T W (p x p): much cheaper than an SVD of the
        # tall W and accurate enough for the condition numbers met here (lambda = sigma^2);
        # SciPy's LAPACK, which stays fast when NumPy's threaded BLAS competes for busy cores
        lam, v = scipy.linalg.eigh(w.T @ w, driver="evr")
        if lam[0] <= lam[-1] * 1e-24:
            return 1e3, np.zeros_like(x)
        if self.criterion == "cond":
            # log cond = (log l_max - log l_min) / 2;  d l_i = 2 v_i^T W^T dW v_i
            value = float(0.5 * np.log(lam[-1] / lam[0]))
            g = w @ (np.outer(v[:, -1], v[:, -1]) / lam[-1] - np.outer(v[:, 0], v[:, 0]) / lam[0])
        else:
            # -log det(W^T W);  d = -2 tr((W^T W)^-1 W^T dW)
            value = float(-np.sum(np.log(lam)))
            g = -2.0 * w @ ((v / lam) @ v.T)
        if feasible and value < self.best[0]:
            self.best = (value, x.copy())
        gk = g.reshape(y.shape[0], y.shape[1], len(self.cols))  # (K, n, p) over the columns
        if self.gradient == "analytic":
            dots = self.state_gradient(states, gk)
        else:
            dots = self.state_gradient_fd(states, y, gk)
        grad = np.zeros((self.n, self.m))
        n = self.n
        for i in range(n):
            # d value / d x_i = sum_k (dV/dq_i dq_i/dx_i + dV/dqd_i dqd_i/dx_i + dV/dqdd_i ...)
            grad[i] = dots[i] @ self.dq + dots[n + i] @ self.dqd + dots[2 * n + i] @ self.dqdd
        return value, grad.ravel()

    def state_gradient(self, states: tuple[np.ndarray, ...], gk: np.ndarray) -> np.ndarray:
        """``d value / d [q, qd, qdd](t_k)``, (3 n, K), by the compiled regressor derivatives.

        ``gk`` (K, n, p): ``d value / d Y`` on the design columns.
        """
        parts = self.model.regressor_derivatives(*states)  # 3 x (K, n, P, n), views
        k, n, p = parts[0].shape[:3]
        g = np.zeros((k, 1, n * p))
        g.reshape(k, n, p)[:, :, self.cols] = gk
        # dV/ds_v(t_k) = sum_jc G_kjc dY_kjc/ds_v: one (1, n P) x (n P, n) product per sample
        return np.concatenate([(g @ d.reshape(k, n * p, n))[:, 0, :] for d in parts], axis=1).T

    def state_gradient_fd(self, states: tuple[np.ndarray, ...], y: np.ndarray,
                          gk: np.ndarray) -> np.ndarray:
        """:meth:`state_gradient` by central differences of the regressor in the states."""
        # central differences in q and qd, a one-sided one in qdd (Y is linear in qdd: exact),
        # all 5 n perturbed copies of the K states in one batched regressor call
        n, h = self.n, 1e-6
        shifts = [(which, i, sign) for which in (0, 1) for i in range(n) for sign in (1.0, -1.0)]
        shifts += [(2, i, 1.0) for i in range(n)]
        batch = [np.repeat(st[None], len(shifts), axis=0) for st in states]  # (S, K, n) each
        for s_idx, (which, i, sign) in enumerate(shifts):
            batch[which][s_idx, :, i] += sign * h
        yb = self.model.regressor(*(b.reshape(-1, n) for b in batch)).reshape((len(shifts),) + y.shape)
        yb[..., self.step_cols] = 0.0
        # d value / d state(t_k) = sum over the rows of sample k of G . dY
        dots = np.einsum("skjp,kjp->sk", yb[..., self.cols], gk)
        y0 = y[..., self.cols].copy()
        y0[..., np.isin(self.cols, self.step_cols)] = 0.0
        dots0 = np.einsum("kjp,kjp->k", y0, gk)
        out = np.empty((3 * n, y.shape[0]))
        for which in (0, 1):
            for i in range(n):
                plus = 2 * (which * n + i)
                out[which * n + i] = (dots[plus] - dots[plus + 1]) / (2 * h)
        out[2 * n:] = (dots[4 * n:] - dots0) / h
        return out


__all__ = [
    "DEFAULT_ACCELERATION",
    "DEFAULT_VELOCITY",
    "Excitation",
    "ExcitationLimits",
    "FourierTrajectory",
    "base_columns",
    "condition_number",
    "excitation",
    "excitation_limits",
    "identification_matrix",
    "random_fourier",
    "write_trajectory_csv",
]
