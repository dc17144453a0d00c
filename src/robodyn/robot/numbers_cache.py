"""``load_numbers``: a robot description's numbers, cached by the content of its file.

The first load of a description (a built-in name, a YAML or URDF file) goes through
:func:`robodyn.robot.load.load` (SymPy) and writes the numbers calibration needs
(:class:`~robodyn.robot.numbers.RobotNumbers`) to ``rd_robot_<hash>.json`` in robodyn's cache
folder (:func:`robodyn.cache.cache_dir`). Later loads of the same content read that file and
import no SymPy. The hash covers the description file's bytes, where it came from, the ``tool``
and ``locked`` arguments, the entry format and the source of the loader itself (the ``robodyn.robot``
package's modules): an edited description, another tool link or a changed loader is loaded in
full again. The warnings the full load gave (implausible inertia, say) are stored with the numbers
and given again on every load from the cache.

A cache entry that cannot be read (truncated, edited, another format) is ignored and written
again; a cache folder that cannot be written only costs the speed-up.
"""

from __future__ import annotations

import builtins
import dataclasses
import functools
import hashlib
import json
import math
import os
import tempfile
import warnings
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robodyn.cache import cache_dir
from robodyn.robot import errors
from robodyn.robot.corrections import corrections_from_plain
from robodyn.robot.load import _LIBRARY, ALIASES, builtin_names, load
from robodyn.robot.numbers import RobotNumbers, robot_numbers

if TYPE_CHECKING:
    from collections.abc import Callable

    from robodyn.robot.model import Robot

__all__ = ["ENTRY_FORMAT", "load_numbers", "numbers_key"]

#: Version of the cache entry's layout (part of the key).
ENTRY_FORMAT = 1

#: The arrays of an entry, in the order of :class:`RobotNumbers`' fields.
_ARRAYS = ("base", "pres", "axes", "posts", "tool", "lower", "upper", "gear_ratios", "masses", "coms",
           "gravity")


@functools.cache
def _loader_digest() -> str:
    """SHA-256 of the ``robodyn.robot`` package's modules (what turns a file into a robot)."""
    h = hashlib.sha256()
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


def _description(source: str | Path) -> tuple[str, bytes] | None:
    """Where a description comes from and its bytes; None for a name that is neither a built-in
    nor an existing file (the full load then says why)."""
    text = str(source)
    text = ALIASES.get(text, text)
    if text in builtin_names():
        return f"builtin:{text}", (resources.files(_LIBRARY) / f"{text}.yaml").read_bytes()
    path = Path(text)
    if not path.is_file():
        return None
    return str(path.resolve()), path.read_bytes()


def numbers_key(origin: str, data: bytes, tool: str | None,
                locked: Mapping[str, float] | None = None) -> str:
    """The cache key (24 hex digits) of a description's bytes ``data`` read from ``origin``
    (with the load's ``tool`` and ``locked`` joints)."""
    h = hashlib.sha256()
    held = sorted((str(k), float(v)) for k, v in (locked or {}).items())
    for part in (str(ENTRY_FORMAT), _loader_digest(), origin, repr(tool), repr(held)):
        h.update(part.encode() + b"\0")
    h.update(data)
    return h.hexdigest()[:24]


def load_numbers(source: str | Path, *, tool: str | None = None,
                 locked: Mapping[str, float] | None = None) -> RobotNumbers:
    """A robot description's numbers, from robodyn's cache where its content was loaded before.

    Parameters
    ----------
    source : str or Path
        As :func:`robodyn.load`: a built-in name or a ``.yaml``/``.yml``/``.urdf`` file.
    tool : str, optional
        URDF only: the end-effector link (as :func:`robodyn.load`).
    locked : mapping of str to float, optional
        URDF only: joints held still (as :func:`robodyn.load`).

    Returns
    -------
    RobotNumbers
        Its :func:`~robodyn.robot.numbers.full_robot` is the loaded ``Robot`` (on a cache hit,
        loaded on first use, importing SymPy then).

    Raises
    ------
    DescriptionError, FileNotFoundError, InputError
        As :func:`robodyn.load` (on a cache miss: the full load raises them).
    """
    found = _description(source)
    entry = None
    if found is not None:
        entry = cache_dir(create=False) / f"rd_robot_{numbers_key(*found, tool, locked)}.json"
        numbers = _read(entry, _loader(source, tool, locked))
        if numbers is not None:
            return numbers
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load(source, tool=tool, locked=locked)
    given = [(w.category.__name__, str(w.message)) for w in caught]
    _warn(given)
    numbers = robot_numbers(robot)
    if entry is not None:
        _write(entry, numbers, given)
    return dataclasses.replace(numbers, loader=lambda: robot)  # this Robot, held


def _loader(source: str | Path, tool: str | None, locked: Mapping[str, float] | None
            ) -> Callable[[], Robot]:
    """The ``Robot`` of a cache hit: loaded on the first call only (its warnings were given when
    the numbers were read, so they are not given again)."""

    @functools.cache
    def robot() -> Robot:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return load(source, tool=tool, locked=locked)

    return robot


def _warn(given: list[tuple[str, str]]) -> None:
    """Give the load's warnings (category name, message) to the caller of :func:`load_numbers`."""
    for name, message in given:
        category = getattr(errors, name, None) or getattr(builtins, name, None)
        if not (isinstance(category, type) and issubclass(category, Warning)):
            category = UserWarning
        warnings.warn(message, category, stacklevel=3)


def _plain(numbers: RobotNumbers, given: list[tuple[str, str]]) -> dict[str, Any]:
    """An entry's JSON data (NaN limits as null)."""
    arrays = {k: getattr(numbers, k).tolist() for k in _ARRAYS}
    for k in ("lower", "upper"):
        arrays[k] = [None if math.isnan(v) else v for v in arrays[k]]
    corrections = None if numbers.corrections is None else \
        numbers.corrections.as_plain(numbers.joint_names)
    return {"format": ENTRY_FORMAT, "name": numbers.name, "source": numbers.source,
            "joint_names": list(numbers.joint_names), "joint_types": list(numbers.joint_types),
            "description_hash": numbers.description_hash, "corrections": corrections,
            "warnings": [list(w) for w in given], **arrays}


def _write(path: Path, numbers: RobotNumbers, given: list[tuple[str, str]]) -> None:
    """Write an entry atomically (a temporary file renamed into place); skip where the cache
    folder cannot be written."""
    text = json.dumps(_plain(numbers, given), allow_nan=False)
    try:
        folder = cache_dir()
        fd, tmp = tempfile.mkstemp(prefix=".rd_robot-", suffix=".json", dir=folder)
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except OSError:
        return


def _read(path: Path, loader: Any) -> RobotNumbers | None:
    """An entry as numbers (its warnings given again); None where missing or unreadable."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        if data.get("format") != ENTRY_FORMAT:
            return None
        names = tuple(data["joint_names"])
        arrays = {k: data[k] for k in _ARRAYS}
        for k in ("lower", "upper"):
            arrays[k] = [math.nan if v is None else float(v) for v in arrays[k]]
        corrections = None if data["corrections"] is None else \
            corrections_from_plain(data["corrections"], names, data["source"])
        numbers = RobotNumbers(name=data["name"], source=data["source"], joint_names=names,
                               joint_types=tuple(data["joint_types"]), corrections=corrections,
                               description_hash=data["description_hash"], loader=loader, **arrays)
        given = [(str(c), str(m)) for c, m in data["warnings"]]
    except (OSError, ValueError, KeyError, TypeError, errors.DescriptionError):
        return None
    _warn(given)
    return numbers
