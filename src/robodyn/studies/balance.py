"""The trolley double inverted pendulum (seed Fig. 3.1) held upright by LQR.

The seed thesis ran this system under "the controller to keep the two links in the upper vertical
position". Here only the trolley is actuated (a horizontal force F); both hinges are passive. The
LQR is designed on the linearisation of the symbolic equations about the upright equilibrium
(``q = 0``: both rods vertical, trolley at the origin) and simulated on the full nonlinear model.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robodyn.numeric.model import Model, compile_model
from robodyn.robot.load import load
from robodyn.simulation.controllers import LQR
from robodyn.simulation.simulation import Trajectory, simulate

#: Default weights: angles matter most, then the trolley position; rates lightly.
DEFAULT_Q = (10.0, 100.0, 100.0, 1.0, 10.0, 10.0)
DEFAULT_R = 1.0


@dataclass(frozen=True, eq=False)
class BalanceResult:
    """Outcome of :func:`balance_double_pendulum`.

    Attributes
    ----------
    simulation : Trajectory
    controller : LQR
    upright : bool
        True when both rods stayed within ``upright_tolerance`` of the vertical at every sample
        and ended within ``final_tolerance``.
    max_tilt : float
        Largest absolute angle of either rod from the upward vertical, rad.
    final_tilt : float
        The same at the end of the run, rad.
    final_position : float
        Trolley position at the end, m.
    peak_force : float
        Largest |F| on the trolley, N.
    figure : Path or None
    """

    simulation: Trajectory
    controller: LQR
    upright: bool
    max_tilt: float
    final_tilt: float
    final_position: float
    peak_force: float
    figure: Path | None = None


def balance_double_pendulum(model: Model | None = None, q0: tuple[float, float, float] = (0.0, 0.1, -0.05),
                            *, duration: float = 5.0, dt: float = 1e-3, Q=DEFAULT_Q,  # noqa: N803
                            R=DEFAULT_R, tau_limit: float | None = None, method: str = "rk4",  # noqa: N803
                            upright_tolerance: float = 0.5, final_tolerance: float = 0.02,
                            figure: str | Path | None = None) -> BalanceResult:
    """Balance the double inverted pendulum from a perturbed start with LQR on the trolley force.

    Parameters
    ----------
    model : Model, optional
        A compiled ``trolley_double_pendulum`` (default: compiled here).
    q0 : (3,)
        Start: trolley position (m), rod 1 angle and rod 2 relative angle (rad, from upright).
    duration, dt : float
        s.
    Q, R
        LQR weights (see :meth:`LQR.about`).
    tau_limit : float, optional
        Limit on |F|, N.
    method : str
        Integration method of :func:`simulate`.
    upright_tolerance : float
        Largest tilt (rad) allowed during the run.
    final_tolerance : float
        Largest tilt (rad) allowed at the end.
    figure : str or Path, optional
        Save a plot of the run there (PNG).

    Returns
    -------
    BalanceResult
    """
    if model is None:
        model = compile_model(load("trolley_double_pendulum"))
    n = model.dof
    # the hinges are passive (zero torque): only the trolley force is limited
    big = np.finfo(float).max
    limit = None if tau_limit is None else np.array([tau_limit, big, big])
    lqr = LQR.about(model, np.zeros(n), Q, R, actuated=[0], tau_limit=limit)
    sim = simulate(model, np.asarray(q0, dtype=float), None, duration, dt, method, lqr)
    # absolute rod angles from the upward vertical: theta1, theta1 + theta2
    tilt = np.abs(np.column_stack([sim.q[:, 1], sim.q[:, 1] + sim.q[:, 2]])).max(axis=1)
    upright = bool(np.all(tilt <= upright_tolerance) and tilt[-1] <= final_tolerance)
    result = BalanceResult(sim, lqr, upright, float(tilt.max()), float(tilt[-1]), float(sim.q[-1, 0]),
                           float(np.max(np.abs(sim.tau[:, 0]))))
    if figure is not None:
        from robodyn.studies import simulation_plots as plots

        path = plots.balance_figure(result, Path(figure))
        result = dataclasses.replace(result, figure=path)
    return result


__all__ = ["BalanceResult", "balance_double_pendulum"]
