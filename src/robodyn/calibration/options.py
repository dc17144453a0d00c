"""The choices of a kinematic calibration other than its data, in one checked object.

:func:`robodyn.calibrate` takes them as keywords (and builds a :class:`CalibrateOptions`) or as
``options=CalibrateOptions(...)``; the calibration keeps the set it ran with (``cal.options``).
The checks of each field and of their combinations live here, once.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from robodyn.calibration.models import MODELS
from robodyn.calibration.solve import LOSSES
from robodyn.robot.errors import InputError

__all__ = ["CalibrateOptions"]


@dataclass(frozen=True, eq=False)
class CalibrateOptions:
    """The choices of :func:`robodyn.calibrate` (keywords of the same names).

    Attributes
    ----------
    model : {"s-model", "hayati", "dh", "poe"}
        The error model (:mod:`robodyn.calibration.models`).
    sigma : float or array_like, shape (N,) or (N, 3)
        Standard uncertainty of each measured coordinate, m (0.05 mm by default).
    loss : {"linear", "huber", "soft_l1", "cauchy", "arctan"}
        Robust loss (on weighted residuals, in units of sigma, scaled by ``loss_scale``).
    initial : {"nominal", "circle-point"}
        Start from the nominal geometry, or from circle-point analysis of ``circle_data``.
    sigma_rot : float
        Standard uncertainty of a measured orientation, rad.
    loss_scale : float
    parallel_tol : float
        Nominal consecutive axes closer than this to parallel (rad) get Hayati's link.
    max_nfev : int, optional
        Most residual evaluations of the final fit.
    nongeometric : sequence of {"compliance", "harmonics"}
        Non-geometric joint errors identified with the geometry
        (:mod:`robodyn.calibration.nongeometric`).
    payload : (float, sequence of float), optional
        Known payload for the compliance torques: mass (kg) and centre of mass in the tool frame (m).
    identify_payload : bool
        Estimate the payload with the compliances (``payload`` is then the starting value).
    length_unit : {"m", "mm"}
        Unit of ``points`` and ``sigma``.
    angle_unit : {"rad", "deg"}
        Unit of the revolute joints' readings and of ``sigma_rot``.
    deflection : {"linear", "exact"}
        Compliance model: the holding torque at the readings, or the static equilibrium at the
        deflected pose (:mod:`robodyn.numeric.deflection`).

    Raises
    ------
    InputError
        On construction: a value outside its choices, or options that do not go together.
    """

    model: str = "s-model"
    sigma: Any = 5e-5
    loss: str = "linear"
    initial: str = "nominal"
    sigma_rot: float = 1e-4
    loss_scale: float = 3.0
    parallel_tol: float = math.radians(1.0)
    max_nfev: int | None = None
    nongeometric: Sequence[str] = ()
    payload: tuple[float, Sequence[float]] | None = None
    identify_payload: bool = False
    length_unit: str = "m"
    angle_unit: str = "rad"
    deflection: str = "linear"

    def __post_init__(self) -> None:
        if self.model not in MODELS:
            raise InputError(f"unknown error model {self.model!r}; choose one of {', '.join(MODELS)}")
        if self.loss not in LOSSES:
            raise InputError(f"unknown loss {self.loss!r}; choose one of {', '.join(LOSSES)}")
        if self.initial not in ("nominal", "circle-point"):
            raise InputError(f"initial must be 'nominal' or 'circle-point', got {self.initial!r}")
        if isinstance(self.nongeometric, str):
            raise InputError(f"nongeometric: expected a sequence of terms, got the text "
                             f"{self.nongeometric!r} (write ({self.nongeometric!r},))")
        terms = tuple(self.nongeometric)
        if (self.identify_payload or self.payload is not None) and "compliance" not in terms:
            raise InputError(f"{'identify_payload' if self.identify_payload else 'payload'} needs the "
                             "'compliance' term (nongeometric=('compliance', ...)): the payload is seen "
                             "only through the joints' deflection under its weight")
        if self.deflection not in ("linear", "exact"):
            raise InputError(f"deflection must be 'linear' or 'exact', got {self.deflection!r}")
        if self.deflection == "exact" and "compliance" not in terms:
            raise InputError("deflection='exact' needs the 'compliance' term (nongeometric=('compliance', "
                             "...)): it changes how the joints deflect under their load")
        for name in ("sigma_rot", "loss_scale", "parallel_tol"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float | np.floating) or not v > 0 \
                    or not math.isfinite(v):
                raise InputError(f"{name} must be a positive number, got {v!r}")
