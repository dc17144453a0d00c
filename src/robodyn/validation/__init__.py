"""Validation of a dynamic model against measured data (thesis ch. 5).

``rd.validate(robot, recording)`` compares the model's predicted torque or motor current with the
measured one (per joint RMS, maximum, relative error, NRMSE), simulates short windows from the
measured state under the measured torque (drift per window), and estimates the target's noise
floor and the residual spectra. :mod:`robodyn.validation.figures` draws the result.
"""

from robodyn.validation.heldout import (
    REFERENCE_CUTOFF_HZ,
    HeldOutError,
    format_held_out,
    held_out_error,
    reference_filter,
)
from robodyn.validation.metrics import ErrorMetrics, error_metrics
from robodyn.validation.spectra import NoiseFloor, ResidualSpectra, noise_floor, residual_spectra
from robodyn.validation.validation import Validation, validate
from robodyn.validation.windows import WindowDrift, simulate_windows

__all__ = ["REFERENCE_CUTOFF_HZ", "ErrorMetrics", "HeldOutError", "NoiseFloor", "ResidualSpectra",
           "Validation", "WindowDrift", "error_metrics", "format_held_out", "held_out_error",
           "noise_floor", "reference_filter", "residual_spectra", "simulate_windows", "validate"]
