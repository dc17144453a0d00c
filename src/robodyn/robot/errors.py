"""Errors and warnings raised while reading robot descriptions (YAML, URDF, built-ins)."""

from __future__ import annotations

__all__ = ["DescriptionError", "DescriptionWarning"]


class DescriptionError(ValueError):
    """A robot description is malformed or physically impossible.

    The message always names where the problem is (file and field path, e.g.
    ``"arm.yaml: joints[2].link.mass"``) and why it is a problem.
    """


class DescriptionWarning(UserWarning):
    """A robot description is readable but physically implausible.

    Raised as :class:`DescriptionError` instead when a loader runs with ``strict=True``.
    """
