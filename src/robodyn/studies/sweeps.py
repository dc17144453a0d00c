"""``sweep``: run a picklable task over the cases of a study on Dask, results as a pandas table.

The cases are cut into batches (many cases per Dask task: a fast simulation costs less than one
Dask task's scheduling), at least :data:`MIN_BATCHES` of them whatever the workers at submission,
all submitted at once: the scheduler hands them to the workers that exist and to those that join
later (``cluster.scale``, ``cluster.adapt``, which sees the whole study queued). They run on the
workers of a Dask cluster:

* no ``client`` and no ``scheduler``: a :class:`distributed.LocalCluster` on 127.0.0.1 with one
  single-threaded worker process per CPU core (or ``workers``), closed when the sweep ends;
* ``client``: that :class:`distributed.Client` (left open);
* ``scheduler="tcp://host:8786"``: a client of that cluster, closed when the sweep ends; a
  scheduler that cannot be reached within ``timeout`` seconds is a :class:`StudyError`.

Dask reruns the batches of a worker that dies; the cases of a batch whose worker died on every
try are run again one at a time, each alone, so that only a case that kills its worker is
recorded as failed; a case whose
task raises is recorded with its message (``on_error="record"``) or stops the study
(``"raise"``); an interrupted sweep raises :class:`SweepInterrupted` carrying the table of the
cases that finished. Compiled models a task lists travel with the tasks
(:mod:`robodyn.studies.shipping`), so workers need no compiler. Nothing here is a scheduler, a pool
or a store of its own: Dask schedules, pandas/pyarrow store.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import tempfile
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from robodyn.extras import require
from robodyn.robot.errors import StudyError
from robodyn.studies.cases import expand_cases

__all__ = ["ERROR_COLUMN", "MIN_BATCHES", "SweepInterrupted", "batches", "default_batch", "default_workers",
           "run_batch", "run_serial", "sweep", "table", "write_table"]

#: Column holding a failed case's error message (None where the case succeeded).
ERROR_COLUMN = "error"

#: One finished case: (case index, flat result columns, error message or None).
Row = tuple[int, dict[str, Any], str | None]


class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by the user (Ctrl-C); ``table`` holds the cases that finished.

    Attributes
    ----------
    table : pandas.DataFrame
        Same layout as a finished sweep's table, only the finished cases (in case order).
    """

    def __init__(self, table: pd.DataFrame) -> None:
        super().__init__(f"sweep interrupted: {len(table)} cases finished")
        self.table = table


def default_workers() -> int:
    """Worker processes of the default LocalCluster: the CPU cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


#: Tasks a sweep is cut into at least (fewer only with fewer cases) when ``batch`` is not given,
#: whatever the workers at submission: a cluster that has none yet or grows afterwards
#: (``cluster.scale``, ``cluster.adapt``) finds work for this many worker threads queued on the
#: scheduler, and ``adapt`` sees the whole study's work when it decides how many workers to ask for.
MIN_BATCHES = 256

#: Seconds the tasks of a sweep wait with no worker at all on the cluster the sweep starts itself
#: before the sweep stops with :class:`StudyError` (its workers died and the nannies could not
#: start new ones). Dask's ``distributed.scheduler.no-workers-timeout``; a cluster the user gives
#: keeps its own setting (an adaptive cluster may legitimately wait longer for workers).
NO_WORKER_TIMEOUT = 60.0


def default_batch(n_cases: int, threads: int) -> int:
    """Cases per Dask task when ``batch`` is not given.

    ``n_cases`` cut into ``max(4 * threads, MIN_BATCHES)`` tasks: 4 per worker thread of a big
    cluster, and at least :data:`MIN_BATCHES` however few threads exist at submission (zero for
    an adaptive cluster that starts empty), all submitted at once. The scheduler hands them to
    the workers as these join; each task costs about 2-5 ms of scheduling and transfer.

    Parameters
    ----------
    n_cases : int
    threads : int
        Worker threads of the cluster at submission (``sum(client.nthreads().values())``).

    Returns
    -------
    int
    """
    return max(1, math.ceil(n_cases / max(4 * threads, MIN_BATCHES)))


def batches(n_cases: int, batch: int) -> list[range]:
    """Consecutive case-index ranges of ``batch`` cases (the last one shorter), shape-free."""
    return [range(s, min(s + batch, n_cases)) for s in range(0, n_cases, batch)]


def _flatten(result: Any, case: int) -> dict[str, Any]:
    """A task's dict of scalars or small 1-D arrays as flat columns (``name[i]`` for arrays)."""
    if not isinstance(result, Mapping):
        raise TypeError(f"case {case}: the task returned {type(result).__name__}, expected a dict "
                        "of scalars or small arrays")
    out: dict[str, Any] = {}
    for key, value in result.items():
        if not isinstance(key, str):
            raise TypeError(f"case {case}: result names must be text, got {key!r}")
        arr = np.asarray(value)
        if arr.ndim == 0:
            out[key] = arr.item() if isinstance(value, np.generic | np.ndarray) else value
        elif arr.ndim == 1:
            for i, v in enumerate(arr.tolist()):
                out[f"{key}[{i}]"] = v
        else:
            raise TypeError(f"case {case}: result {key!r} has shape {arr.shape}; return scalars or "
                            "1-D arrays")
    return out


def run_batch(task: Callable[[dict[str, Any]], Mapping[str, Any]],
              cases: Sequence[tuple[int, dict[str, Any]]], on_error: str = "record") -> list[Row]:
    """Run ``task`` on each ``(index, case)``; what one Dask task (or pool task) executes.

    Parameters
    ----------
    task : callable
        ``task(case) -> dict``; gets a copy of each case.
    cases : sequence of (int, dict)
    on_error : {"record", "raise"}
        "record": a case that raises gives ``(index, {}, "TypeName: message")``; "raise": the
        exception propagates with a note naming the case.

    Returns
    -------
    list of (int, dict, str or None)
    """
    rows: list[Row] = []
    for index, case in cases:
        try:
            rows.append((index, _flatten(task(dict(case)), index), None))
        except Exception as exc:
            if on_error == "raise":
                exc.add_note(f"robodyn.sweep: case {index}: {case}")
                raise
            rows.append((index, {}, f"{type(exc).__name__}: {' '.join(str(exc).split())}"))
    return rows


def _run_part(cases: Sequence[tuple[int, dict[str, Any]]], task: Callable[[dict[str, Any]], Any],
              on_error: str) -> list[Row]:
    """:func:`run_batch` with the batch first (what ``Client.map`` passes)."""
    return run_batch(task, cases, on_error)


def table(cases: Sequence[Mapping[str, Any]], rows: Sequence[Row] | Mapping[int, Row]) -> pd.DataFrame:
    """The study table: one row per finished case, in case order.

    Columns: the case parameters (first-seen order), the result columns (first-seen order; one
    that repeats a parameter name gets the suffix ``" (result)"``), then ``"error"``. Index:
    ``case`` (the case number).
    """
    done = sorted(rows.values() if isinstance(rows, Mapping) else rows, key=lambda r: r[0])
    names = list(dict.fromkeys(k for c in cases for k in c))
    records = []
    for index, result, error in done:
        record = dict(cases[index])
        for k, v in result.items():
            record[f"{k} (result)" if k in names else k] = v
        record[ERROR_COLUMN] = error
        records.append(record)
    out = pd.DataFrame.from_records(records, index=pd.Index([r[0] for r in done], name="case"))
    results = [c for c in out.columns if c not in names and c != ERROR_COLUMN]
    cols = [c for c in names if c in out.columns] + results + [ERROR_COLUMN]
    if out.empty:
        return pd.DataFrame(columns=names + [ERROR_COLUMN], index=pd.Index([], name="case"))
    return out[cols]


def _task_name(task: object) -> str:
    return getattr(task, "__qualname__", None) or type(task).__qualname__


def _check_task(task: object) -> None:
    """Refuse a task that is not callable or cannot be sent to a worker (named)."""
    if not callable(task):
        raise StudyError(f"task {task!r} is not callable: expected a function of one case (dict)")
    cloudpickle = require("cloudpickle", "rd.sweep on Dask (run_serial needs no extra)")

    try:
        cloudpickle.dumps(task)
    except Exception as exc:
        raise StudyError(
            f"task {_task_name(task)!r} cannot be sent to Dask workers: it does not pickle "
            f"({type(exc).__name__}: {exc}); use a module-level function or a dataclass of plain "
            "values (robot description text, not a loaded model)") from None


def _check_options(on_error: str, batch: int | None, workers: int | None) -> None:
    if on_error not in ("record", "raise"):
        raise StudyError(f"on_error must be 'record' or 'raise', got {on_error!r}")
    for name, v in (("batch", batch), ("workers", workers)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, int) or v < 1):
            raise StudyError(f"{name} must be a positive integer, got {v!r}")


def run_serial(task: Callable[[dict[str, Any]], Mapping[str, Any]], cases: Any, *, seed: int | None = 0,
               on_error: str = "record") -> pd.DataFrame:
    """:func:`sweep` in this process, without Dask (same cases, seeds and table)."""
    _check_options(on_error, None, None)
    expanded = expand_cases(cases, seed)
    return table(expanded, run_batch(task, list(enumerate(expanded)), on_error))


@contextmanager
def _connect(client: Any, scheduler: str | None, workers: int | None, timeout: float) -> Iterator[Any]:
    """The Dask client to use; those opened here are closed on exit."""
    require("dask", "rd.sweep on Dask (run_serial needs no extra)")
    Client = require("distributed", "rd.sweep on Dask (run_serial needs no extra)").Client  # noqa: N806

    if client is not None:
        yield client
        return
    if scheduler is not None:
        try:
            own = Client(scheduler, timeout=timeout, set_as_default=False)
        except (OSError, TimeoutError, ValueError) as exc:
            raise StudyError(f"cannot reach the Dask scheduler at {scheduler!r} within {timeout:g} s "
                             f"({type(exc).__name__}: {' '.join(str(exc).split())}); check the "
                             "address (tcp://host:8786) and that the scheduler is running") from None
        try:
            yield own
        finally:
            own.close()
        return
    # the workers' scratch folder (Dask's lock files and spilled data) lives and dies with the run
    with (tempfile.TemporaryDirectory(prefix="robodyn-dask-") as scratch,
          local_cluster(workers, scratch) as cluster, Client(cluster, set_as_default=False) as own):
        yield own


def local_cluster(workers: int | None = None, scratch: str | None = None) -> Any:
    """The default cluster: single-threaded worker processes on 127.0.0.1, no dashboard.

    Dask's nanny starts workers with ``MALLOC_TRIM_THRESHOLD_=65536`` (to hand memory back to
    the system). Setting that variable also switches off glibc's dynamic mmap threshold, so every
    temporary array over 128 KiB is mapped and page-faulted afresh: a simulation case that
    allocates its trajectories ran 30-40 % slower in such a worker than in a plain process
    (measured on the AA300 sizing task). Workers of this cluster keep glibc's default instead;
    clusters a user starts keep their own settings.

    Parameters
    ----------
    workers : int, optional
        Worker processes (default: the usable CPU cores).
    scratch : str, optional
        Folder for the scheduler's and workers' scratch space (Dask's default:
        ``dask-scratch-space`` in the system's temporary folder, which outlives the cluster).

    Tasks that wait :data:`NO_WORKER_TIMEOUT` seconds with no worker on the cluster fail (the
    sweep then stops with a :class:`StudyError`) instead of waiting for ever.

    Returns
    -------
    distributed.LocalCluster
    """
    import dask
    from distributed import LocalCluster

    environ = {k: v for k, v in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items()
               if k != "MALLOC_TRIM_THRESHOLD_"}
    settings: dict[str, Any] = {"distributed.nanny.pre-spawn-environ": environ,
                                "distributed.scheduler.no-workers-timeout": f"{NO_WORKER_TIMEOUT:g}s"}
    if scratch is not None:  # the scheduler's folder too, not only the workers'
        settings["temporary-directory"] = scratch
    with dask.config.set(settings):
        return LocalCluster(n_workers=workers or default_workers(), threads_per_worker=1,
                            processes=True, host="127.0.0.1", dashboard_address=None,
                            silence_logs=logging.ERROR)


def sweep(task: Callable[[dict[str, Any]], Mapping[str, Any]], cases: Any, *, client: Any = None,
          scheduler: str | None = None, workers: int | None = None, batch: int | None = None,
          seed: int | None = 0, on_error: str = "record", progress: bool = False,
          timeout: float = 10.0, on_batch: Callable[[list[Row]], None] | None = None,
          ship: bool | None = None) -> pd.DataFrame:
    """Run ``task`` over ``cases`` on Dask; the table of cases and results, in case order.

    Parameters
    ----------
    task : callable
        ``task(case: dict) -> dict`` of scalars or 1-D arrays (array ``x`` of length k becomes
        columns ``x[0]`` .. ``x[k-1]``). Must pickle (cloudpickle): a module-level function or a
        dataclass such as :class:`robodyn.studies.ActuatorSizing` carrying a robot's description
        text, never a loaded compiled model.
    cases : list of dict, dict of lists (grid), Grid, LatinHypercube or RandomSampler
        See :func:`robodyn.studies.expand_cases`.
    client : distributed.Client, optional
        Run on this client's cluster (not closed).
    scheduler : str, optional
        Address of a running scheduler (``"tcp://host:8786"``); ignored when ``client`` is given.
    workers : int, optional
        Worker processes of the LocalCluster started when neither is given (default: the CPU
        cores available).
    batch : int, optional
        Cases per Dask task (default :func:`default_batch`: at least :data:`MIN_BATCHES` tasks,
        4 per worker thread on a bigger cluster, so that workers that join later get work).
    seed : int or None
        Study seed; case ``i`` gets the column ``seed = case_seed(seed, i)`` (None: no column).
    on_error : {"record", "raise"}
        A case whose task raises: its message in the ``error`` column (the others go on), or the
        exception stops the study.
    progress : bool
        Show a tqdm progress bar (cases) on stderr.
    timeout : float
        Seconds to wait for a ``scheduler`` to answer.
    on_batch : callable, optional
        Called in this process with each finished batch's rows ``[(index, results, error)]``
        (e.g. to save partial results).
    ship : bool or None
        Compiled models sent to the workers with the tasks (:mod:`robodyn.studies.shipping`), for a
        task with ``compiled_models(cases)``: None ships up to
        :data:`~robodyn.studies.shipping.SHIP_LIMIT` models, True any number, False none (each
        worker then builds its own, which needs a C compiler).

    Returns
    -------
    pandas.DataFrame
        Index ``case``; case columns, result columns, ``error``.

    Raises
    ------
    StudyError
        Bad cases or options, a task that does not pickle, an unreachable scheduler.
    SweepInterrupted
        On Ctrl-C (or a KeyboardInterrupt from ``on_batch``); its ``table`` has the finished cases.
    """
    _check_options(on_error, batch, workers)
    _check_task(task)
    expanded = expand_cases(cases, seed)
    if not expanded:
        return table(expanded, [])
    from robodyn.studies.shipping import models_to_ship

    with _connect(client, scheduler, workers, timeout) as dask:
        run = _Run(dask, task, on_error, models_to_ship(task, expanded, ship))
        size = batch or default_batch(len(expanded), sum(dask.nthreads().values()))
        parts = [[(i, expanded[i]) for i in r] for r in batches(len(expanded), size)]
        return table(expanded, run.collect(parts, on_batch, progress, expanded))


class _Run:
    """The Dask futures of one sweep: its batches, and the cases rerun alone after a worker died.

    Parameters
    ----------
    dask : distributed.Client
    task : callable
    on_error : {"record", "raise"}
    bundle : ModelBundle or None
        Compiled models every worker writes into its cache before it runs a batch, as a worker
        plugin (:mod:`robodyn.studies.shipping`): workers that join or restart later get it too.
    """

    def __init__(self, dask: Any, task: Any, on_error: str, bundle: Any) -> None:
        from distributed import as_completed

        self.dask, self.task, self.on_error = dask, task, on_error
        self.token = uuid.uuid4().hex[:12]
        #: cases of each unfinished task by key
        self.part_of: dict[str, list[tuple[int, dict[str, Any]]]] = {}
        #: cases of tasks whose workers died, to run alone; the key of the one running alone
        self.suspects: list[tuple[int, dict[str, Any]]] = []
        self.alone: str | None = None
        self.submitted: list[Any] = []
        self.pending = as_completed(loop=dask.loop)
        self.plugin: str | None = None
        if bundle is not None:
            from robodyn.studies.shipping import ShipModels

            # a plugin, not a task the batches depend on: batches without dependencies stay
            # "root-ish", queued on the scheduler and handed out as workers free up or join
            self.plugin = f"robodyn-models-{self.token}"
            dask.register_plugin(ShipModels(bundle), name=self.plugin)

    def collect(self, parts: list[list[tuple[int, dict[str, Any]]]],
                on_batch: Callable[[list[Row]], None] | None, progress: bool,
                cases: Sequence[dict[str, Any]]) -> dict[int, Row]:
        """Submit ``parts`` and gather their rows by case; cancel everything on an error.

        Raises
        ------
        SweepInterrupted
            On a KeyboardInterrupt, with the table of ``cases`` that finished.
        """
        from tqdm import tqdm

        rows: dict[int, Row] = {}
        bar = tqdm(total=len(cases), unit="case", disable=not progress, desc="sweep")
        try:
            self.submit(parts)
            for fut in self.pending:
                out = self.finished(fut)
                rows.update((row[0], row) for row in out)
                bar.update(len(out))
                if on_batch is not None and out:
                    on_batch(out)
        except KeyboardInterrupt:
            self.cancel()
            raise SweepInterrupted(table(cases, rows)) from None
        except BaseException:
            self.cancel()
            raise
        finally:
            bar.close()
            self.close()
        return rows

    def submit(self, parts: list[list[tuple[int, dict[str, Any]]]]) -> None:
        """Submit one task per batch of ``(index, case)``."""
        keys = [f"robodyn-sweep-{self.token}-{k}" for k in range(len(parts))]
        futures = self.dask.map(_run_part, parts, task=self.task, on_error=self.on_error,
                                pure=False, key=keys)
        self.part_of.update(zip(keys, parts, strict=True))
        self.submitted.extend(futures)
        self.pending.update(futures)

    def cancel(self) -> None:
        """Cancel every task of this sweep."""
        self.dask.cancel(self.submitted)

    def close(self) -> None:
        """Unregister the model plugin (the files stay in the workers' caches)."""
        if self.plugin is not None:
            with contextlib.suppress(Exception):  # a cluster already gone has nothing to remove
                self.dask.unregister_worker_plugin(self.plugin)
            self.plugin = None

    def finished(self, fut: Any) -> list[Row]:
        """The rows of a finished task.

        A task whose worker died on it (the scheduler's ``distributed.scheduler.allowed-failures``
        retries spent: a crash in compiled code, an out-of-memory kill, or a task that sat on
        the same worker as such a case) gives no rows: its cases become suspects. Once nothing
        else of the sweep is in flight, each suspect runs alone, one after the other, so that a
        worker dies only of the case it runs: a suspect whose worker dies on every try is
        recorded as failed, with the reason, the others give their rows.
        """
        from distributed import KilledWorker
        from distributed.scheduler import NoValidWorkerError, NoWorkerError

        part = self.part_of.pop(fut.key)
        rows: list[Row] = []
        if fut.status != "error":
            rows = fut.result()
        else:
            exc = fut.exception()
            if isinstance(exc, NoWorkerError | NoValidWorkerError):
                raise StudyError(f"the cluster had no worker for its tasks ({exc}): its workers "
                                 "died and were not restarted, or none joined; the cases finished "
                                 "so far went to on_batch") from exc
            if not isinstance(exc, KilledWorker) or self.on_error != "record":
                raise exc
            if fut.key == self.alone:
                tries = 1 + int(self.dask.run_on_scheduler(_allowed_failures))
                rows = [(part[0][0], {}, f"the worker running this case died {tries} times, the "
                                         "case running alone (a crash in compiled code or an "
                                         f"out-of-memory kill?): {exc}")]
            else:
                self.suspects.extend(part)
        if not self.part_of and self.suspects:  # nothing else in flight: the next suspect alone
            self._submit_alone(self.suspects.pop(0))
        return rows

    def _submit_alone(self, case: tuple[int, dict[str, Any]]) -> None:
        """Submit one case as the sweep's only task in flight."""
        key = f"robodyn-sweep-{self.token}-case-{case[0]}"
        fut = self.dask.submit(_run_part, [case], task=self.task, on_error=self.on_error,
                               pure=False, key=key)
        self.alone = key
        self.part_of[key] = [case]
        self.pending.add(fut)
        self.submitted.append(fut)


def _allowed_failures(dask_scheduler: Any = None) -> int:
    """The scheduler's ``allowed-failures`` setting (run on the scheduler)."""
    import dask

    return int(dask.config.get("distributed.scheduler.allowed-failures"))


def write_table(frame: pd.DataFrame, directory: str | Path, stem: str = "results") -> tuple[Path, Path]:
    """Write a study table as ``DIR/STEM.parquet`` (pyarrow) and ``DIR/STEM.csv``; their paths."""
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    parquet, csv = out / f"{stem}.parquet", out / f"{stem}.csv"
    require("pyarrow", f"writing the study table {parquet}")
    frame.to_parquet(parquet, engine="pyarrow")
    frame.to_csv(csv)
    return parquet, csv
