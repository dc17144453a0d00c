"""A :class:`~robodyn.robot.model.Robot` carrying a standard parameter vector.

Per joint the 15 standard parameters (see :mod:`robodyn.symbolic.regressor`) map back onto the
description: ``mass = M``; ``com = (MX, MY, MZ) / M`` (the origin when ``M = 0``); inertia about
the centre of mass ``I_c = I_O - M (|c|^2 1 - c c^T)`` (parallel axis theorem, ``I_O`` from XX..ZZ);
rotor inertia ``Ia / G^2`` on the motor side (the drive's gear ratio ``G`` is kept; ``G = 1`` when
the description has none); friction ``(Fv, Fcp, Fcn, Fo)``. Drive gains identified from current
become ``torque_constant = K / G`` so that ``G * torque_constant = K``. Geometry, limits and names
are the nominal robot's; the named parameters are dropped (the new values are numbers). The
links' hydrodynamic blocks and the fluid are kept, their named parameters replaced by the
nominal values (an underwater arm's identification takes the description's hydrodynamic torque
as known: :mod:`robodyn.identification.hydro_load`).
"""

from __future__ import annotations

from dataclasses import fields, is_dataclass, replace
from typing import Any

import numpy as np
import sympy as sp

from robodyn.robot.model import Friction, Robot
from robodyn.symbolic.regressor import PER_JOINT

__all__ = ["robot_with_parameters"]


def _f(x: float) -> sp.Expr:
    return sp.Integer(0) if x == 0 else sp.Float(float(x), 17)


def _num(value: sp.Expr | None, subs: dict) -> sp.Expr | None:
    return None if value is None else sp.sympify(value).xreplace(subs)


def _numeric(value: Any, subs: dict) -> Any:
    """``value`` (a hydrodynamic block, a fluid, or a part of one) with ``subs`` substituted
    into every SymPy expression it holds."""
    if isinstance(value, sp.Basic):
        return value.xreplace(subs)
    if isinstance(value, tuple):
        return tuple(_numeric(v, subs) for v in value)
    if is_dataclass(value) and not isinstance(value, type):
        return replace(value, **{f.name: _numeric(getattr(value, f.name), subs)
                                 for f in fields(value) if f.init})
    return value


def robot_with_parameters(nominal: Robot, standard: np.ndarray, gains: np.ndarray | None = None, *,
                          name: str | None = None, source: str = "") -> Robot:
    """The nominal robot with its inertial, drive and friction data replaced.

    Parameters
    ----------
    nominal : Robot
    standard : numpy.ndarray, shape (15 n,)
        Standard parameters, regressor column order (SI units).
    gains : numpy.ndarray, shape (n,), optional
        Drive gains ``K_j`` (N m / A, joint side) to store; None keeps the nominal drives' values.
    name : str, optional
        Default ``<nominal name>_identified``.
    source : str

    Returns
    -------
    Robot
    """
    subs = nominal.defaults()
    links, joints = [], []
    for j, (joint, link) in enumerate(zip(nominal.joints, nominal.links, strict=True)):
        xx, xy, xz, yy, yz, zz, mx, my, mz, m, ia, fv, fcp, fcn, fo = standard[
            PER_JOINT * j:PER_JOINT * (j + 1)]
        i_o = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        c = np.array([mx, my, mz]) / m if m != 0 else np.zeros(3)
        # I_c = I_O - m (|c|^2 1 - c c^T)
        i_c = i_o - m * (float(c @ c) * np.eye(3) - np.outer(c, c))
        links.append(replace(link, mass=_f(m), com=sp.ImmutableMatrix([_f(v) for v in c]),
                             inertia=sp.ImmutableMatrix([[_f(v) for v in row] for row in i_c]),
                             hydro=_numeric(link.hydro, subs)))
        g = float(sp.sympify(joint.drive.gear_ratio).xreplace(subs))
        g = g if g != 0 else 1.0
        drive = replace(joint.drive, gear_ratio=_f(g), rotor_inertia=_f(ia / g**2),
                        torque_constant=_f(float(gains[j]) / abs(g)) if gains is not None else
                        _f(float(sp.sympify(joint.drive.torque_constant).xreplace(subs))))
        joints.append(replace(
            joint,
            pre=sp.ImmutableMatrix(joint.pre.xreplace(subs)),
            post=sp.ImmutableMatrix(joint.post.xreplace(subs)),
            axis=sp.ImmutableMatrix(joint.axis.xreplace(subs)),
            lower=_num(joint.lower, subs),
            upper=_num(joint.upper, subs),
            velocity_limit=_num(joint.velocity_limit, subs),
            effort_limit=_num(joint.effort_limit, subs),
            drive=drive,
            friction=Friction(viscous=_f(fv), coulomb_positive=_f(fcp), coulomb_negative=_f(fcn),
                              offset=_f(fo)),
        ))
    return Robot(
        name=name or f"{nominal.name}_identified",
        joints=tuple(joints),
        links=tuple(links),
        base=sp.ImmutableMatrix(nominal.base.xreplace(subs)),
        tool=sp.ImmutableMatrix(nominal.tool.xreplace(subs)),
        gravity=sp.ImmutableMatrix(nominal.gravity.xreplace(subs)),
        parameters={},
        source=source or f"identified from {nominal.source}",
        fluid=_numeric(nominal.fluid, subs),
    )
