"""Link inertias a physics engine accepts, equivalent in joint space wherever the chain allows.

MuJoCo compiles a moving body only if its mass and each principal moment of inertia exceed
``mjMINVAL`` (1e-15) and the principal moments satisfy the triangle inequality ``A + B >= C``.
robodyn accepts what descriptions give: massless links, point masses, thin rods (a zero moment),
and published inertias that violate the triangle inequality (the PUMA 560's link 3; links whose
tensor only ever enters the dynamics through the moment about one axis, like Kinova's shoulder).

:func:`engine_inertial` repairs such a link with the smallest change that is invisible in the
joint-space dynamics where the chain allows it:

1. A mass below :data:`MIN_MASS` is raised to it (at the same centre of mass).
2. A valid tensor (smallest moment at least :data:`MIN_INERTIA`, triangle inequality with a
   relative margin of :data:`TRIANGLE_MARGIN` so that the engine's own eigen-decomposition
   cannot round it to the wrong side) is kept as it is.
3. Otherwise, when the link only ever turns about one direction ``e`` fixed in its frame (every
   revolute joint from the base up to it is parallel to the first: planar arms, a first link,
   a pendulum on a trolley; see :func:`rotation_axes`), only ``e^T I e`` enters the joint
   torques, and the tensor becomes ``(e^T I e) * I3`` (floored at :data:`MIN_INERTIA`): the
   joint-space dynamics are unchanged.
4. Otherwise (the link turns about varying axes, or never turns) the principal moments are
   clipped at zero, the two smaller ones are raised by half the triangle deficit each, every
   moment is floored at :data:`MIN_INERTIA`, and the tensor is rebuilt on the same principal
   axes. For a link that never turns this is invisible too; for one that turns about varying
   axes it changes the dynamics, which :func:`engine_inertial` reports.

The floors change the dynamics by at most about :data:`MIN_MASS` kg and :data:`MIN_INERTIA`
kg m^2: far below any measured robot's parameters.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robodyn.export import numeric as nm
from robodyn.robot.errors import InputError
from robodyn.robot.model import Robot

__all__ = [
    "MIN_INERTIA",
    "MIN_MASS",
    "PARALLEL_TOLERANCE",
    "TRIANGLE_MARGIN",
    "EngineInertial",
    "engine_inertial",
    "rotation_axes",
]

#: Smallest link mass written, kg (MuJoCo rejects moving bodies under 1e-15 kg).
MIN_MASS = 1e-9
#: Smallest principal moment of inertia written, kg m^2.
MIN_INERTIA = 1e-12
#: Relative margin kept on the triangle inequality ``A + B >= C (1 + margin)``.
TRIANGLE_MARGIN = 1e-12
#: Two joint axes (unit vectors) count as parallel when ``|a x b|`` is at most this.
PARALLEL_TOLERANCE = 1e-12


@dataclass(frozen=True)
class EngineInertial:
    """A link's mass and inertia as written for the engine.

    Attributes
    ----------
    mass : float
        kg.
    inertia : numpy.ndarray, shape (3, 3)
        About the centre of mass, link frame axes, kg m^2.
    changed : bool
        True when the mass or inertia differs from the description's.
    equivalent : bool
        True when the joint-space dynamics are the same as with the description's values (up to
        the floors :data:`MIN_MASS`, :data:`MIN_INERTIA` and the triangle margin).
    moments_before, moments_after : numpy.ndarray, shape (3,)
        Principal moments (ascending) of the description's and of the written tensor, kg m^2.
    """

    mass: float
    inertia: np.ndarray
    changed: bool
    equivalent: bool
    moments_before: np.ndarray
    moments_after: np.ndarray


def rotation_axes(robot: Robot, values: nm.Values) -> list[np.ndarray | None]:
    """The direction of each link's angular velocity, when it is the same at every state.

    Rotations about parallel axes keep those axes parallel and prismatic joints do not rotate,
    so when every revolute joint from the base up to link ``i`` is parallel to the first one at
    ``q = 0``, link ``i``'s angular velocity is ``(sum of +-qd_j) e`` at every state, with ``e``
    fixed in the link frame.

    Parameters
    ----------
    robot : Robot
    values : dict
        Parameter values (:func:`robodyn.export.numeric.values_of`).

    Returns
    -------
    list, length n
        Per link: the unit vector ``e`` in the link frame, shape (3,); a zero vector when no
        revolute joint precedes the link (it never turns); ``None`` when the direction varies.
    """
    rot = nm.array(robot.base, values, "base")[:3, :3]
    axes: list[np.ndarray] = []
    out: list[np.ndarray | None] = []
    for k, joint in enumerate(robot.joints):
        where = f"{robot.source}: joints[{k}]"
        rot = rot @ nm.array(joint.pre, values, f"{where}.pre")[:3, :3]  # joint frame at q = 0
        if joint.type == "revolute":
            a = rot @ nm.array(joint.axis, values, f"{where}.axis").ravel()
            axes.append(a / np.linalg.norm(a))
        rot = rot @ nm.array(joint.post, values, f"{where}.post")[:3, :3]  # link frame at q = 0
        if not axes:
            out.append(np.zeros(3))
        elif all(np.linalg.norm(np.cross(a, axes[0])) <= PARALLEL_TOLERANCE for a in axes):
            out.append(rot.T @ axes[0])
        else:
            out.append(None)
    return out


def engine_inertial(mass: float, inertia: np.ndarray, axis: np.ndarray | None) -> EngineInertial:
    """Mass and inertia that a physics engine accepts (module docstring for the rules).

    Parameters
    ----------
    mass : float
        kg, non-negative.
    inertia : numpy.ndarray, shape (3, 3)
        About the centre of mass, link frame axes, kg m^2.
    axis : numpy.ndarray, shape (3,), or None
        From :func:`rotation_axes`: the only direction the link turns about (unit), a zero
        vector if it never turns, None if it turns about varying axes.

    Returns
    -------
    EngineInertial

    Raises
    ------
    ValueError
        If ``mass`` is negative.
    """
    if mass < 0:
        raise InputError(f"negative mass {mass} kg")
    inertia = np.asarray(inertia, dtype=float)
    inertia = (inertia + inertia.T) / 2
    moments, vectors = np.linalg.eigh(inertia)
    new_mass = max(float(mass), MIN_MASS)
    valid = moments[0] >= MIN_INERTIA and moments[0] + moments[1] >= moments[2] * (1 + TRIANGLE_MARGIN)
    if valid:
        new, equivalent = inertia, True
    elif axis is not None and np.linalg.norm(axis) > 0:
        # only e^T I e enters the joint torques: keep it, make the tensor isotropic
        new, equivalent = max(float(axis @ inertia @ axis), MIN_INERTIA) * np.eye(3), True
    else:
        lam = np.clip(moments, 0.0, None)
        # raise the two smaller moments by half the deficit each: A + B = C (1 + margin)
        deficit = lam[2] * (1 + TRIANGLE_MARGIN) - lam[0] - lam[1]
        if deficit > 0:
            lam[:2] += deficit / 2
        lam = np.maximum(lam, MIN_INERTIA)
        new = vectors @ np.diag(lam) @ vectors.T
        new = (new + new.T) / 2
        tolerance = max(1e-9 * float(np.abs(moments).max()), 10 * MIN_INERTIA)
        equivalent = axis is not None or float(np.abs(new - inertia).max()) <= tolerance
    changed = new_mass != mass or not np.array_equal(new, inertia)
    arrays = [np.array(a, dtype=float) for a in (new, moments, np.linalg.eigvalsh(new))]
    for a in arrays:
        a.flags.writeable = False  # frozen data
    return EngineInertial(
        mass=new_mass,
        inertia=arrays[0],
        changed=changed,
        equivalent=equivalent,
        moments_before=arrays[1],
        moments_after=arrays[2],
    )
