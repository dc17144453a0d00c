"""The cases of a parameter study: explicit lists, grids and samplers, each case with its own seed.

A study's cases are given as one of

* a list of dicts (``[{"payload": 0.0}, {"payload": 50.0}]``), run as given;
* a grid: a dict of lists (or :class:`Grid`), expanded as the product of its lists in the order
  of the keys, the last key varying fastest (like :func:`itertools.product`);
* a sampler (:class:`LatinHypercube` or :class:`RandomSampler`): ``n`` points drawn in ranges
  with :mod:`scipy.stats.qmc`, reproducible from its ``seed``; ``fixed`` values and a ``grid``
  can be crossed with the samples (every grid combination paired with every sample point).

Each case ``i`` of a study with seed ``s`` gets the seed ``case_seed(s, i)``, derived with
:class:`numpy.random.SeedSequence` from ``(s, i)`` alone: a case's random numbers never depend on
the number of workers, the batch size or which other cases run.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.stats import qmc

from robodyn.robot.errors import StudyError
from robodyn.robot.sizes import env_limit

__all__ = ["SEED_COLUMN", "Grid", "LatinHypercube", "RandomSampler", "Range", "case_seed",
           "expand_cases"]

#: Name of the per-case seed column added by :func:`expand_cases`.
SEED_COLUMN = "seed"


@dataclass(frozen=True)
class Range:
    """A sampled parameter's interval.

    Attributes
    ----------
    low, high : float
        Bounds, in the parameter's unit; ``low <= high``.
    log : bool
        Sample uniformly in ``log(value)`` (both bounds must be > 0).
    integer : bool
        Round each sample to the nearest integer (e.g. a pose count).
    """

    low: float
    high: float
    log: bool = False
    integer: bool = False

    def check(self, where: str) -> None:
        """Raise :class:`StudyError` naming ``where`` when the range is unusable."""
        for name, v in (("min", self.low), ("max", self.high)):
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise StudyError(f"{where}: {name} must be a finite number, got {v!r}")
        if self.low > self.high:
            raise StudyError(f"{where}: min {self.low:g} > max {self.high:g}")
        if self.log and self.low <= 0:
            raise StudyError(f"{where}: a log range needs min > 0, got {self.low:g}")

    def scale(self, u: np.ndarray) -> np.ndarray:
        """Map unit samples ``u`` (K,) in [0, 1) to values (K,) in the range."""
        if self.log:
            # log-uniform: exp(log a + u (log b - log a))
            lo, hi = math.log(self.low), math.log(self.high)
            v = np.exp(lo + u * (hi - lo))
        else:
            v = self.low + u * (self.high - self.low)
        return np.rint(v) if self.integer else v


def _as_range(value: Range | Sequence[float], where: str) -> Range:
    if isinstance(value, Range):
        r = value
    elif isinstance(value, Sequence) and not isinstance(value, str) and len(value) == 2:
        r = Range(value[0], value[1])
    else:
        raise StudyError(f"{where}: a range is (min, max) or robodyn.studies.Range, got {value!r}")
    r.check(where)
    return r


#: Default largest number of cases a study expands to (``$ROBODYN_MAX_CASES`` raises it): checked
#: before the cases are built, so that a grid of 10^9 combinations is refused in a millisecond
#: instead of filling the memory (a case dict costs about 1 kB; each case is also a task result).
MAX_CASES = 1_000_000


def check_case_count(count: int, where: str) -> None:
    """Refuse ``count`` cases above ``$ROBODYN_MAX_CASES`` (default :data:`MAX_CASES`)."""
    limit = env_limit("ROBODYN_MAX_CASES", MAX_CASES)
    if count > limit:
        raise StudyError(f"{where}: {count:.3g} cases, more than {limit:,} (fewer values or "
                         "sample points; or set ROBODYN_MAX_CASES)")


@dataclass(frozen=True)
class Grid:
    """The product of value lists, the last key varying fastest.

    Attributes
    ----------
    values : mapping of str to sequence
        Parameter name -> values (each list non-empty).
    """

    values: Mapping[str, Sequence[Any]]

    def cases(self) -> list[dict[str, Any]]:
        """The expanded cases, in product order."""
        names = list(self.values)
        for name in names:
            vals = self.values[name]
            if isinstance(vals, str | bytes) or not isinstance(vals, Sequence):
                raise StudyError(f"grid parameter {name!r}: expected a list of values, got {vals!r}")
            if len(vals) == 0:
                raise StudyError(f"grid parameter {name!r}: empty list of values")
        check_case_count(math.prod(len(self.values[n]) for n in names),
                         f"grid over {', '.join(names)}")
        return [dict(zip(names, combo, strict=True))
                for combo in itertools.product(*(self.values[n] for n in names))]


@dataclass(frozen=True)
class _Sampler:
    ranges: Mapping[str, Range | Sequence[float]]
    n: int
    seed: int = 0
    fixed: Mapping[str, Any] = field(default_factory=dict)
    grid: Mapping[str, Sequence[Any]] = field(default_factory=dict)

    def _unit(self, d: int) -> np.ndarray:  # pragma: no cover - overridden
        raise NotImplementedError

    def cases(self) -> list[dict[str, Any]]:
        """``n`` sample points (crossed with the grid, if any), each with the fixed values."""
        if isinstance(self.n, bool) or not isinstance(self.n, int | np.integer) or self.n < 1:
            raise StudyError(f"{type(self).__name__}: n must be a positive integer, got {self.n!r}")
        grid = math.prod(len(v) for v in self.grid.values()
                         if isinstance(v, Sequence) and not isinstance(v, str | bytes))
        check_case_count(int(self.n) * grid, f"{type(self).__name__} of n = {self.n}"
                         + (f" crossed with a grid of {grid}" if self.grid else ""))
        names = list(self.ranges)
        if not names:
            raise StudyError(f"{type(self).__name__}: no ranges to sample")
        clash = set(names) & (set(self.fixed) | set(self.grid))
        if clash:
            raise StudyError(f"{type(self).__name__}: {sorted(clash)} given both as a range and a value")
        ranges = [_as_range(self.ranges[k], f"range {k!r}") for k in names]
        u = self._unit(len(names))  # (n, d) in [0, 1)
        cols = [r.scale(u[:, j]) for j, r in enumerate(ranges)]
        points = [{k: (int(c[i]) if r.integer else float(c[i]))
                   for k, c, r in zip(names, cols, ranges, strict=True)} for i in range(self.n)]
        combos = Grid(self.grid).cases() if self.grid else [{}]
        return [{**self.fixed, **g, **p} for g in combos for p in points]


@dataclass(frozen=True)
class LatinHypercube(_Sampler):
    """``n`` Latin-hypercube points in the ``ranges`` (:class:`scipy.stats.qmc.LatinHypercube`).

    Attributes
    ----------
    ranges : mapping of str to Range or (min, max)
    n : int
        Number of points (per grid combination).
    seed : int
        Seed of the design (the same seed gives the same points).
    fixed : mapping of str to value
        Values shared by every case.
    grid : mapping of str to list
        Values crossed with the sample points (product).
    """

    def _unit(self, d: int) -> np.ndarray:
        return qmc.LatinHypercube(d=d, seed=np.random.default_rng(self.seed)).random(self.n)


@dataclass(frozen=True)
class RandomSampler(_Sampler):
    """``n`` independent uniform points in the ``ranges`` (same attributes as :class:`LatinHypercube`)."""

    def _unit(self, d: int) -> np.ndarray:
        return np.random.default_rng(self.seed).random((self.n, d))


def case_seed(seed: int, index: int) -> int:
    """The seed of case ``index`` of a study seeded ``seed``: 63 bits from ``SeedSequence``.

    Depends on ``(seed, index)`` only (``SeedSequence(seed, spawn_key=(index,))``, the
    ``index``-th child of ``SeedSequence(seed)``); fits a signed 64-bit column.
    """
    state = np.random.SeedSequence(seed, spawn_key=(index,)).generate_state(1, np.uint64)[0]
    return int(state >> np.uint64(1))


def expand_cases(cases: Sequence[Mapping[str, Any]] | Mapping[str, Sequence[Any]] | Grid | _Sampler,
                 seed: int | None = 0) -> list[dict[str, Any]]:
    """The study's cases as a list of new dicts, each with its ``seed`` (unless ``seed`` is None).

    Parameters
    ----------
    cases : list of dict, dict of lists (grid), Grid, LatinHypercube or RandomSampler
    seed : int or None
        Study seed: case ``i`` gets ``case_seed(seed, i)`` in the column ``"seed"``, unless the
        case already has one. None: no seed column.

    Returns
    -------
    list of dict
        Copies; the caller's dicts are never modified.
    """
    if isinstance(cases, Grid | _Sampler):
        out = cases.cases()
    elif isinstance(cases, Mapping):
        out = Grid(cases).cases()
    elif isinstance(cases, Sequence) and not isinstance(cases, str | bytes):
        out = []
        for i, case in enumerate(cases):
            if not isinstance(case, Mapping):
                raise StudyError(f"case {i}: expected a dict of parameter values, got "
                                 f"{type(case).__name__}")
            out.append(dict(case))
    else:
        raise StudyError("cases: expected a list of dicts, a dict of lists (grid), a Grid or a "
                         f"sampler, got {type(cases).__name__}")
    for i, case in enumerate(out):
        for key in case:
            if not isinstance(key, str):
                raise StudyError(f"case {i}: parameter names must be text, got {key!r}")
    if seed is not None:
        if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
            raise StudyError(f"seed must be a non-negative integer, got {seed!r}")
        for i, case in enumerate(out):
            case.setdefault(SEED_COLUMN, case_seed(int(seed), i))
    return out
