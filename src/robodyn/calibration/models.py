"""Kinematic error models: parameter vectors that place the joint axes, the base and the target.

Each model is a chain of elementary transforms (:mod:`robodyn.calibration.kinematics`) from the
measuring instrument's frame to the measured target, with these parameters (m, rad):

``"dh"`` - standard Denavit-Hartenberg (Denavit & Hartenberg 1955), per joint
    ``Rz(theta + q) Tz(d) Tx(a) Rx(alpha)`` (prismatic: ``Rz(theta) Tz(d + q) Tx(a) Rx(alpha)``):
    4 per joint. ``theta`` (``d`` for a prismatic joint) is the joint's zero offset. Singular at
    parallel consecutive axes (the common normal is anywhere along them).
``"hayati"`` - Hayati & Mirmirani (1985): as DH, but where joint ``i``'s and ``i + 1``'s axes are
    (nearly) parallel the link is ``Rz(theta + q) Tx(a) Rx(alpha) Ry(beta)`` (no ``d``; prismatic:
    ``Rz(theta) Tz(d + q) Tx(a) Rx(alpha) Ry(beta)``, 5): 4 per revolute joint.
``"s-model"`` - Stone's S-model (Stone 1987; Stone & Sanderson 1987): the DH (Hayati at parallel
    axes) link followed by a screw ``Tz(b) Rz(beta)`` along the next joint axis, so that each
    frame may sit anywhere along its axis and turn freely about it: 6 per joint. ``b`` and ``beta``
    are redundant with the next joint's ``d`` and ``theta``; the chain starts with the frames in
    the DH/Hayati convention (``b = beta = 0``; Stone's circle-centre frames from circle-point
    analysis are converted to it first) and identification holds them there.
``"poe"`` - product of exponentials (Brockett 1984; Okamura & Park 1996; He et al. 2010): each
    joint is the twist about / along a line, moved from its nominal line by a shift ``(u, v)``
    across it and a tilt ``(rx, ry)``: 4 per revolute joint, 2 per prismatic joint. The twists are
    written in the instrument's frame, so joint zero offsets and the base transform are absorbed
    in them (no separate base or offset parameters).

Every DH-family model adds the instrument-to-base transform, 6 parameters
``Tx Ty Tz Rx Ry Rz`` (position in the instrument frame, then small rotations about the
instrument's axes applied to a fixed initial orientation), and every model adds the target
offset: 3 parameters (the target position in the last frame; in frame 0 for POE), plus 3
rotations when target orientations are measured. A minimal complete model has
``4 R + 2 P + 6`` independent parameters for pose measurements and ``4 R + 2 P + 3`` for
position measurements (Everett, Driels & Mooring 1987; Hollerbach & Wampler 1996); the
redundant ones are found and held fixed by :mod:`robodyn.calibration.identifiability`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from robodyn.calibration.kinematics import ChainEval, Op, evaluate, hom, inv, rot
from robodyn.calibration.nominal import (
    RobotGeometry,
    axis_frames,
    default_frame0,
    frame_on_line,
    parallel_links,
)
from robodyn.robot.errors import InputError

if TYPE_CHECKING:
    from robodyn.calibration.nongeometric import NonGeometric

__all__ = ["MODELS", "ErrorModel", "build_model", "extend_model", "model_frames"]

#: The error models, by name.
MODELS = ("dh", "hayati", "s-model", "poe")


@dataclass(frozen=True, eq=False)
class ErrorModel:
    """A kinematic error model of one robot, ready to evaluate.

    Attributes
    ----------
    name : str
        One of :data:`MODELS`.
    ops : tuple of Op
        The chain, instrument frame to target.
    names : tuple of str, length P
        Parameter names (``"q2.a"``, ``"base.x"``, ``"tool.z"``).
    units : tuple of str, length P
        ``"m"`` or ``"rad"``.
    initial : numpy.ndarray, shape (P,)
        Initial parameter values (nominal geometry in the estimated instrument frame, or the
        circle-point estimate).
    priority : tuple of int
        Order in which parameters are kept when some are not separable (earlier wins).
    joint_ops : tuple of int, length n
        Index of each joint's motion op in ``ops``.
    base_op : int
        Index of the op after which the running frame is frame 0 (on joint 1's axis).
    joint_to_robot : numpy.ndarray, shape (n, 4, 4)
        ``K_i``: the robot's own joint frame (after ``pre_i``) in the model's motion frame of
        joint ``i`` (frame just before the joint op, at ``q = 0``), fixed at the nominal geometry.
    base_to_robot : numpy.ndarray, shape (4, 4)
        ``K_0``: the robot's chain base frame in model frame 0, nominal.
    tool_rotation : numpy.ndarray, shape (3, 3)
        Nominal tool orientation in the last link frame (used when orientation is not measured).
    orientation : bool
        Whether the chain ends with target rotation parameters.
    joint_types : tuple of str, length n
    hayati : tuple of bool, length n
        Links built with Hayati's parametrisation.
    targets : int
        ``K``, targets measured at each pose: the chain ends at the first; the others are
        ``tool<k>.x/y/z`` (their positions in the last link frame, after the chain's parameters).
    nongeometric : NonGeometric or None
        Joint corrections ``q + B(q) theta`` (:mod:`robodyn.calibration.nongeometric`), whose
        parameters are the last ``M``.
    """

    name: str
    ops: tuple[Op, ...]
    names: tuple[str, ...]
    units: tuple[str, ...]
    initial: np.ndarray
    priority: tuple[int, ...]
    joint_ops: tuple[int, ...]
    base_op: int
    joint_to_robot: np.ndarray
    base_to_robot: np.ndarray
    tool_rotation: np.ndarray
    orientation: bool
    joint_types: tuple[str, ...]
    hayati: tuple[bool, ...]
    targets: int = 1
    nongeometric: NonGeometric | None = None

    @property
    def n_params(self) -> int:
        """Number of parameters P."""
        return len(self.names)

    @property
    def dof(self) -> int:
        """Number of joints n."""
        return len(self.joint_ops)

    def index(self, name: str) -> int:
        """Position of the parameter called ``name``."""
        return self.names.index(name)

    @property
    def nongeometric_slice(self) -> slice:
        """Positions of the non-geometric parameters (empty without them)."""
        m = self.nongeometric.n_params if self.nongeometric is not None else 0
        return slice(self.n_params - m, self.n_params)

    def evaluate(self, params: np.ndarray, q: np.ndarray, *, derivatives: bool = True) -> ChainEval:
        """Target frames (and Jacobians) for joint readings ``q`` of shape (N, n).

        With ``K`` targets the rows are ``N K`` (pose-major: row ``i K + k`` is target ``k`` at
        pose ``i``). ``jac_joint`` is the chain's Jacobian at the corrected joint values (the
        derivative of the small non-geometric correction itself is left out).
        """
        params = np.asarray(params, dtype=float)
        q = np.asarray(q, dtype=float)
        basis = None
        if self.nongeometric is not None:
            # q_link = q + dq(q, theta), dq = B(q) theta for all but an identified payload
            dq, basis = self.nongeometric.correction(q, params[self.nongeometric_slice])
            q = q + dq
        ev = evaluate(self.ops, params, q, self.n_params, derivatives=derivatives)[0]
        jp, jq = ev.jac_param, ev.jac_joint
        if derivatives and basis is not None:
            # d p / d theta = J_q d dq / d theta
            jp[:, :, self.nongeometric_slice] = jq @ basis
        if self.targets == 1:
            return ChainEval(ev.position, ev.rotation, jp, jq)
        return self._targets(params, ev.position, ev.rotation, jp, jq)

    def target_rotation(self, params: np.ndarray) -> np.ndarray:
        """Rotation (3, 3) of the target frame in the last link frame (identity without
        measured orientation): ``R_target = R_last @ target_rotation``."""
        if not self.orientation:
            return np.eye(3)
        fixed = self.ops[-1]
        assert fixed.kind == "fixed" and fixed.matrix is not None  # last op of _tool_ops
        a = [params[self.index(f"tool.r{x}")] for x in "xyz"]
        return (rot("x", a[0]) @ rot("y", a[1]) @ rot("z", a[2]))[:3, :3] @ fixed.matrix[:3, :3]

    def _targets(self, params, p1, r, jp, jq) -> ChainEval:
        """All ``K`` targets from the first one's evaluation (rows pose-major)."""
        big_n, k_count = len(p1), self.targets
        tool = [self.index(f"tool.{a}") for a in "xyz"]
        t1 = params[tool]
        turn = [self.index(f"tool.r{a}") for a in "xyz"] if self.orientation else []
        r = r @ self.target_rotation(params).T  # the last link's rotation: offsets are given there
        pos = np.empty((big_n, k_count, 3))
        pos[:, 0] = p1
        offsets = []
        for k in range(1, k_count):
            cols = [self.index(f"tool{k + 1}.{a}") for a in "xyz"]
            d = r @ (params[cols] - t1)  # p_k = p_1 + R (t_k - t_1)
            pos[:, k] = p1 + d
            offsets.append((cols, d))
        rot_all = np.repeat(r @ self.target_rotation(params), k_count, axis=0)
        if jp is None:
            return ChainEval(pos.reshape(-1, 3), rot_all, None, None)
        jp_all = np.repeat(jp[:, None], k_count, axis=1)
        jq_all = np.repeat(jq[:, None], k_count, axis=1)
        for k, (cols, d) in enumerate(offsets, start=1):
            # a rotation w moves p_k by w x (p_k - o) = (that of p_1) + w x d
            jp_all[:, k, :3] += np.cross(jp[:, 3:], d[:, :, None], axisa=1, axisb=1, axisc=1)
            jq_all[:, k, :3] += np.cross(jq[:, 3:], d[:, :, None], axisa=1, axisb=1, axisc=1)
            jp_all[:, k, :3][:, :, tool] = 0.0
            jp_all[:, k, :3][:, :, turn] = 0.0  # turning the target frame moves no target
            jp_all[:, k, :3][:, :, cols] = r
        return ChainEval(pos.reshape(-1, 3), rot_all, jp_all.reshape(big_n * k_count, 6, -1),
                         jq_all.reshape(big_n * k_count, 6, -1))


class _Builder:
    """Accumulates ops, names, units and values."""

    def __init__(self) -> None:
        self.ops: list[Op] = []
        self.names: list[str] = []
        self.units: list[str] = []
        self.values: list[float] = []
        self.groups: dict[str, list[int]] = {"base": [], "tool": [], "core": [], "extra": []}

    def param(self, kind: str, name: str, value: float, group: str, joint: int = -1) -> int:
        k = len(self.names)
        self.names.append(name)
        self.units.append("rad" if kind[0] == "r" else "m")
        self.values.append(float(value))
        self.groups[group].append(k)
        self.ops.append(Op(kind, param=k, joint=joint))
        return k

    def fixed(self, matrix: np.ndarray) -> None:
        self.ops.append(Op("fixed", matrix=np.array(matrix, dtype=float)))

    def op(self, kind: str, param: int = -1, sign: float = 1.0, joint: int = -1) -> None:
        self.ops.append(Op(kind, param=param, sign=sign, joint=joint))


def _tool_ops(b: _Builder, target: np.ndarray, orientation: bool) -> None:
    """Target position (and rotation) parameters after the last frame."""
    for k, axis in enumerate("xyz"):
        b.param("t" + axis, f"tool.{axis}", target[k, 3], "tool")
    if orientation:
        for axis in "xyz":
            b.param("r" + axis, f"tool.r{axis}", 0.0, "tool")
        b.fixed(hom(target[:3, :3]))


def _dh_family(name: str, geometry: RobotGeometry, frames: np.ndarray, links: list,
               target: np.ndarray, orientation: bool) -> tuple[_Builder, list[int], int]:
    """Ops of the DH, Hayati and S-model chains. ``frames`` and ``target`` in instrument coords."""
    b = _Builder()
    f0 = frames[0]
    for k, axis in enumerate("xyz"):
        b.param("t" + axis, f"base.{axis}", f0[k, 3], "base")
    for axis in "xyz":
        b.param("r" + axis, f"base.r{axis}", 0.0, "base")
    b.fixed(hom(f0[:3, :3]))
    base_op = len(b.ops) - 1
    joint_ops = []
    for i, (jname, jtype, link) in enumerate(zip(geometry.joint_names, geometry.joint_types, links,
                                                 strict=True)):
        revolute = jtype == "revolute"
        b.param("rz", f"{jname}.theta", link.theta, "core", joint=i if revolute else -1)
        if revolute:
            joint_ops.append(len(b.ops) - 1)
        if link.kind == "dh" or not revolute:
            b.param("tz", f"{jname}.d", link.d, "core", joint=-1 if revolute else i)
            if not revolute:
                joint_ops.append(len(b.ops) - 1)
        b.param("tx", f"{jname}.a", link.a, "core")
        b.param("rx", f"{jname}.alpha", link.alpha, "core")
        if link.kind == "hayati":
            b.param("ry", f"{jname}.beta_y" if name == "s-model" else f"{jname}.beta", link.beta, "core")
        if name == "s-model":
            b.param("tz", f"{jname}.b", 0.0, "extra")
            b.param("rz", f"{jname}.beta", 0.0, "extra")
    _tool_ops(b, inv(frames[-1]) @ target, orientation)
    return b, joint_ops, base_op


def _poe(geometry: RobotGeometry, base0: np.ndarray, twist_frames: np.ndarray, lines: tuple | None,
         target: np.ndarray, orientation: bool) -> tuple[_Builder, list[int], int]:
    """Ops of the POE chain; ``twist_frames`` (n, 4, 4) in frame-0 coordinates (nominal lines)."""
    b = _Builder()
    b.fixed(base0)
    base_op = 0
    joint_ops = []
    for i, (jname, jtype) in enumerate(zip(geometry.joint_names, geometry.joint_types, strict=True)):
        g = twist_frames[i]
        u = v = ax = ay = 0.0
        if lines is not None:
            # initial shift and tilt that put the nominal twist frame's z on the measured line
            c = inv(base0 @ g) @ np.append(lines[0][i], 1.0)
            w = (inv(base0 @ g)[:3, :3] @ lines[1][i])
            w = w / np.linalg.norm(w)
            # Rx(ax) Ry(ay) e_z = (sin ay, -sin ax cos ay, cos ax cos ay)
            ay = float(np.arcsin(np.clip(w[0], -1, 1)))
            ax = float(np.arctan2(-w[1], w[2]))
            s = -c[2] / w[2]
            u, v = c[0] + s * w[0], c[1] + s * w[1]
        b.fixed(g)
        shift = []
        if jtype == "revolute":
            shift = [b.param("tx", f"{jname}.u", u, "core"), b.param("ty", f"{jname}.v", v, "core")]
        tilt = [b.param("rx", f"{jname}.rx", ax, "core"), b.param("ry", f"{jname}.ry", ay, "core")]
        b.op("rz" if jtype == "revolute" else "tz", joint=i)
        joint_ops.append(len(b.ops) - 1)
        b.op("ry", tilt[1], -1.0)
        b.op("rx", tilt[0], -1.0)
        for k, kind in zip(reversed(shift), ("ty", "tx"), strict=False):
            b.op(kind, k, -1.0)
        b.fixed(inv(g))
    _tool_ops(b, inv(base0) @ target, orientation)
    return b, joint_ops, base_op


def _assemble(name: str, geometry: RobotGeometry, kinds: list[str], base: np.ndarray,
              lines: tuple | None, target: np.ndarray, orientation: bool,
              nominal: tuple[np.ndarray, list]) -> tuple[_Builder, list[int], int]:
    """The chain for instrument placement ``base`` (instrument -> robot world)."""
    frames_nom, _ = nominal
    refs = base @ frames_nom
    if lines is None:
        points = (base[:3, :3] @ geometry.points.T).T + base[:3, 3]
        dirs = (base[:3, :3] @ geometry.directions.T).T
    else:
        points, dirs = lines
    f0 = frame_on_line(points[0], dirs[0], refs[0][:3, 3], refs[0][:3, 0])
    frames, links = axis_frames(points, dirs, f0, refs, kinds, where=geometry_name(geometry))
    if name == "poe":
        base0 = refs[0]
        twist = inv(frames_nom[0]) @ frames_nom[:-1]
        return _poe(geometry, base0, twist, lines, target, orientation)
    return _dh_family(name, geometry, frames, links, target, orientation)


def geometry_name(geometry: RobotGeometry) -> str:
    """A short label for error messages."""
    return "robot(" + ", ".join(geometry.joint_names) + ")"


def build_model(
    name: str,
    geometry: RobotGeometry,
    *,
    base: np.ndarray | None = None,
    lines: tuple[np.ndarray, np.ndarray] | None = None,
    target: np.ndarray | None = None,
    orientation: bool = False,
    parallel_tol: float = np.radians(1.0),
) -> ErrorModel:
    """Build error model ``name`` of a robot, with an initial estimate.

    Parameters
    ----------
    name : {"dh", "hayati", "s-model", "poe"}
    geometry : RobotGeometry
        The nominal robot (:func:`robodyn.calibration.nominal.robot_geometry`).
    base : numpy.ndarray, shape (4, 4), optional
        Initial estimate of the robot's world frame in the instrument frame (identity: the
        instrument frame is the robot's world frame).
    lines : tuple of numpy.ndarray, optional
        Measured joint axes at ``q = 0`` in the instrument frame: points (n, 3) and directions
        (n, 3) (circle-point analysis); default: the nominal axes placed by ``base``.
    target : numpy.ndarray, shape (4, 4), optional
        Initial target frame at ``q = 0`` in the instrument frame; default: the nominal tool.
    orientation : bool
        Add target rotation parameters (orientation measured).
    parallel_tol : float
        Consecutive nominal axes closer than this to parallel (rad) get Hayati's link.

    Returns
    -------
    ErrorModel
    """
    if name not in MODELS:
        raise InputError(f"unknown error model {name!r}; choose one of {', '.join(MODELS)}")
    base = np.eye(4) if base is None else np.asarray(base, dtype=float)
    par = parallel_links(geometry.directions, parallel_tol)
    kinds = ["hayati" if (p and name != "dh") else "dh" for p in par]
    refs = np.concatenate((geometry.base[None], geometry.link_frames))
    frames_nom, links_nom = axis_frames(geometry.points, geometry.directions, default_frame0(geometry),
                                        refs, kinds, where=geometry_name(geometry))
    nominal = (frames_nom, links_nom)
    # joint_to_robot from the nominal chain in the robot's world frame
    b_nom, jops, base_op = _assemble(name, geometry, kinds, np.eye(4), None, geometry.target,
                                     False, nominal)
    frames0, motion = _frames(b_nom.ops, np.array(b_nom.values), jops, base_op, geometry.dof)
    k_joint = inv(motion) @ geometry.joint_frames
    k_base = inv(frames0) @ geometry.base
    target = base @ geometry.target if target is None else np.asarray(target, dtype=float)
    b, jops, base_op = _assemble(name, geometry, kinds, base, lines, target, orientation, nominal)
    priority = b.groups["base"] + b.groups["tool"] + b.groups["core"] + b.groups["extra"]
    return ErrorModel(
        name=name,
        ops=tuple(b.ops),
        names=tuple(b.names),
        units=tuple(b.units),
        initial=np.array(b.values),
        priority=tuple(priority),
        joint_ops=tuple(jops),
        base_op=base_op,
        joint_to_robot=k_joint,
        base_to_robot=k_base,
        tool_rotation=geometry.tool[:3, :3].copy(),
        orientation=orientation,
        joint_types=geometry.joint_types,
        hayati=tuple(k == "hayati" for k in kinds),
    )


def extend_model(model: ErrorModel, offsets: np.ndarray | None = None,
                 nongeometric: NonGeometric | None = None) -> ErrorModel:
    """``model`` with more targets and non-geometric terms.

    Parameters
    ----------
    model : ErrorModel
        A geometric model (one target, no non-geometric terms).
    offsets : numpy.ndarray, shape (K - 1, 3), optional
        Initial positions of targets 2..K in the last link frame, m.
    nongeometric : NonGeometric, optional
        Their parameters start at zero.

    Raises
    ------
    ValueError
        ``model`` is already extended.
    """
    if model.targets != 1 or model.nongeometric is not None:
        raise InputError("extend_model: the model is already extended")
    offsets = np.zeros((0, 3)) if offsets is None else np.asarray(offsets, dtype=float).reshape(-1, 3)
    names, units, values = list(model.names), list(model.units), list(model.initial)
    placement = [k for k in model.priority if names[k].startswith(("base.", "tool."))]
    extra = [k for k in model.priority if k in _extra_group(model)]
    core = [k for k in model.priority if k not in placement and k not in extra]
    targets = []
    for k, off in enumerate(offsets, start=2):
        for a, v in zip("xyz", off, strict=True):
            targets.append(len(names))
            names.append(f"tool{k}.{a}")
            units.append("m")
            values.append(float(v))
    ng = []
    if nongeometric is not None:
        ng = list(range(len(names), len(names) + nongeometric.n_params))
        names += nongeometric.names
        units += nongeometric.units
        values += [float(v) for v in nongeometric.initial] if nongeometric.initial is not None \
            else [0.0] * nongeometric.n_params
    # placement and targets first, then the joints' parameters, then the terms, then the redundant
    priority = placement + targets + core + ng + extra
    return replace(model, names=tuple(names), units=tuple(units), initial=np.array(values),
                   priority=tuple(priority), targets=len(offsets) + 1, nongeometric=nongeometric)


def _extra_group(model: ErrorModel) -> set[int]:
    """The S-model's redundant screw parameters ``b`` and ``beta`` (last in priority)."""
    if model.name != "s-model":
        return set()
    return {k for k, n in enumerate(model.names) if n.endswith((".b", ".beta"))}


def _frames(ops, params, joint_ops, base_op, n) -> tuple[np.ndarray, np.ndarray]:
    """Frame 0 and the joint motion frames at ``q = 0``: shapes (4, 4) and (n, 4, 4)."""
    _, rec = evaluate(ops, params, np.zeros((1, n)), derivatives=False,
                      frames_after=(base_op, *joint_ops))
    return rec[0][0], np.array([f[0] for f in rec[1:]])


def model_frames(model: ErrorModel, params: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frames of a model at ``q = 0`` in the instrument frame.

    Returns
    -------
    frame0 : numpy.ndarray, shape (4, 4)
        Model frame 0 (on joint 1's axis).
    motion : numpy.ndarray, shape (n, 4, 4)
        Each joint's motion frame: the joint turns about (slides along) its z axis.
    target : numpy.ndarray, shape (4, 4)
        Target frame.
    """
    n = model.dof
    ev, rec = evaluate(model.ops, params, np.zeros((1, n)), derivatives=False,
                       frames_after=(model.base_op, *model.joint_ops))
    target = hom(ev.rotation[0], ev.position[0])
    return rec[0][0], np.array([f[0] for f in rec[1:]]), target
