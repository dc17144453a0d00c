"""An underwater arm's hydrodynamic torque, taken from its description as a known load.

The regressor holds the rigid body, the drives and the friction; a wet link adds the fluid's
torque (added mass, drag, lift, skin friction and buoyancy: :mod:`robodyn.symbolic.hydro`), which
is not linear in those parameters. :func:`robodyn.identify` takes it from the description, as it
takes a known payload's::

    tau_h(q, qd, qdd) = ID(q, qd, qdd) - ID_dry(q, qd, qdd)

the inverse dynamics of the robot with and without its hydrodynamic blocks (the same rigid body,
drives and friction, so only the fluid's share is left). The target's filter is applied to it as
to the regressor rows, and it joins the known payloads' torque (N m): taken off the target
through the drive gains (``K_j y_j - P_j - tau_h,j`` for a current target, so that it is in
amperes at the gains the fit uses, absorbed, estimated or the description's) before anything is
fitted or chosen; :meth:`~robodyn.identification.result.Identification.predict` adds it to the
predicted torque before dividing by the gains, and the written robot keeps the hydrodynamic blocks,
so ``rd.validate`` of it predicts as ``ident.predict`` does.

Without this (before 2026-12-07), the fit absorbed the fluid's torque into the rigid-body and
friction parameters and the written robot added it a second time: on a virtual
``underwater_2r`` (100 Hz joint torques, 0.05 N m noise) ``ident.predict`` missed another run by
0.133 (relative) and ``rd.validate`` of the written robot by 0.873 (the description: 0.0009).
Until later the same day, a current target took it in amperes through the description's drive
gains: wrong by the gains' ratio where they are absorbed (a description without drive data).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from robodyn.identification.preprocess import Preprocess, Samples, filtered_rows
from robodyn.numeric.model import Model, compile_model
from robodyn.robot.model import Robot

__all__ = ["HydroLoad", "hydro_load", "hydro_rows"]


@dataclass(frozen=True, eq=False)
class HydroLoad:
    """The description's hydrodynamic torque.

    Attributes
    ----------
    wet, dry : Model
        The robot's compiled model with and without its hydrodynamic blocks.
    """

    wet: Model
    dry: Model

    def torque(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """The fluid's torque at states ``q, qd, qdd`` (N, n), N m (N for a prismatic joint)."""
        # tau_h = ID(q, qd, qdd) - ID_dry(q, qd, qdd)
        return self.wet.inverse_dynamics(q, qd, qdd) - self.dry.inverse_dynamics(q, qd, qdd)


def hydro_load(robot: Robot, model: Model) -> HydroLoad | None:
    """The hydrodynamic load of ``robot`` (None for a dry robot).

    Parameters
    ----------
    robot : Robot
    model : Model
        Its compiled model (with the hydrodynamic terms).
    """
    if not any(link.hydro is not None for link in robot.links):
        return None
    dry = replace(robot, links=tuple(replace(link, hydro=None) for link in robot.links), fluid=None)
    return HydroLoad(model, compile_model(dry))


def hydro_rows(load: HydroLoad, full: Sequence[Samples], settings: Preprocess) -> list[np.ndarray]:
    """The hydrodynamic torque at the processed samples ``full``, filtered like the regressor
    rows (the target's filter), (N_k, n) each, N m."""
    # H tau_h: the target's filter, as on the regressor rows
    return [filtered_rows(s.t, load.torque(s.q, s.qd, s.qdd), settings, 1) for s in full]
