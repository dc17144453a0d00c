"""Simulation over short windows: start from the measured state, drive by the measured torque.

An open-loop simulation of a real arm drifts away from the measured motion within a fraction of
a second (unmodelled friction, noise in the torque, the missing controller), so a long run says
little. Restarting from the measured state every ``window`` seconds and measuring how far the
simulated positions drift by the end of each window tests the forward dynamics the way the
inverse-dynamics error tests the inverse dynamics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robodyn.numeric.model import Model
from robodyn.robot.errors import InputError
from robodyn.simulation.rollouts import FeedbackLaw, RolloutOptions, rollout

__all__ = ["WindowDrift", "simulate_windows"]


@dataclass(frozen=True, eq=False)
class WindowDrift:
    """Drift of windowed simulations from the measured motion (arrays read-only).

    Attributes
    ----------
    window : float
        Window length, s.
    dt : float
        Integration step (the recording's median sample period), s.
    starts : (W,) ndarray
        Start time of each window, s.
    final : (W, n) ndarray
        ``|q_sim - q_meas|`` at the end of each window, rad (m); NaN where the simulation
        stopped being finite.
    rms : (W, n) ndarray
        RMS of ``q_sim - q_meas`` over each window, rad (m).
    velocity_final : (W, n) ndarray
        ``|qd_sim - qd_meas|`` at the end of each window, rad/s (m/s).
    baseline_final : (W, n) ndarray
        The same end-of-window drift for the model-free guess ``q0 + qd0 (t - t0)`` (constant
        velocity): a model worth having drifts less.
    failed : int
        Windows whose simulation stopped being finite.
    """

    window: float
    dt: float
    starts: np.ndarray
    final: np.ndarray
    rms: np.ndarray
    velocity_final: np.ndarray
    baseline_final: np.ndarray
    failed: int

    @property
    def median_final(self) -> np.ndarray:
        """Median end-of-window drift per joint, (n,)."""
        return _nan_stat(np.nanmedian, self.final)

    @property
    def max_final(self) -> np.ndarray:
        """Largest end-of-window drift per joint, (n,)."""
        return _nan_stat(np.nanmax, self.final)

    @property
    def median_baseline(self) -> np.ndarray:
        """Median end-of-window drift of the constant-velocity guess per joint, (n,)."""
        return _nan_stat(np.nanmedian, self.baseline_final)


def _nan_stat(fn, values: np.ndarray) -> np.ndarray:
    if values.size == 0 or np.all(np.isnan(values)):
        return np.full(values.shape[1], np.nan)
    with np.errstate(all="ignore"):
        return fn(values, axis=0)


def simulate_windows(model: Model, t: np.ndarray, q: np.ndarray, qd: np.ndarray, tau: np.ndarray,
                     window: float = 0.2, q_measured: np.ndarray | None = None) -> WindowDrift:
    """Simulate consecutive windows from the measured state under the measured torque.

    Each window starts at a sample ``i0`` (windows tile the recording without overlap), from
    ``x0 = [q[i0], qd[i0]]``, and is integrated by RK4 at the median sample period with the
    measured torque, linearly interpolated to the step times, held over each step. The
    measured positions are interpolated to the same times for the comparison, so irregular
    time stamps are handled.

    Parameters
    ----------
    model : Model
    t : (N,) array_like
        Sample times, s, strictly increasing.
    q, qd : (N, n) array_like
        Measured positions (rad, m) and velocities (rad/s, m/s).
    tau : (N, n) array_like
        Measured joint torques (N m, N) driving the simulation.
    window : float
        Window length, s.
    q_measured : (N, n) array_like, optional
        Positions the simulation is compared with (default ``q``; e.g. the raw positions when
        ``q``, ``qd`` are filtered start states).

    Returns
    -------
    WindowDrift

    Raises
    ------
    ValueError
        When ``window`` is not positive or shorter than two sample periods, or the recording is
        shorter than one window.
    """
    t = np.asarray(t, dtype=float)
    q, qd, tau = (np.asarray(a, dtype=float) for a in (q, qd, tau))
    q_ref = q if q_measured is None else np.asarray(q_measured, dtype=float)
    dt = float(np.median(np.diff(t)))
    if not window > 0:
        raise InputError(f"simulation window must be positive, got {window:g} s")
    steps = int(round(window / dt))
    if steps < 2:
        raise InputError(f"simulation window {window:g} s is shorter than two sample periods "
                         f"({dt:g} s each)")
    span = steps * dt
    if t[-1] - t[0] < span:
        raise InputError(f"the recording ({t[-1] - t[0]:.4g} s) is shorter than one simulation "
                         f"window ({span:.4g} s)")
    n = model.dof
    options = RolloutOptions(steps, dt, "rk4")
    starts, finals, rmss, vfinals, bases = [], [], [], [], []
    failed = 0
    t0 = t[0]
    while t0 + span <= t[-1] + 1e-9 * span:
        i0 = int(np.searchsorted(t, t0 - 1e-9 * dt))
        t0 = t[i0]
        if t0 + span > t[-1] + 1e-9 * span:
            break
        grid = t0 + dt * np.arange(steps + 1)
        ff = _interp(grid[:-1], t, tau)
        q_meas = _interp(grid, t, q_ref)
        qd_end = _interp(grid[-1:], t, qd)[0]
        x0 = np.concatenate([q[i0], qd[i0]])
        try:
            x, _ = rollout(model, x0, options, FeedbackLaw(feedforward=ff))
        except FloatingPointError:
            failed += 1
            x = np.full((steps + 1, 2 * n), np.nan)
        e = x[:, :n] - q_meas
        starts.append(t0)
        finals.append(np.abs(e[-1]))
        rmss.append(np.sqrt(np.mean(e**2, axis=0)))
        vfinals.append(np.abs(x[-1, n:] - qd_end))
        # model-free guess: q(t) = q0 + qd0 (t - t0)
        bases.append(np.abs(q[i0] + qd[i0] * span - q_meas[-1]))
        t0 = t0 + span
    arrays = [np.array(a).reshape(-1, n) for a in (finals, rmss, vfinals, bases)]
    out = WindowDrift(float(window), dt, np.array(starts), *arrays, failed)
    for arr in (out.starts, *arrays):
        arr.flags.writeable = False
    return out


def _interp(x: np.ndarray, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """Column-wise linear interpolation of ``fp`` (N, n) at ``x`` (K,) -> (K, n)."""
    return np.column_stack([np.interp(x, xp, fp[:, k]) for k in range(fp.shape[1])])
