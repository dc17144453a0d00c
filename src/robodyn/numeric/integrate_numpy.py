"""The NumPy twin of the generated C integrator (``Model.integrate`` with ``backend="numpy"``).

Both are built from the descriptions of :mod:`robodyn.codegen.fixed_step`: the same RK4
tableau, the same semi-implicit Euler step and the same sampled law, in the same order.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robodyn.codegen.fixed_step import RK4, law, semi_implicit_step

if TYPE_CHECKING:
    from robodyn.numeric.model import Model

__all__ = ["integrate_numpy"]


def integrate_numpy(model: Model, steps: int, dt: float, method: int, mode: int,
                    a: dict[str, np.ndarray | None], x_out: np.ndarray, tau_out: np.ndarray,
                    continuous: bool = False) -> int:
    """The NumPy twin of the generated C ``simulate`` (same law, same steps); returns its status.

    ``a`` holds ``x0`` (2 n,) and the law's inputs (:func:`robodyn.codegen.fixed_step.law`);
    ``x_out`` (steps + 1, 2 n) and ``tau_out`` (steps, n) are written in place.
    """
    n = model.dof
    x = a["x0"].copy()
    x_out[0] = x
    integ = np.zeros(n)
    zero = np.zeros(n)
    p = a.get("params")
    if p is not None:
        model = model.with_parameters(dict(zip(model.runtime_parameters, p.tolist(), strict=True)))
    f = model.state_derivative
    terms = {"mass_matrix": lambda q, qd: model.mass_matrix(q),
             "bias": lambda q, qd: model.inverse_dynamics(q, qd, zero),
             "gravity": lambda q, qd: model.gravity(q)}

    def torque(row: int, xs: np.ndarray, z: np.ndarray) -> np.ndarray:
        return law(a, row, xs, z, mode, lambda name, q, qd: terms[name](q, qd))

    def rate(row: int, xs: np.ndarray) -> np.ndarray:
        # e_q = q_ref - q
        return (a["reference"][row, :n] if a["reference"] is not None else 0.0) - xs[:n]

    for k in range(steps):
        if continuous:
            # RK4 with the law at every stage; the error integral z is extra state, z' = e_q
            tau = torque(2 * k, x, integ)

            def slopes(i: int, s: tuple[np.ndarray, ...], k: int = k, tau: np.ndarray = tau
                       ) -> tuple[np.ndarray, np.ndarray]:
                row = 2 * k + RK4.rows[i]
                return f(s[0], tau if i == 0 else torque(row, s[0], s[1])), rate(row, s[0])

            x, integ = RK4.step((x, integ), dt, slopes)
        else:
            integ = integ + rate(k, x) * dt
            tau = torque(k, x, integ)
            if method == 0:
                x = RK4.step((x,), dt, lambda i, s, tau=tau: (f(s[0], tau),))[0]
            else:
                x = semi_implicit_step(x, dt, f(x, tau)[n:])
        if not np.all(np.isfinite(x)):
            return k + 1
        x_out[k + 1] = x
        tau_out[k] = tau
    return 0
