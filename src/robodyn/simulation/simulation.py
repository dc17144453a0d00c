"""``simulate``: forward-dynamic simulation of a compiled model, passive or under a controller.

Methods
-------
"rk4", "semi_implicit"
    Fixed step ``dt``. With no controller or a built-in controller
    (:mod:`robodyn.simulation.controllers`) the whole run is ONE call into the generated C
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

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from robodyn.keywords import resolve
from robodyn.numeric.model import Model
from robodyn.numeric.runtime_parameters import ParameterValues, check_physics
from robodyn.robot.errors import InputError, SimulationError
from robodyn.simulation.controllers import Controller
from robodyn.simulation.energy import potential_energy
from robodyn.simulation.options import ADAPTIVE, FIXED_STEP, MAX_SAMPLES, SimulateOptions
from robodyn.simulation.steppers import (
    CHUNK_STEPS,
    ControllerLike,
    _adaptive,
    _controller_model,
    _diagnosed,
    _fixed_step_batch,
    _fixed_step_c,
    _fixed_step_python,
    _member_model,
)


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A simulated motion, sampled every ``dt`` (all arrays read-only).

    ``S`` samples; a run from a batch of ``N`` initial states (``q0`` of shape (N, n)) carries
    the batch axis first on every array but ``t``.

    Attributes
    ----------
    t : (S,) ndarray
        Time, s.
    q, qd, qdd : (S, n) or (N, S, n) ndarray
        Joint positions (rad, m), velocities and accelerations.
    tau : (S, n) or (N, S, n) ndarray
        Joint torques/forces (N m, N): with a fixed-step method, ``tau[k]`` is the torque held
        over ``[t_k, t_k+1)``; the last row is the law at the final state. ``qdd[k]`` is the
        acceleration at ``(q[k], qd[k], tau[k])``.
    kinetic, potential, energy : (S,) or (N, S) ndarray
        ``0.5 qd^T M(q) qd`` (rotor inertia included), gravitational ``V(q)`` (see
        :func:`robodyn.simulation.energy.potential_energy`) and their sum, J.
    method : str
    dt : float
        Integration step of the fixed-step methods, s; samples are ``decimate * dt`` apart.
    controller : str
        Name of the controller ("none" when passive).
    robot : str
    backend : str
    evaluations : int
        Right-hand-side evaluations (``state_derivative`` calls), per trajectory.
    decimate : int
        Every ``decimate``-th step was kept.
    options : SimulateOptions or None
        The choices the run was made with (:mod:`robodyn.simulation.options`).
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
    decimate: int = 1
    options: SimulateOptions | None = None

    @property
    def x(self) -> np.ndarray:
        """States ``[q, qd]``, (S, 2 n) or (N, S, 2 n)."""
        return np.concatenate([self.q, self.qd], axis=-1)

    @property
    def batch(self) -> int | None:
        """Number of trajectories of a batch run, None for a single run."""
        return self.q.shape[0] if self.q.ndim == 3 else None

    @property
    def energy_drift(self) -> float | np.ndarray:
        """``max |E(t) - E(0)| / max(|E(0)|, max K)``: the relative energy error of a passive run
        (a float, or (N,) for a batch)."""
        e0 = self.energy[..., 0]
        scale = np.maximum(np.maximum(np.abs(e0), np.max(self.kinetic, axis=-1)), 1e-300)
        drift = np.max(np.abs(self.energy - e0[..., None]), axis=-1) / scale
        return float(drift) if drift.ndim == 0 else drift

    def member(self, i: int) -> Trajectory:
        """Trajectory ``i`` of a batch run, as a single-run :class:`Trajectory` (views)."""
        if self.batch is None:
            raise InputError("member: this trajectory is a single run, not a batch")
        if not -self.batch <= i < self.batch:
            raise IndexError(f"member: index {i} out of range for a batch of {self.batch}")
        return dataclasses.replace(
            self, q=self.q[i], qd=self.qd[i], qdd=self.qdd[i], tau=self.tau[i],
            kinetic=self.kinetic[i], potential=self.potential[i], energy=self.energy[i])


def simulate(model: Model, q0: np.ndarray, qd0: np.ndarray | None, duration: float, dt: float,
             method: str = "rk4", controller: ControllerLike = None, *,
             tau_limit: float | np.ndarray | None = None, rtol: float = 1e-9,
             atol: float = 1e-12, control: str = "sampled", decimate: int = 1,
             max_samples: int | None = MAX_SAMPLES, substeps: int = 1,
             threads: int = 1, parameters: ParameterValues = None,
             options: SimulateOptions | None = None) -> Trajectory:
    """Simulate ``model`` from ``(q0, qd0)`` for ``duration`` seconds.

    A batch of ``N`` initial states (``q0`` of shape (N, n)) is integrated in one call into the
    generated C per piece of the run (:meth:`Model.integrate` on an ensemble, SIMD across
    trajectories), under the same controller: a fixed-step method with ``control="sampled"``,
    ``substeps=1`` and no controller or a built-in one using the plant's model. Each trajectory
    equals its own single run (to 1e-12); the result's arrays gain a leading N.

    Parameters
    ----------
    model : Model
        From :func:`robodyn.compile_model` (either backend).
    q0 : (n,) or (N, n) array_like
        Initial joint positions (rad, m), or a batch of N of them.
    qd0 : (n,) or (N, n) array_like or None
        Initial velocities, the shape of ``q0`` (None: at rest).
    duration : float
        s, a whole number of steps ``dt``.
    dt : float
        Step (fixed-step methods) and output interval (all methods), s.
    method : {"rk4", "semi_implicit", "RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA"}
    controller : Controller, callable or None
        A built-in controller, any ``(t, q, qd) -> tau`` callable, or None (no torque). A
        built-in controller constructed with its own ``model=`` (gravity compensation, computed
        torque) computes its law with that model, not the plant's: a controller with a wrong
        model tracks worse. The run then steps in Python (the generated C integrator only knows
        the plant's model), unless both models have the same description and parameters.
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
    decimate : int
        Keep every ``decimate``-th step (the integration still uses ``dt``); ``duration`` must
        be a whole number of ``decimate * dt``.
    max_samples : int or None
        Refuse a run that would keep more samples than this (default :data:`MAX_SAMPLES`,
        checked before anything is allocated); None: no limit.
    substeps : int
        Fixed-step methods with ``control="sampled"``: the law is still evaluated every ``dt``
        and held, but the plant is integrated with ``substeps`` steps of ``dt / substeps`` (the
        loop over the control steps then runs in Python). For a plant stiffer than the control
        rate: RK4 is stable only while ``|lambda| dt < 2.79`` for every mode ``lambda`` of the
        held-torque dynamics (e.g. viscous friction over a small wrist inertia, ``-b / m``).
    threads : int
        Threads of a batch run (C backend with OpenMP); the result does not depend on it.
    parameters : mapping, sequence of N mappings, or (P,) / (N, P), optional
        Values of the model's runtime parameters (a model from ``compile_model(robot,
        runtime_parameters=...)``; columns in the order of ``model.runtime_parameters``): one
        set for the run, or for a batch one set per trajectory, every trajectory integrated
        with its own parameters (plant and built-in model-based law) in the same C call.
        Checked like compile-time values. None: the model's defaults.
    options : SimulateOptions, optional
        ``method``, ``tau_limit``, ``rtol``, ``atol``, ``control``, ``decimate``,
        ``max_samples``, ``substeps`` and ``threads`` at once, instead of the keywords (a keyword
        other than its default given as well is refused); ``traj.options`` is the set a run used.

    Returns
    -------
    Trajectory
        Arrays of shape (S, ...) for one initial state, (N, S, ...) for a batch.

    Raises
    ------
    ValueError
        Wrong shapes, non-finite values, non-positive ``dt`` or ``duration``, unknown method,
        more samples than ``max_samples`` (counted over all trajectories of a batch), a
        controller model with another number of joints, a batch with a method, control,
        ``substeps`` or controller that the ensemble integrator does not run.
    TypeError
        A controller that is neither built-in nor callable.
    SimulationError
        (a ``FloatingPointError`` and a ``ValueError``) When the state stops being finite; a
        :class:`~robodyn.robot.errors.SingularMassMatrixError` when the mass matrix is singular.
    """
    opts = resolve(SimulateOptions, options, dict(
        method=method, tau_limit=tau_limit, rtol=rtol, atol=atol, control=control,
        decimate=decimate, max_samples=max_samples, substeps=substeps, threads=threads), InputError)
    method, tau_limit, rtol, atol, control = opts.method, opts.tau_limit, opts.rtol, opts.atol, opts.control
    decimate, max_samples, substeps, threads = opts.decimate, opts.max_samples, opts.substeps, opts.threads
    n = model.dof
    q0, qd0, batch = _initial_states(q0, qd0, n)
    count = len(q0) if batch else 1
    dt, duration, steps, decimate = _step_count(duration, dt, decimate)
    _check_samples(steps, decimate, count, n, duration, dt, max_samples, batch)
    _check_options(method, control, substeps, controller)
    limit = _torque_limit(tau_limit, controller, n)
    own = _controller_model(controller, model)
    model, rows = _run_parameters(model, parameters, count, batch)
    if batch:
        _check_batch(method, control, substeps, controller, own)
    if own is not None:
        # the law with the controller's own model, stepped in Python
        controller = _with_own_model(controller, own)
    t = dt * np.arange(0, steps + 1, decimate)
    if batch:
        x0 = np.concatenate([q0, qd0], axis=1)
        x, tau, evals = _run_batch(model, x0, steps, dt, decimate, method, controller, limit,
                                   threads, rows, control)
        return replace(_result(model, t, x, tau, method, dt, controller, evals, decimate, rows),
                       options=opts)
    x0 = np.concatenate([q0, qd0])
    x, tau, evals = _run_single(model, x0, t, steps, dt, decimate, method, controller, limit,
                                control, substeps, max_samples, rtol, atol)
    return replace(_result(model, t, x, tau, method, dt, controller, evals, decimate), options=opts)


def _initial_states(q0: np.ndarray, qd0: np.ndarray | None,
                    n: int) -> tuple[np.ndarray, np.ndarray, bool]:
    """The checked initial state and whether it is a batch.

    Parameters
    ----------
    q0 : (n,) or (N, n) array_like
        Initial joint positions (rad, m).
    qd0 : (n,) or (N, n) array_like or None
        Initial velocities (None: at rest).
    n : int
        Degrees of freedom.

    Returns
    -------
    q0, qd0 : (n,) or (N, n) ndarray
    batch : bool
        True when ``q0`` is (N, n).
    """
    batch = np.ndim(q0) == 2
    if batch:
        q0 = _states(q0, n, "q0")
        qd0 = np.zeros_like(q0) if qd0 is None else _states(qd0, n, "qd0", len(q0))
    else:
        q0 = _vector(q0, n, "q0")
        qd0 = np.zeros(n) if qd0 is None else _vector(qd0, n, "qd0")
    return q0, qd0, batch


def _step_count(duration: float, dt: float, decimate: int) -> tuple[float, float, int, int]:
    """The checked ``dt`` (s), ``duration`` (s), number of steps and ``decimate``.

    Raises ValueError unless ``duration`` is a whole number of ``decimate * dt``.
    """
    dt = _positive(dt, "dt")
    duration = _positive(duration, "duration")
    steps = round(duration / dt)
    if steps < 1 or abs(steps * dt - duration) > 1e-9 * duration:
        raise InputError(f"duration {duration:g} s is not a whole number of steps dt = {dt:g} s")
    if isinstance(decimate, bool) or not isinstance(decimate, int | np.integer) or decimate < 1:
        raise InputError(f"simulate: decimate must be a positive integer, got {decimate!r}")
    decimate = int(decimate)
    if steps % decimate:
        raise InputError(f"simulate: duration {duration:g} s is {steps} steps of {dt:g} s, not a "
                         f"whole number of decimate = {decimate} steps")
    return dt, duration, steps, decimate


def _check_samples(steps: int, decimate: int, count: int, n: int, duration: float, dt: float,
                   max_samples: int | None, batch: bool) -> None:
    """Refuse a run of ``count`` trajectories keeping more than ``max_samples`` samples in all.

    ``duration`` and ``dt`` (s) only word the error message.
    """
    samples = steps // decimate + 1
    if max_samples is not None and count * samples > max_samples:
        # a batch keeps its samples for every trajectory
        per_run = max_samples // count
        each = f"{count} x {samples:,}" if batch else f"{samples:,}"
        k_min = -(-steps // (per_run - 1)) if per_run > 1 else steps
        raise InputError(
            f"simulate: {duration:g} s at dt = {dt:g} s keeps {each} samples (about "
            f"{output_bytes(count * samples, n) / 1e6:,.0f} MB of arrays), above max_samples = "
            f"{max_samples:,}; keep every k-th step with decimate=k (k >= {k_min}), shorten the "
            f"run{', split the batch' if batch else ''}, or raise max_samples")


def _check_options(method: str, control: str, substeps: int, controller: ControllerLike) -> None:
    """Refuse a controller that is not callable (the options are checked by
    :class:`~robodyn.simulation.options.SimulateOptions`)."""
    if controller is not None and not callable(controller):
        raise TypeError(f"controller must be a built-in controller, a callable (t, q, qd) -> tau or "
                        f"None, got {type(controller).__name__}")


def _torque_limit(tau_limit: float | np.ndarray | None, controller: ControllerLike,
                  n: int) -> np.ndarray | None:
    """The actuator limits of the run, (n,) N m (N): ``tau_limit``, else the controller's own.

    None when neither gives one.
    """
    limit = _tau_limit(tau_limit, n) if tau_limit is not None else None
    if limit is None and isinstance(controller, Controller) and controller.tau_limit is not None:
        limit = _tau_limit(controller.tau_limit, n)
    return limit


def _run_parameters(model: Model, parameters: ParameterValues, count: int,
                    batch: bool) -> tuple[Model, np.ndarray | None]:
    """The plant and the runtime parameter rows of the run.

    Returns
    -------
    model : Model
        ``model``, or for one set of values on a single run the model with those defaults.
    rows : (N, P) ndarray or None
        One row per trajectory of a batch; None for the model's own values.
    """
    rows = None
    if parameters is not None:
        rows = model.parameter_input(parameters, (count,) if batch else (), "simulate")
        check_physics(model.robot, model.runtime_parameters, model.parameters, rows,
                      "simulate(parameters=...)")
        if not batch:
            # one set: the model with those defaults (no compilation)
            model = model.with_parameters(dict(zip(model.runtime_parameters, rows.tolist(),
                                                   strict=True)))
            rows = None
    return model, rows


def _with_own_model(controller: Controller,
                    own: Model) -> Callable[[float, np.ndarray, np.ndarray], np.ndarray]:
    """``controller``'s law on its own model ``own``, as a ``(t, q, qd) -> tau`` callable."""
    ctrl = controller

    def with_own_model(tk: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        return ctrl.law(own, tk, np.concatenate([q, qd]), None)

    with_own_model.__name__ = controller.name
    return with_own_model


def _run_batch(model: Model, x0: np.ndarray, steps: int, dt: float, decimate: int, method: str,
               controller: Controller | None, limit: np.ndarray | None, threads: int,
               rows: np.ndarray | None, control: str) -> tuple[np.ndarray, np.ndarray, int]:
    """The batch from ``x0`` (N, 2 n), a blow-up diagnosed on its trajectory.

    Returns ``x`` (N, S, 2 n), ``tau`` (N, S, n) and the evaluations per trajectory.
    """
    try:
        return _fixed_step_batch(model, x0, steps, dt, decimate, method, controller, limit,
                                 threads, rows)
    except SimulationError as exc:
        i = getattr(exc, "trajectory", 0)
        raise _diagnosed(exc, _member_model(model, rows, i), x0[i], dt, method,
                         control) from None


def _run_single(model: Model, x0: np.ndarray, t: np.ndarray, steps: int, dt: float,
                decimate: int, method: str, controller: ControllerLike,
                limit: np.ndarray | None, control: str, substeps: int, max_samples: int | None,
                rtol: float, atol: float) -> tuple[np.ndarray, np.ndarray, int]:
    """One run from ``x0`` (2 n,) by ``method``, a fixed-step blow-up diagnosed.

    Returns ``x`` (S, 2 n), ``tau`` (S, n) and the evaluations, ``t`` (S,) s being the samples.
    """
    continuous = control == "continuous"
    try:
        if method in FIXED_STEP and substeps == 1 and (controller is None
                                                       or isinstance(controller, Controller)):
            x, tau, evals = _fixed_step_c(model, x0, steps, dt, decimate, method, controller, limit,
                                          continuous, max_samples)
        elif method in FIXED_STEP:
            x, tau, evals = _fixed_step_python(model, x0, steps, dt, decimate, method, controller,
                                               limit, continuous, substeps)
    except SimulationError as exc:
        raise _diagnosed(exc, model, x0, dt / substeps, method, control) from None
    if method in ADAPTIVE:
        x, tau, evals = _adaptive(model, x0, t, method, controller, limit, rtol, atol)
    return x, tau, evals

def output_bytes(samples: int, n: int) -> int:
    """Bytes of the arrays of a :class:`Trajectory` of ``samples`` rows and ``n`` joints."""
    # t, kinetic, potential, energy and q, qd, qdd, tau
    return 8 * samples * (4 + 4 * n)


def _check_batch(method: str, control: str, substeps: int, controller: ControllerLike,
                 own: Model | None) -> None:
    """Refuse a batch run that the ensemble integrator cannot do in C."""
    why = None
    if method not in FIXED_STEP:
        why = f"method={method!r} (solve_ivp, adaptive steps per trajectory)"
    elif control != "sampled":
        why = f"control={control!r} (the law at every RK4 stage)"
    elif substeps != 1:
        why = f"substeps={substeps} (a Python loop over the control steps)"
    elif controller is not None and not isinstance(controller, Controller):
        why = f"a Python callable controller ({_name(controller)})"
    elif own is not None:
        why = f"a {controller.name} with its own model (its law steps in Python)"
    if why is not None:
        raise InputError(
            "simulate: a batch of initial states (q0 of shape (N, n)) runs in one generated-C "
            "call per piece, with method 'rk4' or 'semi_implicit', control='sampled', "
            f"substeps=1 and no controller or a built-in one on the plant's model; {why} is not "
            "supported there: simulate each row of q0 on its own")


def _result(model: Model, t: np.ndarray, x: np.ndarray, tau: np.ndarray, method: str, dt: float,
            controller: ControllerLike, evals: int, decimate: int,
            rows: np.ndarray | None = None) -> Trajectory:
    n = model.dof
    lead = x.shape[:-1]  # (S,) or (N, S) for a batch
    q, qd = np.ascontiguousarray(x[..., :n]), np.ascontiguousarray(x[..., n:])
    # the kernels on the samples of all trajectories as one (N S, n) batch
    qf, qdf = q.reshape(-1, n), qd.reshape(-1, n)
    # each sample with its trajectory's runtime parameters (None: the model's own)
    pf = None if rows is None else np.repeat(rows, lead[-1], axis=0)
    qdd = model.forward_dynamics(qf, qdf, tau.reshape(-1, n), parameters=pf).reshape(q.shape)
    kinetic = np.empty(qf.shape[0])
    for k0 in range(0, qf.shape[0], CHUNK_STEPS):
        # K = 0.5 qd^T M qd (M in pieces: (S, n, n) would dwarf the trajectory)
        part = slice(k0, k0 + CHUNK_STEPS)
        mass = model.mass_matrix(qf[part], parameters=None if pf is None else pf[part])
        kinetic[part] = 0.5 * np.einsum("ki,kij,kj->k", qdf[part], mass, qdf[part])
    kinetic = kinetic.reshape(lead)
    potential = potential_energy(model, qf, parameters=pf).reshape(lead)
    arrays = [t, q, qd, qdd, tau, kinetic, potential, kinetic + potential]
    for a in arrays:
        a.flags.writeable = False
    return Trajectory(*arrays, method=method, dt=dt, controller=_name(controller),
                      robot=model.robot.name, backend=model.backend, evaluations=evals,
                      decimate=decimate)


def _name(controller: ControllerLike) -> str:
    if controller is None:
        return "none"
    if isinstance(controller, Controller):
        return controller.name
    return getattr(controller, "__name__", type(controller).__name__)


def _vector(v: np.ndarray, n: int, name: str) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    if arr.shape != (n,):
        raise InputError(f"simulate: {name} must have shape ({n},), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"simulate: {name} contains non-finite values")
    return arr


def _states(v: np.ndarray, n: int, name: str, count: int | None = None) -> np.ndarray:
    """A batch of states (N, n), checked (``count``: the required N)."""
    arr = np.asarray(v, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != n or arr.shape[0] < 1 or (count is not None
                                                                   and arr.shape[0] != count):
        want = f"({count}, {n})" if count is not None else f"(N, {n}) with N >= 1"
        raise InputError(f"simulate: {name} must have shape {want}, got {arr.shape}")
    bad = np.flatnonzero(~np.all(np.isfinite(arr), axis=1))
    if bad.size:
        raise InputError(f"simulate: {name} contains non-finite values (row {int(bad[0])})")
    return arr


def _positive(v: float, name: str) -> float:
    try:
        val = float(v)
    except (TypeError, ValueError):
        raise InputError(f"simulate: {name} must be a positive number, got {v!r}") from None
    if not np.isfinite(val) or val <= 0:
        raise InputError(f"simulate: {name} must be a positive finite number, got {v!r}")
    return val


def _tau_limit(v: float | np.ndarray, n: int) -> np.ndarray:
    arr = np.broadcast_to(np.asarray(v, dtype=float), (n,)) if np.ndim(v) == 0 else np.asarray(v, float)
    if arr.size == 1:
        arr = np.full(n, float(arr.ravel()[0]))
    if arr.shape != (n,) or np.any(~np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError(f"simulate: tau_limit must be positive, a scalar or ({n},), got {v!r}")
    return np.ascontiguousarray(arr)


__all__ = ["ADAPTIVE", "CHUNK_STEPS", "FIXED_STEP", "MAX_SAMPLES", "Trajectory", "output_bytes",
           "simulate"]
