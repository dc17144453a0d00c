"""The stepping engines behind :func:`robodyn.simulation.simulate`.

Fixed steps in one call into the generated C (a run or an ensemble, piece by piece for bounded
memory), a Python loop for a Python controller, ``scipy.integrate.solve_ivp`` for the adaptive
methods; and the diagnosis of a run whose state stopped being finite.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
from scipy.integrate import solve_ivp

from robodyn.codegen.fixed_step import RK4
from robodyn.numeric.model import Model
from robodyn.robot.errors import InputError, SimulationError
from robodyn.simulation.controllers import Controller
from robodyn.simulation.rollouts import MAX_INTEGRATE_BYTES, FeedbackLaw, RolloutOptions, rollout

#: Steps per call into the generated integrator: long runs are integrated piece by piece so that
#: memory is bounded by the kept samples, not by the number of steps.
CHUNK_STEPS = 65_536

ControllerLike = Controller | Callable[[float, np.ndarray, np.ndarray], np.ndarray] | None


def _controller_model(controller: ControllerLike, model: Model) -> Model | None:
    """The controller's own model when it differs from the plant's, else None."""
    own = getattr(controller, "model", None) if isinstance(controller, Controller) else None
    if own is None or own is model:
        return None
    if own.dof != model.dof:
        raise InputError(f"simulate: the controller's model ({own.robot.name}) has {own.dof} "
                         f"joints, the simulated robot ({model.robot.name}) {model.dof}")
    same = (own.robot.description_hash and own.robot.description_hash == model.robot.description_hash
            and own.parameter_values == model.parameter_values)
    return None if same else own


def _fixed_step_c(model: Model, x0: np.ndarray, steps: int, dt: float, decimate: int, method: str,
                  controller: Controller | None, limit: np.ndarray | None, continuous: bool,
                  max_samples: int | None) -> tuple[np.ndarray, np.ndarray, int]:
    """Passive or built-in controller: the generated integrator, CHUNK_STEPS steps per call.

    A PID's error integral restarts at zero in each call; the integral of the earlier pieces
    enters as a constant feedforward ``Ki z``. Continuous-time PID (whose RK4 integral is not
    returned) runs as one call.
    """
    n = model.dof
    integral = controller is not None and controller.has_integral
    chunk = CHUNK_STEPS
    if integral and continuous:
        if max_samples is not None and steps > max(max_samples, CHUNK_STEPS):
            raise InputError(f"simulate: a PID with control='continuous' runs in one piece, at "
                             f"most {max(max_samples, CHUNK_STEPS):,} steps (this run has "
                             f"{steps:,}); use control='sampled', a SciPy method or a larger dt")
        chunk = steps
    keep = steps // decimate + 1
    x_out, tau_out = np.empty((keep, 2 * n)), np.empty((keep, n))
    x_out[0] = x0
    x, z = x0, np.zeros(n)
    for k0 in range(0, steps, chunk):
        m = min(chunk, steps - k0)
        # continuous: the inputs sampled every dt/2, for the RK4 stages
        times = (0.5 * dt * np.arange(2 * k0, 2 * (k0 + m) + 1) if continuous
                 else dt * np.arange(k0, k0 + m))
        law = None if controller is None else controller.sampled(model, times)
        if integral and k0:
            # tau = Ki (z0 + z_piece) + ...: the earlier pieces' integral as feedforward
            law = replace(law, feedforward=np.tile(law.integral_gain * z, (times.size, 1)))
        options = RolloutOptions(m, dt, method, "continuous" if continuous else "sampled", limit)
        xs, taus = rollout(model, x, options, law)
        if integral and not continuous:
            # z += dt sum_k (q_ref(t_k) - q_k), as the C loop does
            z = z + dt * np.sum(law.reference[:, :n] - xs[:-1, :n], axis=0)
        # global step k is kept when k % decimate == 0
        first = -k0 % decimate
        x_out[(k0 + first) // decimate: (k0 + m) // decimate + 1] = xs[first::decimate]
        tau_rows = taus[first::decimate]
        tau_out[(k0 + first) // decimate: (k0 + first) // decimate + len(tau_rows)] = tau_rows
        x = xs[-1]
    if controller is None:
        last = np.zeros(n)
    else:
        t_end = steps * dt
        if integral and continuous:
            errors = np.array([controller.position_error(k * dt, xk[:n]) for k, xk in enumerate(xs)])
            # the trapezoidal rule (the integrator's RK4 value is not returned; O(dt^2) apart)
            z = dt * (errors.sum(axis=0) - 0.5 * (errors[0] + errors[-1]))
        elif integral:
            z = z + dt * controller.position_error(t_end, x[:n])
        last = controller.law(model, t_end, x, z if integral else None)
    tau_out[-1] = _clip(last, limit)
    return x_out, tau_out, steps * (4 if method == "rk4" else 1)


def _member_model(model: Model, rows: np.ndarray | None, i: int) -> Model:
    """The model of trajectory ``i`` of a batch: its own runtime parameter values, if any."""
    if rows is None:
        return model
    return model.with_parameters(dict(zip(model.runtime_parameters, rows[i].tolist(), strict=True)))


def _fixed_step_batch(model: Model, x0: np.ndarray, steps: int, dt: float, decimate: int,
                      method: str, controller: Controller | None, limit: np.ndarray | None,
                      threads: int, rows: np.ndarray | None = None,
                      ) -> tuple[np.ndarray, np.ndarray, int]:
    """N trajectories from ``x0`` (N, 2 n) under one sampled law: the ensemble integrator.

    Returns ``x`` (N, S, 2 n), ``tau`` (N, S, n) and the evaluations per trajectory. The run is
    split in pieces of about CHUNK_STEPS states in all (the steps of one piece times N); each
    piece continues from the last states, so the pieces do not change the result. A PID runs as
    one piece (its integral restarts in each call, and the earlier pieces' integral, different
    for every trajectory, cannot enter as the shared feedforward).
    """
    count, n = x0.shape[0], model.dof
    integral = controller is not None and controller.has_integral
    chunk = steps if integral else max(1, CHUNK_STEPS // count)
    size = 8 * (steps + 1) * 3 * n * count
    if integral and size > MAX_INTEGRATE_BYTES:
        raise InputError(f"simulate: a batch under a PID runs in one call, and {count} x {steps:,} "
                         f"steps need {size / 2**20:,.0f} MiB, above {MAX_INTEGRATE_BYTES / 2**20:,.0f} "
                         "MiB; split the batch or shorten the run")
    keep = steps // decimate + 1
    x_out, tau_out = np.empty((count, keep, 2 * n)), np.empty((count, keep, n))
    x_out[:, 0] = x0
    x = x0
    for k0 in range(0, steps, chunk):
        m = min(chunk, steps - k0)
        times = dt * np.arange(k0, k0 + m)
        law = None if controller is None else controller.sampled(model, times)
        xs, taus = rollout(model, x, RolloutOptions(m, dt, method, tau_limit=limit, threads=threads),
                           law, rows)
        # global step k is kept when k % decimate == 0
        first = -k0 % decimate
        x_out[:, (k0 + first) // decimate: (k0 + m) // decimate + 1] = xs[:, first::decimate]
        tau_rows = taus[:, first::decimate]
        start = (k0 + first) // decimate
        tau_out[:, start: start + tau_rows.shape[1]] = tau_rows
        x = xs[:, -1]
    t_end = steps * dt
    for i in range(count):
        # the last row: the law at the final state, as a single run computes it
        if controller is None:
            last = np.zeros(n)
        elif integral:
            # z = dt sum_k (q_ref(t_k) - q_k) over the steps and the final sample
            z = dt * np.sum(law.reference[:, :n] - xs[i, :-1, :n], axis=0)
            z = z + dt * controller.position_error(t_end, x[i, :n])
            last = controller.law(_member_model(model, rows, i), t_end, x[i], z)
        else:
            last = controller.law(_member_model(model, rows, i), t_end, x[i], None)
        tau_out[i, -1] = _clip(last, limit)
    return x_out, tau_out, steps * (4 if method == "rk4" else 1)


def _fixed_step_python(model: Model, x0: np.ndarray, steps: int, dt: float, decimate: int,
                       method: str, controller: ControllerLike, limit: np.ndarray | None,
                       continuous: bool, substeps: int = 1) -> tuple[np.ndarray, np.ndarray, int]:
    """The loop over the control steps in Python: a callable (sampled or at every RK4 stage), or
    any sampled law held over ``substeps`` integration steps."""
    n = model.dof
    keep = steps // decimate + 1
    x_out, tau_out = np.empty((keep, 2 * n)), np.empty((keep, n))
    f = model.state_derivative
    z = np.zeros(n)

    def law(tk: float, xk: np.ndarray) -> np.ndarray:
        nonlocal z
        if controller is None:
            return np.zeros(n)
        if not isinstance(controller, Controller):
            return _clip(_call(controller, tk, xk, n), limit)
        if controller.has_integral:
            # z += dt (q_ref(t_k) - q_k) before the torque, as the generated loop does
            z = z + dt * controller.position_error(tk, xk[:n])
        return _clip(controller.law(model, tk, xk, z), limit)

    x = x0
    for k in range(steps):
        tk = k * dt
        tau = law(tk, x)
        if k % decimate == 0:
            x_out[k // decimate], tau_out[k // decimate] = x, tau
        if continuous:
            # RK4 (robodyn.codegen.fixed_step.RK4) with the callable at every stage's time
            last = [x]

            def slopes(i: int, s: tuple[np.ndarray, ...], tk: float = tk, tau: np.ndarray = tau,
                       last: list[np.ndarray] = last) -> tuple[np.ndarray]:
                last[0] = s[0]
                return (f(s[0], tau if i == 0 else law(tk + 0.5 * RK4.rows[i] * dt, s[0])),)

            x = RK4.step((x,), dt, slopes)[0]
            if not np.all(np.isfinite(x)):
                model.check_mass_matrix(last[0][:n])
                raise SimulationError(f"the simulated state stopped being finite at step {k} "
                                      f"(t = {tk:g} s); reduce dt or check the inputs")
        else:
            # the torque held over the step (zero-order hold), the plant in substeps
            held = np.broadcast_to(tau, (substeps, n))
            try:
                x = rollout(model, x, RolloutOptions(substeps, dt / substeps, method),
                            FeedbackLaw(feedforward=held))[0][-1]
            except SimulationError:
                exc = SimulationError(f"the simulated state stopped being finite at step {k} "
                                      f"(t = {tk:g} s); reduce dt or check the inputs")
                exc.state = x
                raise exc from None
    x_out[-1], tau_out[-1] = x, law(steps * dt, x)
    return x_out, tau_out, steps * substeps * (4 if method == "rk4" else 1)


#: Largest ``|lambda| h`` on the negative real axis for which one step is stable.
_STABLE = {"rk4": 2.785, "semi_implicit": 2.0}


def _diagnosed(exc: SimulationError, model: Model, x: np.ndarray, h: float, method: str,
               control: str) -> SimulationError:
    """The blow-up explained when the plant is too stiff for the integration step ``h``.

    Linearises the held-torque dynamics ``xd = f(x, tau)`` at the initial state ``x`` (central
    differences; the last finite state is already far off) and compares its fastest mode with
    the method's stability limit.
    """
    if method not in _STABLE:
        return exc
    n = model.dof
    # a typical held torque: the one that keeps the current velocities unaccelerated
    tau = model.inverse_dynamics(x[:n], x[n:], np.zeros(n))
    jac = np.empty((2 * n, 2 * n))
    for i in range(2 * n):
        eps = 1e-6 * max(1.0, abs(x[i]))
        e = np.zeros(2 * n)
        e[i] = eps
        # A[:, i] = (f(x + e) - f(x - e)) / 2 eps
        jac[:, i] = (model.state_derivative(x + e, tau) - model.state_derivative(x - e, tau)) / (2 * eps)
    if not np.all(np.isfinite(jac)):
        return exc
    lam, vec = np.linalg.eig(jac)
    k = int(np.argmax(np.abs(lam)))
    rate = float(np.abs(lam[k]))
    if rate * h <= _STABLE[method]:
        return SimulationError(f"{exc}; the plant's fastest mode ({rate:.3g} 1/s) is within "
                               f"{method}'s stability at dt = {h:g} s, so the control loop itself "
                               "diverged: lower the gains or sample faster")
    joint = model.robot.joints[int(np.argmax(np.abs(vec[n:, k])))].name
    # |lambda| h <= 1 resolves the mode; the stability limit alone leaves it barely damped
    fixes = (f"substeps >= {int(np.ceil(rate * h))} (the plant integrated at |lambda| h <= 1, "
             "the law still sampled every dt)" if control == "sampled"
             else f"a step below {1 / rate:.2g} s")
    return SimulationError(
        f"{exc}: the held-torque dynamics has a mode of {rate:.4g} 1/s (mostly joint {joint!r}: "
        f"e.g. viscous friction over a small inertia) and {method} is stable only while |lambda| "
        f"dt < {_STABLE[method]:g}, not {rate * h:.3g} at dt = {h:g} s: a numerical, not a "
        f"physical, instability. Use {fixes}, control='continuous', or method='Radau' or 'BDF'")


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
        raise SimulationError(f"solve_ivp ({method}) failed at t = {sol.t[-1]:g} s: {sol.message}")
    y = sol.y.T
    tau = np.array([torque(tk, yk) for tk, yk in zip(t, y, strict=True)])
    return np.ascontiguousarray(y[:, : 2 * n]), tau, int(sol.nfev)


def _call(controller: Callable, t: float, x: np.ndarray, n: int) -> np.ndarray:
    tau = np.asarray(controller(float(t), x[:n].copy(), x[n:].copy()), dtype=float)
    if tau.shape != (n,):
        raise InputError(f"the controller returned shape {tau.shape}; it must return ({n},) torques")
    if not np.all(np.isfinite(tau)):
        raise FloatingPointError(f"the controller returned non-finite torques at t = {t:g} s")
    return tau


def _clip(tau: np.ndarray, limit: np.ndarray | None) -> np.ndarray:
    return tau if limit is None else np.clip(tau, -limit, limit)
