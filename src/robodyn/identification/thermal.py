"""Temperature-dependent friction: viscous and Coulomb levels that change linearly with temperature.

Gear and bearing lubricants thin as a drive warms up, so the same arm run cold and warm shows
different friction (the Kinova Gen3 runs in ``../shared`` differ by about 10 deg C and their
friction by more than their inertia). The model adds to the linear friction of joint ``j``::

    tau_T = (T_j - T_ref,j) (cv_j qd_j + cc_j sign(qd_j))

with ``T_j`` the drive temperature (deg C, the recording's ``temperature``), ``T_ref,j`` the mean
temperature of the identification data, ``cv_j`` (N m s/rad/K) and ``cc_j`` (N m/K); ``sign`` is
zero inside the Coulomb dead band, as for the Coulomb columns. The two columns per joint are
linear in the parameters, so they enter the identification matrix beside the base columns and
are estimated with them (low-passed like every other column: parallel filtering). The written
description carries the friction at ``T_ref``; :meth:`Identification.predict` adds ``tau_T`` for
a recording with temperatures.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robodyn.identification.preprocess import Preprocess, Samples, evaluation_step, filtered_rows
from robodyn.robot.errors import IdentificationError

__all__ = ["ThermalData", "ThermalFit", "reference_temperature", "thermal_columns", "thermal_data",
           "temperatures"]


def temperatures(rec: Any, index: int, dof: int) -> np.ndarray:
    """The drive temperatures (N, n) of a recording, deg C, or an error naming what is missing."""
    temp = getattr(rec, "temperature", None)
    src = str(getattr(rec, "source", "") or f"recordings[{index}]")
    if temp is None:
        raise IdentificationError(f"{src}: temperature: thermal friction needs drive temperatures "
                                  f"and the recording has none")
    temp = np.asarray(temp, dtype=float)
    if temp.shape != (np.asarray(rec.q).shape[0], dof):
        raise IdentificationError(f"{src}: temperature: expected shape (N, {dof}), got {temp.shape}")
    if not np.all(np.isfinite(temp)):
        row, col = (int(a[0]) for a in np.nonzero(~np.isfinite(temp)))
        raise IdentificationError(f"{src}: temperature: value {temp[row, col]} is not finite at row "
                                  f"{row}, column {col} (a joint without a sensor cannot take "
                                  f"thermal friction)")
    return temp


def reference_temperature(temps: list[np.ndarray]) -> np.ndarray:
    """``T_ref`` (n,): the mean temperature of each joint over all identification samples, deg C."""
    return np.mean(np.vstack(temps), axis=0)


def thermal_columns(qd: np.ndarray, temp: np.ndarray, t_ref: np.ndarray, band: float) -> np.ndarray:
    """Rows (N, n, 2 n) of the thermal columns: joint j's row has ``(T - T_ref) qd`` in column
    ``2 j`` and ``(T - T_ref) sign(qd)`` (0 inside the dead band ``band``, rad/s) in ``2 j + 1``."""
    count, n = qd.shape
    dt = temp - t_ref[None, :]
    sign = np.where(np.abs(qd) < band, 0.0, np.sign(qd))
    out = np.zeros((count, n, 2 * n))
    idx = np.arange(n)
    out[:, idx, 2 * idx] = dt * qd  # (T - T_ref) qd
    out[:, idx, 2 * idx + 1] = dt * sign  # (T - T_ref) sign(qd)
    return out


@dataclass(frozen=True, eq=False)
class ThermalFit:
    """Temperature coefficients of the friction (module docstring).

    Attributes
    ----------
    t_ref : numpy.ndarray, shape (n,)
        Reference temperature of each joint, deg C (the description's friction holds there).
    viscous : numpy.ndarray, shape (n,)
        ``cv``, change of the viscous coefficient per kelvin, N m s/rad/K.
    coulomb : numpy.ndarray, shape (n,)
        ``cc``, change of the Coulomb level per kelvin, N m/K.
    """

    t_ref: np.ndarray
    viscous: np.ndarray
    coulomb: np.ndarray

    @property
    def coefficients(self) -> np.ndarray:
        """``(cv_1, cc_1, ..., cv_n, cc_n)`` (2 n,), the order of :func:`thermal_columns`."""
        return np.column_stack([self.viscous, self.coulomb]).reshape(-1)

    def torque(self, qd: np.ndarray, temp: np.ndarray, band: float) -> np.ndarray:
        """``tau_T`` (N, n), N m, at velocities ``qd`` (N, n) and temperatures ``temp`` (N, n)."""
        return thermal_columns(qd, temp, self.t_ref, band) @ self.coefficients


@dataclass(frozen=True, eq=False)
class ThermalData:
    """The thermal columns of the identification data (one entry per recording).

    Attributes
    ----------
    fit_rows : list of numpy.ndarray, shape (N_k, n, 2 n)
        Low-passed with the target's filter and decimated, as the fit's regressor rows.
    test_rows : list of numpy.ndarray, shape (N_k, n, 2 n)
        Unfiltered at the same samples, as a prediction's rows (cross-validation).
    t_ref : numpy.ndarray, shape (n,)
        Reference temperature of each joint, deg C.
    """

    fit_rows: list[np.ndarray]
    test_rows: list[np.ndarray]
    t_ref: np.ndarray


def thermal_data(recs: list[Any], full: list[Samples], settings: Preprocess) -> ThermalData:
    """The thermal columns of recordings ``recs`` processed into samples ``full`` (not decimated)."""
    n = full[0].q.shape[1]
    temps = [temperatures(r, i, n) for i, r in enumerate(recs)]
    t_ref = reference_temperature(temps)
    d, band = settings.decimate, settings.dead_band
    fit_rows, test_rows = [], []
    for s, temp in zip(full, temps, strict=True):
        m = evaluation_step(s.t, settings, d)
        rows = thermal_columns(s.qd[::m], temp[::m], t_ref, band)
        fit_rows.append(filtered_rows(s.t[::m], rows, settings, d // m))
        test_rows.append(thermal_columns(s.qd[::d], temp[::d], t_ref, band))
    return ThermalData(fit_rows, test_rows, t_ref)
