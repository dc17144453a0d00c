"""Compiled models shipped to sweep workers with the sweep: workers need no toolchain.

A process finds a compiled model in robodyn's cache (:func:`robodyn.codegen.build.cache_dir`)
without deriving or compiling anything when the cache holds the generated sources
(``rd_model_<key>.c``/``.cdef``), the library (``rd_<key>.so`` and its manifest) and the index
``rd_<source hash>.src`` that names the library built from that source on this kind of processor.
:func:`robodyn.studies.sweeps` fills its workers' caches with those files:

1. it asks the task which compiled models its cases use (an optional method
   ``compiled_models(cases) -> list of ModelSpec``: :class:`~robodyn.studies.ActuatorSizing` and
   :class:`~robodyn.studies.IdentificationMonteCarlo` and
   :class:`~robodyn.studies.underwater_task.UnderwaterEffects` have one), builds or loads them here
   (:func:`bundle_models`) and reads their cache files into one :class:`ModelBundle`;
2. the bundle travels with the sweep as a Dask worker plugin (:class:`ShipModels`, registered
   for the sweep's duration), which Dask sends to every worker before that worker takes a task:
   those that exist, those that join later (``cluster.scale``, ``cluster.adapt``) and those a
   nanny restarts after a crash;
3. each worker process writes the files its cache lacks (:func:`install_once`; files are written
   to a temporary name and renamed, so processes sharing a cache never see half a file).

A plugin rather than a Dask task the batches depend on: batches without dependencies stay
"root-ish" to the scheduler, which queues them and hands them out as worker threads free up or
join; made to depend on a task holding the bundle, they were all assigned to the workers at
submission (tried here), so a worker that crashed took its whole share with it, again and again.

The libraries are built with ``-march=native``, so a worker uses them only on the same kind of
processor (the index's name includes the processor model): elsewhere it derives nothing (the
generated sources are shipped) but compiles the library, which then needs a compiler. The
library links the compiler's OpenMP runtime (``libgomp``) when the building machine has it.
"""

from __future__ import annotations

import hashlib
import logging
import os
import re
import tempfile
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

from distributed.diagnostics.plugin import WorkerPlugin

from robodyn.codegen.build import CompiledLibrary, _cpu_id, _source_key, cache_dir
from robodyn.numeric.model import Model
from robodyn.robot.errors import InputError
from robodyn.studies.models import ModelSpec

__all__ = ["SHIP_LIMIT", "ModelBundle", "ShipModels", "bundle_models", "install_once", "models_to_ship"]

log = logging.getLogger("robodyn.studies")

#: Distinct compiled models a sweep ships by default (``ship=None``); with more, each worker
#: builds its own (``ship=True`` ships any number).
SHIP_LIMIT = 16

#: File names a bundle may carry: robodyn's own cache entries, nothing with a folder in it.
_NAME = re.compile(r"rd_(?:[a-z]+_)?[0-9a-f]{24}(?:\.so(?:\.sha256)?|\.src|\.c|\.cdef|\.py|\.singular)")
#: Written first: a library before its manifest, both before the index that names them.
_ORDER = (".so", ".so.sha256", ".src")


@dataclass(frozen=True)
class ModelBundle:
    """Cache files of compiled models, to be written into a worker's cache.

    Attributes
    ----------
    cpu : str
        Processor model of the machine that built the libraries.
    files : tuple of (str, bytes)
        File names (robodyn's cache names) and contents.
    """

    cpu: str
    files: tuple[tuple[str, bytes], ...]

    def __post_init__(self) -> None:
        for name, _ in self.files:
            if not _NAME.fullmatch(name):
                raise InputError(f"not a robodyn cache file name: {name!r}")

    @cached_property
    def token(self) -> str:
        """SHA-256 of the processor model and the files (names and contents)."""
        digest = hashlib.sha256(self.cpu.encode())
        for name, data in self.files:
            digest.update(f"\0{name}\0{len(data)}\0".encode())
            digest.update(data)
        return digest.hexdigest()

    @property
    def size(self) -> int:
        """Bytes of file contents."""
        return sum(len(data) for _, data in self.files)

    def install(self, directory: str | Path | None = None) -> list[str]:
        """Write the files ``directory`` (default: this process's cache) lacks or holds otherwise.

        Libraries, their manifests and indexes are skipped on another kind of processor.

        Parameters
        ----------
        directory : str or Path, optional

        Returns
        -------
        list of str
            Names of the files written.
        """
        folder = Path(directory) if directory is not None else cache_dir()
        same_cpu = self.cpu == _cpu_id()
        written = []
        for name, data in sorted(self.files, key=lambda f: _rank(f[0])):
            if _rank(name) < len(_ORDER) and not same_cpu:
                continue
            target = folder / name
            if _holds(target, data):
                continue
            fd, tmp = tempfile.mkstemp(dir=folder, prefix=".ship-", suffix=".tmp")
            try:
                with os.fdopen(fd, "wb") as fh:
                    fh.write(data)
                os.replace(tmp, target)  # atomic: readers see no file or the whole one
            except BaseException:
                Path(tmp).unlink(missing_ok=True)
                raise
            written.append(name)
        return written


def _rank(name: str) -> int:
    """Install order of a file: libraries, manifests, indexes, then generated sources."""
    return next((rank for rank, suffix in enumerate(_ORDER) if name.endswith(suffix)), len(_ORDER))


def _holds(target: Path, data: bytes) -> bool:
    """Whether ``target`` exists with exactly ``data``."""
    try:
        return target.stat().st_size == len(data) and target.read_bytes() == data
    except OSError:
        return False


def bundle_models(models: Iterable[Model]) -> ModelBundle:
    """The cache files of ``models`` (built or loaded in this process) as one bundle.

    Parameters
    ----------
    models : iterable of Model
        From :func:`robodyn.compile_model` or :func:`robodyn.studies.models.model_of`.

    Returns
    -------
    ModelBundle
    """
    paths: dict[Path, None] = {}
    for model in models:
        paths.update(dict.fromkeys(model.sources))
        impl = model._impl
        if isinstance(impl, CompiledLibrary):
            library = impl.path
            paths.update(dict.fromkeys((library, library.with_name(library.name + ".sha256"))))
            c_source = next((p for p in model.sources if p.suffix == ".c"), None)
            if c_source is not None:
                index = library.with_name(f"rd_{_source_key(c_source.read_text())}.src")
                if index.is_file():
                    paths[index] = None
    return ModelBundle(_cpu_id(), tuple((p.name, p.read_bytes()) for p in paths))


def models_to_ship(task: Any, cases: Sequence[dict[str, Any]], ship: bool | None) -> ModelBundle | None:
    """The bundle a sweep sends its workers, or None.

    Parameters
    ----------
    task : callable
        A study task; one with ``compiled_models(cases) -> list of ModelSpec`` (or of other specs
        with a ``model()`` method) has those built (or loaded from the cache) here.
    cases : sequence of dict
    ship : bool or None
        None: ship when the task lists at most :data:`SHIP_LIMIT` models; True: whatever the
        count; False: never.

    Returns
    -------
    ModelBundle or None
        None when nothing is shipped. A model that cannot be built here (no compiler, a bad
        parameter value) is left out with a log message: the workers build it, or its cases
        report the error.
    """
    listed = getattr(task, "compiled_models", None)
    if ship is False or listed is None:
        return None
    try:
        # a ModelSpec, or any spec with a model() method (UnderwaterEffects' EffectModelSpec)
        specs = list(dict.fromkeys(s if callable(getattr(s, "model", None)) else ModelSpec(*s)
                                   for s in listed(cases)))
    except Exception as exc:  # noqa: BLE001 - listing is an optimisation: the cases still run
        log.warning("robodyn.sweep: compiled models not shipped: listing them failed (%s: %s)",
                    type(exc).__name__, exc)
        return None
    if not specs or (ship is None and len(specs) > SHIP_LIMIT):
        if specs:
            log.info("robodyn.sweep: %d compiled models (over %d): each worker builds its own "
                     "(ship=True to build them here and ship them)", len(specs), SHIP_LIMIT)
        return None
    models = []
    for spec in specs:
        try:
            models.append(spec.model())
        except Exception as exc:  # noqa: BLE001 - the cases report it, or the workers build it
            log.warning("robodyn.sweep: model %s not shipped: %s: %s", spec, type(exc).__name__, exc)
    if not models:
        return None
    try:
        return bundle_models(models)
    except OSError as exc:  # a cache file removed meanwhile (another process's eviction)
        log.warning("robodyn.sweep: compiled models not shipped: %s", exc)
        return None


#: Bundles this process has installed: (token, cache folder).
_INSTALLED: set[tuple[str, str]] = set()


def install_once(bundle: ModelBundle) -> None:
    """Write ``bundle`` into this process's cache, once per process and cache folder.

    A cache that cannot be written is logged, not raised: the cases then build their models
    themselves or report why they cannot.
    """
    where = cache_dir()
    key = (bundle.token, str(where))
    if key in _INSTALLED:
        return
    try:
        written = bundle.install(where)
    except OSError as exc:
        log.warning("robodyn.sweep: shipped models not written to %s: %s", where, exc)
    else:
        log.debug("robodyn.sweep: %d shipped cache files written to %s", len(written), where)
    _INSTALLED.add(key)


class ShipModels(WorkerPlugin):
    """Dask worker plugin writing a :class:`ModelBundle` into each worker's cache at its setup.

    Parameters
    ----------
    bundle : ModelBundle
    """

    def __init__(self, bundle: ModelBundle) -> None:
        self.bundle = bundle

    def setup(self, worker: Any) -> None:
        """Write the bundle's files (runs in the worker process, before it takes tasks)."""
        install_once(self.bundle)
