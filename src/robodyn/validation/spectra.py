"""Residual spectra and the noise floor of a measured target."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import welch

__all__ = ["NoiseFloor", "ResidualSpectra", "noise_floor", "residual_spectra"]


@dataclass(frozen=True, eq=False)
class ResidualSpectra:
    """Welch power spectral densities per joint (arrays read-only).

    Attributes
    ----------
    frequency : (F,) ndarray
        Hz.
    residual : (F, n) ndarray
        PSD of ``predicted - measured``, unit^2 / Hz.
    noise : (F, n) ndarray
        PSD of ``measured - filtered(measured)`` (the noise-floor estimate), unit^2 / Hz.
    """

    frequency: np.ndarray
    residual: np.ndarray
    noise: np.ndarray


def residual_spectra(residual: np.ndarray, noise: np.ndarray, dt: float) -> ResidualSpectra:
    """Welch PSDs (Hann windows of up to 256 samples, 50 % overlap) of the residual and the noise.

    Parameters
    ----------
    residual, noise : (N, n) array_like
        ``predicted - measured`` and ``measured - filtered``, one column per joint.
    dt : float
        Sample period, s (irregular stamps: their median).

    Returns
    -------
    ResidualSpectra
    """
    residual = np.asarray(residual, dtype=float)
    noise = np.asarray(noise, dtype=float)
    nperseg = min(256, residual.shape[0])
    has = ~np.all(np.isnan(residual), axis=0)  # joints without a measurement give NaN
    freq, p = welch(residual[:, has], fs=1.0 / dt, nperseg=nperseg, axis=0)
    _, pn = welch(noise[:, has], fs=1.0 / dt, nperseg=nperseg, axis=0)
    p_res = np.full((len(freq), residual.shape[1]), np.nan)
    p_noise = np.full_like(p_res, np.nan)
    p_res[:, has], p_noise[:, has] = p, pn
    out = ResidualSpectra(freq, p_res, p_noise)
    for arr in (out.frequency, out.residual, out.noise):
        arr.flags.writeable = False
    return out


@dataclass(frozen=True, eq=False)
class NoiseFloor:
    """What a perfect model of the filtered signal would still miss (arrays read-only).

    The noise is estimated as the measured target minus its zero-phase low-pass filtered
    version: a model that predicted the filtered signal exactly would show this error.

    Attributes
    ----------
    cutoff : float
        Low-pass cut-off frequency used, Hz.
    rms : (n,) ndarray
        RMS of ``raw - filtered`` per joint, in the target's unit.
    relative : (n,) ndarray
        ``||raw - filtered|| / ||raw||`` per joint: the lowest relative error a model can reach
        against the raw target (NaN where the target is identically zero).
    total_relative : float
        The same over all joints together.
    """

    cutoff: float
    rms: np.ndarray
    relative: np.ndarray
    total_relative: float


def noise_floor(raw: np.ndarray, filtered: np.ndarray, cutoff: float) -> NoiseFloor:
    """Noise floor of ``raw`` given its low-pass filtered version.

    Parameters
    ----------
    raw, filtered : (N, n) array_like
    cutoff : float
        The filter's cut-off frequency, Hz (recorded in the result).

    Returns
    -------
    NoiseFloor
    """
    raw = np.asarray(raw, dtype=float)
    noise = raw - np.asarray(filtered, dtype=float)
    norm = np.linalg.norm(raw, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        # relative_j = ||y_j - lowpass(y_j)|| / ||y_j||
        relative = np.where(norm > 0, np.linalg.norm(noise, axis=0) / norm, np.nan)
    has = ~np.all(np.isnan(raw), axis=0)  # joints with this sensor
    total = float(np.linalg.norm(raw[:, has]))
    out = NoiseFloor(float(cutoff), np.sqrt(np.mean(noise**2, axis=0)), relative,
                     float(np.linalg.norm(noise[:, has])) / total if total > 0 else float("nan"))
    for arr in (out.rms, out.relative):
        arr.flags.writeable = False
    return out
