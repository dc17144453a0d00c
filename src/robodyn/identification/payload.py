"""A known payload on the last link: its standard parameters and the joint torques it adds.

A payload rigidly attached to the last link (mass ``m``, centre of mass ``c`` and inertia
``I_c`` about ``c``, given in the last link's frame or in the tool frame) adds to the joint
torques exactly what the same change of the last link's inertial parameters would::

    tau_payload(q, qd, qdd) = Y_n(q, qd, qdd) pi_payload               (N, n)

with ``Y_n`` the last link's ten inertial columns of the regressor and ``pi_payload`` the
payload's standard parameters in that link's frame (XX..ZZ about the frame origin, MX MY MZ, M).
Its torque is known, so a run with the payload fixes the scale that a current target leaves
free (:mod:`robodyn.identification.drive_gains`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from robodyn.robot.errors import IdentificationError
from robodyn.robot.model import Robot
from robodyn.symbolic.regressor import INERTIAL_NAMES, PER_JOINT

__all__ = ["FRAMES", "Payload", "payload_standard", "payload_torque"]

FRAMES = ("link", "tool")
#: Relative tolerance of the symmetry and triangle-inequality checks of the inertia.
INERTIA_RTOL = 1e-9


@dataclass(frozen=True, eq=False)
class Payload:
    """A rigid payload of known inertia attached to the robot's last link.

    Attributes
    ----------
    mass : float
        kg, > 0.
    com : numpy.ndarray, shape (3,)
        Centre of mass, m, in ``frame``.
    inertia : numpy.ndarray, shape (3, 3)
        Inertia about the centre of mass, kg m^2, axes of ``frame``: symmetric, positive
        semi-definite, principal moments satisfying the triangle inequality (a rigid body).
    frame : {"link", "tool"}
        The last link's frame, or the robot's tool frame (``robot.tool`` relative to it).

    Raises
    ------
    IdentificationError
        A field that is not finite, a shape, a mass <= 0, or an inertia no rigid body has.
    """

    mass: float
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    frame: str = "link"

    def __post_init__(self) -> None:
        mass = _finite("mass", self.mass, ())
        if not mass > 0:
            raise IdentificationError(f"Payload.mass: must be > 0 kg, got {mass:g}")
        com = _finite("com", self.com, (3,))
        inertia = _finite("inertia", self.inertia, (3, 3))
        scale = max(float(np.abs(inertia).max()), 1e-300)
        if np.abs(inertia - inertia.T).max() > INERTIA_RTOL * scale:
            raise IdentificationError(f"Payload.inertia: not symmetric (max |I - I^T| = "
                                      f"{np.abs(inertia - inertia.T).max():.3g} kg m^2)")
        moments = np.linalg.eigvalsh(inertia)
        if moments[0] < -INERTIA_RTOL * scale:
            raise IdentificationError(f"Payload.inertia: not positive semi-definite (principal "
                                      f"moments {moments.tolist()} kg m^2)")
        # a rigid body: each principal moment <= the sum of the other two
        if moments[2] > moments[0] + moments[1] + INERTIA_RTOL * scale:
            raise IdentificationError(f"Payload.inertia: principal moments {moments.tolist()} kg m^2 "
                                      f"violate the triangle inequality I3 <= I1 + I2 (no rigid "
                                      f"body has them)")
        if self.frame not in FRAMES:
            raise IdentificationError(f"Payload.frame: expected one of {FRAMES}, got {self.frame!r}")
        for name, value in (("mass", mass), ("com", com), ("inertia", inertia)):
            if isinstance(value, np.ndarray):
                value.flags.writeable = False
            object.__setattr__(self, name, value)


def _finite(name: str, value: object, shape: tuple[int, ...]) -> np.ndarray | float:
    try:
        a = np.array(value, dtype=float)  # a copy: the user's array is never touched
    except (TypeError, ValueError) as exc:
        raise IdentificationError(f"Payload.{name}: expected numbers, got {value!r}") from exc
    if a.shape != shape:
        raise IdentificationError(f"Payload.{name}: expected shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise IdentificationError(f"Payload.{name}: not finite: {a.tolist()}")
    return float(a) if shape == () else a


def payload_standard(robot: Robot, payload: Payload) -> np.ndarray:
    """The payload's standard parameters in the last link's frame (10,), ``INERTIAL_NAMES`` order.

    Parameters
    ----------
    robot : Robot
        Gives the tool frame when ``payload.frame == "tool"``.
    payload : Payload

    Returns
    -------
    numpy.ndarray, shape (10,)
        XX, XY, XZ, YY, YZ, ZZ (kg m^2, about the link frame origin), MX, MY, MZ (kg m), M (kg).
    """
    c, i_c = payload.com, payload.inertia
    if payload.frame == "tool":
        tool = np.array(robot.tool.xreplace(robot.defaults()), dtype=float)
        rot, p = tool[:3, :3], tool[:3, 3]
        # c_link = R c_tool + p,  I_link = R I_tool R^T
        c, i_c = rot @ c + p, rot @ i_c @ rot.T
    m = payload.mass
    # I_O = I_c + m (|c|^2 1 - c c^T)  (parallel axis theorem)
    i_o = i_c + m * (float(c @ c) * np.eye(3) - np.outer(c, c))
    return np.array([i_o[0, 0], i_o[0, 1], i_o[0, 2], i_o[1, 1], i_o[1, 2], i_o[2, 2],
                     m * c[0], m * c[1], m * c[2], m])


def payload_torque(regressor: np.ndarray, pi: np.ndarray) -> np.ndarray:
    """Joint torques of the payload ``Y_n pi`` from a full regressor.

    Parameters
    ----------
    regressor : numpy.ndarray, shape (N, n, 15 n)
        ``Y(q, qd, qdd)`` (filtered like the target, where it was).
    pi : numpy.ndarray, shape (10,)
        :func:`payload_standard`.

    Returns
    -------
    numpy.ndarray, shape (N, n)
        N m (N).
    """
    n = regressor.shape[1]
    start = PER_JOINT * (n - 1)
    # tau_payload = Y_n pi: the last link's inertial columns
    return regressor[:, :, start:start + len(INERTIAL_NAMES)] @ pi
