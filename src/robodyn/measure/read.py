"""``read_recording``: one entry point for every recording format (dispatch by file name)."""

from __future__ import annotations

from collections.abc import Mapping
from os import PathLike
from pathlib import Path
from typing import Any

from robodyn.measure.recording import Recording
from robodyn.robot.errors import RecordingError

__all__ = ["read_recording"]


def read_recording(path: str | PathLike[str], spec: str | PathLike[str] | Mapping[str, Any] | None = None,
                   *, robot: Any = None, **options: Any) -> Recording:
    """Read a measured run from a file.

    Parameters
    ----------
    path : str or path
        ``.csv``/``.tsv``/``.txt`` (optionally ``.gz``) read through a recording spec, or
        ``.mcap``: a ROS 2 bag with ``sensor_msgs/msg/JointState`` messages (no spec needed).
    spec : str, path or mapping, optional
        Recording spec for CSV/TSV: a built-in name (``"kinova_gen3"``, ``"robodyn"``), a YAML
        file, or the spec as a dict (see ``docs/recording-spec.md``). None: the file must be in
        robodyn's own CSV layout (as written by :func:`robodyn.measure.csv_io.write_csv`).
    robot : Robot, optional
        Joints are matched by name to ``robot.joint_names`` and returned in chain order.
    **options
        Passed to the format's reader (MCAP: ``joint_topic``, ``tool_topic``).

    Returns
    -------
    Recording

    Raises
    ------
    RecordingError
        Unreadable or invalid file or spec; the message names the file, field/column, row and reason.
    FileNotFoundError
        No such file.
    """
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"{p}: no such file")
    suffixes = [s.lower() for s in p.suffixes]
    if suffixes and suffixes[-1] == ".mcap":
        if spec is not None:
            raise RecordingError(f"{p.name}: spec: an MCAP bag is read without a spec")
        from robodyn.measure.mcap_io import read_mcap

        return read_mcap(p, robot=robot, **options)
    if options:
        raise RecordingError(f"{p.name}: unexpected options for a CSV file: {', '.join(options)}")
    from robodyn.measure.csv_io import read_csv

    return read_csv(p, spec=spec, robot=robot)
