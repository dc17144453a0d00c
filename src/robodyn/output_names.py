"""Output file names built from user text (``--stem``, a robot's name) stay inside the folder.

A stem is one plain file-name component: not empty, no path separator (``/``, and ``\\`` on every
platform, so that a Windows path given on Linux is refused too), not ``.`` or ``..``, no control
characters, at most 200 characters. ``--stem ../../x`` or an absolute path would otherwise write
outside the output folder given with ``-o``.
"""

from __future__ import annotations

from pathlib import Path

from robodyn.robot.errors import InputError

__all__ = ["MAX_STEM_LENGTH", "check_stem", "output_path"]

#: Longest stem accepted, characters (file systems allow 255 bytes per name, suffixes included).
MAX_STEM_LENGTH = 200


def check_stem(stem: str, *, what: str = "--stem") -> str:
    """Return ``stem`` when it is one plain file-name component; raise otherwise.

    Parameters
    ----------
    stem : str
        The file-name stem (without suffix).
    what : str
        Where the stem came from, for the message (an option, or e.g. ``"robot name"``).

    Returns
    -------
    str
        ``stem`` unchanged.

    Raises
    ------
    ValueError
        Naming ``what``, the stem and the reason.
    """
    reason = None
    if not isinstance(stem, str) or not stem.strip():
        reason = "it is empty"
    elif "/" in stem or "\\" in stem:
        reason = "it contains a path separator; give only a file name (the folder is -o)"
    elif stem in (".", ".."):
        reason = "it names a folder, not a file"
    elif any(ord(c) < 32 or ord(c) == 127 for c in stem):
        reason = "it contains control characters"
    elif len(stem) > MAX_STEM_LENGTH:
        reason = f"it is {len(stem)} characters long (at most {MAX_STEM_LENGTH})"
    if reason is not None:
        raise InputError(f"{what} {stem!r} is not a plain file name: {reason}")
    return stem


def output_path(directory: str | Path, stem: str, suffix: str, *, what: str = "--stem") -> Path:
    """``directory / (stem + suffix)``, refused unless it lies directly inside ``directory``.

    Parameters
    ----------
    directory : str or Path
        The output folder.
    stem : str
        Checked with :func:`check_stem`.
    suffix : str
        Appended as given (e.g. ``"_report.json"``, ``".yaml"``).
    what : str
        Where the stem came from, for the message.

    Returns
    -------
    Path

    Raises
    ------
    ValueError
        The stem is not a plain file name.
    """
    path = Path(directory) / (check_stem(stem, what=what) + suffix)
    if path.parent != Path(directory) or path.name != stem + suffix:
        raise InputError(f"{what} {stem!r} does not name a file inside {directory}")
    return path
