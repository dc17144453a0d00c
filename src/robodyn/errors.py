"""robodyn's errors and warnings in one place: ``except robodyn.errors.RobodynError`` catches every
error robodyn raises about its input (a description, a recording, a study file, a simulation that
cannot run). Each is also a :class:`ValueError`.

They are declared in :mod:`robodyn.robot.errors` (the lowest layer, so that every package can
raise them) and re-exported here.
"""

from __future__ import annotations

from robodyn.robot.errors import (
    DataFileError,
    DescriptionError,
    DescriptionWarning,
    IdentificationError,
    InputError,
    MissingExtraError,
    RecordingError,
    RecordingWarning,
    RobodynError,
    SimulationError,
    SingularMassMatrixError,
    StudyError,
    ValidationError,
)

__all__ = ["DataFileError", "DescriptionError", "DescriptionWarning", "IdentificationError",
           "InputError", "MissingExtraError", "RecordingError", "RecordingWarning", "RobodynError",
           "SimulationError", "SingularMassMatrixError", "StudyError", "ValidationError"]
