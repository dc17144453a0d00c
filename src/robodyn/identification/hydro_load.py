"""An underwater arm's hydrodynamic torque, taken from its description as a known load.

The regressor holds the rigid body, the drives and the friction; a wet link adds the fluid's
torque (added mass, drag, lift, skin friction and buoyancy: :mod:`robodyn.symbolic.hydro`), which
is not linear in those parameters. :func:`robodyn.identify` takes it from the description, as it
takes a known payload's::

    tau_h(q, qd, qdd) = ID(q, qd, qdd) - ID_dry(q, qd, qdd)

the inverse dynamics of the robot with and without its hydrodynamic blocks (the same rigid body,
drives and friction, so only the fluid's share is left). The target's filter is applied to it as
to the regressor rows, it is taken off the target before anything is fitted or chosen, and
:meth:`~robodyn.identification.result.Identification.predict` adds it back at the processed
states; the written robot keeps the hydrodynamic blocks, so ``rd.validate`` of it predicts as
``ident.predict`` does. With motor current as the target it enters in amperes through the
description's signed drive gain ``gear_ratio x torque_constant`` (an error where that is 0).

Without this (before 2026-12-07), the fit absorbed the fluid's torque into the rigid-body and
friction parameters and the written robot added it a second time: on a virtual
``underwater_2r`` (100 Hz joint torques, 0.05 N m noise) ``ident.predict`` missed another run by
0.133 (relative) and ``rd.validate`` of the written robot by 0.873 (the description: 0.0009).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from robodyn.identification.preprocess import Preprocess, Samples, filtered_rows
from robodyn.identification.prior import description_gains
from robodyn.numeric.model import Model, compile_model
from robodyn.robot.errors import IdentificationError
from robodyn.robot.model import Robot

__all__ = ["HydroLoad", "hydro_load", "without_hydro"]


@dataclass(frozen=True, eq=False)
class HydroLoad:
    """The description's hydrodynamic torque in the target's unit.

    Attributes
    ----------
    wet, dry : Model
        The robot's compiled model with and without its hydrodynamic blocks.
    scale : numpy.ndarray, shape (n,)
        Target units per N m: 1 for a torque target, ``1 / (gear_ratio x torque_constant)``
        (A / N m) for a current target.
    """

    wet: Model
    dry: Model
    scale: np.ndarray

    def target(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """The fluid's share of the target at states ``q, qd, qdd`` (N, n), (N, n)."""
        # tau_h = ID(q, qd, qdd) - ID_dry(q, qd, qdd), in the target's unit
        tau = self.wet.inverse_dynamics(q, qd, qdd) - self.dry.inverse_dynamics(q, qd, qdd)
        return tau * self.scale[None, :]


def hydro_load(robot: Robot, model: Model, target: str) -> HydroLoad | None:
    """The hydrodynamic load of ``robot`` (None for a dry robot).

    Parameters
    ----------
    robot : Robot
    model : Model
        Its compiled model (with the hydrodynamic terms).
    target : {"tau", "current"}

    Raises
    ------
    IdentificationError
        A current target and a joint whose description has no drive gain.
    """
    if not any(link.hydro is not None for link in robot.links):
        return None
    dry = replace(robot, links=tuple(replace(link, hydro=None) for link in robot.links), fluid=None)
    scale = np.ones(robot.dof)
    if target == "current":
        k = description_gains(robot, signed=True)
        if np.any(k == 0) or not np.all(np.isfinite(k)):
            bad = [robot.joint_names[j] for j in np.flatnonzero((k == 0) | ~np.isfinite(k))]
            raise IdentificationError(
                f"robot: joints {bad} have no drive gain (gear_ratio x torque_constant); an "
                "underwater arm's hydrodynamic torque is taken off a current target through it")
        scale = 1.0 / k
    return HydroLoad(model, compile_model(dry), scale)


def without_hydro(load: HydroLoad, full: Sequence[Samples], settings: Preprocess
                  ) -> tuple[list[Samples], list[np.ndarray]]:
    """Processed samples ``full`` with the filtered hydrodynamic target taken off their target,
    and that target, (N_k, n) each."""
    out, taken = [], []
    for s in full:
        # H tau_h: the target's filter, as on the regressor rows
        h = filtered_rows(s.t, load.target(s.q, s.qd, s.qdd), settings, 1)
        out.append(replace(s, y=None if s.y is None else s.y - h))
        taken.append(h)
    return out, taken

