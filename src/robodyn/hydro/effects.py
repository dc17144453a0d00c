"""Names of the underwater effect series (light: the command line reads them for its help)."""

from __future__ import annotations

from collections.abc import Mapping

#: The series, in order: each variant adds one effect to the one before.
EFFECTS: tuple[str, ...] = ("dry", "buoyancy", "added_mass", "drag", "lift", "current")
LABELS: Mapping[str, str] = {
    "dry": "dry (in air)", "buoyancy": "+ buoyancy", "added_mass": "+ added mass",
    "drag": "+ drag", "lift": "+ lift", "current": "+ current",
}
#: Current of the ``current`` variant when neither the call nor the description gives one:
#: 0.5 m/s along base x (a moderate tidal current), ASSUMED.
DEFAULT_CURRENT: tuple[float, float, float] = (0.5, 0.0, 0.0)
