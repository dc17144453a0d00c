"""``load``: one entry point for built-in names, robodyn YAML files and URDF files."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from robodyn.robot.model import Robot

_LIBRARY = "robodyn.robot.library"


def builtin_names() -> list[str]:
    """Names of the robots shipped with robodyn (YAML files in ``robodyn/robot/library``)."""
    files = resources.files(_LIBRARY).iterdir()
    return sorted(f.name[:-5] for f in files if f.name.endswith(".yaml"))


def load(source: str | Path, *, strict: bool = False) -> Robot:
    """Load a robot description.

    Parameters
    ----------
    source : str or Path
        A built-in name (see :func:`builtin_names`), or a path to a ``.yaml``/``.yml`` robodyn
        description or a ``.urdf`` file.
    strict : bool
        Turn physical-plausibility warnings (inertia not positive definite, triangle inequality)
        into errors.

    Returns
    -------
    Robot
    """
    from robodyn.robot import urdf, yaml_loader

    text = str(source)
    if text in builtin_names():
        ref = resources.files(_LIBRARY) / f"{text}.yaml"
        return yaml_loader.load_yaml_text(ref.read_text(), source=f"builtin:{text}", strict=strict)
    path = Path(source)
    if not path.exists():
        raise FileNotFoundError(
            f"{text}: no such file, and not a built-in robot (built-ins: {', '.join(builtin_names())})"
        )
    suffix = path.suffix.lower()
    if suffix in (".yaml", ".yml"):
        return yaml_loader.load_yaml_file(path, strict=strict)
    if suffix == ".urdf":
        return urdf.load_urdf(path, strict=strict)
    raise ValueError(f"{path}: unknown description format {suffix!r} (expected .yaml, .yml or .urdf)")
