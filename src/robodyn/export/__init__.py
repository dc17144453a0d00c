"""Export a :class:`~robodyn.robot.model.Robot` to other tools' description formats.

* :func:`robodyn.export.urdf.to_urdf`: URDF (Pinocchio, ROS, robodyn's own loader);
* :func:`robodyn.export.mjcf.to_mjcf`: MuJoCo MJCF.

:func:`export` picks one by name (``"urdf"`` or ``"mjcf"``), for command-line front ends. What
each format keeps and drops is listed in ``docs/export.md`` and in each module's docstring.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from robodyn.export.mjcf import to_mjcf
from robodyn.export.urdf import to_urdf
from robodyn.robot.errors import InputError
from robodyn.robot.model import Robot

__all__ = ["FORMATS", "export", "to_mjcf", "to_urdf"]

#: Exporter of each format name.
FORMATS: dict[str, Callable[..., str]] = {"urdf": to_urdf, "mjcf": to_mjcf}


def export(robot: Robot, format: str, path: str | Path | None = None, **options: Any) -> str:
    """Export ``robot`` in the named format.

    Parameters
    ----------
    robot : Robot
    format : {"urdf", "mjcf"}
        Case-insensitive.
    path : str or Path, optional
        File to write as well.
    **options
        Keyword options of the format's exporter (``parameters``; for MJCF also ``timestep``
        and ``integrator``).

    Returns
    -------
    str
        The document text.

    Raises
    ------
    ValueError
        If the format is unknown (the message lists the known ones), or as the exporter raises.
    """
    key = str(format).lower()
    if key not in FORMATS:
        raise InputError(f"unknown export format {format!r}; choose one of {', '.join(FORMATS)}")
    return FORMATS[key](robot, path, **options)
