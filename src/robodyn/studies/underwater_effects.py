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
#: C_d of the sensitivity sweep: half, about the nominal and twice the subcritical
#: circular-cylinder value (:mod:`robodyn.studies.underwater_sensitivity`).
DEFAULT_CD_VALUES: tuple[float, ...] = (0.6, 1.2, 2.4)
#: Current speeds of the sensitivity sweep, m/s (still water to a strong tidal current).
DEFAULT_CURRENT_SPEEDS: tuple[float, ...] = (0.0, 0.5, 1.0)
