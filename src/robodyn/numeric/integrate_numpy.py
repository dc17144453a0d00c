"""The NumPy twin of the generated C integrator (``Model.integrate`` with ``backend="numpy"``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from robodyn.numeric.model import Model

__all__ = ["integrate_numpy"]


def integrate_numpy(model: Model, steps: int, dt: float, method: int, mode: int,
                     a: dict[str, np.ndarray | None], x_out: np.ndarray, tau_out: np.ndarray,
                     continuous: bool = False) -> int:
    """The NumPy twin of the generated C ``simulate`` (same law, same steps); returns its status."""
    n = model.dof
    x = a["x0"].copy()
    x_out[0] = x
    integ = np.zeros(n)
    zero = np.zeros(n)
    p = a.get("params")
    if p is not None:
        model = model.with_parameters(dict(zip(model.runtime_parameters, p.tolist(), strict=True)))
    f = model.state_derivative

    def rate(row: int, xs: np.ndarray) -> np.ndarray:
        # e_q = q_ref - q
        return (a["reference"][row, :n] if a["reference"] is not None else 0.0) - xs[:n]

    def law(row: int, xs: np.ndarray, z: np.ndarray) -> np.ndarray:
        # e = reference_row - x
        e = np.broadcast_to((a["reference"][row] if a["reference"] is not None else 0.0) - xs, (2 * n,))
        v = a["feedforward"][row].copy() if a["feedforward"] is not None else np.zeros(n)
        if a["gain"] is not None:
            v += a["gain"] @ e
        if a["integral_gain"] is not None:
            v += a["integral_gain"] * z
        # tau = M(q) v + (C qd + g + friction) under computed torque
        tau = model.mass_matrix(xs[:n]) @ v + model.inverse_dynamics(xs[:n], xs[n:], zero) if mode == 2 else v
        if mode == 1:
            tau = tau + model.gravity(xs[:n])
        if a["tau_limit"] is not None:
            tau = np.clip(tau, -a["tau_limit"], a["tau_limit"])
        return tau

    for k in range(steps):
        if continuous:
            # RK4 with the law at every stage; the error integral z is extra state, z' = e_q
            tau = law(2 * k, x, integ)
            k1, r1 = f(x, tau), rate(2 * k, x)
            xs, zs = x + 0.5 * dt * k1, integ + 0.5 * dt * r1
            k2, r2 = f(xs, law(2 * k + 1, xs, zs)), rate(2 * k + 1, xs)
            xs, zs = x + 0.5 * dt * k2, integ + 0.5 * dt * r2
            k3, r3 = f(xs, law(2 * k + 1, xs, zs)), rate(2 * k + 1, xs)
            xs, zs = x + dt * k3, integ + dt * r3
            k4, r4 = f(xs, law(2 * k + 2, xs, zs)), rate(2 * k + 2, xs)
            x = x + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            integ = integ + dt / 6.0 * (r1 + 2.0 * r2 + 2.0 * r3 + r4)
        else:
            integ = integ + rate(k, x) * dt
            tau = law(k, x, integ)
            if method == 0:
                k1 = f(x, tau)
                k2 = f(x + 0.5 * dt * k1, tau)
                k3 = f(x + 0.5 * dt * k2, tau)
                k4 = f(x + dt * k3, tau)
                x = x + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            else:
                qd = x[n:] + dt * f(x, tau)[n:]
                x = np.concatenate([x[:n] + dt * qd, qd])
        if not np.all(np.isfinite(x)):
            return k + 1
        x_out[k + 1] = x
        tau_out[k] = tau
    return 0
