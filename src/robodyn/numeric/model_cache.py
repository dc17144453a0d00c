"""The compiled-model cache's plumbing: source keys, atomic writes, cached loads, kernel memo.

What :func:`robodyn.numeric.model.compile_model` needs to find, write and load generated code
(the cache folder itself is :func:`robodyn.codegen.build.cache_dir`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import importlib.util
import os
import subprocess
import sys
import tempfile
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from types import ModuleType
from typing import Any

from robodyn.codegen.build import CFLAGS, CompilerNotFoundError, find_compiler
from robodyn.codegen.cpu import BLOCK
from robodyn.codegen.kernels import KernelSet, build_kernels
from robodyn.robot.model import Robot

__all__ = ["openmp_flags"]


def _code_hash(robot: Robot) -> str:
    """The description's hash without what the generated code does not depend on (joint-reading
    corrections, applied in NumPy before the kernels): a calibrated description shares its
    compiled model with the same geometry without corrections."""
    if robot.corrections is None:
        return robot.description_hash
    return dataclasses.replace(robot, corrections=None).description_hash


def _from_cache(paths: Sequence[Path], write: Callable[[], None], load: Callable[[], Any]) -> Any:
    """``load()`` of generated sources ``paths``, written by ``write()`` when missing. Sources
    found in the cache that do not compile or import (a truncated or edited file) are generated
    again once instead of failing every later run."""
    if not all(p.exists() for p in paths):
        write()
        return load()
    _touch(*paths)
    try:
        return load()
    except Exception:  # noqa: BLE001 - any failure of cached sources: rebuilt, then raised if it recurs
        write()
        return load()


@functools.cache
def openmp_flags() -> tuple[str, ...]:
    """Compiler flags of the models: :data:`CFLAGS` plus ``-fopenmp`` when the compiler has it.

    Without OpenMP the ``*_batch_threads`` functions run on one thread (same results).
    """
    flags = (*CFLAGS, "-fopenmp")
    # a throwaway compilation outside the cache (which holds models only)
    try:
        compiler = find_compiler()
    except CompilerNotFoundError:
        return CFLAGS
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "probe.c"
        src.write_text("#ifndef _OPENMP\n#error no OpenMP\n#endif\nint rd_openmp_probe(void) { return 1; }\n")
        proc = subprocess.run([compiler, *flags, str(src), "-o", str(Path(tmp) / "probe.so")],
                              capture_output=True, check=False)
    return flags if proc.returncode == 0 else CFLAGS


def _touch(*paths: Path) -> None:
    """Mark cached generated sources as recently used (the cache evicts least-recently used)."""
    for p in paths:
        with contextlib.suppress(OSError):
            os.utime(p)


@functools.cache
def _generator_hash() -> str:
    """Hash of what decides what is generated: the generator's source files and the block width.

    Taken once per process, when this module is imported (with the generator's modules): a
    process that loaded the generator before its files were edited must not store what it
    generates under the hash of the edited files.
    """
    import robodyn.codegen as codegen_pkg
    import robodyn.symbolic as symbolic_pkg
    import robodyn.symbolic.hydro as hydro_pkg

    digest = hashlib.sha256()
    # the hydrodynamic terms (robodyn.symbolic.hydro) are part of every underwater model's kernels
    for pkg in (codegen_pkg, hydro_pkg, symbolic_pkg):
        for path in sorted(Path(pkg.__file__).parent.glob("*.py")):
            digest.update(path.read_bytes())
    # the block width is written into the C source (robodyn.codegen.cpu): each width has its own
    # cache entries, so that ROBODYN_BLOCK=w never loads kernels generated for another width
    digest.update(f"block width {BLOCK}".encode())
    return digest.hexdigest()


_generator_hash()


def _write_atomic(path: Path, text: str) -> None:
    """Write ``text`` so that readers see the old file or the whole new one."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)


_KERNEL_MEMO: dict[tuple[str, tuple], KernelSet] = {}


def _kernels_cached(robot: Robot, parameters: Mapping[str, float] | None,
                    runtime: tuple[str, ...] = ()) -> KernelSet:
    """Kernels are deterministic in (description, parameters): derive them once per process."""
    folded = tuple(sorted((k, v) for k, v in (parameters or {}).items() if k not in runtime))
    key = (_code_hash(robot), folded, runtime)
    if key not in _KERNEL_MEMO:
        _KERNEL_MEMO[key] = build_kernels(robot, parameters, runtime=runtime)
    return _KERNEL_MEMO[key]


#: The last line of a cached generated module: the SHA-256 of the text above it.
_CHECK_PREFIX = "# robodyn-sha256: "


def _write_checked(path: Path, text: str) -> None:
    """Write a generated module to the cache with its checksum as the last line (see
    :func:`_import_file`)."""
    body = (text if text.endswith("\n") else text + "\n").encode("utf-8")
    data = body + f"{_CHECK_PREFIX}{hashlib.sha256(body).hexdigest()}\n".encode()
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
    with os.fdopen(fd, "wb") as fh:  # bytes: no newline or encoding translation
        fh.write(data)
    os.replace(tmp, path)


def _verify_checksum(path: Path) -> None:
    """Raise ValueError unless ``path`` ends with the checksum line :func:`_write_checked` wrote
    and the text above it matches it (a truncated, emptied or edited cache file)."""
    data = path.read_bytes()
    body, _, last = data.rstrip(b"\n").rpartition(b"\n")
    digest = hashlib.sha256(body + b"\n").hexdigest()
    expected = f"{_CHECK_PREFIX}{digest}".encode()
    if not body or last != expected:
        raise ValueError(f"{path}: the cached generated module does not match its checksum")


def _import_file(path: Path, name: str) -> ModuleType:
    """Import a generated NumPy module (once per process), written by :func:`_write_checked`.

    Raises
    ------
    ValueError
        When the file does not match its checksum (the caller generates it again).
    """
    if name in sys.modules:
        return sys.modules[name]
    _verify_checksum(path)
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    sys.modules[name] = module
    return module
