"""Non-geometric joint errors: joint compliance and transmission harmonics.

Both are corrections of the joint readings, linear in their parameters ``theta``::

    q_link = q + B(q) theta          B (N, n, M): one column per parameter

so the position Jacobian with respect to ``theta`` is the joint Jacobian times ``B`` and every
geometric error model (:mod:`robodyn.calibration.models`) can carry them.

Compliance (elastostatic joints): joint ``j`` twists under the load its drive holds,
``dq_j = -c_j tau_j(q)``, with ``tau_j(q)`` the static torque that holds the arm still
(the robot's gravity model, ``rd.compile_model(robot).gravity(q)``, evaluated numerically by
:func:`gravity_torque` without compiling anything; plus a payload when given) and ``c_j >= 0`` the joint's
compliance in rad/(N m) (m/N for a prismatic joint). When the description has no masses, ``tau``
is a gravity-shaped basis instead: the holding torque of a 1 kg point mass at the origin of every
joint frame after joint ``j`` and at the tool (then ``c_j`` absorbs the unknown mass scale and its
unit is rad/(N m) per that unit-mass torque).

Payload: a known payload (mass, centre of mass in the tool frame) adds its holding torque to
``tau``. An identified payload (``identify_payload``) has four parameters, its mass ``m`` and first
moments ``m r`` (kg m, tool frame), so ``tau_j = g_j(q) + T_j(q) pi`` with ``pi = (m, m r_x, m r_y,
m r_z)`` and ``T`` the holding torques of a unit mass at the tool origin and of unit first moments
along the tool axes; the deflection ``-c_j tau_j`` is then bilinear in ``(c, pi)``
(:meth:`NonGeometric.correction` gives it with its exact Jacobian). At ``c = 0`` the payload has
no effect, so it is identified after the compliances (:func:`robodyn.calibration.calibrate` fits in
two stages).

Harmonics (transmission errors): ``dq_j = k_j q_j + a_j cos(q_j) + b_j sin(q_j)``: a
transmission ratio error ``k_j`` (the reading's scale) and the first harmonic of the joint angle
(eccentricity of the output gear), and, when the description gives a gear ratio ``G_j`` other than 1, also
``a'_j cos(G_j q_j) + b'_j sin(G_j q_j)`` (the motor's first harmonic seen at the link), rad.
Only revolute joints get harmonics.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from robodyn.numeric.joint_corrections import holding_torque
from robodyn.robot.corrections import CORRECTION_KINDS, HoldingTorque, JointCorrections
from robodyn.robot.errors import InputError
from robodyn.robot.numbers import RobotNumbers, full_robot, robot_numbers

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["DEFLECTIONS", "NONGEOMETRIC", "NonGeometric", "build_nongeometric", "gravity_torque",
           "nominal_frames"]

#: The non-geometric terms, by name.
NONGEOMETRIC = ("compliance", "harmonics")
#: Compliance models: holding torque at the readings, or at the deflected pose.
DEFLECTIONS = ("linear", "exact")


@dataclass(frozen=True, eq=False)
class NonGeometric:
    """Non-geometric joint corrections of one robot (module docstring).

    Attributes
    ----------
    terms : tuple of str
        Subset of :data:`NONGEOMETRIC`.
    names : tuple of str, length M
        Parameter names: ``"q2.compliance"``, ``"q1.ratio"``, ``"q1.cos1"``, ``"q1.sin1"``,
        ``"q1.motor_cos1"``, ``"q1.motor_sin1"``.
    units : tuple of str, length M
        ``"rad/(N m)"``, ``"m/N"``, ``"rad"`` or ``"1"`` (ratio error).
    joints : tuple of int, length M
        The joint each parameter corrects (-1 for the payload's).
    kinds : tuple of str, length M
        ``"compliance"``, ``"ratio"``, ``"cos"``, ``"sin"``, ``"motor_cos"``, ``"motor_sin"``,
        ``"payload_mass"``, ``"payload_moment"``.
    gear_ratio : numpy.ndarray, shape (n,)
        Gear ratios (NaN where the description gives none).
    torque : callable or None
        ``torque(q)``: holding torques (N, n) for readings (N, n), N m; None without compliance.
    torque_source : str
        ``"gravity model"``, ``"gravity model + payload"`` or ``"gravity-shaped basis"`` (or ``""``),
        with ``" + identified payload"`` when the payload is estimated.
    initial : numpy.ndarray, shape (M,)
        Starting values (zero, or the given payload for an identified one).
    payload_torque : callable or None
        ``payload_torque(q)``: ``T`` (N, n, 4), the holding torques per unit payload parameter
        ``(m, m r_x, m r_y, m r_z)``, N m per kg (per kg m); None unless the payload is identified.
    deflection : {"linear", "exact"}
        ``"linear"``: the holding torque at the readings, ``dq = -C tau(q)``. ``"exact"``: at the
        deflected pose, ``x = u - C tau(x)`` (:mod:`robodyn.numeric.deflection`).
    torque_jacobian : callable or None
        ``torque_jacobian(x)``: ``d tau / d x`` (N, n, n) for ``"exact"``.
    exact_torque : callable or None
        ``exact_torque(x)``: the holding torques (N, n) used by ``"exact"`` (the compiled model's
        gravity, plus a known payload).
    holding : HoldingTorque or None
        The point masses whose holding torque ``torque`` evaluates (without an identified
        payload); what a calibrated description stores (:meth:`corrections`).
    tool_zero : numpy.ndarray, shape (4, 4), or None
        The nominal tool frame at zero readings (places an identified payload in ``holding``).
    """

    terms: tuple[str, ...]
    names: tuple[str, ...]
    units: tuple[str, ...]
    joints: tuple[int, ...]
    kinds: tuple[str, ...]
    gear_ratio: np.ndarray
    torque: Callable[[np.ndarray], np.ndarray] | None
    torque_source: str
    initial: np.ndarray | None = None
    payload_torque: Callable[[np.ndarray], np.ndarray] | None = None
    deflection: str = "linear"
    torque_jacobian: Callable[[np.ndarray], np.ndarray] | None = None
    exact_torque: Callable[[np.ndarray], np.ndarray] | None = None
    holding: HoldingTorque | None = None
    tool_zero: np.ndarray | None = None
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def n_params(self) -> int:
        """Number of parameters M."""
        return len(self.names)

    def _of_readings(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """``B(q)`` and ``T(q)`` for readings ``q``, kept for the last ``q`` (they depend on the
        readings only, not on the parameters: one gravity evaluation per data set, not per
        iteration)."""
        last = self._cache.get("q")
        if last is None or last.shape != q.shape or not np.array_equal(last, q):
            b = self._basis(q)
            t = self.payload_torque(q) if self.payload_torque is not None else None
            for a in (b, t):
                if a is not None:
                    a.flags.writeable = False  # shared by every evaluation of these readings
            self._cache.update(q=q.copy(), basis=b, payload=t)
        return self._cache["basis"], self._cache["payload"]

    def basis(self, q: np.ndarray) -> np.ndarray:
        """``B(q)``, shape (N, n, M): the linear part, ``q_link = q + B(q) theta`` without an
        identified payload, for readings ``q`` (N, n)."""
        return self._of_readings(np.asarray(q, dtype=float))[0].copy()

    def correction(self, q: np.ndarray, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Joint corrections ``dq`` (N, n) for readings ``q`` (N, n) and parameters ``theta``
        (M,), and their Jacobian ``d dq / d theta`` (N, n, M): ``q_link = q + dq``."""
        q = np.asarray(q, dtype=float)
        b, t = self._of_readings(q)
        if self.deflection == "exact":
            return self._exact_correction(q, b, theta)
        dq = b @ theta
        if t is None:
            return dq, b
        jac = b.copy()
        kinds = np.array(self.kinds)
        pay = np.flatnonzero(np.char.startswith(kinds, "payload"))
        comp = np.flatnonzero(kinds == "compliance")
        joints = np.array(self.joints)[comp]
        c = np.zeros(q.shape[1])
        c[joints] = theta[comp]
        tp = t @ theta[pay]  # (N, n) payload holding torque
        # dq_j = -c_j (g_j + T_j pi): d/dc_j adds -T_j pi, d/dpi = -c_j T_j
        dq = dq - c * tp
        jac[:, joints, comp] -= tp[:, joints]
        jac[:, :, pay] = -c[None, :, None] * t
        return dq, jac

    def _exact_correction(self, q: np.ndarray, b: np.ndarray, theta: np.ndarray,
                          ) -> tuple[np.ndarray, np.ndarray]:
        """``dq = x - q`` (N, n) with ``x = u - C tau(x)``, ``u = q + B_h theta_h`` (the terms other
        than compliance), and its exact Jacobian (N, n, M) by the implicit function theorem."""
        from robodyn.numeric.deflection import exact_deflection

        kinds = np.array(self.kinds)
        comp = np.flatnonzero(kinds == "compliance")
        other = np.flatnonzero(kinds != "compliance")
        joints = np.array(self.joints)[comp]
        c = np.zeros(q.shape[1])
        c[joints] = theta[comp]
        u = q + b[:, :, other] @ theta[other]
        d = exact_deflection(u, c, self.exact_torque, self.torque_jacobian)
        jac = np.zeros(b.shape)
        # dx/dtheta_h = (I + C G)^-1 B_h;  dx/dc_j = -(I + C G)^-1 e_j tau_j(x)
        jac[:, :, other] = d.sensitivity @ b[:, :, other]
        jac[:, :, comp] = -d.sensitivity[:, :, joints] * d.torque[:, None, joints]
        return d.q_link - q, jac

    def _basis(self, q: np.ndarray) -> np.ndarray:
        out = np.zeros((len(q), q.shape[1], self.n_params))
        tau = self.torque(q) if "compliance" in self.kinds else None
        for m, (j, kind) in enumerate(zip(self.joints, self.kinds, strict=True)):
            if kind == "compliance":
                out[:, j, m] = -tau[:, j]  # dq = -c tau: the joint gives way under its load
            elif kind == "ratio":
                out[:, j, m] = q[:, j]  # dq = k q: scale error of the transmission
            elif kind == "cos":
                out[:, j, m] = np.cos(q[:, j])
            elif kind == "sin":
                out[:, j, m] = np.sin(q[:, j])
            elif kind == "motor_cos":
                out[:, j, m] = np.cos(self.gear_ratio[j] * q[:, j])  # motor angle G q
            elif kind == "motor_sin":
                out[:, j, m] = np.sin(self.gear_ratio[j] * q[:, j])
            # payload_mass, payload_moment: bilinear, in correction()
        return out

    def corrections(self, theta: np.ndarray) -> JointCorrections:
        """The terms at parameters ``theta`` (M,) as a description's joint-reading corrections.

        Loaded with a calibrated description, forward kinematics then gives what
        ``cal.predict`` gives (:mod:`robodyn.robot.corrections`): the same transmission terms, and
        the compliance's holding torque of the same point masses (an identified payload added
        as a point mass, or a mass and first moment, at the tool).
        """
        theta = np.asarray(theta, dtype=float)
        column = {"ratio": 0, "cos": 1, "sin": 2, "motor_cos": 3, "motor_sin": 4, "compliance": 5}
        table = np.zeros((len(self.gear_ratio), len(CORRECTION_KINDS)))
        for j, kind, value in zip(self.joints, self.kinds, theta, strict=True):
            if kind in column:
                table[j, column[kind]] = value
        holding = self.holding if "compliance" in self.terms else None
        pay = [m for m, kind in enumerate(self.kinds) if kind.startswith("payload")]
        if holding is not None and pay and self.tool_zero is not None:
            pi = theta[pay]  # (m, m r) in the tool frame
            moment = self.tool_zero[:3, :3] @ pi[1:] + pi[0] * self.tool_zero[:3, 3]
            holding = replace(holding, masses=holding.masses + (float(pi[0]),),
                              moments=holding.moments + _rows(moment),
                              moved_by=holding.moved_by + (len(self.gear_ratio),),
                              source=holding.source + " + identified payload")
        return JointCorrections(tuple(tuple(float(v) for v in row) for row in table), holding,
                                self.deflection)

    def as_dict(self, values: np.ndarray) -> dict:
        """The terms and their values as plain data (for the YAML/JSON output)."""
        return {
            "terms": list(self.terms),
            "torque_source": self.torque_source,
            "deflection": self.deflection,
            "parameters": [{"name": n, "joint": int(j), "kind": k, "value": float(v), "unit": u}
                           for n, j, k, v, u in zip(self.names, self.joints, self.kinds, values,
                                                    self.units, strict=True)],
        }


def robot_holding(robot: Robot | RobotNumbers) -> HoldingTorque:
    """The robot's own links as point masses on its nominal geometry (world frame, zero readings).

    The links' masses and centres of mass ride on the nominal geometry at ``q = 0``
    (:func:`robodyn.calibration.nominal.robot_geometry`); link ``j`` moves with joints ``1 .. j``.
    """
    from robodyn.calibration.nominal import robot_geometry

    geometry = robot_geometry(robot)
    num = robot_numbers(robot)
    gravity, masses, coms = num.gravity, num.masses, num.coms
    com0 = np.einsum("nij,nj->ni", geometry.link_frames[:, :3, :3], coms) + geometry.link_frames[:, :3, 3]
    dirs = geometry.directions / np.linalg.norm(geometry.directions, axis=1, keepdims=True)
    return HoldingTorque(_rows(geometry.points), _rows(dirs), tuple(geometry.joint_types),
                         tuple(float(m) for m in masses), _rows(masses[:, None] * com0),
                         tuple(range(1, num.dof + 1)), tuple(float(g) for g in gravity), "gravity model")


def _rows(a: np.ndarray) -> tuple[tuple[float, float, float], ...]:
    return tuple(tuple(float(v) for v in row) for row in np.asarray(a, dtype=float).reshape(-1, 3))


def _with_points(holding: HoldingTorque, masses: Sequence[float], points: np.ndarray,
                 moved_by: Sequence[int], source: str) -> HoldingTorque:
    """``holding`` with point masses added (kg at ``points`` (K, 3), m, zero readings)."""
    moments = np.asarray(masses, dtype=float)[:, None] * np.asarray(points, dtype=float).reshape(-1, 3)
    return replace(holding, masses=holding.masses + tuple(float(m) for m in masses),
                   moments=holding.moments + _rows(moments),
                   moved_by=holding.moved_by + tuple(int(b) for b in moved_by), source=source)


def gravity_torque(robot: Robot) -> Callable[[np.ndarray], np.ndarray]:
    """``g(q)`` (N, n), N m (N): the holding torques of the robot's own links, evaluated numerically.

    :func:`robot_holding` evaluated by :func:`robodyn.numeric.joint_corrections.holding_torque`
    (product of exponentials on the nominal geometry): the same as
    ``rd.compile_model(robot).gravity(q)`` without deriving or compiling the whole model
    (tests/calibration/test_payload.py compares them).
    """
    holding = robot_holding(robot)
    return lambda q: holding_torque(holding, q)


def _compiled_gravity(robot: Robot | RobotNumbers, extra: Callable[[np.ndarray], np.ndarray] | None,
                      h: float = 1e-6,
                      ) -> tuple[Callable[[np.ndarray], np.ndarray], Callable[[np.ndarray], np.ndarray]]:
    """``tau(x)`` (N, n) and ``G(x) = d tau / d x`` (N, n, n) from the compiled model.

    ``tau = g(x)`` (plus ``extra(x)``, a known payload's holding torque) and ``G`` from
    ``inverse_dynamics_derivatives(x, 0, 0)`` (at rest ``d tau / d q = d g / d q``), plus the
    payload's derivative by central differences of ``extra`` (step ``h``). The model is compiled
    on the first call only (cached on disk by :func:`robodyn.compile_model`), so building the
    terms costs nothing until they are evaluated.
    """
    state: dict = {}

    def model():
        if "m" not in state:
            from robodyn.numeric.model import compile_model  # on first use only

            state["m"] = compile_model(full_robot(robot))
        return state["m"]

    def torque(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        tau = np.asarray(model().gravity(x), dtype=float).reshape(x.shape)
        return tau + extra(x) if extra is not None else tau

    def jacobian(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        zero = np.zeros_like(x)
        g = np.array(model().inverse_dynamics_derivatives(x, zero, zero)[0]).reshape(len(x), x.shape[1],
                                                                                   x.shape[1])
        if extra is not None:
            for k in range(x.shape[1]):
                e = np.zeros(x.shape[1])
                e[k] = h
                g[:, :, k] += (extra(x + e) - extra(x - e)) / (2 * h)  # d tau_p / d x_k
        return g

    return torque, jacobian


def _payload_unit_torque(frames: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
                         types: Sequence[str], gravity: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """``T(q)`` (N, n, 4): holding torques per unit payload mass and per unit first moment.

    A payload of mass ``m`` with centre ``r`` (tool frame) sits at ``p = R r + t``; its holding
    torque ``-m (dp/dq_j) . gravity`` is linear in ``pi = (m, m r)``.
    """
    types = tuple(types)

    def torque(q: np.ndarray) -> np.ndarray:
        origins, axes, tool = frames(q)
        out = np.zeros((len(q), len(types), 4))
        for j, kind in enumerate(types):
            z = axes[:, j]
            if kind == "revolute":
                # m dp/dq_j = m z x (t - o_j) + z x (R m r)
                out[:, j, 0] = -np.cross(z, tool[:, :3, 3] - origins[:, j]) @ gravity
                for k in range(3):
                    out[:, j, k + 1] = -np.cross(z, tool[:, :3, k]) @ gravity
            else:
                out[:, j, 0] = -z @ gravity  # dp/dq_j = z
        return out

    return torque


def nominal_frames(geometry) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """``frames(q)`` of :func:`build_nongeometric` from the nominal geometry (Hayati chain, world frame)."""
    from robodyn.calibration.kinematics import evaluate
    from robodyn.calibration.models import build_model

    chain = build_model("hayati", geometry, orientation=True)

    def frames(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        ev, rec = evaluate(chain.ops, chain.initial, q, derivatives=False, frames_after=chain.joint_ops)
        origins = np.stack([f[:, :3, 3] for f in rec], axis=1)
        axes = np.stack([f[:, :3, 2] for f in rec], axis=1)
        tool = np.zeros((len(q), 4, 4))
        tool[:, :3, :3], tool[:, :3, 3], tool[:, 3, 3] = ev.rotation, ev.position, 1.0
        return origins, axes, tool

    return frames


def build_nongeometric(robot: Robot | RobotNumbers, terms: Sequence[str], frames, *,
                       payload: tuple[float, Sequence[float]] | None = None,
                       identify_payload: bool = False, deflection: str = "linear") -> NonGeometric:
    """The non-geometric terms ``terms`` of ``robot``.

    Parameters
    ----------
    robot : Robot or RobotNumbers
        The nominal robot (masses, gravity, gear ratios).
    terms : sequence of str
        Subset of :data:`NONGEOMETRIC`.
    frames : callable
        ``frames(q)`` -> joint origins (N, n, 3), joint axes (N, n, 3) and tool frames
        (N, 4, 4) of the nominal chain in the robot's world frame (for the gravity-shaped basis
        and the payload).
    payload : (float, sequence of float), optional
        Payload mass (kg) and centre of mass in the tool frame (m): its holding torque is added
        to the gravity model's (or, with ``identify_payload``, the starting values).
    identify_payload : bool
        Estimate the payload (parameters ``payload.mass``, kg, and ``payload.mx``, ``.my``,
        ``.mz``, its first moments in the tool frame, kg m); needs ``"compliance"``.
    deflection : {"linear", "exact"}
        ``"exact"`` solves the static equilibrium at the deflected pose
        (:mod:`robodyn.numeric.deflection`) with the holding torques and their analytic
        derivatives from ``rd.compile_model(robot)`` (compiled on first use, cached); a known
        payload's torque derivative is taken by central differences of its closed form. Needs
        masses in the description; not combined with ``identify_payload``.

    Raises
    ------
    ValueError
        An unknown term, a negative payload mass, ``identify_payload`` without compliance, an
        unknown ``deflection``, ``"exact"`` with ``identify_payload`` or without link masses.
    """
    terms = _checked_terms(terms, deflection, identify_payload)
    num = robot_numbers(robot)
    gear = np.where(num.gear_ratios != 1.0, num.gear_ratios, np.nan)
    names, units, joints, kinds = [], [], [], []
    torque = exact_torque = torque_jacobian = holding = tool0 = None
    source = ""
    gravity = num.gravity
    load = _payload_load(payload)
    if "compliance" in terms:
        holding, tool0, exact_torque, torque_jacobian = _compliance_holding(
            robot, frames, None if identify_payload else load, deflection)
        torque = lambda q, holding=holding: holding_torque(holding, q)  # noqa: E731
        source = holding.source
        for j, (name, kind) in enumerate(zip(num.joint_names, num.joint_types, strict=True)):
            names.append(f"{name}.compliance")
            units.append("rad/(N m)" if kind == "revolute" else "m/N")
            joints.append(j)
            kinds.append("compliance")
    if "harmonics" in terms:
        for j, (name, jtype) in enumerate(zip(num.joint_names, num.joint_types, strict=True)):
            if jtype != "revolute":
                continue
            pairs = [("ratio", "ratio"), ("cos", "cos1"), ("sin", "sin1")]
            if np.isfinite(gear[j]):
                pairs += [("motor_cos", "motor_cos1"), ("motor_sin", "motor_sin1")]
            for kind, suffix in pairs:
                names.append(f"{name}.{suffix}")
                units.append("1" if kind == "ratio" else "rad")
                joints.append(j)
                kinds.append(kind)
    initial = [0.0] * len(names)
    payload_torque = None
    if identify_payload:
        payload_torque = _payload_unit_torque(frames, list(num.joint_types), gravity)
        source += " + identified payload"
        start = [0.0] * 4 if load is None else [load[0], *(load[0] * load[1])]
        kinds4 = ("payload_mass", "payload_moment", "payload_moment", "payload_moment")
        for suffix, kind, unit, v in zip(("mass", "mx", "my", "mz"), kinds4,
                                         ("kg", "kg m", "kg m", "kg m"), start, strict=True):
            names.append(f"payload.{suffix}")
            units.append(unit)
            joints.append(-1)
            kinds.append(kind)
            initial.append(float(v))
    if "compliance" not in terms:
        deflection = "linear"  # nothing deflects: the option changes nothing
    return NonGeometric(terms, tuple(names), tuple(units), tuple(joints), tuple(kinds), gear, torque,
                        source, np.array(initial), payload_torque, deflection, torque_jacobian,
                        exact_torque, holding, tool0)


def _checked_terms(terms: Sequence[str], deflection: str, identify_payload: bool) -> tuple[str, ...]:
    """The terms without repeats; refuses unknown terms and options that do not go together."""
    terms = tuple(dict.fromkeys(terms))
    if deflection not in DEFLECTIONS:
        raise InputError(f"deflection must be one of {', '.join(DEFLECTIONS)}, got {deflection!r}")
    if deflection == "exact" and identify_payload:
        raise InputError("deflection='exact' cannot be combined with identify_payload: the exact "
                         "Jacobian of the identified payload's terms is not implemented; identify the "
                         "payload with deflection='linear', then give it as a known payload")
    unknown = [t for t in terms if t not in NONGEOMETRIC]
    if unknown:
        raise InputError(f"unknown non-geometric term {unknown[0]!r}; choose from {', '.join(NONGEOMETRIC)}")
    if identify_payload and "compliance" not in terms:
        raise InputError("identify_payload needs the 'compliance' term: the payload is seen only "
                         "through the joints' deflection under its weight")
    return terms


def _payload_load(payload: tuple[float, Sequence[float]] | None) -> tuple[float, np.ndarray] | None:
    """``payload`` as (kg, centre of mass (3,) in the tool frame, m), checked."""
    if payload is None:
        return None
    mass, com = float(payload[0]), np.asarray(payload[1], dtype=float).reshape(3)
    if not mass >= 0:
        raise InputError(f"payload mass must be >= 0 kg, got {mass}")
    return mass, com


def _compliance_holding(robot: Robot | RobotNumbers, frames, known: tuple[float, np.ndarray] | None,
                        deflection: str,
                        ) -> tuple[HoldingTorque, np.ndarray, Callable | None, Callable | None]:
    """The point masses whose holding torque loads the joints (the links' own, or a unit-mass
    basis without masses; plus a known payload), the nominal tool frame at zero readings
    (4, 4), and for ``"exact"`` the compiled torque and its Jacobian."""
    num = robot_numbers(robot)
    n, gravity, masses = num.dof, num.gravity, num.masses.tolist()
    origins0, axes0, tool0 = (a[0] for a in frames(np.zeros((1, n))))
    payload_point = [] if known is None else [tool0[:3, :3] @ known[1] + tool0[:3, 3]]
    exact_torque = torque_jacobian = None
    if any(m > 0 for m in masses):
        holding = robot_holding(robot)  # numerically: no model to derive or compile
        if known:
            holding = _with_points(holding, [known[0]], payload_point, [n], "gravity model + payload")
        if deflection == "exact":
            extra = None
            if known:
                alone = _with_points(replace(holding, masses=(), moments=(), moved_by=()),
                                     [known[0]], payload_point, [n], "payload")
                extra = lambda x, alone=alone: holding_torque(alone, x)  # noqa: E731
            exact_torque, torque_jacobian = _compiled_gravity(robot, extra)
        return holding, tool0, exact_torque, torque_jacobian
    if deflection == "exact":
        raise InputError(f"deflection='exact' needs the link masses of {robot.name}: its "
                         "description has none, so the compliance torques are a gravity-shaped "
                         "basis of unknown scale; use deflection='linear'")
    # a 1 kg point mass on the axis of every joint after the first (riding on the link before
    # it) and at the tool
    empty = HoldingTorque(_rows(origins0), _rows(axes0), num.joint_types, (), (), (),
                          tuple(float(g) for g in gravity))
    holding = _with_points(empty, [1.0] * n + ([known[0]] if known else []),
                           np.vstack([origins0[1:], tool0[None, :3, 3], *payload_point]),
                           list(range(1, n + 1)) + ([n] if known else []),
                           "gravity-shaped basis" + (" + payload" if known else ""))
    return holding, tool0, None, None
