"""Pinocchio compiled natively, the fair peer of robodyn's kernels (issue 22, item 1a).

``benchmarks/native/pinocchio_bench.cpp`` is built with the C++ driver of the compiler robodyn
uses for its kernels (``robodyn.codegen.build.find_compiler``; ``$CXX`` if set, checked to be
the same version) and robodyn's optimisation flags (``robodyn.codegen.build.CFLAGS`` without
``-fPIC -shared -std=c99``), plus ``-std=c++17 -DNDEBUG`` (a release build: no Eigen
assertions) and the Boost.MPL limits that Pinocchio's own CMake target requires. Headers: the
``pin`` wheel's ``cmeel.prefix/include`` and Eigen's from ``cmeel-eigen``. Header-only: no
``libpinocchio*.so`` is linked, every algorithm is instantiated for this CPU.

The binary is cached in ``benchmarks/.build/`` (git-ignored) under a hash of the source, the
compiler and its version, the flags, the header versions and the processor. Where no compiler
or no headers exist, :class:`NativeUnavailable` says why in one line.

The model is written from the Python Pinocchio model of the benchmark (joint types, placements,
inertias, armature, gravity), so both libraries see exactly the same numbers.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robodyn.codegen.build import (
    CFLAGS,
    SCALAR_GCC_FLAGS,
    CompilerNotFoundError,
    compiler_flags,
    find_compiler,
)

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "native" / "pinocchio_bench.cpp"
BUILD_DIR = HERE / ".build"
#: Compile definitions of Pinocchio's CMake target ``pinocchio::pinocchio_headers``.
PINOCCHIO_DEFINES = ("BOOST_MPL_LIMIT_LIST_SIZE=30", "BOOST_MPL_LIMIT_VECTOR_SIZE=30",
                     "BOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "BOOST_FUSION_INVOKE_MAX_ARITY=12")
#: robodyn's flags that do not apply to a C++ executable.
_NOT_FOR_EXECUTABLE = ("-fPIC", "-shared", "-std=c99")
_CXX_OF = {"cc": "c++", "gcc": "g++", "clang": "clang++"}


class NativeUnavailable(RuntimeError):
    """The native peer cannot be built here (no C++ compiler, no headers): one line why."""


@dataclass(frozen=True)
class NativeBuild:
    """A built native peer.

    Attributes
    ----------
    path : Path
        The executable.
    compiler : str
        The C++ driver used.
    version : str
        Its version line.
    flags : tuple of str
        All flags given to it (include folders apart).
    cached : bool
        Whether the executable came from the cache.
    """

    path: Path
    compiler: str
    version: str
    flags: tuple[str, ...]
    cached: bool


@dataclass(frozen=True)
class NativeRun:
    """Timings and outputs of one run of the native peer.

    Attributes
    ----------
    seconds : dict
        Kernel name (``rnea``, ``aba``, ``aba_world``, ``aba_derivatives``) to wall seconds of
        each repeat of its loop over all states.
    tau, qdd : ndarray (N, n)
        ``rnea(q, qd, qdd)`` and ``aba(q, qd, tau)`` (LOCAL convention).
    ddq_dq, ddq_dv, minv : ndarray (ncheck, n, n)
        ``computeABADerivatives`` at the first ``ncheck`` states.
    versions : dict
        Pinocchio and Eigen versions the binary was compiled against.
    """

    seconds: dict[str, list[float]]
    tau: np.ndarray
    qdd: np.ndarray
    ddq_dq: np.ndarray
    ddq_dv: np.ndarray
    minv: np.ndarray
    versions: dict[str, str]


def _version(compiler: str) -> str:
    proc = subprocess.run([compiler, "--version"], capture_output=True, text=True, check=False)
    return proc.stdout.splitlines()[0].strip() if proc.returncode == 0 and proc.stdout else ""


def _dump_version(compiler: str) -> str:
    proc = subprocess.run([compiler, "-dumpfullversion", "-dumpversion"], capture_output=True,
                          text=True, check=False)
    return proc.stdout.strip()


def cxx_compiler() -> tuple[str, str]:
    """The C++ driver of robodyn's C compiler, and its version line.

    Returns
    -------
    compiler, version : str

    Raises
    ------
    NativeUnavailable
        No C or C++ compiler, or the C++ one is not the same compiler version as robodyn's C one.
    """
    try:
        cc = find_compiler()
    except CompilerNotFoundError as exc:
        raise NativeUnavailable("no C compiler for robodyn's kernels, so no peer built with "
                                "the same compiler") from exc
    name = Path(cc).name
    base, _, suffix = name.partition("-")
    guess = _CXX_OF.get(base, base) + ("-" + suffix if suffix else "")
    wanted = os.environ.get("CXX") or guess
    cxx = shutil.which(wanted) or shutil.which(os.path.join(os.path.dirname(cc), wanted))
    if not cxx:
        raise NativeUnavailable(f"no C++ compiler {wanted} beside robodyn's C compiler {cc} "
                                "($CXX, else the C compiler's C++ driver); install g++ or set CXX")
    c_family, cxx_family = ("clang" in _version(c).lower() for c in (cc, cxx))
    if _dump_version(cc) != _dump_version(cxx) or c_family != cxx_family:
        raise NativeUnavailable(f"C++ compiler {cxx} ({_version(cxx)}) is not the same compiler "
                                f"as robodyn's {cc} ({_version(cc)}); set CXX")
    return cxx, _version(cxx)


def native_flags() -> tuple[str, ...]:
    """robodyn's optimisation flags for C++ (with those it adds for its compiler's vector code,
    :func:`robodyn.codegen.build.compiler_flags`), ``-std=c++17 -DNDEBUG`` and Pinocchio's
    defines."""
    robodyn = tuple(f for f in CFLAGS if f not in _NOT_FOR_EXECUTABLE)
    try:
        added = tuple(f for f in compiler_flags(find_compiler()) if f not in SCALAR_GCC_FLAGS)
    except CompilerNotFoundError:
        added = ()
    return (*robodyn, *added, "-std=c++17", "-DNDEBUG", *(f"-D{d}" for d in PINOCCHIO_DEFINES))


def include_dirs() -> list[Path]:
    """The ``pin`` wheel's headers (with Boost) and Eigen's from ``cmeel-eigen``.

    Raises
    ------
    NativeUnavailable
        When either is not installed.
    """
    prefix = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "include"
    if not (prefix / "pinocchio" / "algorithm" / "aba-derivatives.hpp").exists():
        raise NativeUnavailable(f"no Pinocchio headers in {prefix} (pip install pin)")
    if not (prefix / "eigen3" / "Eigen" / "Core").exists():
        raise NativeUnavailable(f"no Eigen headers in {prefix / 'eigen3'} (pip install "
                                "cmeel-eigen, in robodyn's 'test' extra)")
    return [prefix, prefix / "eigen3"]


def _cpu_key() -> str:
    """Processor model and feature flags (what ``-march=native`` compiles for)."""
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        return sys.platform
    return "\n".join(next((x for x in lines if x.startswith(k)), "") for k in ("model name", "flags"))


def build(log: Any = print) -> NativeBuild:
    """Build the native peer, or find it in the cache.

    Parameters
    ----------
    log : callable
        Told one line before a (slow, about 2 minutes) compilation.

    Returns
    -------
    NativeBuild

    Raises
    ------
    NativeUnavailable
        No compiler, no headers, or the compilation failed (its last lines included).
    """
    cxx, version = cxx_compiler()
    includes = include_dirs()
    flags = native_flags()
    headers = [(d / "pinocchio" / "config.hpp") for d in includes[:1]]
    headers.append(includes[1] / "Eigen" / "src" / "Core" / "util" / "Macros.h")
    key = hashlib.sha256("\0".join([SOURCE.read_text(), cxx, version, *flags, _cpu_key(),
                                    *(h.read_text() for h in headers if h.exists())]).encode())
    exe = BUILD_DIR / f"pinocchio_bench_{key.hexdigest()[:20]}"
    if exe.exists():
        return NativeBuild(exe, cxx, version, flags, cached=True)
    BUILD_DIR.mkdir(parents=True, exist_ok=True)
    log(f"building the native Pinocchio peer ({Path(cxx).name} {' '.join(flags[:4])} ...; "
        "about 2 minutes, once, then cached in benchmarks/.build/)")
    with tempfile.TemporaryDirectory(dir=BUILD_DIR) as tmp:
        out = Path(tmp) / "pinocchio_bench"
        args = [cxx, *flags, *(f"-I{d}" for d in includes), str(SOURCE), "-o", str(out)]
        proc = subprocess.run(args, capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            tail = "\n".join(proc.stderr.splitlines()[-15:])
            raise NativeUnavailable(f"compiling {SOURCE.name} failed:\n{tail}")
        os.replace(out, exe)
    return NativeBuild(exe, cxx, version, flags, cached=False)


_TYPES = {"JointModelRX": "RX", "JointModelRY": "RY", "JointModelRZ": "RZ",
          "JointModelPX": "PX", "JointModelPY": "PY", "JointModelPZ": "PZ",
          "JointModelRevoluteUnaligned": "RU", "JointModelPrismaticUnaligned": "PU"}


def model_text(pmodel: Any) -> str:
    """The benchmark's Python Pinocchio model in the native peer's text format.

    Parameters
    ----------
    pmodel : pinocchio.Model
        A chain of one-degree-of-freedom joints, one body each.

    Returns
    -------
    str
        ``nq``, ``gravity`` and one ``joint`` line per joint (see the C++ source).
    """
    lines = [f"nq {pmodel.nq}", "gravity " + " ".join(f"{g:.17g}" for g in pmodel.gravity.linear)]
    for j in range(1, pmodel.njoints):
        joint = pmodel.joints[j]
        kind = _TYPES.get(joint.shortname())
        if kind is None or joint.nq != 1 or joint.nv != 1:
            raise NativeUnavailable(f"joint type {joint.shortname()} not supported by the peer")
        axis = np.asarray(joint.extract().axis, float) if kind in ("RU", "PU") else np.zeros(3)
        place, inertia = pmodel.jointPlacements[j], pmodel.inertias[j]
        i = np.asarray(inertia.inertia)
        numbers = [*axis, *np.asarray(place.rotation).ravel(), *place.translation, inertia.mass,
                   *inertia.lever, i[0, 0], i[0, 1], i[0, 2], i[1, 1], i[1, 2], i[2, 2],
                   pmodel.armature[joint.idx_v]]
        lines.append(f"joint {kind} {pmodel.parents[j]} " + " ".join(f"{x:.17g}" for x in numbers))
    return "\n".join(lines) + "\n"


class NativeRunner:
    """Runs the native peer over fixed states; the input files are written once.

    Used as a context manager (the files live in a temporary folder until it exits), so that
    the benchmark can call :meth:`run` once per round, taking turns with the other libraries.

    Parameters
    ----------
    native : NativeBuild
    pmodel : pinocchio.Model
        The model (written with :func:`model_text`).
    states : tuple of ndarray (N, n)
        ``q, qd, qdd, tau``: ``rnea`` at ``(q, qd, qdd)``, ``aba`` and its derivatives at
        ``(q, qd, tau)``.
    """

    def __init__(self, native: NativeBuild, pmodel: Any, states: tuple[np.ndarray, ...]) -> None:
        self.native = native
        self.count, self.n = states[0].shape
        self._tmp = tempfile.TemporaryDirectory()
        self.folder = Path(self._tmp.name)
        (self.folder / "model.txt").write_text(model_text(pmodel))
        with open(self.folder / "states.bin", "wb") as fh:
            np.array([self.count, self.n], "<i8").tofile(fh)
            for a in states:
                np.ascontiguousarray(a, "<f8").tofile(fh)

    def __enter__(self) -> NativeRunner:
        return self

    def __exit__(self, *exc: object) -> None:
        self._tmp.cleanup()

    def run(self, repeats: int, ncheck: int) -> NativeRun:
        """One process: ``repeats`` timed loops per kernel, outputs read back.

        Parameters
        ----------
        repeats : int
            Timed loops over all states per kernel (taking turns inside the process).
        ncheck : int
            States whose derivatives are written back for the error check.

        Returns
        -------
        NativeRun
        """
        count, n, folder = self.count, self.n, self.folder
        args = [str(self.native.path), str(folder / "model.txt"), str(folder / "states.bin"),
                str(folder / "out.bin"), str(repeats), str(ncheck)]
        proc = subprocess.run(args, capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            raise RuntimeError(f"native Pinocchio peer failed: {proc.stderr.strip()}")
        report = json.loads(proc.stdout.strip().splitlines()[-1])
        out = np.fromfile(folder / "out.bin", "<f8")
        ncheck = min(ncheck, count)
        tau, qdd = out[:count * n].reshape(count, n), out[count * n:2 * count * n].reshape(count, n)
        derivs = out[2 * count * n:].reshape(ncheck, 3, n, n)
        minv = np.triu(derivs[:, 2]) + np.swapaxes(np.triu(derivs[:, 2], 1), 1, 2)
        versions = {k: report.pop(k) for k in ("pinocchio", "eigen")}
        return NativeRun(report, tau, qdd, derivs[:, 0], derivs[:, 1], minv, versions)
