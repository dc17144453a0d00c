"""Built-in joint controllers: PD, PID, gravity-compensated PD, computed torque, LQR.

Each controller is a frozen dataclass that can be used three ways:

* by :func:`robodyn.simulation.simulate` with a fixed-step method: it translates itself into the
  law of :func:`robodyn.simulation.rollouts.rollout` (``sampled``: a :class:`FeedbackLaw`), so the
  whole run is one call into generated C, with the law held over each step;
* by :func:`~robodyn.simulation.simulate` with a SciPy method: its continuous law ``law`` is
  evaluated inside the right-hand side (a PID's error integral becomes extra states);
* as a plain callable ``controller(t, q, qd) -> tau``. Controllers that need the dynamics
  (gravity compensation, computed torque) must then be given ``model=``.

References ``q_ref`` are a constant (n,) set point or a planned
:class:`~robodyn.simulation.trajectory.JointTrajectory` (its velocity then enters the D term).
Gains are a scalar, an (n,) diagonal or an (n, n) matrix. Every law is clipped to
``+-tau_limit`` (N m or N) when one is given.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.linalg import solve_continuous_are

from robodyn.codegen.fixed_step import LAW_MODES
from robodyn.codegen.fixed_step import law as sampled_law
from robodyn.numeric.model import Model
from robodyn.robot.errors import InputError
from robodyn.simulation.linearization import Linearization, linearize
from robodyn.simulation.rollouts import FeedbackLaw
from robodyn.simulation.trajectory import JointTrajectory

Reference = np.ndarray | JointTrajectory


class Controller:
    """Common behaviour of the built-in controllers (not instantiated itself)."""

    tau_limit: np.ndarray | None
    model: Model | None = None

    @property
    def name(self) -> str:
        """Short name for reports."""
        return type(self).__name__

    # --- to override ---------------------------------------------------------------------------
    def sampled(self, model: Model, t: np.ndarray) -> FeedbackLaw:
        """The law of :func:`~robodyn.simulation.rollouts.rollout` for steps starting at times
        ``t`` (steps,): its inputs per step (:func:`robodyn.codegen.fixed_step.law`) and mode."""
        raise NotImplementedError

    # --- shared --------------------------------------------------------------------------------
    def law(self, model: Model | None, t: float, x: np.ndarray,
            integral: np.ndarray | None = None) -> np.ndarray:
        """Unclipped torque (n,) at time ``t`` (s) and state ``x = [q; qd]`` (2 n,).

        The controller's inputs at ``t`` (:meth:`sampled`) through the one law that the
        generated C and NumPy integrators run (:func:`robodyn.codegen.fixed_step.law`).
        ``integral`` is the time integral of the position error (rad s or m s), used by PID.
        ``model``: the plant's model (the controller's own ``model=`` is used instead for the
        model terms of gravity compensation and computed torque when it has one).
        """
        x = np.asarray(x, dtype=float)
        n = x.size // 2
        inputs = self.sampled(model if model is not None else _Joints(n), np.array([float(t)]))
        mode = _MODE[inputs.mode]
        z = np.zeros(n) if integral is None else np.asarray(integral, dtype=float)
        own = _need_model(self, model) if mode else None
        zero = np.zeros(n)
        terms = {"mass_matrix": lambda q, qd: own.mass_matrix(q),  # type: ignore[union-attr]
                 "bias": lambda q, qd: own.inverse_dynamics(q, qd, zero),  # type: ignore[union-attr]
                 "gravity": lambda q, qd: own.gravity(q)}  # type: ignore[union-attr]
        return sampled_law({**inputs.arrays(), "tau_limit": None}, 0, x, z, mode,
                           lambda name, q, qd: terms[name](q, qd))

    @property
    def has_integral(self) -> bool:
        """True when the law needs the error integral as extra state."""
        return False

    def position_error(self, t: float, q: np.ndarray) -> np.ndarray:
        """``q_ref(t) - q`` (the integrand of the I term)."""
        return _reference_at(self._ref(), t, q.size)[0] - q

    def _ref(self) -> Reference:
        raise NotImplementedError

    def clip(self, tau: np.ndarray) -> np.ndarray:
        """``tau`` clipped to ``+-tau_limit``."""
        return tau if self.tau_limit is None else np.clip(tau, -self.tau_limit, self.tau_limit)

    def __call__(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Torque (n,) at time ``t`` for joint positions ``q`` and velocities ``qd``."""
        model = self.model
        x = np.concatenate([np.asarray(q, dtype=float), np.asarray(qd, dtype=float)])
        return self.clip(self.law(model, t, x, None))  # type: ignore[arg-type]


@dataclass(frozen=True)
class _Joints:
    """Stands for a model where only its number of joints is needed (a controller called alone)."""

    dof: int


#: The law's mode names to the integer the integrators take.
_MODE = {name: k for k, name in LAW_MODES.items()}


def _freeze(a: np.ndarray | None) -> np.ndarray | None:
    if a is None:
        return None
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


def _gain(k: Any, n: int, name: str) -> np.ndarray:
    """A gain as an (n, n) matrix from a scalar, an (n,) diagonal or an (n, n) matrix."""
    arr = np.asarray(k, dtype=float)
    if arr.ndim == 0:
        return float(arr) * np.eye(n)
    if arr.shape == (n,):
        return np.diag(arr)
    if arr.shape == (n, n):
        return arr
    raise InputError(f"{name} must be a scalar, an ({n},) diagonal or an ({n}, {n}) matrix, "
                     f"got shape {arr.shape}")


def _reference_at(ref: Reference, t: float | np.ndarray, n: int) -> tuple[np.ndarray, ...]:
    """``(q_ref, qd_ref, qdd_ref)`` at t: (n,) for a scalar t, (K, n) for a (K,) array."""
    if isinstance(ref, JointTrajectory):
        if ref.dof != n:
            raise InputError(f"the reference trajectory has {ref.dof} joints, the model {n}")
        return ref.at(t)
    q = np.asarray(ref, dtype=float)
    if q.shape != (n,):
        raise InputError(f"q_ref must have shape ({n},) (or be a JointTrajectory), got {q.shape}")
    shape = np.shape(t) + (n,)
    return np.broadcast_to(q, shape).copy(), np.zeros(shape), np.zeros(shape)


def _check_ref(ref: Any) -> Reference:
    if isinstance(ref, JointTrajectory):
        return ref
    arr = np.asarray(ref, dtype=float)
    if arr.ndim != 1 or not np.all(np.isfinite(arr)):
        raise InputError(f"q_ref must be a finite (n,) array or a JointTrajectory, got {ref!r}")
    return _freeze(arr)  # type: ignore[return-value]


def _limit(v: Any) -> np.ndarray | None:
    if v is None:
        return None
    arr = np.atleast_1d(np.asarray(v, dtype=float))
    if arr.ndim != 1 or np.any(~np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError(f"tau_limit must be positive (a scalar or an (n,) array), got {v!r}")
    return _freeze(arr)


def _pd_sampled(kp: np.ndarray, kd: np.ndarray, ref: Reference, n: int, t: np.ndarray) -> dict[str, Any]:
    q_r, qd_r, _ = _reference_at(ref, t, n)
    return {"reference": np.hstack([q_r, qd_r]), "gain": np.hstack([_gain(kp, n, "kp"), _gain(kd, n, "kd")])}


class _Tracking(Controller):
    """A controller that follows a reference: a set point or a planned trajectory.

    The dataclass field named by ``_reference_field`` (``q_ref`` unless a subclass names
    another) holds the reference, a constant (n,) array (rad or m) or a
    :class:`~robodyn.simulation.trajectory.JointTrajectory`; ``tau_limit`` (n,) N m or N.
    Both are checked and frozen after construction.
    """

    _reference_field = "q_ref"

    def __post_init__(self) -> None:
        name = self._reference_field
        object.__setattr__(self, name, _check_ref(getattr(self, name)))
        object.__setattr__(self, "tau_limit", _limit(self.tau_limit))

    def _ref(self) -> Reference:
        return getattr(self, self._reference_field)


@dataclass(frozen=True, eq=False)
class PD(_Tracking):
    """``tau = Kp (q_ref - q) + Kd (qd_ref - qd)``.

    Parameters
    ----------
    kp : float, (n,) or (n, n)
        Stiffness, N m/rad (N/m).
    kd : float, (n,) or (n, n)
        Damping, N m s/rad (N s/m).
    q_ref : (n,) array_like or JointTrajectory
    tau_limit : float or (n,), optional
    """

    kp: Any
    kd: Any
    q_ref: Reference
    tau_limit: np.ndarray | None = None

    def sampled(self, model: Model, t: np.ndarray) -> FeedbackLaw:
        return FeedbackLaw("feedback", **_pd_sampled(self.kp, self.kd, self.q_ref, model.dof, t))


@dataclass(frozen=True, eq=False)
class PID(_Tracking):
    """``tau = Kp e + Ki integral(e dt) + Kd ed`` with ``e = q_ref - q``.

    ``ki`` must be diagonal (a scalar or (n,)). Used as a plain callable, the integral is
    accumulated between calls as ``sum e_k (t_k - t_{k-1})`` (call :meth:`reset` before reuse);
    inside :func:`~robodyn.simulation.simulate` it is integrated exactly as extra states (SciPy
    methods) or summed per step in C (``integral += e dt`` before the torque is formed).
    """

    kp: Any
    ki: Any
    kd: Any
    q_ref: Reference
    tau_limit: np.ndarray | None = None
    _state: dict = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        ki = np.asarray(self.ki, dtype=float)
        if ki.ndim > 1:
            raise InputError("PID: ki must be a scalar or an (n,) diagonal (the integral gain acts "
                             "joint by joint)")

    @property
    def has_integral(self) -> bool:
        return True

    def _ki(self, n: int) -> np.ndarray:
        return np.diag(_gain(self.ki, n, "ki")).copy()

    def reset(self) -> None:
        """Forget the accumulated integral of the callable form."""
        self._state.clear()

    def __call__(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        e = self.position_error(t, q)
        z = self._state.get("z", np.zeros(q.size))
        if "t" in self._state:
            z = z + e * (t - self._state["t"])
        self._state.update(t=t, z=z)
        x = np.concatenate([q, np.asarray(qd, dtype=float)])
        return self.clip(self.law(self.model, t, x, z))  # type: ignore[arg-type]

    def sampled(self, model: Model, t: np.ndarray) -> FeedbackLaw:
        return FeedbackLaw("feedback", integral_gain=self._ki(model.dof),
                           **_pd_sampled(self.kp, self.kd, self.q_ref, model.dof, t))


@dataclass(frozen=True, eq=False)
class GravityCompensation(_Tracking):
    """PD plus the gravity load: ``tau = Kp e + Kd ed + g(q)``.

    Parameters as :class:`PD`. ``model``: the controller's model of the robot, needed for the
    plain-callable form; inside :func:`~robodyn.simulation.simulate` it is used instead of the
    plant's model when given (the plant's model otherwise).
    """

    kp: Any
    kd: Any
    q_ref: Reference
    tau_limit: np.ndarray | None = None
    model: Model | None = field(default=None, repr=False)

    def sampled(self, model: Model, t: np.ndarray) -> FeedbackLaw:
        return FeedbackLaw("gravity", **_pd_sampled(self.kp, self.kd, self.q_ref, model.dof, t))


@dataclass(frozen=True, eq=False)
class ComputedTorque(_Tracking):
    """Inverse-dynamics tracking of a planned trajectory.

    ``tau = M(q) (qdd_ref + Kp e + Kd ed) + h(q, qd)`` with ``h = C qd + g + friction`` (the
    model's inverse dynamics at zero acceleration): with an exact model the error obeys
    ``ed' + Kd ed + Kp e = 0``.

    Parameters
    ----------
    trajectory : JointTrajectory or (n,) array_like
        Reference motion (a constant set point is allowed).
    kp, kd : float, (n,) or (n, n)
        Error dynamics gains, 1/s^2 and 1/s.
    tau_limit : float or (n,), optional
    model : Model, optional
        The controller's model of the robot. Needed for the plain-callable form; inside
        :func:`~robodyn.simulation.simulate` it is used instead of the simulated plant's model
        (a controller with a wrong model tracks worse); without it the plant's model is used
        (an exact model).
    """

    trajectory: Reference
    kp: Any
    kd: Any
    tau_limit: np.ndarray | None = None
    model: Model | None = field(default=None, repr=False)
    _reference_field = "trajectory"

    def sampled(self, model: Model, t: np.ndarray) -> FeedbackLaw:
        _, _, qdd_r = _reference_at(self.trajectory, t, model.dof)
        return FeedbackLaw("computed_torque", feedforward=qdd_r,
                           **_pd_sampled(self.kp, self.kd, self.trajectory, model.dof, t))


@dataclass(frozen=True, eq=False)
class LQR(Controller):
    """Linear-quadratic regulator about an equilibrium: ``tau = u_eq + K (x_eq - x)``.

    Build it with :meth:`LQR.about`, which linearises the robot's symbolic equations and solves
    the continuous algebraic Riccati equation ``A^T P + P A - P B R^-1 B^T P + Q = 0``,
    ``K = R^-1 B^T P``.

    Attributes
    ----------
    K : (n, 2 n) ndarray
        State-feedback gain.
    x_eq : (2 n,) ndarray
    u_eq : (n,) ndarray
        Equilibrium torque ``g(q_eq)`` (plus constant friction offsets).
    linearization : Linearization or None
    P : (2 n, 2 n) ndarray or None
        Riccati solution.
    tau_limit : (n,) ndarray or None
    """

    K: np.ndarray
    x_eq: np.ndarray
    u_eq: np.ndarray
    linearization: Linearization | None = field(default=None, repr=False)
    P: np.ndarray | None = field(default=None, repr=False)
    tau_limit: np.ndarray | None = None

    def __post_init__(self) -> None:
        K, x_eq, u_eq = (np.asarray(v, dtype=float) for v in (self.K, self.x_eq, self.u_eq))
        n = u_eq.size
        if u_eq.shape != (n,) or x_eq.shape != (2 * n,) or K.shape != (n, 2 * n):
            raise InputError(f"LQR: K must be (n, 2 n), x_eq (2 n,) and u_eq (n,); got {K.shape}, "
                             f"{x_eq.shape}, {u_eq.shape}")
        for name, v in (("K", K), ("x_eq", x_eq), ("u_eq", u_eq)):
            object.__setattr__(self, name, _freeze(v))
        object.__setattr__(self, "tau_limit", _limit(self.tau_limit))

    @classmethod
    def about(cls, model: Model, q_eq: np.ndarray, Q: Any, R: Any, *,  # noqa: N803 - textbook names
              actuated: Sequence[int] | None = None, tau_limit: Any = None) -> LQR:
        """LQR about the equilibrium ``(q_eq, qd = 0, u_eq = g(q_eq))``.

        Parameters
        ----------
        model : Model
        q_eq : (n,) array_like
        Q : float, (2 n,) or (2 n, 2 n)
            State weight (positive semi-definite).
        R : float, (m,) or (m, m)
            Input weight (positive definite), m = number of actuated joints.
        actuated : sequence of int, optional
            Indices of the joints that have an actuator (default: all). The others get zero
            torque (rows of ``K`` are zero), e.g. ``[0]`` for a trolley pushing a passive
            double pendulum; their equilibrium torque must then be zero.
        tau_limit : float or (n,), optional

        Returns
        -------
        LQR

        Raises
        ------
        ValueError
            When ``q_eq`` needs a torque on an unactuated joint, or the linearisation is not
            stabilisable with the actuated joints (the Riccati equation has no solution).
        """
        n = model.dof
        lin = linearize(model, q_eq)
        act = list(range(n)) if actuated is None else [int(i) for i in actuated]
        if not act or len(set(act)) != len(act) or not all(0 <= i < n for i in act):
            raise InputError(f"LQR: actuated must list distinct joint indices in 0..{n - 1}, "
                             f"got {actuated!r}")
        passive = [i for i in range(n) if i not in act]
        if passive and np.max(np.abs(lin.u0[passive])) > 1e-9 * max(1.0, np.max(np.abs(lin.u0))):
            raise InputError(f"LQR: q_eq is not an equilibrium without torque on the unactuated joints "
                             f"{passive} (it needs {lin.u0[passive]})")
        b = lin.B[:, act]
        q_mat, r_mat = _gain(Q, 2 * n, "Q"), _gain(R, len(act), "R")
        # A^T P + P A - P B R^-1 B^T P + Q = 0
        try:
            p = solve_continuous_are(lin.A, b, q_mat, r_mat)
        except (np.linalg.LinAlgError, ValueError) as exc:
            raise InputError(f"LQR: no stabilising solution of the Riccati equation ({exc})") from exc
        # K = R^-1 B^T P (zero rows for the unactuated joints)
        k = np.zeros((n, 2 * n))
        k[act] = np.linalg.solve(r_mat, b.T @ p)
        u_eq = np.array(lin.u0)
        u_eq[passive] = 0.0
        return cls(k, lin.x0, u_eq, lin, p, tau_limit)

    @property
    def closed_loop_poles(self) -> np.ndarray:
        """Eigenvalues of ``A - B K`` (1/s), when built by :meth:`about`."""
        if self.linearization is None:
            raise InputError("LQR: closed_loop_poles needs the linearisation (build with LQR.about)")
        lin = self.linearization
        return np.linalg.eigvals(lin.A - lin.B @ self.K)

    def _ref(self) -> Reference:
        return self.x_eq[: self.u_eq.size]

    def sampled(self, model: Model, t: np.ndarray) -> FeedbackLaw:
        steps, n = t.size, model.dof
        if self.u_eq.size != n:
            raise InputError(f"LQR was built for {self.u_eq.size} joints, the model has {n}")
        return FeedbackLaw("feedback", feedforward=np.tile(self.u_eq, (steps, 1)),
                           reference=np.tile(self.x_eq, (steps, 1)), gain=np.array(self.K))


def _need_model(ctrl: Controller, model: Model | None) -> Model:
    """The controller's own ``model=`` when it has one (its belief about the plant), else ``model``."""
    model = ctrl.model if ctrl.model is not None else model
    if model is None:
        raise InputError(f"{ctrl.name} needs the robot's dynamics: construct it with model=... to "
                         f"call it directly (simulate() passes its model itself)")
    return model


__all__ = ["PD", "PID", "LQR", "ComputedTorque", "Controller", "GravityCompensation"]
