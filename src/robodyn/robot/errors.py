"""Errors and warnings raised while reading robot descriptions (YAML, URDF, built-ins)."""

from __future__ import annotations

__all__ = ["DescriptionError", "DescriptionWarning", "IdentificationError", "ValidationError"]


class DescriptionError(ValueError):
    """A robot description is malformed or physically impossible.

    The message always names where the problem is (file and field path, e.g.
    ``"arm.yaml: joints[2].link.mass"``) and why it is a problem.
    """


class DescriptionWarning(UserWarning):
    """A robot description is readable but physically implausible.

    Raised as :class:`DescriptionError` instead when a loader runs with ``strict=True``.
    """


class ValidationError(ValueError):
    """Measured data cannot be compared with a robot's model.

    Raised by :func:`robodyn.validate`: the message names the recording (its source file), the
    field or joint, the row where one matters, and the reason (joints that do not match the
    robot, a missing target signal, too few samples, values that are not finite).
    """


class IdentificationError(ValueError):
    """Measured data cannot be used to identify a robot's parameters, or an estimator failed.

    Raised by :func:`robodyn.identify`: the message names the recording (its source file), the
    field or joint, the row where one matters, and the reason (joints that do not match the
    robot, too few samples for the parameters, values that are not finite, an infeasible or
    failed semidefinite program).
    """
