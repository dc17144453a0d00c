"""Study files: a YAML document naming the robot, the task, what varies and how it is sampled.

Layout (``examples/studies/aa300_sizing.yaml`` is a commented example)::

    task: actuator_sizing          # or calibration_monte_carlo, identification_monte_carlo,
                                   # underwater_effects
    robot: aa300                   # built-in name, or a description path relative to this file
    settings: {dt: 0.001}          # the task class's fixed options (see TASKS)
    parameters:                    # what varies, by name (the task's case parameters)
      payload: [0, 25, 50]         # a list: grid values (crossed with everything else)
      bandwidth_hz: {min: 2, max: 8}              # a range: sampled (needs 'sampler')
      zeta: {min: 0.7, max: 1.0, steps: 4}        # a range with steps: evenly spaced grid values
      gravity_compensation: true                  # one value: fixed for every case
    sampler: {kind: latin_hypercube, n: 20}       # or random; n points per grid combination
    repeat: 1                      # Monte Carlo: each case repeated with new seeds
    seed: 0
    batch: 50                      # cases per Dask task (optional)
    plot: {x: payload, y: bandwidth_hz, result: peak_torque.column}   # optional

Range options: ``log: true`` (log-uniform), ``integer: true`` (rounded). Every error names the file,
the field and the reason.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robodyn.robot.errors import StudyError
from robodyn.robot.safe_yaml import safe_yaml
from robodyn.studies.calibration_mc import CalibrationMonteCarlo
from robodyn.studies.cases import Grid, LatinHypercube, RandomSampler, Range, check_case_count
from robodyn.studies.identification_mc import IdentificationMonteCarlo
from robodyn.studies.models import RobotSource
from robodyn.studies.sizing import ActuatorSizing
from robodyn.studies.underwater_task import UnderwaterEffects

__all__ = ["TASKS", "Study", "read_study"]

#: Study-file task names and the task classes they build.
TASKS: Mapping[str, type] = {"actuator_sizing": ActuatorSizing,
                             "calibration_monte_carlo": CalibrationMonteCarlo,
                             "identification_monte_carlo": IdentificationMonteCarlo,
                             "underwater_effects": UnderwaterEffects}
_KEYS = ("task", "robot", "tool", "settings", "parameters", "sampler", "repeat", "seed", "batch", "plot")
_SAMPLERS: Mapping[str, Callable[..., Any]] = {"latin_hypercube": LatinHypercube, "random": RandomSampler}


@dataclass(frozen=True, eq=False)
class Study:
    """A study read from a file.

    Attributes
    ----------
    path : Path
    task : callable
        An instance of a :data:`TASKS` class (picklable).
    cases : Grid, LatinHypercube or RandomSampler
    seed : int
    batch : int or None
    varying : tuple of str
        Parameters that take more than one value (for figures).
    plot : mapping
        ``x``, ``y``, ``result`` for the figure (optional keys).
    """

    path: Path
    task: Any
    cases: Any
    seed: int
    batch: int | None
    varying: tuple[str, ...]
    plot: Mapping[str, str]


def _int(value: Any, where: str, low: int = 0) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise StudyError(f"{where}: expected an integer >= {low}, got {value!r}")
    return value


def _range(spec: Mapping[str, Any], where: str) -> Range | list[float]:
    unknown = set(spec) - {"min", "max", "steps", "log", "integer"}
    if unknown:
        raise StudyError(f"{where}: unknown key(s) {sorted(unknown)} (a range has min, max and "
                         "optionally steps, log, integer)")
    if "min" not in spec or "max" not in spec:
        raise StudyError(f"{where}: a range needs both min and max")
    r = Range(spec["min"], spec["max"], bool(spec.get("log", False)), bool(spec.get("integer", False)))
    r.check(where)
    if "steps" not in spec:
        return r
    steps = _int(spec["steps"], f"{where}.steps", 1)
    check_case_count(steps, f"{where}.steps")  # before its values are built
    # evenly spaced grid values (in log when log: true)
    values = r.scale(np.linspace(0.0, 1.0, steps)) if steps > 1 else np.array([r.low])
    return [int(v) if r.integer else float(v) for v in values]


def read_study(path: str | Path) -> Study:
    """Read and check a study file (module docstring); nothing runs yet.

    Raises
    ------
    StudyError
        Unknown keys, task or parameters; a range with min > max; a sampler missing or unused.
    FileNotFoundError
    """
    path = Path(path)
    name = str(path)
    data = _load_mapping(path)
    task = _task(data, path)
    params = data.get("parameters") or {}
    if not isinstance(params, dict) or not params:
        raise StudyError(f"{name}: parameters: expected a mapping of parameter name -> values or range")
    seed = _int(data.get("seed", 0), f"{name}: seed")
    repeat = _int(data.get("repeat", 1), f"{name}: repeat", 1)
    _check_declared_count(params, data.get("sampler"), repeat, name)
    grid, ranges, fixed = _split_parameters(params, task, name)
    if repeat > 1:
        grid["repeat"] = list(range(repeat))
    cases = _cases(data.get("sampler"), grid, ranges, fixed, seed, name)
    batch = data.get("batch")
    if batch is not None:
        batch = _int(batch, f"{name}: batch", 1)
    plot = data.get("plot") or {}
    if not isinstance(plot, dict) or set(plot) - {"x", "y", "result"}:
        raise StudyError(f"{name}: plot: expected a mapping with x, y and result")
    varying = tuple(k for k in params if k in ranges or len(grid.get(k, ())) > 1)
    if "repeat" in grid and "repeat" not in task.parameters():
        task = _Repeat(task)
    return Study(path, task, cases, seed, batch, varying, plot)


def _declared_sizes(params: Mapping[str, Any], sampler: Any, repeat: int) -> dict[str, int]:
    """The number of values each field declares, by field (``parameters.<name>`` for a list,
    ``parameters.<name>.steps`` for a range with steps, ``sampler.n`` when a range is sampled,
    ``repeat``), read from the file without building any of them; a malformed size counts 1
    (its field's own check reports it)."""
    sizes: dict[str, int] = {}
    sampled = False
    for key, value in params.items():
        if isinstance(value, list):
            sizes[f"parameters.{key}"] = len(value)
        elif isinstance(value, dict) and "steps" in value:
            steps = value["steps"]
            if isinstance(steps, int) and not isinstance(steps, bool) and steps > 1:
                sizes[f"parameters.{key}.steps"] = steps
        elif isinstance(value, dict):
            sampled = True
    n = sampler.get("n") if isinstance(sampler, dict) else None
    if sampled and isinstance(n, int) and not isinstance(n, bool) and n > 1:
        sizes["sampler.n"] = n
    if repeat > 1:
        sizes["repeat"] = repeat
    return sizes


def _check_declared_count(params: Mapping[str, Any], sampler: Any, repeat: int, name: str) -> None:
    """Refuse a study whose declared sizes multiply to more cases than the limit, before any
    list, grid value or sample point is built (``steps: 1e12`` was a 7 TiB allocation)."""
    sizes = _declared_sizes(params, sampler, repeat)
    count = math.prod(sizes.values())
    big = {k: v for k, v in sizes.items() if v > 1}
    fields = " times ".join(f"{k} = {v}" for k, v in big.items()) or "parameters"
    check_case_count(count, f"{name}: {fields}")


def _load_mapping(path: Path) -> dict[str, Any]:
    """The study file's top-level mapping, its keys and task name checked."""
    name = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise StudyError(f"{name}: not a UTF-8 text file") from None
    data = safe_yaml(text, name, StudyError)
    if not isinstance(data, dict):
        raise StudyError(f"{name}: expected a mapping with task, robot and parameters")
    unknown = [k for k in data if k not in _KEYS]
    if unknown:
        raise StudyError(f"{name}: unknown key {unknown[0]!r} (known: {', '.join(_KEYS)})")
    if data.get("task") not in TASKS:
        raise StudyError(f"{name}: task: expected one of {', '.join(TASKS)}, got {data.get('task')!r}")
    return data


def _task(data: Mapping[str, Any], path: Path) -> Any:
    """The task object built from ``task``, ``robot``, ``tool`` and ``settings``."""
    name = str(path)
    kind = data["task"]
    if "robot" not in data and kind == "actuator_sizing":
        raise StudyError(f"{name}: robot: missing (a built-in name or a description file)")
    settings = data.get("settings") or {}
    if not isinstance(settings, dict):
        raise StudyError(f"{name}: settings: expected a mapping of task options")
    kwargs = dict(settings)
    for key in ("q_start", "q_goal", "vmax", "amax"):
        if key in kwargs and isinstance(kwargs[key], list):
            kwargs[key] = tuple(kwargs[key])
    if "robot" in data:
        robot = str(data["robot"])
        target = robot if (path.parent / robot).suffix == "" else str(path.parent / robot)
        try:
            kwargs["robot"] = RobotSource.of(target, data.get("tool"))
        except (FileNotFoundError, StudyError) as exc:
            raise StudyError(f"{name}: robot: {exc}") from None
    try:
        return TASKS[kind](**kwargs)
    except TypeError as exc:
        raise StudyError(f"{name}: settings: {exc} (see the {TASKS[kind].__name__} options)") from None
    except StudyError as exc:
        raise StudyError(f"{name}: settings: {exc}") from None


def _split_parameters(params: Mapping[str, Any], task: Any, name: str
                      ) -> tuple[dict[str, list[Any]], dict[str, Range], dict[str, Any]]:
    """Parameters split into value lists (grid), ranges to sample and fixed values."""
    grid: dict[str, list[Any]] = {}
    ranges: dict[str, Range] = {}
    fixed: dict[str, Any] = {}
    for key, value in params.items():
        where = f"{name}: parameters.{key}"
        task.check_case({key: None}, where)
        if isinstance(value, list):
            if not value:
                raise StudyError(f"{where}: empty list of values")
            grid[key] = value
        elif isinstance(value, dict):
            r = _range(value, where)
            if isinstance(r, Range):
                ranges[key] = r
            else:
                grid[key] = r
        else:
            fixed[key] = value
    return grid, ranges, fixed


def _cases(sampler: Any, grid: dict[str, list[Any]], ranges: dict[str, Range],
           fixed: dict[str, Any], seed: int, name: str) -> Any:
    """The case set: a sampler over the ranges (crossed with the grid), or the plain grid."""
    combos = math.prod(len(v) for v in grid.values())
    if not ranges:
        if sampler is not None:
            raise StudyError(f"{name}: sampler: given but no parameter is a range to sample")
        check_case_count(combos, f"{name}: parameters: a grid over {', '.join(grid) or 'nothing'}")
        return Grid({**{k: [v] for k, v in fixed.items()}, **grid})
    if not isinstance(sampler, dict) or "n" not in sampler:
        raise StudyError(f"{name}: sampler: ranges {sorted(ranges)} need a sampler "
                         "{kind: latin_hypercube | random, n: N}")
    skind = sampler.get("kind", "latin_hypercube")
    if skind not in _SAMPLERS:
        raise StudyError(f"{name}: sampler.kind: expected latin_hypercube or random, got {skind!r}")
    n = _int(sampler["n"], f"{name}: sampler.n", 1)
    check_case_count(n * combos, f"{name}: sampler.n = {n}" + (f" times a grid of {combos}" if grid else ""))
    return _SAMPLERS[skind](ranges, n=n, seed=seed, fixed=fixed, grid=grid)


@dataclass(frozen=True)
class _Repeat:
    """A task that ignores the ``repeat`` counter (each repetition differs only by its seed)."""

    task: Any

    def parameters(self) -> tuple[str, ...]:
        return (*self.task.parameters(), "repeat")

    def __call__(self, case: Mapping[str, Any]) -> Any:
        return self.task({k: v for k, v in case.items() if k != "repeat"})

    def compiled_models(self, cases: Sequence[Mapping[str, Any]]) -> list[Any]:
        """The task's compiled models, if it lists them (:mod:`robodyn.studies.shipping`)."""
        listed = getattr(self.task, "compiled_models", None)
        if listed is None:
            return []
        return list(listed([{k: v for k, v in c.items() if k != "repeat"} for c in cases]))

