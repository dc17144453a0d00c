"""Fixed-step rollouts of a compiled model under a state-feedback law: one C call per run.

The model is constant data and a rollout is a function over it, the initial states and an
options object (as MuJoCo's ``rollout``): :func:`rollout` ``(model, x0, options, law)``.
:class:`RolloutOptions` holds how the run integrates (steps, step, method, when the law is
evaluated, actuator limits, threads); :class:`FeedbackLaw` holds the law and its per-sample
inputs. :func:`robodyn.simulation.simulate` builds on it; the built-in controllers give their
law as a :class:`FeedbackLaw` (``Controller.sampled``).

With ``e = reference[row] - x`` the law is::

    "feedback":         tau = feedforward[row] + gain e + integral_gain * integral(e_q dt)
    "gravity":          the same + g(q)
    "computed_torque":  tau = M(q) (feedforward[row] + gain e) + C qd + g + friction

then clipped to ``+-tau_limit``. ``control="sampled"``: the law is evaluated at the start of step
k (row k) and held over the step, as a digital controller at the integration rate; the integral
is ``dt sum(e_q)`` including the current sample. ``control="continuous"`` (RK4 only): the law is
evaluated at every RK4 stage on the stage's state, with rows sampled every ``dt / 2`` (row 2k at
the start of step k), and the integral is integrated by the same RK4: a continuous-time
controller.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import ModuleType

import numpy as np

from robodyn.codegen.fixed_step import LAW_MODES
from robodyn.numeric.checks import thread_count
from robodyn.numeric.integrate_numpy import integrate_numpy
from robodyn.numeric.model import Model
from robodyn.numeric.runtime_parameters import ParameterValues, check_physics
from robodyn.robot.errors import InputError, SimulationError
from robodyn.simulation.options import positive_int

__all__ = ["MAX_INTEGRATE_BYTES", "FeedbackLaw", "RolloutOptions", "rollout"]

#: Largest output of one :func:`rollout` call (states and torques), bytes: longer runs are split
#: into several calls (as :func:`robodyn.simulation.simulate` does).
MAX_INTEGRATE_BYTES = 1 << 30

#: Fixed-step methods of a rollout and their codes in the generated C.
_METHODS = {"rk4": 0, "semi_implicit": 1}
#: The law's modes and their codes in the generated C.
_MODES = {name: code for code, name in LAW_MODES.items()}


@dataclass(frozen=True, eq=False)
class RolloutOptions:
    """How :func:`rollout` integrates.

    Attributes
    ----------
    steps : int
        Fixed steps (the output has ``steps + 1`` states).
    dt : float
        Step, s.
    method : {"rk4", "semi_implicit"}
        Classical RK4, or semi-implicit Euler (velocity first, then position with the new
        velocity: symplectic only while M is constant, first order in general).
    control : {"sampled", "continuous"}
        The law held over each step, or evaluated at every RK4 stage (module docstring).
    tau_limit : numpy.ndarray, shape (n,), optional
        Actuator limits, N m (N), positive.
    threads : int
        Threads of an ensemble (C backend with OpenMP; results do not depend on it).

    Raises
    ------
    InputError
        On construction: a value outside its choices or an inconsistent combination.
    """

    steps: int
    dt: float
    method: str = "rk4"
    control: str = "sampled"
    tau_limit: np.ndarray | None = None
    threads: int = 1

    def __post_init__(self) -> None:
        if self.method not in _METHODS:
            raise InputError(f"unknown fixed-step method {self.method!r}; choose {', '.join(_METHODS)}")
        if self.control not in ("sampled", "continuous"):
            raise InputError(f"unknown control {self.control!r}; choose 'sampled' or 'continuous'")
        if self.control == "continuous" and self.method != "rk4":
            raise InputError(f"control='continuous' needs method='rk4' ({self.method} evaluates the "
                             "law once per step: use control='sampled')")
        if not positive_int(self.steps):
            raise InputError(f"rollout: steps must be a positive integer, got {self.steps!r}")
        if isinstance(self.dt, bool) or not isinstance(self.dt, int | float | np.floating) \
                or not math.isfinite(self.dt) or self.dt <= 0:
            raise InputError(f"rollout: dt must be a positive number of seconds, got {self.dt!r}")
        thread_count(self.threads)


@dataclass(frozen=True, eq=False)
class FeedbackLaw:
    """A state-feedback law and its inputs per sample (module docstring); all optional.

    Attributes
    ----------
    mode : {"feedback", "gravity", "computed_torque"}
    feedforward : numpy.ndarray, shape (steps, n), or (2 steps + 1, n) when continuous, optional
        Torques, or accelerations under "computed_torque".
    reference : numpy.ndarray, shape (steps, 2 n), or (2 steps + 1, 2 n) when continuous, optional
        Desired ``[q, qd]`` per sample.
    gain : numpy.ndarray, shape (n, 2 n), optional
        State-feedback gain (``[Kp, Kd]`` for PD, an LQR gain, ...).
    integral_gain : numpy.ndarray, shape (n,), optional
    """

    mode: str = "feedback"
    feedforward: np.ndarray | None = field(default=None, repr=False)
    reference: np.ndarray | None = field(default=None, repr=False)
    gain: np.ndarray | None = field(default=None, repr=False)
    integral_gain: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if self.mode not in _MODES:
            raise InputError(f"unknown controller mode {self.mode!r}; choose {', '.join(_MODES)}")

    def arrays(self) -> dict[str, np.ndarray | None]:
        """The law's inputs by name: feedforward, reference, gain, integral_gain."""
        return {"feedforward": self.feedforward, "reference": self.reference, "gain": self.gain,
                "integral_gain": self.integral_gain}


def rollout(model: Model, x0: np.ndarray, options: RolloutOptions, law: FeedbackLaw | None = None,
            parameters: ParameterValues = None) -> tuple[np.ndarray, np.ndarray]:
    """Fixed-step trajectory of ``model`` under ``law`` (none: zero torque), in one call.

    An ensemble: ``x0`` of shape (N, 2 n) integrates N trajectories under the same law and
    inputs in one C call (sampled control only), a block of trajectories per vector loop
    (SIMD across trajectories) and blocks on ``options.threads`` threads; each trajectory has
    the same bits as its own run. Results gain a leading N.

    Parameters
    ----------
    model : Model
    x0 : numpy.ndarray, shape (2 n,) or (N, 2 n)
        Initial ``[q, qd]`` (rad or m, rad/s or m/s), or one per trajectory.
    options : RolloutOptions
    law : FeedbackLaw, optional
    parameters : mapping, sequence of N mappings, or (P,) / (N, P), optional
        Values of the model's :attr:`~robodyn.numeric.model.Model.runtime_parameters`: one set,
        or one per trajectory of an ensemble (each integrated with its own dynamics and
        model-based law, in the same one C call); checked like compile-time values (finite,
        physically possible).

    Returns
    -------
    x : numpy.ndarray, shape (steps + 1, 2 n) or (N, steps + 1, 2 n)
        States, ``x[0] = x0``.
    tau : numpy.ndarray, shape (steps, n) or (N, steps, n)
        Torques at the start of each step (those applied over it when sampled), N m (N).

    Raises
    ------
    InputError
        A shape that does not fit the model, an ensemble under continuous control, an output
        above :data:`MAX_INTEGRATE_BYTES`.
    SimulationError
        When the state stops being finite (the step is named; ``exc.state`` holds the last
        finite state).
    """
    if not isinstance(options, RolloutOptions):
        raise InputError(f"rollout: options must be a RolloutOptions, got {type(options).__name__}")
    law = FeedbackLaw() if law is None else law
    model._require_dynamics()
    n, nx = model.dof, 2 * model.dof
    steps, dt, threads = int(options.steps), float(options.dt), int(options.threads)
    continuous = options.control == "continuous"
    ensemble = np.ndim(x0) == 2
    if ensemble and continuous:
        raise InputError("rollout: an ensemble (x0 of shape (N, 2 n)) runs control='sampled' "
                         "only; integrate continuous-time control one trajectory at a time")
    count = np.shape(x0)[0] if ensemble else 1
    size = 8 * (steps + 1) * 3 * n * count
    if size > MAX_INTEGRATE_BYTES:
        raise InputError(f"rollout: {steps:,} steps of {n} joints need {size / 2**20:,.0f} MiB "
                         f"of output, above {MAX_INTEGRATE_BYTES / 2**20:,.0f} MiB; split the "
                         "run into several calls from the last state (simulate() does so)")
    checked = _checked_inputs(model, x0, options, law, parameters,
                              (count,) if ensemble else ())
    method, mode = _METHODS[options.method], _MODES[law.mode]
    if ensemble:
        return _ensemble(model, checked, steps, dt, method, mode, threads)
    x_out = np.empty((steps + 1, nx))
    tau_out = np.empty((steps, n))
    if isinstance(model._impl, ModuleType):
        status = integrate_numpy(model, steps, dt, method, mode, checked, x_out, tau_out,
                                 continuous)
    else:
        ffi = model._impl.ffi
        ptr = {k: (ffi.NULL if v is None else ffi.from_buffer("double[]", v))
               for k, v in checked.items()}
        params = (ptr["params"],) if model.runtime_parameters else ()
        status = model._impl.lib.rd_simulate(
            steps, float(dt), method, ptr["x0"], ptr["feedforward"], ptr["reference"],
            ptr["gain"], ptr["integral_gain"], mode, ptr["tau_limit"], *params,
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


def _checked_inputs(model: Model, x0: np.ndarray, options: RolloutOptions, law: FeedbackLaw,
                    parameters: ParameterValues, batch: tuple[int, ...]
                    ) -> dict[str, np.ndarray | None]:
    """The integrator's arrays, C-contiguous float64, each of its expected shape (or None),
    and ``"params"``: the runtime parameter values, one set or one per trajectory of ``batch``
    (checked like compile-time values)."""
    n, nx = model.dof, 2 * model.dof
    steps = int(options.steps)
    rows = 2 * steps + 1 if options.control == "continuous" else steps
    arrays = {
        "x0": (x0, batch + (nx,)), "feedforward": (law.feedforward, (rows, n)),
        "reference": (law.reference, (rows, nx)), "gain": (law.gain, (n, nx)),
        "integral_gain": (law.integral_gain, (n,)), "tau_limit": (options.tau_limit, (n,)),
    }
    checked: dict[str, np.ndarray | None] = {}
    for key, (val, shape) in arrays.items():
        if val is None:
            checked[key] = None
            continue
        arr = np.ascontiguousarray(val, dtype=np.float64)
        if arr.shape != shape:
            raise InputError(f"rollout: {key} must have shape {shape}, got {arr.shape}")
        checked[key] = arr
    checked["params"] = None
    if model.runtime_parameters or parameters is not None:
        checked["params"] = model.parameter_input(parameters, batch, "rollout")
        check_physics(model.robot, model.runtime_parameters, model.parameters, checked["params"],
                      "rollout(parameters=...)")
    return checked


def _ensemble(model: Model, a: dict[str, np.ndarray | None], steps: int, dt: float,
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
