"""Errors and warnings raised while reading robot descriptions (YAML, URDF, built-ins)."""

from __future__ import annotations

__all__ = [
    "DataFileError",
    "RecordingError",
    "RecordingWarning",
    "RobodynError",
    "DescriptionError",
    "DescriptionWarning",
    "IdentificationError",
    "InputError",
    "MissingExtraError",
    "SimulationError",
    "SingularMassMatrixError",
    "StudyError",
    "ValidationError",
]


class RobodynError(Exception):
    """Base of every error robodyn raises about its input: catch this to handle them all.

    Each subclass is also a :class:`ValueError` (bad input), as before, except
    :class:`MissingExtraError` (an optional package not installed), an :class:`ImportError`.
    """


class InputError(RobodynError, ValueError):
    """An argument a robodyn function cannot use (a shape, a range, an unknown name or option).

    The message names the argument and the reason. The command line reports it as bad input
    (exit 2); anything that is not a :class:`RobodynError` is a bug (exit 1).
    """


class DescriptionError(RobodynError, ValueError):
    """A robot description is malformed or physically impossible.

    The message always names where the problem is (file and field path, e.g.
    ``"arm.yaml: joints[2].link.mass"``) and why it is a problem.
    """


class DescriptionWarning(UserWarning):
    """A robot description is readable but physically implausible.

    Raised as :class:`DescriptionError` instead when a loader runs with ``strict=True``.
    """


class ValidationError(RobodynError, ValueError):
    """Measured data cannot be compared with a robot's model.

    Raised by :func:`robodyn.validation`: the message names the recording (its source file), the
    field or joint, the row where one matters, and the reason (joints that do not match the
    robot, a missing target signal, too few samples, values that are not finite).
    """


class RecordingError(RobodynError, ValueError):
    """Measured data (a recording file, a recording spec or arrays) is malformed.

    The message names the file (or ``Recording``), the field or column, the row or line where
    known, and the reason, e.g. ``"run.csv: column 'Position3' (position.columns[2]): NaN at
    line 17"``.
    """


class RecordingWarning(UserWarning):
    """Measured data is readable but suspicious (e.g. gaps in the time stamps)."""


class SimulationError(RobodynError, FloatingPointError, ValueError):
    """A simulation (or a forward-dynamics call) stopped being finite.

    A ``FloatingPointError`` (what the integrators always raised) and a ``ValueError`` (what the
    command line reports as bad input, exit 2). The message says when it happened and what to
    change.
    """


class SingularMassMatrixError(SimulationError):
    """The joint-space mass matrix is singular (a joint moves no mass, inertia or rotor), so the
    forward dynamics has no solution. The message names the robot and the joint."""


class IdentificationError(RobodynError, ValueError):
    """Measured data cannot be used to identify a robot's parameters, or an estimator failed.

    Raised by :func:`robodyn.identification`: the message names the recording (its source file), the
    field or joint, the row where one matters, and the reason (joints that do not match the
    robot, too few samples for the parameters, values that are not finite, an infeasible or
    failed semidefinite program).
    """


class StudyError(RobodynError, ValueError):
    """A parameter study (``rd.sweep`` or a study file) cannot run as given.

    The message names the study file and field where one applies (e.g. ``"study.yaml:
    parameters.payload: min 50 > max 10"``), the task or case, and the reason (an unknown
    parameter, an empty or reversed range, a task that cannot be sent to Dask workers, a
    scheduler that cannot be reached).
    """


class DataFileError(RobodynError, ValueError):
    """A data table (calibration poses, ISO 9283 cycles, approach records) cannot be read.

    Raised by :func:`robodyn.calibration.io.read_table` and the readers built on it: the message
    names the file, the line (1-based, as an editor counts) and the column where known, and the
    reason (not a UTF-8 text file, a row with more or fewer values than the header, a missing or
    repeated column, a value that is not a finite number).
    """



class MissingExtraError(RobodynError, ImportError):
    """A feature needs an optional dependency that is not installed; the message names the
    pip extra that installs it (:mod:`robodyn.extras`)."""
