"""Compile generated C into a shared library in a content-addressed cache, and load it.

The cache directory (``$ROBODYN_CACHE``, else ``$XDG_CACHE_HOME/robodyn``, else
``~/.cache/robodyn``) is created private to the user (mode 0700) and holds one ``rd_<hash>.so``
per distinct source and compiler command, with a manifest ``rd_<hash>.so.sha256`` (size and
SHA-256 of the library) beside it; the compiled models also keep their generated sources there
(``rd_model_<hash>.c``/``.cdef``/``.py``). A library is compiled into a private temporary
folder and renamed into place, so concurrent processes never see a half-written library and at
worst compile the same thing twice. A library whose size or hash does not match its manifest (a
truncated or altered file) is compiled again before it is loaded. An index
``rd_<source hash>.src`` names the library last built from a source on this kind of processor,
so that a process without a C compiler (a cluster worker sharing the cache) loads it instead of
failing: only a source never built needs the compiler.

Size limit: after each compilation the least recently used files (by modification time, which
loading a library refreshes) are removed until the cache holds at most ``$ROBODYN_CACHE_MAX_MB``
megabytes (default :data:`DEFAULT_CACHE_MAX_MB`); the library just built is always kept.
``robodyn cache info`` and ``robodyn cache clear`` show and empty the cache.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import platform
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import cffi

from robodyn.cache import cache_dir
from robodyn.codegen.cpu import BLOCK, vector_flags
from robodyn.robot.errors import InputError

__all__ = [
    "CFLAGS",
    "DEFAULT_CACHE_MAX_MB",
    "CacheInfo",
    "CompiledLibrary",
    "CompilerNotFoundError",
    "cache_dir",
    "cache_info",
    "cache_limit",
    "clear_cache",
    "compile_library",
    "GCC_FLAGS",
    "applied_flags",
    "compiler_flags",
    "find_compiler",
]

#: Default size limit of the cache, megabytes (``$ROBODYN_CACHE_MAX_MB`` overrides it).
DEFAULT_CACHE_MAX_MB = 1024

_ENTRY_PREFIX = "rd_"
_MANIFEST = ".sha256"

#: Flags: IEEE arithmetic without reassociation (no -ffast-math: results must match the symbolic
#: model), but with ``a * b + c`` contracted to fused multiply-adds where the CPU has them (one
#: rounding instead of two; GCC's default outside strict ISO mode, which -std=c99 would turn off);
#: and on AVX2 processors without AVX-512 the full 256-bit registers (:func:`vector_flags`).
CFLAGS = ("-O3", "-fPIC", "-shared", "-std=c99", "-fno-math-errno", "-ffp-contract=fast",
          "-march=native", *vector_flags())


#: GCC's RTL combine pass takes time superlinear in the length of a basic block of scalar code.
#: At one state per block (``ROBODYN_BLOCK=1``) the PUMA 560's regressor-derivative kernel
#: (295 kB of C, one straight-line block) took 12 min to compile with GCC 12 on an AMD EPYC
#: (``-ftime-report``: combine 711 s of 729 s) and 14 s without the pass; at 8 states per block
#: (vector code) the same kernel compiles in 20 s. The scalar PUMA 560 kernels built without the
#: pass ran at the same speed, within the run-to-run noise (10^5 states, ns per state, min of 7:
#: inverse dynamics 245 vs 240, forward dynamics 427 vs 430, regressor 2269 vs 2196).
SCALAR_GCC_FLAGS = ("-fdisable-rtl-combine",)


#: GCC: every loop starts on a 64-byte boundary (a line of the instruction cache, and of the
#: micro-op cache on AMD Zen), instead of GCC's default of up to 16 bytes skipped. The hot loops
#: are few (sines and cosines, the block body, the transpositions), so the code grows little.
#: Measured on the AMD EPYC with AVX2 (2026-12-06, 10^5 states through ``Model``, ns per state,
#: builds taking turns, min of 25): PUMA 560 inverse dynamics 45.3-45.4 -> 40.6-41.6, forward
#: dynamics 77.9 -> 74.9-77.1; Kinova Gen3 within the noise (ID 104.3-104.8 -> 103.6-103.8, FD
#: 203.7-205.6 -> 202.6-203.7); compile times unchanged. What a loop's alignment gains depends
#: on the code around it: with the previous sines and cosines the PUMA's ID did not move.
GCC_FLAGS = ("-falign-loops=64",)


def compiler_flags(compiler: str, width: int = BLOCK) -> tuple[str, ...]:
    """Flags for this ``compiler`` (path) and block ``width``, added to every compilation.

    :data:`GCC_FLAGS` for code compiled by GCC (the path, links followed, names gcc: ``cc`` is
    usually a link to it), then :data:`SCALAR_GCC_FLAGS` for scalar code (``width`` 1); none
    for other compilers.
    """
    name = Path(os.path.realpath(compiler)).name
    if re.search(r"(^|-)gcc(-[\d.]+)?$", name) is None:
        return ()
    return (*GCC_FLAGS, *(SCALAR_GCC_FLAGS if width == 1 else ()))


def applied_flags(flags: tuple[str, ...] = CFLAGS) -> tuple[str, ...]:
    """What :func:`compile_library` gives this machine's compiler for ``flags``: ``flags`` and
    :func:`compiler_flags` (``flags`` alone where there is no compiler)."""
    try:
        return (*flags, *compiler_flags(find_compiler()))
    except CompilerNotFoundError:
        return tuple(flags)


class CompilerNotFoundError(RuntimeError):
    """No C compiler: say which fallback works without one."""


@dataclass(frozen=True)
class CompiledLibrary:
    """A loaded shared library.

    Attributes
    ----------
    path : Path
        The cached ``.so`` file.
    ffi : cffi.FFI
        The FFI the declarations were given to.
    lib : object
        cffi's library object: one attribute per exported function.
    """

    path: Path
    ffi: cffi.FFI
    lib: object


@dataclass(frozen=True)
class CacheInfo:
    """What the cache holds.

    Attributes
    ----------
    path : Path
        The cache directory.
    entries : int
        Compiled libraries (``rd_*.so``).
    files : int
        All robodyn files (libraries, manifests, generated sources).
    size : int
        Total size of those files, bytes.
    limit : int
        Size limit, bytes (``$ROBODYN_CACHE_MAX_MB``).
    """

    path: Path
    entries: int
    files: int
    size: int
    limit: int


def cache_limit() -> int:
    """The cache size limit in bytes (``$ROBODYN_CACHE_MAX_MB``, default 1024 MB).

    Raises
    ------
    ValueError
        When the variable is set to something other than a non-negative number.
    """
    text = os.environ.get("ROBODYN_CACHE_MAX_MB", "").strip()
    if not text:
        return DEFAULT_CACHE_MAX_MB * 2**20
    try:
        mb = float(text)
    except ValueError:
        mb = -1.0
    if not mb >= 0 or mb == float("inf"):
        raise InputError(f"ROBODYN_CACHE_MAX_MB={text!r}: expected a non-negative number of "
                         "megabytes")
    return int(mb * 2**20)


#: The names robodyn gives its cache files: ``rd_<24 hex>.so`` and its manifest, generated
#: sources ``rd_<tag>_<24 hex>.c/.cdef/.py/.singular`` and the numbers of loaded descriptions
#: ``rd_robot_<24 hex>.json`` (:mod:`robodyn.robot.numbers_cache`); nothing else is ever removed.
_OWN_NAME = re.compile(
    r"rd_(?:[a-z]+_)?[0-9a-f]{24}(?:\.so(?:\.sha256)?|\.src|\.c|\.cdef|\.py|\.singular|\.json)")
#: A temporary compilation folder: ``tempfile``'s ``.build-`` plus 8 name characters.
_OWN_BUILD = re.compile(r"\.build-[a-z0-9_]{8}")


def _entries(directory: Path) -> list[Path]:
    """robodyn's own files in the cache (names :data:`_OWN_NAME`; never anything else the folder
    holds, such as a user's ``rd_measurements.csv``)."""
    if not directory.is_dir():
        return []
    return [p for p in directory.iterdir() if _OWN_NAME.fullmatch(p.name) and p.is_file()]


def cache_info() -> CacheInfo:
    """Location, number of compiled libraries, files and total size of the cache."""
    directory = cache_dir(create=False)
    files = _entries(directory)
    size = sum(_size(p) for p in files)
    libraries = sum(p.suffix == ".so" for p in files)
    return CacheInfo(directory, libraries, len(files), size, cache_limit())


def clear_cache() -> tuple[int, int]:
    """Remove robodyn's files from the cache; returns (files removed, bytes freed)."""
    directory = cache_dir(create=False)
    removed = freed = 0
    for p in _entries(directory):
        size = _size(p)
        try:
            p.unlink()
        except FileNotFoundError:
            continue  # another process removed it
        removed, freed = removed + 1, freed + size
    if directory.is_dir():
        for tmp in directory.glob(".build-*"):
            if _OWN_BUILD.fullmatch(tmp.name) and tmp.is_dir() and not tmp.is_symlink():
                shutil.rmtree(tmp, ignore_errors=True)  # left by an interrupted compilation
    return removed, freed


def _size(path: Path) -> int:
    try:
        return path.stat().st_size
    except OSError:
        return 0


def _evict(directory: Path, keep: Path) -> None:
    """Remove least recently used entries until the cache is within its limit.

    An entry is a file with its manifest (``rd_<hash>.so`` and ``rd_<hash>.so.sha256``), used
    when the newer of the two was modified.
    """
    limit = cache_limit()
    groups: dict[str, list[tuple[float, int, Path]]] = {}
    for p in _entries(directory):
        try:
            st = p.stat()
        except OSError:
            continue
        groups.setdefault(p.name.removesuffix(_MANIFEST), []).append((st.st_mtime, st.st_size, p))
    total = sum(size for files in groups.values() for _, size, _ in files)
    for name, files in sorted(groups.items(), key=lambda g: max(f[0] for f in g[1])):
        if total <= limit:
            break
        if name == keep.name:
            continue
        for _, size, p in files:
            with contextlib.suppress(OSError):
                p.unlink()
                total -= size


def _digest(path: Path) -> str:
    """``"<size> <sha256>"`` of a file."""
    h = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return f"{path.stat().st_size} {h.hexdigest()}"


def _intact(target: Path) -> bool:
    """Whether a cached library exists and matches its manifest (size and SHA-256)."""
    manifest = target.with_name(target.name + _MANIFEST)
    try:
        return manifest.read_text().strip() == _digest(target)
    except OSError:
        return False


def find_compiler() -> str:
    """Path of the C compiler (``$CC``, else cc/gcc/clang on PATH)."""
    for cand in (os.environ.get("CC"), "cc", "gcc", "clang"):
        if cand:
            found = shutil.which(cand)
            if found:
                return found
    raise CompilerNotFoundError(
        "no C compiler found (tried $CC, cc, gcc, clang); install one (e.g. gcc) or use "
        "rd.compile_model(robot, backend='numpy'), which needs no compiler"
    )


def compile_library(source: str, declarations: str, flags: tuple[str, ...] = CFLAGS) -> CompiledLibrary:
    """Compile ``source`` (cached by content) and load it with ``declarations`` as cffi's cdef.

    Parameters
    ----------
    source : str
        A complete C translation unit.
    declarations : str
        Prototypes of the functions to expose (C declarations cffi can parse).
    flags : tuple of str
        Compiler flags (part of the cache key), followed by :func:`compiler_flags`.

    Returns
    -------
    CompiledLibrary

    Raises
    ------
    CompilerNotFoundError
        When no compiler is installed.
    RuntimeError
        When compilation fails (the compiler's message is included).
    """
    # a library built before from this source for this processor is used without a compiler
    # (a worker that has the cache but no toolchain): the index names it
    index = cache_dir() / f"{_ENTRY_PREFIX}{_source_key(source)}.src"
    try:
        compiler = find_compiler()
    except CompilerNotFoundError:
        built = _indexed(index)
        if built is None:
            raise
        return _load(built, declarations)
    # -march=native code is only valid on this kind of processor: it is part of the key
    flags = (*flags, *compiler_flags(compiler))
    key = hashlib.sha256("\0".join([source, compiler, *flags, _cpu_id()]).encode()).hexdigest()[:24]
    target = cache_dir() / f"{_ENTRY_PREFIX}{key}.so"
    if _intact(target):
        with contextlib.suppress(OSError):
            os.utime(target)  # most recently used: evicted last
    else:
        # missing, or truncated/altered since it was built: compile (again)
        with tempfile.TemporaryDirectory(dir=target.parent, prefix=".build-") as tmp:
            src = Path(tmp) / "model.c"
            src.write_text(source)
            out = Path(tmp) / "model.so"
            proc = subprocess.run([compiler, *flags, str(src), "-o", str(out), "-lm"],
                                  capture_output=True, text=True, check=False)
            if proc.returncode != 0:
                raise RuntimeError(f"compiling the generated model failed ({compiler}):\n"
                                   f"{proc.stderr[-4000:]}")
            manifest = Path(tmp) / "model.so.sha256"
            manifest.write_text(_digest(out) + "\n")
            # atomic: other processes see the old state or the whole library (then its manifest)
            os.replace(out, target)
            os.replace(manifest, target.with_name(target.name + _MANIFEST))
        _evict(target.parent, keep=target)
    with contextlib.suppress(OSError):
        if _indexed(index) != target:
            _write_index(index, target)
    return _load(target, declarations)


def _load(target: Path, declarations: str) -> CompiledLibrary:
    ffi = cffi.FFI()
    ffi.cdef(declarations)
    lib = ffi.dlopen(str(target))
    return CompiledLibrary(target, ffi, lib)


def _source_key(source: str) -> str:
    """The compiler-independent key of a source: its text and the processor (not the flags: a
    process without a compiler cannot probe for OpenMP, and the library built with or without
    it has the same functions)."""
    return hashlib.sha256("\0".join([source, _cpu_id()]).encode()).hexdigest()[:24]


def _indexed(index: Path) -> Path | None:
    """The intact cached library an index file names, or None (also for a name that is not one
    of the cache's own library names, such as a path: checked before it is used as a name)."""
    try:
        name = index.read_text(encoding="utf-8").strip()
    except (OSError, UnicodeDecodeError):
        return None
    if not _OWN_NAME.fullmatch(name) or not name.endswith(".so"):
        return None
    target = index.with_name(name)
    return target if _intact(target) else None


def _write_index(index: Path, target: Path) -> None:
    tmp = index.with_name(f".{index.name}.{os.getpid()}.tmp")
    tmp.write_text(target.name + "\n", encoding="utf-8")
    os.replace(tmp, index)  # atomic


def _cpu_id() -> str:
    """The processor model, for the cache key."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line
    except OSError:
        pass
    return platform.machine() + platform.processor()
