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
from dataclasses import dataclass, field

import numpy as np

from robodyn.robot.errors import InputError
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
        deflected pose, ``x = u - C tau(x)`` (:mod:`robodyn.calibration.deflection`).
    torque_jacobian : callable or None
        ``torque_jacobian(x)``: ``d tau / d x`` (N, n, n) for ``"exact"``.
    exact_torque : callable or None
        ``exact_torque(x)``: the holding torques (N, n) used by ``"exact"`` (the compiled model's
        gravity, plus a known payload).
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
        from robodyn.calibration.deflection import exact_deflection

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


def _point_mass_torque(frames: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
                       types: Sequence[str], gravity: np.ndarray, masses: Sequence[tuple[int, float]],
                       payload: tuple[float, np.ndarray] | None = None,
                       ) -> Callable[[np.ndarray], np.ndarray]:
    """Holding torques of point masses on the nominal chain.

    ``frames(q)`` gives joint origins (N, n, 3), axes (N, n, 3) and tool frames (N, 4, 4) in the
    frame of ``gravity``; ``masses`` are (after-joint index, kg) with the mass at the origin of the
    next joint's frame (index n: the tool); ``payload`` is (kg, point in the tool frame).
    """
    types = tuple(types)
    n = len(types)

    def torque(q: np.ndarray) -> np.ndarray:
        origins, axes, tool = frames(q)
        pts = np.concatenate((origins, tool[:, None, :3, 3]), axis=1)  # (N, n + 1, 3)
        out = np.zeros((len(q), n))
        loads = [(pts[:, k], m, k) for k, m in masses]
        if payload is not None:
            p = tool[:, :3, :3] @ payload[1] + tool[:, :3, 3]
            loads.append((p, payload[0], n))
        for p, m, k in loads:
            for j in range(min(k, n)):
                z = axes[:, j]
                # dp/dq_j = z x (p - o_j) (revolute) or z (prismatic); g_j = -m gravity . dp/dq_j
                dp = np.cross(z, p - origins[:, j]) if types[j] == "revolute" else z
                out[:, j] -= m * dp @ gravity
        return out

    return torque


def gravity_torque(robot: Robot) -> Callable[[np.ndarray], np.ndarray]:
    """``g(q)`` (N, n), N m (N): the holding torques of the robot's own links, evaluated numerically.

    The links' masses and centres of mass ride on the nominal geometry at ``q = 0``
    (:func:`robodyn.calibration.nominal.robot_geometry`) moved by the joints' screw motions
    (product of exponentials); ``g_j = -sum_{i >= j} m_i gravity . dc_i/dq_j`` with
    ``dc/dq_j = u_j x (c - p_j)`` (revolute) or ``u_j`` (prismatic) about the moved axis
    ``(p_j, u_j)``. The same as ``rd.compile_model(robot).gravity(q)`` without deriving or
    compiling the whole model (tests/calibration/test_payload.py compares them).
    """
    from robodyn.calibration.nominal import numeric, robot_geometry

    geometry = robot_geometry(robot)
    subs = robot.defaults()
    gravity = np.array(robot.gravity.xreplace(subs), dtype=float).ravel()
    masses = np.array([float(link.mass.xreplace(subs)) for link in robot.links])
    coms = np.array([numeric(link.com, subs).ravel() for link in robot.links])
    com0 = np.einsum("nij,nj->ni", geometry.link_frames[:, :3, :3], coms) + geometry.link_frames[:, :3, 3]
    pts, dirs, types = geometry.points, geometry.directions, geometry.joint_types
    n = len(types)

    def torque(q: np.ndarray) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        big_n = len(q)
        rot = np.broadcast_to(np.eye(3), (big_n, 3, 3)).copy()  # G = prod exp(S_k q_k), k < j
        trans = np.zeros((big_n, 3))
        axis_p, axis_u, c = (np.zeros((big_n, n, 3)) for _ in range(3))
        for j in range(n):
            axis_p[:, j] = rot @ pts[j] + trans
            axis_u[:, j] = rot @ dirs[j]
            if types[j] == "revolute":
                k = np.array([[0, -dirs[j][2], dirs[j][1]], [dirs[j][2], 0, -dirs[j][0]],
                              [-dirs[j][1], dirs[j][0], 0]])
                s, co = np.sin(q[:, j])[:, None, None], np.cos(q[:, j])[:, None, None]
                r = np.eye(3) + s * k + (1 - co) * (k @ k)  # Rodrigues
                t = pts[j] - r @ pts[j]  # rotation about the line through p_j
            else:
                r = np.broadcast_to(np.eye(3), (big_n, 3, 3))
                t = q[:, j, None] * dirs[j]
            trans = np.einsum("nij,nj->ni", rot, t) + trans
            rot = rot @ r
            c[:, j] = rot @ com0[j] + trans  # link j moves with joints 1..j
        out = np.zeros((big_n, n))
        for j in range(n):
            if types[j] == "revolute":
                dc = np.cross(axis_u[:, j, None], c[:, j:] - axis_p[:, j, None])
            else:
                dc = np.broadcast_to(axis_u[:, j, None], c[:, j:].shape)
            out[:, j] = -(dc @ gravity) @ masses[j:]
        return out

    return torque


def _compiled_gravity(robot: Robot, extra: Callable[[np.ndarray], np.ndarray] | None,
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

            state["m"] = compile_model(robot)
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


def build_nongeometric(robot: Robot, terms: Sequence[str], frames, *,
                       payload: tuple[float, Sequence[float]] | None = None,
                       identify_payload: bool = False, deflection: str = "linear") -> NonGeometric:
    """The non-geometric terms ``terms`` of ``robot``.

    Parameters
    ----------
    robot : Robot
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
        (:mod:`robodyn.calibration.deflection`) with the holding torques and their analytic
        derivatives from ``rd.compile_model(robot)`` (compiled on first use, cached); a known
        payload's torque derivative is taken by central differences of its closed form. Needs
        masses in the description; not combined with ``identify_payload``.

    Raises
    ------
    ValueError
        An unknown term, a negative payload mass, ``identify_payload`` without compliance, an
        unknown ``deflection``, ``"exact"`` with ``identify_payload`` or without link masses.
    """
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
    subs = robot.defaults()
    n = robot.dof
    gear = np.full(n, np.nan)
    for j, joint in enumerate(robot.joints):
        g = float(joint.drive.gear_ratio.xreplace(subs))
        if g != 1.0:
            gear[j] = g
    names, units, joints, kinds = [], [], [], []
    torque = exact_torque = torque_jacobian = None
    source = ""
    if "compliance" in terms:
        gravity = np.array(robot.gravity.xreplace(subs), dtype=float).ravel()
        masses = [float(link.mass.xreplace(subs)) for link in robot.links]
        load = None
        if payload is not None:
            mass, com = float(payload[0]), np.asarray(payload[1], dtype=float).reshape(3)
            if not mass >= 0:
                raise InputError(f"payload mass must be >= 0 kg, got {mass}")
            load = (mass, com)
        known = None if identify_payload else load
        types = [j.type for j in robot.joints]
        if any(m > 0 for m in masses):
            own = gravity_torque(robot)  # numerically: no model to derive or compile
            extra = _point_mass_torque(frames, types, gravity, [], known) if known else None

            def torque(q: np.ndarray, own=own, extra=extra) -> np.ndarray:
                tau = own(q)
                return tau + extra(q) if extra is not None else tau

            source = "gravity model" + (" + payload" if known else "")
            if deflection == "exact":
                exact_torque, torque_jacobian = _compiled_gravity(robot, extra)
        else:
            if deflection == "exact":
                raise InputError(f"deflection='exact' needs the link masses of {robot.name}: its "
                                 "description has none, so the compliance torques are a gravity-shaped "
                                 "basis of unknown scale; use deflection='linear'")
            torque = _point_mass_torque(frames, types, gravity, [(k, 1.0) for k in range(1, n + 1)],
                                        known)
            source = "gravity-shaped basis"
        for j, joint in enumerate(robot.joints):
            names.append(f"{joint.name}.compliance")
            units.append("rad/(N m)" if joint.type == "revolute" else "m/N")
            joints.append(j)
            kinds.append("compliance")
    if "harmonics" in terms:
        for j, joint in enumerate(robot.joints):
            if joint.type != "revolute":
                continue
            pairs = [("ratio", "ratio"), ("cos", "cos1"), ("sin", "sin1")]
            if np.isfinite(gear[j]):
                pairs += [("motor_cos", "motor_cos1"), ("motor_sin", "motor_sin1")]
            for kind, suffix in pairs:
                names.append(f"{joint.name}.{suffix}")
                units.append("1" if kind == "ratio" else "rad")
                joints.append(j)
                kinds.append(kind)
    initial = [0.0] * len(names)
    payload_torque = None
    if identify_payload:
        payload_torque = _payload_unit_torque(frames, [j.type for j in robot.joints], gravity)
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
                        exact_torque)
