"""``calibrate``: kinematic calibration from measured target positions, end to end.

Steps (each a function of its own module):

1. the nominal geometry of the robot (:mod:`~robodyn.calibration.nominal`);
2. the instrument placement and target offset for the nominal kinematics: rigid registration of
   the nominal predictions onto the measurements (Kabsch, alternated with a linear solve for the
   target offset), refined by least squares on those 6 + 3 parameters only. Its residuals are
   the "before" errors;
3. the initial estimate: the nominal model so placed, or circle-point analysis
   (:mod:`~robodyn.calibration.joint_axes`);
4. identifiability (:mod:`~robodyn.calibration.identifiability`): the parameters no pose set can
   identify (found on random poses at the initial estimate), then those this pose set cannot;
5. weighted Levenberg-Marquardt on all poses (:mod:`~robodyn.calibration.solve`);
6. the calibrated robot (:mod:`~robodyn.calibration.to_robot`) and the result.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from robodyn.calibration.data_checks import check_data, check_magnitude, convert_units
from robodyn.calibration.identifiability import (
    Unidentifiable,
    compress_rows,
    describe,
    independent_columns,
    observability,
)
from robodyn.calibration.joint_axes import CirclePointResult, circle_point
from robodyn.calibration.kinematics import hom, inv
from robodyn.calibration.models import ErrorModel, build_model, extend_model, model_frames
from robodyn.calibration.nominal import RobotGeometry, default_frame0, robot_geometry
from robodyn.calibration.options import CalibrateOptions
from robodyn.calibration.result import Calibration, ErrorStats, Parameter
from robodyn.calibration.solve import Fit, fit
from robodyn.keywords import resolve
from robodyn.robot.errors import InputError
from robodyn.robot.numbers import RobotNumbers, robot_numbers

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["calibrate", "identifiable_parameters", "nominal_placement", "random_configurations"]

#: Threshold of :func:`~robodyn.calibration.identifiability.independent_columns`.
RANK_TOL = 1e-7


def target_offsets(model: ErrorModel, params: np.ndarray, q: np.ndarray, points: np.ndarray,
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Positions in the last link frame of further targets, by linear least squares.

    Parameters
    ----------
    model : ErrorModel
        A geometric model with one target (its tool parameters are set to zero here).
    params : numpy.ndarray, shape (P,)
    q : numpy.ndarray, shape (N, n)
    points : numpy.ndarray, shape (N, K', 3)
        Measured positions of the further targets, m.

    Returns
    -------
    offsets : numpy.ndarray, shape (K', 3)
    residuals : numpy.ndarray, shape (N, K', 3)
    """
    p = np.array(params, dtype=float)
    p[[model.index(f"tool.{a}") for a in "xyz"]] = 0.0
    ev = model.evaluate(p, q, derivatives=False)
    r_last = ev.rotation @ model.target_rotation(p).T  # offsets are in the last link frame
    offsets = np.zeros((points.shape[1], 3))
    res = np.zeros(points.shape)
    for k in range(points.shape[1]):
        # R_i t = y_ik - o_i, stacked over poses
        offsets[k], *_ = np.linalg.lstsq(r_last.reshape(-1, 3), (points[:, k] - ev.position).ravel(),
                                         rcond=None)
        res[:, k] = points[:, k] - ev.position - r_last @ offsets[k]
    return offsets, res


def random_configurations(robot: Robot | RobotNumbers, count: int, rng: np.random.Generator | int = 0,
                          ) -> np.ndarray:
    """Uniformly random joint readings within the joint limits, shape (count, n).

    Joints without limits range over ``[-pi, pi]`` (revolute) or ``[-0.5, 0.5]`` m (prismatic).
    """
    rng = np.random.default_rng(rng)
    num = robot_numbers(robot)
    revolute = np.array([t == "revolute" for t in num.joint_types])
    lo = np.where(np.isnan(num.lower), np.where(revolute, -math.pi, -0.5), num.lower)
    hi = np.where(np.isnan(num.upper), np.where(revolute, math.pi, 0.5), num.upper)
    return rng.uniform(lo, hi, size=(count, num.dof))


def _rows(model: ErrorModel, params: np.ndarray, q: np.ndarray, weights: np.ndarray,
          rot_weight: float) -> np.ndarray:
    """Weighted identification Jacobian, shape (N * r, P)."""
    jac = model.evaluate(params, q).jac_param
    j = jac[:, :3] * weights[:, :, None]
    if model.orientation and model.targets > 1:
        # one orientation per pose (the rows of every target carry the same rotation)
        rot = jac[:: model.targets, 3:] * rot_weight
        return np.concatenate((j.reshape(-1, model.n_params), rot.reshape(-1, model.n_params)))
    if model.orientation:
        j = np.concatenate((j, jac[:, 3:] * rot_weight), axis=1)
    return j.reshape(-1, model.n_params)


def nominal_placement(geometry: RobotGeometry, q: np.ndarray, points: np.ndarray,
              orientations: np.ndarray | None, sigma: np.ndarray, sigma_rot: float,
              ) -> tuple[np.ndarray, np.ndarray, ErrorModel, np.ndarray]:
    """Instrument placement and target for the nominal kinematics ("before" calibration).

    Returns the robot world frame in the instrument frame (4, 4), the before residuals (N, 3),
    and the placed nominal DH model with its fitted parameters.
    """
    nominal = build_model("dh", geometry)
    p = nominal.initial.copy()
    tool = [nominal.index(f"tool.{a}") for a in "xyz"]
    offset = p[tool].copy()
    p[tool] = 0.0
    ev = nominal.evaluate(p, q, derivatives=False)  # last model frame, world
    rn, on = ev.rotation, ev.position
    x = np.eye(4)
    for _ in range(50):
        y = rn @ offset + on
        x = _kabsch(y, points)
        # linear target offset: (R R_n) p = points - t - R o_n
        a = (x[:3, :3] @ rn).reshape(-1, 3)
        b = (points - x[:3, 3] - on @ x[:3, :3].T).ravel()
        new, *_ = np.linalg.lstsq(a, b, rcond=None)
        if np.linalg.norm(new - offset) < 1e-12:
            offset = new
            break
        offset = new
    r_tool = np.eye(3)
    if orientations is not None:
        # tool rotation in the last frame: the rotation nearest mean_k (R_x R_n,k)^T R_measured,k
        u, _, vt = np.linalg.svd(np.einsum("kji,kjl->il", x[:3, :3] @ rn, orientations))
        r_tool = u @ np.diag([1.0, 1.0, np.linalg.det(u @ vt)]) @ vt
    zero = nominal.evaluate(p, np.zeros((1, geometry.dof)), derivatives=False)
    target = x @ hom(zero.rotation[0] @ r_tool, zero.rotation[0] @ offset + zero.position[0])
    placed = build_model("dh", geometry, base=x, target=target, orientation=orientations is not None)
    p0 = placed.initial.copy()
    names = [f"base.{a}" for a in ("x", "y", "z", "rx", "ry", "rz")] + [f"tool.{a}" for a in "xyz"]
    if orientations is not None:
        names += [f"tool.r{a}" for a in "xyz"]
    cand = [placed.index(name) for name in names]
    rot_weight = 1.0 / sigma_rot if orientations is not None else 0.0
    jac = _rows(placed, p0, q, 1.0 / sigma, rot_weight)[:, cand]
    free = [cand[k] for k in independent_columns(jac, range(len(cand)), RANK_TOL)]
    res = fit(placed, p0, free, q, points, sigma=sigma, orientations=orientations, sigma_rot=sigma_rot)
    frame0, _, _ = model_frames(placed, res.params)
    world = frame0 @ inv(default_frame0(geometry))
    return world, res.residuals, placed, res.params


def _kabsch(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rigid transform (4, 4) minimising ``sum |R a_k + t - b_k|^2`` for point sets (N, 3)."""
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    h = (a - ca).T @ (b - cb)
    u, _, vt = np.linalg.svd(h)
    d = np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))])
    r = vt.T @ d @ u.T
    return hom(r, cb - r @ ca)


def identifiable_parameters(robot: Robot | RobotNumbers, model: ErrorModel, params: np.ndarray,
                            q: np.ndarray,
                            weights: np.ndarray | float = 1.0, rot_weight: float = 1.0,
                            ) -> tuple[list[int], list[Unidentifiable]]:
    """Identifiable parameters of ``model`` for the poses ``q``, and the reasons for the others.

    Structure first: random poses within the joint limits, unit weights, at ``params``; then the
    given poses with ``weights`` (1 / sigma, scalar or (N, 3)) and ``rot_weight`` (1 / sigma_rot).

    Returns
    -------
    free : list of int
        Indices of the identifiable parameters, in the model's priority order.
    unidentifiable : list of Unidentifiable
    """
    weights = np.broadcast_to(np.asarray(weights, dtype=float).reshape(-1, 3) if np.ndim(weights) else
                              weights, (len(q) * model.targets, 3))
    qr = random_configurations(robot, max(3 * model.n_params, 60), rng=12345)
    ones = np.ones((len(qr) * model.targets, 3))
    js = compress_rows(_rows(model, params, qr, ones, 1.0))  # same column geometry, L rows
    kept_s = independent_columns(js, model.priority, RANK_TOL)
    drop_s = [k for k in model.priority if k not in kept_s]
    out = [Unidentifiable(model.names[k], float(params[k]), "structural", combo,
                          f"{text}, whatever the poses")
           for k, (combo, text) in zip(drop_s, describe(js, model.names, kept_s, drop_s), strict=True)]
    jd = compress_rows(_rows(model, params, q, weights, rot_weight))
    order = [k for k in model.priority if k in kept_s]
    kept_d = independent_columns(jd, order, RANK_TOL)
    drop_d = [k for k in order if k not in kept_d]
    still = [robot.joint_names[j] for j in range(robot.dof) if np.ptp(q[:, j]) <= 1e-9]
    note = f"; joint(s) {', '.join(still)} take a single value in every pose" if still else ""
    for k, (combo, text) in zip(drop_d, describe(jd, model.names, kept_d, drop_d), strict=True):
        out.append(Unidentifiable(model.names[k], float(params[k]), "pose set", combo,
                                  f"{text} on this pose set (a richer pose set would identify it){note}"))
    return sorted(kept_d, key=model.priority.index), out


def calibrate(
    robot: Robot | RobotNumbers,
    q,
    points,
    model: str = "s-model",
    *,
    sigma: float | np.ndarray = 5e-5,
    loss: str = "linear",
    initial: str = "nominal",
    circle_data: Sequence[tuple[np.ndarray, np.ndarray]] | None = None,
    orientations=None,
    sigma_rot: float = 1e-4,
    loss_scale: float = 3.0,
    parallel_tol: float = math.radians(1.0),
    max_nfev: int | None = None,
    nongeometric: Sequence[str] = (),
    payload: tuple[float, Sequence[float]] | None = None,
    identify_payload: bool = False,
    length_unit: str = "m",
    angle_unit: str = "rad",
    deflection: str = "linear",
    options: CalibrateOptions | None = None,
) -> Calibration:
    """Identify a robot's kinematics from measured target positions.

    Parameters
    ----------
    robot : Robot or RobotNumbers
        The nominal robot, or its numbers (:func:`robodyn.robot.numbers_cache.load_numbers`:
        no SymPy before the solve; the calibrated robots are built in full after it).
    q : array_like, shape (N, n)
        Joint readings at the measured poses, rad (m for prismatic joints).
    points : array_like, shape (N, 3) or (N, K, 3)
        Measured target positions in the instrument's frame, m; (N, K, 3) for K targets
        (reflectors) measured at each pose, each with its own offset on the last link, all fitted
        together. The instrument-to-base transform and the target offsets are unknown and
        estimated.
    model, sigma, loss, initial, sigma_rot, loss_scale, parallel_tol, max_nfev
        The choices: the attributes of the same names of
        :class:`~robodyn.calibration.options.CalibrateOptions` (what each does, its values and
        default). ``model``: "s-model" (default), "hayati", "dh" or "poe"; ``sigma``: the
        standard uncertainty of each measured coordinate, m (0.05 mm by default).
    nongeometric, payload, identify_payload, length_unit, angle_unit, deflection
        Likewise.
    circle_data : sequence of (q, points), optional
        One data set per joint that moves only that joint (see
        :func:`robodyn.calibration.circle_point`); used for the initial estimate only
        (``initial="circle-point"``).
    orientations : array_like, shape (N, 3, 3), optional
        Measured target orientations in the instrument frame (then the target's orientation is
        estimated too).
    options : CalibrateOptions, optional
        All the choices at once, instead of the keywords (a keyword other than its default
        given as well is refused); ``cal.options`` is the set a run used.

    Returns
    -------
    Calibration

    Raises
    ------
    ValueError
        On bad input: shapes, lengths, NaN, unknown options, too few poses for the identifiable
        parameters, a circle-point set in which its joint never moved.
    """
    opts = resolve(CalibrateOptions, options, dict(
        model=model, sigma=sigma, loss=loss, initial=initial, sigma_rot=sigma_rot,
        loss_scale=loss_scale, parallel_tol=parallel_tol, max_nfev=max_nfev,
        nongeometric=nongeometric, payload=payload, identify_payload=identify_payload,
        length_unit=length_unit, angle_unit=angle_unit, deflection=deflection), InputError)
    (model, sigma, loss, initial, sigma_rot, loss_scale, parallel_tol, max_nfev, nongeometric, payload,
     identify_payload, length_unit, angle_unit, deflection) = (
        opts.model, opts.sigma, opts.loss, opts.initial, opts.sigma_rot, opts.loss_scale,
        opts.parallel_tol, opts.max_nfev, opts.nongeometric, opts.payload, opts.identify_payload,
        opts.length_unit, opts.angle_unit, opts.deflection)
    if initial == "circle-point" and circle_data is None:
        raise InputError("initial='circle-point' needs circle_data: one (q, points) set per joint")
    q, points, orientations, sig, sigma_rot, geometry = _prepared_data(
        robot, q, points, orientations, sigma, sigma_rot, length_unit, angle_unit)
    oriented = orientations is not None
    pts3 = points if points.ndim == 3 else points[:, None]
    sig3 = sig.reshape(pts3.shape)
    world, target, placed, placed_params, before_res = _before_calibration(
        geometry, q, pts3, orientations, sig3, sigma_rot, points.shape)
    em, cp = _error_model(robot, geometry, model, initial, circle_data, target, world, oriented,
                          parallel_tol, q, pts3, nongeometric, payload, identify_payload, deflection)
    points = pts3.reshape(-1, 3)
    sig = sig3.reshape(-1, 3)
    res, unid = _identify(robot, em, model, q, points, sig, orientations, sigma_rot, pts3.shape[1],
                          loss, loss_scale, max_nfev, identify_payload)
    if not res.success:
        warnings.warn(f"calibration of {robot.name} did not converge: {res.message}", RuntimeWarning,
                      stacklevel=2)
    _warn_variance_factor(robot.name, res.variance_factor)
    return replace(_calibration(robot, geometry, em, res, unid, q, sig, before_res, placed,
                                placed_params, loss, initial, cp), options=opts)


def _prepared_data(robot: Robot | RobotNumbers, q, points, orientations, sigma, sigma_rot: float,
                   length_unit: str,
                   angle_unit: str,
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray, float, RobotGeometry]:
    """The data of :func:`calibrate` in m and rad, checked, with the robot's nominal geometry.

    Returns
    -------
    q : numpy.ndarray, shape (N, n)
        Joint readings, rad (m for prismatic joints).
    points : numpy.ndarray, shape (N, 3) or (N, K, 3)
        Measured target positions, m.
    orientations : numpy.ndarray or None, shape (N, 3, 3)
    sigma : numpy.ndarray, shape of ``points``
        Standard uncertainty of each coordinate, m.
    sigma_rot : float
        Standard uncertainty of an orientation, rad.
    geometry : RobotGeometry
    """
    q, points, sigma, sigma_rot = convert_units(robot, q, points, sigma, sigma_rot, length_unit,
                                                angle_unit)
    q, points, orientations, sig = check_data(robot, q, points, orientations, sigma)
    geometry = robot_geometry(robot)
    check_magnitude(geometry, q, points, length_unit)
    return q, points, orientations, sig, sigma_rot, geometry


def _before_calibration(geometry: RobotGeometry, q: np.ndarray, pts3: np.ndarray,
                        orientations: np.ndarray | None, sig3: np.ndarray, sigma_rot: float,
                        shape: tuple[int, ...],
                        ) -> tuple[np.ndarray, np.ndarray, ErrorModel, np.ndarray, np.ndarray]:
    """The nominal model placed on the measurements, and its ("before") residuals.

    ``q`` is (N, n); ``pts3`` (N, K, 3) the measured positions and ``sig3`` (N, K, 3) their
    uncertainties, m; ``orientations`` (N, 3, 3) or None, ``sigma_rot`` in rad; ``shape`` that of
    the points as given, (N, 3) or (N, K, 3).

    Returns
    -------
    world : numpy.ndarray, shape (4, 4)
        The robot world frame in the instrument frame.
    target : numpy.ndarray, shape (4, 4)
        The first target's frame at ``q = 0``, instrument frame.
    placed : ErrorModel
        The placed nominal DH model.
    placed_params : numpy.ndarray, shape (P,)
    before_res : numpy.ndarray, shape ``shape``
        Residuals of the placed nominal model (with every target's offset fitted), m.
    """
    world, before1, placed, placed_params = nominal_placement(geometry, q, pts3[:, 0], orientations,
                                                              sig3[:, 0], sigma_rot)
    _, before_k = target_offsets(placed, placed_params, q, pts3[:, 1:])
    before_res = np.concatenate((before1[:, None], before_k), axis=1).reshape(shape)
    target = model_frames(placed, placed_params)[2]
    return world, target, placed, placed_params, before_res


def _identify(robot: Robot | RobotNumbers, em: ErrorModel, model: str, q: np.ndarray,
              points: np.ndarray,
              sig: np.ndarray, orientations: np.ndarray | None, sigma_rot: float, k_count: int,
              loss: str, loss_scale: float, max_nfev: int | None, identify_payload: bool,
              ) -> tuple[Fit, list[Unidentifiable]]:
    """The identifiable parameters of ``em`` and their fit from its initial values.

    With ``identify_payload``, identifiability is checked again at the solution and the fit
    repeated from it while the identifiable set grows (at most three more times).

    ``q`` is (N, n); ``points`` (N * K, 3) the measured positions (the K = ``k_count`` targets of
    each pose together) and ``sig`` (N * K, 3) their uncertainties, m; ``orientations``
    (N, 3, 3) or None, ``sigma_rot`` in rad.

    Returns
    -------
    fit : Fit
    unidentifiable : list of Unidentifiable
        Those of the last identifiability check.

    Raises
    ------
    ValueError
        Too few poses for the identifiable parameters.
    """
    oriented = orientations is not None
    weights = 1.0 / sig
    rot_weight = 1.0 / sigma_rot if oriented else 0.0
    free, unid = identifiable_parameters(robot, em, em.initial, q, weights, rot_weight)
    _check_pose_count(robot, em, model, unid, q, k_count, oriented)
    res = fit(em, em.initial, free, q, points, sigma=sig, orientations=orientations,
              sigma_rot=sigma_rot, loss=loss, loss_scale=loss_scale, max_nfev=max_nfev)
    for _ in range(3 if identify_payload else 0):
        # at c = 0 the payload has no effect, and a joint the arm alone does not load (a wrist)
        # shows its compliance only under the payload: identifiability again at the solution,
        # refit from it while the identifiable set grows
        again, unid_again = identifiable_parameters(robot, em, res.params, q, weights, rot_weight)
        if set(again) <= set(free):
            break
        free, unid = again, unid_again
        res = fit(em, res.params, free, q, points, sigma=sig, orientations=orientations,
                  sigma_rot=sigma_rot, loss=loss, loss_scale=loss_scale, max_nfev=max_nfev)
    return res, unid


#: Fewer equations per identifiable parameter than this draw a warning (a rule of thumb: below it
#: held-out errors grow, e.g. 25 tracker poses with compliance and harmonics, 0.31 -> 0.49 mm).
EQUATIONS_PER_PARAMETER = 3.0


def _check_pose_count(robot: Robot | RobotNumbers, em: ErrorModel, model: str,
                      unid: Sequence[Unidentifiable],
                      q: np.ndarray, k_count: int, oriented: bool) -> None:
    """Refuse fewer equations than structurally identifiable parameters (ValueError).

    ``q`` is (N, n); each pose gives 3 equations per target (``k_count`` of them) and 3 more
    with a measured orientation.
    """
    per = 3 * k_count + (3 if oriented else 0)
    rows = q.shape[0] * per
    n_struct = em.n_params - sum(u.kind == "structural" for u in unid)
    if rows <= n_struct:
        raise InputError(
            f"too few poses: {len(q)} poses give {rows} equations for {n_struct} identifiable "
            f"parameters of the {model} model of {robot.name}; at least {n_struct // per + 1} poses "
            "are needed (several times more for a useful calibration)"
        )
    if rows < EQUATIONS_PER_PARAMETER * n_struct:
        warnings.warn(
            f"calibration of {robot.name}: {len(q)} poses give {rows} equations for {n_struct} "
            f"identifiable parameters of the {model} model (fewer than {EQUATIONS_PER_PARAMETER:g} "
            "per parameter): the fit can follow the measurement noise rather than the arm; add "
            "poses or leave terms out (robodyn calibrate cross-validates the non-geometric terms)",
            RuntimeWarning, stacklevel=4)


def _calibration(robot: Robot | RobotNumbers, geometry: RobotGeometry, em: ErrorModel, res: Fit,
                 unid: Sequence[Unidentifiable], q: np.ndarray, sig: np.ndarray,
                 before_res: np.ndarray, placed: ErrorModel, placed_params: np.ndarray, loss: str,
                 initial: str, cp: CirclePointResult | None) -> Calibration:
    """The :class:`Calibration` of a fit: parameters with uncertainties, statistics, robots.

    Parameters
    ----------
    q : numpy.ndarray, shape (N, n)
    sig : numpy.ndarray, shape (N * K, 3)
        Standard uncertainties of the measured coordinates, m.
    before_res : numpy.ndarray, shape (N, 3) or (N, K, 3)
        Residuals of the placed nominal model, m (the shape of the measured points).
    placed : ErrorModel
        The placed nominal model, with its parameters ``placed_params`` (P',).
    """
    std = np.sqrt(np.diag(res.covariance))
    parameters = tuple(
        Parameter(em.names[k], float(res.params[k]), float(s), float(em.initial[k]), em.units[k])
        for k, s in zip(res.free, std, strict=True)
    )
    from robodyn.calibration.to_robot import calibrated_robot  # SymPy: after the solve

    obs = observability(_rows(em, res.params, q, np.ones((len(sig), 3)), 1.0)[:, res.free], len(q))
    return Calibration(
        robot=calibrated_robot(robot, geometry, em, res.params),
        model=em,
        params=res.params,
        parameters=parameters,
        covariance=res.covariance,
        unidentifiable=tuple(unid),
        residuals=res.residuals.reshape(before_res.shape),
        rotation_residuals=res.rotation_residuals,
        before_residuals=before_res,
        before=ErrorStats.from_residuals(before_res),
        after=ErrorStats.from_residuals(res.residuals),
        observability=obs,
        variance_factor=res.variance_factor,
        pose_count=len(q),
        sigma=float(np.mean(sig)),
        loss=loss,
        initial=initial,
        nfev=res.nfev,
        converged=res.success,
        message=res.message,
        circle_point=cp,
        before_robot=calibrated_robot(robot, geometry, placed, placed_params,
                                      name=f"{robot.name}_placed"),
        targets_axis=before_res.ndim == 3,
    )


def _error_model(robot: Robot | RobotNumbers, geometry: RobotGeometry, model: str, initial: str,
                 circle_data: Any,
                 target: np.ndarray, world: np.ndarray, oriented: bool, parallel_tol: float,
                 q: np.ndarray, pts3: np.ndarray, nongeometric: Sequence[str], payload: Any,
                 identify_payload: bool, deflection: str) -> tuple[ErrorModel, CirclePointResult | None]:
    """The error model at its starting point (nominal or circle-point), with the other targets'
    offsets and the non-geometric terms added; and the circle-point result when used."""
    cp: CirclePointResult | None = None
    if initial == "circle-point":
        cp = circle_point(geometry, circle_data, parallel_tol=parallel_tol)
        t0 = target.copy()
        t0[:3, 3] = cp.target
        em = build_model(model, geometry, base=cp.registration, lines=(cp.points, cp.directions),
                         target=t0, orientation=oriented, parallel_tol=parallel_tol)
    else:
        em = build_model(model, geometry, base=world, target=target, orientation=oriented,
                         parallel_tol=parallel_tol)
    if pts3.shape[1] > 1 or nongeometric:
        ng = None
        if nongeometric:
            from robodyn.calibration.nongeometric import build_nongeometric, nominal_frames

            ng = build_nongeometric(robot, nongeometric, nominal_frames(geometry), payload=payload,
                                    identify_payload=identify_payload, deflection=deflection)
        offsets, _ = target_offsets(em, em.initial, q, pts3[:, 1:])
        em = extend_model(em, offsets, ng)
    return em, cp


def _warn_variance_factor(name: str, variance_factor: float) -> None:
    """Warn when the variance factor says the given sigma is off by more than 3x either way."""
    ratio = math.sqrt(variance_factor)
    if ratio > 3.0 or ratio < 1.0 / 3.0:
        warnings.warn(f"calibration of {name}: the variance factor {variance_factor:.4g} says the "
                      f"given sigma is wrong by a factor of about {ratio:.3g} (residuals "
                      f"{'larger' if ratio > 1 else 'smaller'} than sigma); the standard uncertainties "
                      "are scaled by it, but check sigma (or the data's units, or unmodelled errors)",
                      RuntimeWarning, stacklevel=3)


