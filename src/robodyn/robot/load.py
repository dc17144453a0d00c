"""``load``: one entry point for built-in names, robodyn YAML files and URDF files.

Built-in robots carry their published data unchanged, including two documented quirks that the
plausibility check of user files flags (see :data:`KNOWN_PROPERTIES`): loading a built-in does
not warn about those, and still warns (or raises under ``strict``) about anything else.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING

from robodyn.robot.errors import DescriptionError, DescriptionWarning, InputError

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["ALIASES", "KNOWN_PROPERTIES", "builtin_names", "load"]

_LIBRARY = "robodyn.robot.library"

#: Other names of built-in robots (the name a publication uses -> the built-in's file name).
ALIASES: Mapping[str, str] = MappingProxyType({"underwater_2link": "underwater_2r"})

#: Documented properties of the built-ins' published inertial data, by built-in and link name:
#: the failed plausibility condition (as worded in the warning). puma560 and puma560_akb: link
#: 1's inertia is its axis term only (the others never enter the dynamics) and puma560's link 3
#: is kept as published (ixx + izz < iyy) so the model matches the Robotics Toolbox (see the
#: comments in puma560.yaml and puma560_akb.yaml); kinova_gen3: the manufacturer's shoulder-link
#: inertia as given in gen3.urdf.
KNOWN_PROPERTIES: Mapping[str, Mapping[str, str]] = MappingProxyType({
    "puma560": MappingProxyType({"link1": "triangle inequality", "link3": "triangle inequality"}),
    "puma560_akb": MappingProxyType({"link1": "triangle inequality"}),
    "kinova_gen3": MappingProxyType({"shoulder_link": "triangle inequality"}),
})


def builtin_names() -> list[str]:
    """Names of the robots shipped with robodyn (YAML files in ``robodyn/robot/library``)."""
    files = resources.files(_LIBRARY).iterdir()
    return sorted(f.name[:-5] for f in files if f.name.endswith(".yaml"))


def load(source: str | Path, *, strict: bool = False, tool: str | None = None,
         locked: Mapping[str, float] | None = None) -> Robot:
    """Load a robot description.

    Parameters
    ----------
    source : str or Path
        A built-in name (see :func:`builtin_names`; or one of :data:`ALIASES`), or a path to a
        ``.yaml``/``.yml`` robodyn description or a ``.urdf`` file.
    strict : bool
        Turn physical-plausibility warnings (inertia not positive definite, triangle inequality,
        singular mass matrix) into errors. The documented properties of the built-ins
        (:data:`KNOWN_PROPERTIES`) are not reported either way.
    tool : str, optional
        URDF only: the link whose frame is the end effector (``Robot.tool``, the pose
        ``model.forward_kinematics`` returns), e.g. ``"tool0"``; see
        :func:`robodyn.robot.urdf.load_urdf` for the default.
    locked : mapping of str to float, optional
        URDF only: moving joints held still at these positions (rad, or m for a prismatic
        joint) and treated as fixed, e.g. ``{"finger_joint1": 0.04}`` for a gripper's fingers
        (a ``<mimic>`` joint follows the joint it mimics): the robot's joints are the others.

    Returns
    -------
    Robot

    Raises
    ------
    DescriptionError
        The description is invalid (the message names the file, field and reason), or ``tool``
        or ``locked`` is given for a description that is not a URDF file.
    FileNotFoundError
        ``source`` is neither a built-in name nor an existing file.
    """
    from robodyn.robot import validation, yaml_loader

    text = str(source)
    if text in ALIASES:
        source = text = ALIASES[text]
    path = Path(source)
    suffix = path.suffix.lower()
    if locked and (text in builtin_names() or suffix != ".urdf"):
        raise DescriptionError(
            f"{text}: locked= holds joints of a URDF file still; this description is not one "
            "(remove the joints from a robodyn YAML file instead)"
        )
    if tool is not None and (text in builtin_names() or suffix != ".urdf"):
        raise DescriptionError(
            f"{text}: tool={tool!r} selects a link of a URDF file; this description's tool "
            "frame is set in the description itself ('tool' in a robodyn YAML file)"
        )
    if text in builtin_names():
        return _load_builtin(text, strict=strict)
    if not path.exists():
        raise FileNotFoundError(
            f"{text}: no such file, and not a built-in robot (built-ins: {', '.join(builtin_names())})"
        )
    if suffix in (".yaml", ".yml"):
        robot = yaml_loader.load_yaml_file(path, strict=strict)
        validation.check_mass_matrix(robot, where=str(path), strict=strict)
        return robot
    if suffix == ".urdf":
        from robodyn.robot import urdf  # yourdfpy and trimesh: only for URDF files

        return urdf.load_urdf(path, strict=strict, tool=tool, locked=locked)
    raise InputError(f"{path}: unknown description format {suffix!r} (expected .yaml, .yml or .urdf)")


def _load_builtin(name: str, *, strict: bool) -> Robot:
    """A built-in robot; warnings other than its :data:`KNOWN_PROPERTIES` pass through."""
    from robodyn.robot import validation, yaml_loader

    ref = resources.files(_LIBRARY) / f"{name}.yaml"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DescriptionWarning)
        robot = yaml_loader.load_yaml_text(ref.read_text(), source=f"builtin:{name}", strict=False)
        validation.check_mass_matrix(robot, where=f"builtin:{name}", strict=False)
    known = KNOWN_PROPERTIES.get(name, {})
    for w in caught:
        message = str(w.message)
        if issubclass(w.category, DescriptionWarning) and any(
            f"link {link!r}:" in message and condition in message
            for link, condition in known.items()
        ):
            continue
        if strict and issubclass(w.category, DescriptionWarning):
            raise DescriptionError(message + " (strict mode)")
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return robot
