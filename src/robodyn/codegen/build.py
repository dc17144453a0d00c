"""Compile generated C into a shared library in a content-addressed cache, and load it.

The cache directory (``$ROBODYN_CACHE``, else ``$XDG_CACHE_HOME/robodyn``, else
``~/.cache/robodyn``) holds one ``<hash>.so`` per distinct source and compiler command. A library
is compiled into a private temporary file and renamed into place, so concurrent processes never
see a half-written library and at worst compile the same thing twice.
"""

from __future__ import annotations

import hashlib
import os
import platform
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import cffi

#: Flags: IEEE arithmetic without reassociation (no -ffast-math: results must match the symbolic
#: model), but with ``a * b + c`` contracted to fused multiply-adds where the CPU has them (one
#: rounding instead of two; GCC's default outside strict ISO mode, which -std=c99 would turn off).
CFLAGS = ("-O3", "-fPIC", "-shared", "-std=c99", "-fno-math-errno", "-ffp-contract=fast",
          "-march=native")


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


def cache_dir() -> Path:
    """The compiled-model cache directory (created when missing)."""
    root = os.environ.get("ROBODYN_CACHE")
    if root:
        path = Path(root)
    else:
        base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
        path = Path(base) / "robodyn"
    path.mkdir(parents=True, exist_ok=True)
    return path


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
        Compiler flags (part of the cache key).

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
    compiler = find_compiler()
    # -march=native code is only valid on this kind of processor: it is part of the key
    key = hashlib.sha256("\0".join([source, compiler, *flags, _cpu_id()]).encode()).hexdigest()[:24]
    target = cache_dir() / f"rd_{key}.so"
    if not target.exists():
        with tempfile.TemporaryDirectory(dir=target.parent, prefix=".build-") as tmp:
            src = Path(tmp) / "model.c"
            src.write_text(source)
            out = Path(tmp) / "model.so"
            proc = subprocess.run([compiler, *flags, str(src), "-o", str(out), "-lm"],
                                  capture_output=True, text=True, check=False)
            if proc.returncode != 0:
                raise RuntimeError(f"compiling the generated model failed ({compiler}):\n"
                                   f"{proc.stderr[-4000:]}")
            # atomic: other processes see the old state or the whole library
            os.replace(out, target)
    ffi = cffi.FFI()
    ffi.cdef(declarations)
    lib = ffi.dlopen(str(target))
    return CompiledLibrary(target, ffi, lib)


def _cpu_id() -> str:
    """The processor model, for the cache key."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line
    except OSError:
        pass
    return platform.machine() + platform.processor()
