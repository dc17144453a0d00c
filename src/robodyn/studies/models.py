"""Robots and compiled models on study workers: sent as description text, built once per process.

A study task carries a :class:`RobotSource` (the description's text and where it came from), never
a loaded robot or a cffi library: those do not pickle and would be rebuilt for every case. On a
worker, :func:`robot_of` parses the text once per process and :func:`model_of` compiles (or loads
from robodyn's content-hash cache, ``rd.compile_model``) once per process and
``(description, payload, parameter values, backend)``; every later case on that worker reuses it.
On a cluster without a shared file system each worker fills its own cache once, unless the
sweep ships the models: a task that lists the models its cases need (a method
``compiled_models(cases) -> list of ModelSpec``) has them built here and sent to the workers with
the tasks (:mod:`robodyn.studies.shipping`).
"""

from __future__ import annotations

import hashlib
import tempfile
import warnings
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import NamedTuple

from robodyn.numeric.model import Model, compile_model
from robodyn.robot.errors import StudyError
from robodyn.robot.load import builtin_names
from robodyn.robot.model import Robot

__all__ = ["ModelSpec", "RobotSource", "model_of", "robot_of"]

#: Compiled models kept per worker process (least recently used dropped beyond it).
MODELS_PER_PROCESS = 64


@dataclass(frozen=True)
class RobotSource:
    """A robot description as text, cheap to pickle and hash.

    Attributes
    ----------
    name : str
        Built-in name or the file it was read from (for messages).
    text : str
        The YAML or URDF document.
    format : {"yaml", "urdf"}
    tool : str or None
        URDF only: the end-effector link.
    """

    name: str
    text: str
    format: str = "yaml"
    tool: str | None = None

    @classmethod
    def of(cls, source: str | Path, tool: str | None = None) -> RobotSource:
        """Read a built-in name or a ``.yaml``/``.yml``/``.urdf`` file (as ``rd.load`` does)."""
        text = str(source)
        if text in builtin_names():
            ref = resources.files("robodyn.robot.library") / f"{text}.yaml"
            return cls(text, ref.read_text(encoding="utf-8"), "yaml", tool)
        path = Path(source)
        suffix = path.suffix.lower()
        if suffix not in (".yaml", ".yml", ".urdf"):
            raise StudyError(f"{text}: not a built-in robot and not a .yaml/.yml/.urdf file "
                             f"(built-ins: {', '.join(builtin_names())})")
        if not path.is_file():
            raise FileNotFoundError(f"{text}: no such file, and not a built-in robot")
        return cls(str(path), path.read_text(encoding="utf-8"), "urdf" if suffix == ".urdf" else "yaml",
                   tool)

    @property
    def digest(self) -> str:
        """SHA-256 of format, tool and text (the per-process memo key)."""
        return hashlib.sha256(repr((self.format, self.tool, self.text)).encode()).hexdigest()


@lru_cache(maxsize=16)
def _robot(source: RobotSource) -> Robot:
    from robodyn.robot import urdf, validation, yaml_loader

    with warnings.catch_warnings():
        # plausibility notes were shown when the study was set up; not once per worker
        warnings.simplefilter("ignore")
        if source.format == "urdf":
            with tempfile.TemporaryDirectory() as tmp:
                path = Path(tmp) / Path(source.name).name
                path.write_text(source.text, encoding="utf-8")
                return urdf.load_urdf(path, tool=source.tool)
        where = source.name if source.name not in builtin_names() else f"builtin:{source.name}"
        robot = yaml_loader.load_yaml_text(source.text, source=where)
        validation.check_mass_matrix(robot, where=where, strict=False)
        return robot


def robot_of(source: RobotSource) -> Robot:
    """The :class:`Robot` of ``source``, parsed once per process."""
    return _robot(source)


@lru_cache(maxsize=MODELS_PER_PROCESS)
def _model(source: RobotSource, payload: float, parameters: tuple[tuple[str, float], ...],
           backend: str) -> Model:
    from robodyn.studies.aa300 import with_payload

    robot = with_payload(robot_of(source), payload)
    return compile_model(robot, backend, parameters=dict(parameters) or None)  # type: ignore[arg-type]


def model_of(source: RobotSource, payload: float = 0.0,
             parameters: tuple[tuple[str, float], ...] = (), backend: str = "c") -> Model:
    """The compiled model of ``source`` with a tool payload (kg) and parameter values, once per process.

    Parameters
    ----------
    source : RobotSource
    payload : float
        Point mass at the tool point, kg (merged into the last link).
    parameters : tuple of (str, float)
        Values of the description's named parameters, sorted by name.
    backend : {"c", "numpy"}

    Returns
    -------
    Model
    """
    return _model(source, float(payload), tuple(sorted(parameters)), backend)


class ModelSpec(NamedTuple):
    """The arguments of :func:`model_of`: one compiled model a study task uses.

    Tasks list them in ``compiled_models(cases)`` so that a sweep can build the models once, here,
    and ship them to its workers (:mod:`robodyn.studies.shipping`).
    """

    source: RobotSource
    payload: float = 0.0
    parameters: tuple[tuple[str, float], ...] = ()
    backend: str = "c"

    def model(self) -> Model:
        """The model, through :func:`model_of` (once per process)."""
        return model_of(self.source, self.payload, self.parameters, self.backend)
