"""Fixed-step rollouts of a compiled model under a state-feedback law: one C call per run.

:func:`rollout` is what :meth:`robodyn.numeric.model.Model.integrate` runs (the model is the
constant data, the rollout a function over it and the initial states, as MuJoCo's ``rollout``);
:func:`robodyn.simulation.simulate` builds on it.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np

from robodyn.numeric.integrate_numpy import integrate_numpy
from robodyn.numeric.runtime_parameters import ParameterValues, check_physics
from robodyn.robot.errors import InputError, SimulationError

__all__ = ["MAX_INTEGRATE_BYTES", "rollout", "thread_count"]

#: Largest output of one :func:`rollout` call (states and torques), bytes: longer runs are split
#: into several calls (as :func:`robodyn.simulation.simulate` does).
MAX_INTEGRATE_BYTES = 1 << 30


def thread_count(threads: int) -> int:
    """``threads`` checked: a positive integer."""
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise InputError(f"threads must be a positive integer, got {threads!r}")
    return int(threads)


def rollout(model: Any, x0: np.ndarray, steps: int, dt: float, method: str = "rk4", *,
              feedforward: np.ndarray | None = None, reference: np.ndarray | None = None,
              gain: np.ndarray | None = None, integral_gain: np.ndarray | None = None,
              mode: str = "feedback", tau_limit: np.ndarray | None = None,
              control: str = "sampled", threads: int = 1,
              parameters: ParameterValues = None) -> tuple[np.ndarray, np.ndarray]:
    """Fixed-step trajectory of ``model`` (a :class:`~robodyn.numeric.model.Model`) under a
    state-feedback law, in one call (:meth:`Model.integrate <robodyn.numeric.model.Model.integrate>`).

    With ``e = reference[row] - x``::

        "feedback":         tau = feedforward[row] + gain e + integral_gain * integral(e_q dt)
        "gravity":          the same + g(q)
        "computed_torque":  tau = M(q) (feedforward[row] + gain e) + C qd + g + friction

    then clipped to ``+-tau_limit``. ``control="sampled"``: the law is evaluated at the start
    of step k (row k) and held over the step, as a digital controller at the integration
    rate; the integral is ``dt sum(e_q)`` including the current sample.
    ``control="continuous"`` (RK4 only): the law is evaluated at every RK4 stage on the
    stage's state, with rows sampled every ``dt / 2`` (row 2k at the start of step k), and
    the integral is integrated by the same RK4: a continuous-time controller.

    An ensemble: ``x0`` of shape (N, 2 n) integrates N trajectories under the same law and
    inputs in one C call (sampled control only), a block of trajectories per vector loop
    (SIMD across trajectories) and blocks on ``threads`` threads; each trajectory has the
    same bits as its own run. Results gain a leading N.

    Parameters
    ----------
    model : Model
    x0 : (2 n,) or (N, 2 n)
        Initial ``[q, qd]``, or one per trajectory.
    steps : int
    dt : float
        Step (s).
    method : {"rk4", "semi_implicit"}
        Classical RK4, or semi-implicit Euler (velocity first, then position with the new
        velocity: symplectic only while M is constant, first order in general).
    feedforward : (steps, n) or (2 steps + 1, n) when continuous, optional
        Torques, or accelerations under "computed_torque".
    reference : (steps, 2 n) or (2 steps + 1, 2 n) when continuous, optional
        Desired ``[q, qd]`` per sample.
    gain : (n, 2 n), optional
        State-feedback gain (``[Kp, Kd]`` for PD, an LQR gain, ...).
    integral_gain : (n,), optional
    mode : {"feedback", "gravity", "computed_torque"}
    tau_limit : (n,), optional
        Actuator limits (N m or N), positive.
    control : {"sampled", "continuous"}
    threads : int
        Threads of an ensemble (C backend with OpenMP; results do not depend on it).
    parameters : mapping, sequence of N mappings, or (P,) / (N, P), optional
        Values of the model's :attr:`~Model.runtime_parameters`: one set, or one per trajectory of an
        ensemble (each integrated with its own dynamics and model-based law, in the same
        one C call); checked like compile-time values (finite, physically possible).

    Returns
    -------
    x : (steps + 1, 2 n) or (N, steps + 1, 2 n)
        States, ``x[0] = x0``.
    tau : (steps, n) or (N, steps, n)
        Torques at the start of each step (those applied over it when sampled).

    Raises
    ------
    FloatingPointError
        When the state stops being finite (the step is named).
    """
    model._require_dynamics()
    n, nx = model.dof, 2 * model.dof
    methods = {"rk4": 0, "semi_implicit": 1}
    modes = {"feedback": 0, "gravity": 1, "computed_torque": 2}
    if method not in methods:
        raise InputError(f"unknown fixed-step method {method!r}; choose {', '.join(methods)}")
    if mode not in modes:
        raise InputError(f"unknown controller mode {mode!r}; choose {', '.join(modes)}")
    if control not in ("sampled", "continuous"):
        raise InputError(f"unknown control {control!r}; choose 'sampled' or 'continuous'")
    continuous = control == "continuous"
    if continuous and method != "rk4":
        raise InputError(f"control='continuous' needs method='rk4' ({method} evaluates the law "
                         "once per step: use control='sampled')")
    steps = int(steps)
    if steps < 1:
        raise InputError(f"integrate: steps must be a positive integer, got {steps}")
    threads = thread_count(threads)
    ensemble = np.ndim(x0) == 2
    if ensemble and continuous:
        raise InputError("integrate: an ensemble (x0 of shape (N, 2 n)) runs control='sampled' "
                         "only; integrate continuous-time control one trajectory at a time")
    count = np.shape(x0)[0] if ensemble else 1
    size = 8 * (steps + 1) * 3 * n * count
    if size > MAX_INTEGRATE_BYTES:
        raise InputError(f"integrate: {steps:,} steps of {n} joints need {size / 2**20:,.0f} MiB "
                         f"of output, above {MAX_INTEGRATE_BYTES / 2**20:,.0f} MiB; split the "
                         "run into several calls from the last state (simulate() does so)")
    rows = 2 * steps + 1 if continuous else steps
    arrays = {
        "x0": (x0, (count, nx) if ensemble else (nx,)), "feedforward": (feedforward, (rows, n)),
        "reference": (reference, (rows, nx)), "gain": (gain, (n, nx)),
        "integral_gain": (integral_gain, (n,)), "tau_limit": (tau_limit, (n,)),
    }
    checked: dict[str, np.ndarray | None] = {}
    for key, (val, shape) in arrays.items():
        if val is None:
            checked[key] = None
            continue
        arr = np.ascontiguousarray(val, dtype=np.float64)
        if arr.shape != shape:
            raise InputError(f"integrate: {key} must have shape {shape}, got {arr.shape}")
        checked[key] = arr
    checked["params"] = None
    if model.runtime_parameters or parameters is not None:
        checked["params"] = model.parameter_input(parameters, (count,) if ensemble else (), "integrate")
        check_physics(model.robot, model.runtime_parameters, model.parameters, checked["params"],
                      "integrate(parameters=...)")
    if ensemble:
        return _ensemble(model, checked, steps, dt, methods[method], modes[mode], threads)
    x_out = np.empty((steps + 1, nx))
    tau_out = np.empty((steps, n))
    if isinstance(model._impl, ModuleType):
        status = integrate_numpy(model, steps, dt, methods[method], modes[mode], checked, x_out,
                                  tau_out, continuous)
    else:
        ffi = model._impl.ffi
        ptr = {k: (ffi.NULL if v is None else ffi.from_buffer("double[]", v))
               for k, v in checked.items()}
        params = (ptr["params"],) if model.runtime_parameters else ()
        status = model._impl.lib.rd_simulate(
            steps, float(dt), methods[method], ptr["x0"], ptr["feedforward"], ptr["reference"],
            ptr["gain"], ptr["integral_gain"], modes[mode], ptr["tau_limit"], *params,
            int(continuous), ffi.from_buffer("double[]", x_out),
            ffi.from_buffer("double[]", tau_out))
    if status:
        # the last finite state: a singular mass matrix there is the explanation
        model.check_mass_matrix(x_out[status - 1, :n], checked["params"])
        exc = SimulationError(f"the simulated state stopped being finite at step {status - 1} "
                              f"(t = {(status - 1) * dt:g} s); reduce dt or check the inputs")
        # the last finite state, for a caller's diagnosis
        exc.state = x_out[status - 1].copy()
        raise exc
    return x_out, tau_out

def _ensemble(model: Any, a: dict[str, np.ndarray | None], steps: int, dt: float,
                        method: int, mode: int, threads: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`rollout` of ``a["x0"]`` (N, 2 n) checked: one C call, or N NumPy runs."""
    n, nx = model.dof, 2 * model.dof
    count = a["x0"].shape[0]
    x_out = np.empty((count, steps + 1, nx))
    tau_out = np.empty((count, steps, n))
    status = np.zeros(count, dtype=np.int64)
    params = a["params"]
    if isinstance(model._impl, ModuleType):
        for i in range(count):
            row = {"x0": a["x0"][i], "params": None if params is None else params[i]}
            status[i] = integrate_numpy(model, steps, dt, method, mode, {**a, **row},
                                         x_out[i], tau_out[i])
    elif count:
        ffi = model._impl.ffi
        ptr = {k: (ffi.NULL if v is None else ffi.from_buffer("double[]", v)) for k, v in a.items()}
        extra = (ptr["params"],) if model.runtime_parameters else ()
        model._impl.lib.rd_simulate_ensemble(
            count, steps, float(dt), method, ptr["x0"], ptr["feedforward"], ptr["reference"],
            ptr["gain"], ptr["integral_gain"], mode, ptr["tau_limit"], *extra, threads,
            ffi.from_buffer("double[]", x_out), ffi.from_buffer("double[]", tau_out),
            ffi.from_buffer("long[]", status))
    failed = np.flatnonzero(status)
    if failed.size:
        i, k = int(failed[0]), int(status[failed[0]])
        model.check_mass_matrix(x_out[i, k - 1, :n], None if params is None else params[i])
        exc = SimulationError(
            f"{failed.size} of {count} trajectories stopped being finite; the first, "
            f"trajectory {i}, at step {k - 1} (t = {(k - 1) * dt:g} s); reduce dt or check "
            "the inputs")
        exc.state = x_out[i, k - 1].copy()
        exc.trajectory = i
        raise exc
    return x_out, tau_out
