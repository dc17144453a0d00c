"""A calibrated :class:`~robodyn.robot.model.Robot` from error-model parameters.

Which frames change. Every joint keeps its axis vector, its ``post`` transform, its limits, drive
and friction, and every link keeps its inertial data: each link frame stays where it was on its
own joint's frame (``L_i = W_i post_i``, with ``W_i`` the frame after ``pre_i``). Calibration
moves the joint frames ``W_i`` with the calibrated joint axes, so only these change:

* ``pre_i = L_{i-1}^-1 W_i``: the joint's placement on the previous link, with its zero offset;
* ``base``: the chain base frame in the measuring instrument's frame (the calibrated robot's
  world frame is the instrument frame);
* ``tool``: the measured target in the last link frame (its orientation is the nominal tool's
  unless orientations were measured);
* ``gravity``: the nominal world gravity turned into the instrument frame by the calibrated
  base rotation (so the robot's base is assumed to sit as level as its description says).

``W_i`` follows the model's motion frame ``M_i`` of joint ``i`` rigidly: ``W_i = M_i K_i`` with
``K_i = M_i^-1 W_i`` fixed at the nominal geometry. Because ``K_i`` keeps the joint axis on the
motion frame's z axis, the robot's forward kinematics equal the model's for all readings. Link
inertial data are thereby carried with the joint that drives the link; where a link's mass sits
relative to the corrected geometry is not measured, and the error of this choice is of the order
of the kinematic corrections (millimetres), far below the uncertainty of inertial data.
"""

from __future__ import annotations

from dataclasses import replace
from types import MappingProxyType

import numpy as np
import sympy as sp

from robodyn.calibration.kinematics import inv
from robodyn.calibration.models import ErrorModel, model_frames
from robodyn.calibration.nominal import RobotGeometry, numeric
from robodyn.robot.model import Robot
from robodyn.robot.numbers import RobotNumbers, full_robot

__all__ = ["calibrated_robot", "sym"]


def sym(m: np.ndarray, snap: float = 1e-15) -> sp.ImmutableMatrix:
    """A float array as a SymPy matrix: exact 0 and 1 where the float is within ``snap`` of them."""
    out = []
    for row in np.atleast_2d(m):
        vals = []
        for v in row:
            if abs(v) <= snap:
                vals.append(sp.Integer(0))
            elif abs(v - 1.0) <= snap:
                vals.append(sp.Integer(1))
            elif abs(v + 1.0) <= snap:
                vals.append(sp.Integer(-1))
            else:
                vals.append(sp.Float(float(v)))
        out.append(vals)
    return sp.ImmutableMatrix(out)


def calibrated_robot(nominal: Robot | RobotNumbers, geometry: RobotGeometry, model: ErrorModel,
                     params: np.ndarray, *, name: str | None = None) -> Robot:
    """The robot described by ``model`` at ``params`` (see the module docstring).

    Parameters
    ----------
    nominal : Robot or RobotNumbers
        The robot the model was built from (names, links, drives, friction, limits); numbers
        from the cache are loaded in full (:func:`~robodyn.robot.numbers.full_robot`).
    geometry : RobotGeometry
        Its nominal geometry.
    model : ErrorModel
    params : numpy.ndarray, shape (P,)
    name : str, optional
        Name of the new robot (default ``<nominal name>_calibrated``).

    With non-geometric terms in ``model``, the robot carries them as joint-reading corrections
    (``robot.corrections``, :meth:`~robodyn.calibration.nongeometric.NonGeometric.corrections`), so
    that its forward kinematics of the readings equal the model's.

    Returns
    -------
    Robot
        Numeric kinematics; ``robot.base`` is the chain base frame in the instrument frame.
    """
    nominal = full_robot(nominal)
    frame0, motion, target = model_frames(model, params)
    w = motion @ model.joint_to_robot  # robot joint frames, instrument coords
    base = frame0 @ model.base_to_robot
    subs = nominal.defaults()
    joints = []
    prev = base
    for joint, wi, post in zip(nominal.joints, w, geometry.posts, strict=True):
        pre = inv(prev) @ wi
        axis = numeric(joint.axis, subs).ravel()
        joints.append(replace(
            joint,
            pre=sym(pre),
            axis=sym((axis / np.linalg.norm(axis))[:, None]),
            post=sym(post),
            convention="origin",
            source_params=MappingProxyType({}),
        ))
        prev = wi @ post
    tool = inv(prev) @ target
    if not model.orientation:
        tool[:3, :3] = model.tool_rotation
    rot = base[:3, :3] @ geometry.base[:3, :3].T  # instrument <- robot world
    gravity = rot @ numeric(nominal.gravity, subs).ravel()
    ng = model.nongeometric
    corrections = ng.corrections(params[model.nongeometric_slice]) if ng is not None else None
    return Robot(
        corrections=corrections,
        name=name or f"{nominal.name}_calibrated",
        joints=tuple(joints),
        links=nominal.links,
        base=sym(base),
        tool=sym(tool),
        gravity=sym(gravity[:, None]),
        parameters=dict(nominal.parameters),
        source=f"calibrated ({model.name}) from {nominal.source}",
    )
