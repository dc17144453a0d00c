"""``simulate``: forward-dynamic simulation of a compiled model, passive or under a controller.

Methods
-------
"rk4", "semi_implicit"
    Fixed step ``dt``. With no controller or a built-in controller
    (:mod:`robodyn.simulate.controllers`) the whole run is ONE call into the generated C
    (``Model.integrate``): the controller is sampled at each step and its torque held over the
    step (zero-order hold, a digital controller running at the integration rate). A Python
    callable ``(t, q, qd) -> tau`` is sampled the same way, but the loop over the steps runs in
    Python (one ``integrate`` call per step): about 30 microseconds per step instead of a fraction
    of one (60x slower on the planar 2R arm).
"RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA"
    ``scipy.integrate.solve_ivp`` on ``Model.state_derivative`` with adaptive steps, the
    controller evaluated continuously (no hold), the output sampled every ``dt``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from robodyn.numeric.model import Model
from robodyn.simulate.controllers import Controller
from robodyn.simulate.energy import potential_energy

FIXED_STEP = ("rk4", "semi_implicit")
ADAPTIVE = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")

ControllerLike = Controller | Callable[[float, np.ndarray, np.ndarray], np.ndarray] | None


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A simulated motion, sampled every ``dt`` (all arrays read-only).

    Attributes
    ----------
    t : (N,) ndarray
        Time, s.
    q, qd, qdd : (N, n) ndarray
        Joint positions (rad, m), velocities and accelerations.
    tau : (N, n) ndarray
        Joint torques/forces (N m, N): with a fixed-step method, ``tau[k]`` is the torque held
        over ``[t_k, t_k+1)``; the last row is the law at the final state. ``qdd[k]`` is the
        acceleration at ``(q[k], qd[k], tau[k])``.
    kinetic, potential, energy : (N,) ndarray
        ``0.5 qd^T M(q) qd`` (rotor inertia included), gravitational ``V(q)`` (see
        :func:`robodyn.simulate.energy.potential_energy`) and their sum, J.
    method : str
    dt : float
        Output (and, for fixed-step methods, integration) step, s.
    controller : str
        Name of the controller ("none" when passive).
    robot : str
    backend : str
    evaluations : int
        Right-hand-side evaluations (``state_derivative`` calls).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    energy: np.ndarray
    method: str
    dt: float
    controller: str
    robot: str
    backend: str
    evaluations: int

    @property
    def x(self) -> np.ndarray:
        """States ``[q, qd]``, (N, 2 n)."""
        return np.hstack([self.q, self.qd])

    @property
    def energy_drift(self) -> float:
        """``max |E(t) - E(0)| / max(|E(0)|, max K)``: the relative energy error of a passive run."""
        scale = max(abs(float(self.energy[0])), float(np.max(self.kinetic)), 1e-300)
        return float(np.max(np.abs(self.energy - self.energy[0])) / scale)


def simulate(model: Model, q0: np.ndarray, qd0: np.ndarray | None, duration: float, dt: float,
             method: str = "rk4", controller: ControllerLike = None, *,
             tau_limit: float | np.ndarray | None = None, rtol: float = 1e-9,
             atol: float = 1e-12, control: str = "sampled") -> Trajectory:
    """Simulate ``model`` from ``(q0, qd0)`` for ``duration`` seconds.

    Parameters
    ----------
    model : Model
        From :func:`robodyn.compile_model` (either backend).
    q0 : (n,) array_like
        Initial joint positions (rad, m).
    qd0 : (n,) array_like or None
        Initial velocities (None: at rest).
    duration : float
        s, a whole number of steps ``dt``.
    dt : float
        Step (fixed-step methods) and output interval (all methods), s.
    method : {"rk4", "semi_implicit", "RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA"}
    controller : Controller, callable or None
        A built-in controller, any ``(t, q, qd) -> tau`` callable, or None (no torque).
    tau_limit : float or (n,), optional
        Actuator limits, N m (N), applied to every torque; overrides the controller's own.
    rtol, atol : float
        Tolerances of the SciPy methods.
    control : {"sampled", "continuous"}
        Fixed-step methods only. "sampled": the controller is evaluated at the start of each
        step and its torque held over the step (a digital controller at the integration rate).
        "continuous" (RK4): evaluated at every RK4 stage, a continuous-time controller tracked
        to the integrator's fourth order (built-in controllers in C; a callable from Python).
        The SciPy methods always evaluate the law wherever they evaluate the dynamics.

    Returns
    -------
    Trajectory

    Raises
    ------
    ValueError
        Wrong shapes, non-finite values, non-positive ``dt`` or ``duration``, unknown method.
    TypeError
        A controller that is neither built-in nor callable.
    FloatingPointError
        When the state stops being finite.
    """
    n = model.dof
    q0 = _vector(q0, n, "q0")
    qd0 = np.zeros(n) if qd0 is None else _vector(qd0, n, "qd0")
    dt = _positive(dt, "dt")
    duration = _positive(duration, "duration")
    steps = int(round(duration / dt))
    if steps < 1 or abs(steps * dt - duration) > 1e-9 * duration:
        raise ValueError(f"duration {duration:g} s is not a whole number of steps dt = {dt:g} s")
    if method not in FIXED_STEP + ADAPTIVE:
        raise ValueError(f"unknown method {method!r}; choose one of {', '.join(FIXED_STEP + ADAPTIVE)}")
    if control not in ("sampled", "continuous"):
        raise ValueError(f"unknown control {control!r}; choose 'sampled' or 'continuous'")
    if control == "continuous" and method == "semi_implicit":
        raise ValueError("control='continuous' needs method='rk4' or a SciPy method (semi-implicit "
                         "Euler evaluates the law once per step: use control='sampled')")
    if controller is not None and not callable(controller):
        raise TypeError(f"controller must be a built-in controller, a callable (t, q, qd) -> tau or "
                        f"None, got {type(controller).__name__}")
    limit = _tau_limit(tau_limit, n) if tau_limit is not None else None
    if limit is None and isinstance(controller, Controller) and controller.tau_limit is not None:
        limit = _tau_limit(controller.tau_limit, n)
    t = dt * np.arange(steps + 1)
    x0 = np.concatenate([q0, qd0])
    if method in FIXED_STEP:
        x, tau, evals = _fixed_step(model, x0, t, dt, method, controller, limit,
                                    control == "continuous")
    else:
        x, tau, evals = _adaptive(model, x0, t, method, controller, limit, rtol, atol)
    return _result(model, t, x, tau, method, dt, controller, evals)


def _fixed_step(model: Model, x0: np.ndarray, t: np.ndarray, dt: float, method: str,
                controller: ControllerLike, limit: np.ndarray | None,
                continuous: bool = False) -> tuple[np.ndarray, np.ndarray, int]:
    n, steps = model.dof, t.size - 1
    per_step = 4 if method == "rk4" else 1
    if controller is None or isinstance(controller, Controller):
        # continuous: the inputs sampled every dt/2, for the RK4 stages
        times = 0.5 * dt * np.arange(2 * steps + 1) if continuous else t[:-1]
        kwargs = {} if controller is None else controller.sampled(model, times)
        x, tau = model.integrate(x0, steps, dt, method, tau_limit=limit,
                                 control="continuous" if continuous else "sampled", **kwargs)
        last = np.zeros(n) if controller is None else controller.law(
            model, t[-1], x[-1], _error_integral(controller, t, x, dt, continuous))
        return x, np.vstack([tau, _clip(last, limit)]), steps * per_step
    x = np.empty((steps + 1, 2 * n))
    tau = np.empty((steps + 1, n))
    x[0] = x0
    f = model.state_derivative

    def law(tk: float, xk: np.ndarray) -> np.ndarray:
        return _clip(_call(controller, tk, xk, n), limit)

    for k in range(steps):
        tau[k] = law(t[k], x[k])
        if continuous:
            # RK4 with the callable evaluated at every stage
            k1 = f(x[k], tau[k])
            xs = x[k] + 0.5 * dt * k1
            k2 = f(xs, law(t[k] + 0.5 * dt, xs))
            xs = x[k] + 0.5 * dt * k2
            k3 = f(xs, law(t[k] + 0.5 * dt, xs))
            xs = x[k] + dt * k3
            k4 = f(xs, law(t[k] + dt, xs))
            x[k + 1] = x[k] + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        else:
            # one step with the torque held (zero-order hold)
            x[k + 1] = model.integrate(x[k], 1, dt, method, feedforward=tau[k][None])[0][1]
    tau[-1] = law(t[-1], x[-1])
    return x, tau, steps * per_step


def _error_integral(controller: Controller, t: np.ndarray, x: np.ndarray, dt: float,
                    continuous: bool) -> np.ndarray | None:
    """The error integral at the last sample, for the last row of ``tau``.

    Sampled: the C integrator's own ``dt sum_{j<=N} e_j``. Continuous: the trapezoidal rule over
    the samples (the integrator's RK4 value is not returned; this differs by O(dt^2)).
    """
    if not controller.has_integral:
        return None
    n = x.shape[1] // 2
    errors = np.array([controller.position_error(tk, xk[:n]) for tk, xk in zip(t, x, strict=True)])
    if continuous:
        return dt * (errors.sum(axis=0) - 0.5 * (errors[0] + errors[-1]))
    return dt * errors.sum(axis=0)


def _adaptive(model: Model, x0: np.ndarray, t: np.ndarray, method: str, controller: ControllerLike,
              limit: np.ndarray | None, rtol: float, atol: float) -> tuple[np.ndarray, np.ndarray, int]:
    n = model.dof
    builtin = isinstance(controller, Controller)
    extra = n if builtin and controller.has_integral else 0

    def torque(tk: float, y: np.ndarray) -> np.ndarray:
        if controller is None:
            return np.zeros(n)
        if builtin:
            z = y[2 * n:] if extra else None
            return _clip(controller.law(model, tk, y[: 2 * n], z), limit)
        return _clip(_call(controller, tk, y[: 2 * n], n), limit)

    def rhs(tk: float, y: np.ndarray) -> np.ndarray:
        xd = model.state_derivative(y[: 2 * n], torque(tk, y))
        if not extra:
            return xd
        # z' = q_ref(t) - q: the PID error integral
        return np.concatenate([xd, controller.position_error(tk, y[:n])])

    y0 = np.concatenate([x0, np.zeros(extra)])
    sol = solve_ivp(rhs, (t[0], t[-1]), y0, method=method, t_eval=t, rtol=rtol, atol=atol)
    if sol.status != 0 or sol.y.shape[1] != t.size:
        raise FloatingPointError(f"solve_ivp ({method}) failed at t = {sol.t[-1]:g} s: {sol.message}")
    y = sol.y.T
    tau = np.array([torque(tk, yk) for tk, yk in zip(t, y, strict=True)])
    return np.ascontiguousarray(y[:, : 2 * n]), tau, int(sol.nfev)


def _result(model: Model, t: np.ndarray, x: np.ndarray, tau: np.ndarray, method: str, dt: float,
            controller: ControllerLike, evals: int) -> Trajectory:
    n = model.dof
    q, qd = np.ascontiguousarray(x[:, :n]), np.ascontiguousarray(x[:, n:])
    qdd = model.forward_dynamics(q, qd, tau)
    m = model.mass_matrix(q)
    # K = 0.5 qd^T M qd
    kinetic = 0.5 * np.einsum("ki,kij,kj->k", qd, m, qd)
    potential = potential_energy(model, q)
    arrays = [t, q, qd, qdd, tau, kinetic, potential, kinetic + potential]
    for a in arrays:
        a.flags.writeable = False
    return Trajectory(*arrays, method=method, dt=dt, controller=_name(controller),
                      robot=model.robot.name, backend=model.backend, evaluations=evals)


def _call(controller: Callable, t: float, x: np.ndarray, n: int) -> np.ndarray:
    tau = np.asarray(controller(float(t), x[:n].copy(), x[n:].copy()), dtype=float)
    if tau.shape != (n,):
        raise ValueError(f"the controller returned shape {tau.shape}; it must return ({n},) torques")
    if not np.all(np.isfinite(tau)):
        raise FloatingPointError(f"the controller returned non-finite torques at t = {t:g} s")
    return tau


def _clip(tau: np.ndarray, limit: np.ndarray | None) -> np.ndarray:
    return tau if limit is None else np.clip(tau, -limit, limit)


def _name(controller: ControllerLike) -> str:
    if controller is None:
        return "none"
    if isinstance(controller, Controller):
        return controller.name
    return getattr(controller, "__name__", type(controller).__name__)


def _vector(v: np.ndarray, n: int, name: str) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    if arr.shape != (n,):
        raise ValueError(f"simulate: {name} must have shape ({n},), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"simulate: {name} contains non-finite values")
    return arr


def _positive(v: float, name: str) -> float:
    try:
        val = float(v)
    except (TypeError, ValueError):
        raise ValueError(f"simulate: {name} must be a positive number, got {v!r}") from None
    if not np.isfinite(val) or val <= 0:
        raise ValueError(f"simulate: {name} must be a positive finite number, got {v!r}")
    return val


def _tau_limit(v: float | np.ndarray, n: int) -> np.ndarray:
    arr = np.broadcast_to(np.asarray(v, dtype=float), (n,)) if np.ndim(v) == 0 else np.asarray(v, float)
    if arr.size == 1:
        arr = np.full(n, float(arr.ravel()[0]))
    if arr.shape != (n,) or np.any(~np.isfinite(arr)) or np.any(arr <= 0):
        raise ValueError(f"simulate: tau_limit must be positive, a scalar or ({n},), got {v!r}")
    return np.ascontiguousarray(arr)


__all__ = ["ADAPTIVE", "FIXED_STEP", "Trajectory", "simulate"]
