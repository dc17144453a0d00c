"""``compile_model``: a robot's generated kernels, loaded in-process behind batched NumPy calls.

Array rules (DESIGN.md): one state is ``(n,)``, a batch is ``(N, n)``; results are ``(n,)``,
``(n, n)``, ``(4, 4)`` for one state and gain a leading ``N`` for a batch, whatever the values.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from types import ModuleType
from typing import Literal

import numpy as np

from robodyn.codegen.build import (
    CompiledLibrary,
    cache_dir,
    compile_library,
)
from robodyn.codegen.c import CPrinter
from robodyn.codegen.c_outputs import STREAM_MIN_BYTES
from robodyn.codegen.kernels import (
    DERIVATIVE_KERNEL_NAMES,
    REGRESSOR_DERIVATIVE_KERNEL_NAMES,
    KernelSet,
    build_kernels,
    kernel_signature,
)
from robodyn.codegen.python import PythonPrinter
from robodyn.numeric.checks import (
    batch_inputs,
    out_buffer,
    structural_singularity,
    thread_count,
    without_infinities,
)
from robodyn.numeric.joint_corrections import link_positions
from robodyn.numeric.model_cache import (
    _code_hash,
    _from_cache,
    _generator_hash,
    _import_file,
    _kernels_cached,
    _write_atomic,
    _write_checked,
    openmp_flags,
)
from robodyn.numeric.runtime_parameters import (
    ParameterValues,
    check_physics,
    parameter_array,
    runtime_names,
)
from robodyn.robot.errors import InputError, SingularMassMatrixError
from robodyn.robot.model import Robot
from robodyn.robot.overrides import checked_parameter_values

Backend = Literal["c", "numpy"]
_PREFIX = "rd_"



@dataclass(frozen=True, eq=False)
class Model:
    """Numeric dynamics and kinematics of one robot with fixed parameter values.

    Built by :func:`compile_model`. Every method accepts one state ``(n,)`` or a batch ``(N, n)``.

    Attributes
    ----------
    robot : Robot
    backend : {"c", "numpy"}
    parameter_values : tuple of (str, float)
        The parameter values compiled in (for runtime parameters: the values used when a call
        gives none).
    runtime_parameters : tuple of str
        Named parameters that are kernel inputs rather than compiled constants
        (``compile_model(robot, runtime_parameters=...)``): every method then takes
        ``parameters=`` (one set, or one per state of a batch; see :data:`ParameterValues`), and
        :func:`~robodyn.simulation.rollouts.rollout` one set per trajectory of an ensemble.
        Empty: all folded.
    singular : str or None
        Why the mass matrix is singular in every configuration (a kinematics-only description,
        such as a calibration's), or None. Such a model still gives kinematics, inverse dynamics
        and the regressor; forward dynamics, simulation and their derivatives raise
        :class:`~robodyn.robot.errors.SingularMassMatrixError` with this reason.
    sources : tuple of Path
        The cache files the model was generated into (``rd_model_<key>.c`` and ``.cdef``, or
        ``.py``; and ``.singular`` when it exists): what :mod:`robodyn.studies.shipping` sends to
        workers with the compiled library so that they need neither the derivation nor a compiler.
    """

    robot: Robot
    backend: str
    parameter_values: tuple[tuple[str, float], ...]
    _impl: CompiledLibrary | ModuleType = field(repr=False, compare=False)
    runtime_parameters: tuple[str, ...] = ()
    singular: str | None = None
    sources: tuple[Path, ...] = field(default=(), repr=False, compare=False)

    @property
    def dof(self) -> int:
        """Number of joints n."""
        return self.robot.dof

    @property
    def parameters(self) -> dict[str, float]:
        """The parameter values compiled into the model."""
        return dict(self.parameter_values)

    @cached_property
    def kernels(self) -> KernelSet:
        """The generated programs (printable in any language by :mod:`robodyn.codegen`)."""
        return _kernels_cached(self.robot, self.parameters, self.runtime_parameters)

    def with_parameters(self, values: Mapping[str, float]) -> Model:
        """The same compiled code with other default values of its runtime parameters.

        No compilation: the new model shares the loaded library. Values are checked like
        ``compile_model(parameters=...)`` (finite, physically possible).

        Parameters
        ----------
        values : mapping of str to float
            New values of some of :attr:`runtime_parameters`.

        Returns
        -------
        Model
        """
        names = self.runtime_parameters
        row = parameter_array(names, self.parameters, dict(values), (), "with_parameters")
        check_physics(self.robot, names, self.parameters, row, "with_parameters")
        merged = {**self.parameters, **dict(zip(names, row.tolist(), strict=True))}
        return Model(self.robot, self.backend, tuple(sorted(merged.items())), self._impl, names,
                     self.singular, self.sources)

    # --- public kernels ------------------------------------------------------------------------
    def inverse_dynamics(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, *,
                         threads: int = 1, parameters: ParameterValues = None,
                         out: np.ndarray | None = None) -> np.ndarray:
        """Joint torques ``tau = M qdd + C qd + g + friction``, shape like ``q`` (N m or N).

        ``threads``: threads of a batch call (every method takes it; the result bits do not
        depend on it; the NumPy backend uses one). ``parameters``: values of the
        :attr:`runtime_parameters` (every method takes it): a mapping, a sequence of N
        mappings or an array (P,) / (N, P) (one set, or one per state); None: the defaults.
        ``out``: an array that receives the result (as for :meth:`regressor`; also taken by
        :meth:`mass_matrix`, :meth:`gravity`, :meth:`coriolis`, :meth:`forward_dynamics` and
        :meth:`state_derivative`): repeated batches reuse its memory instead of allocating and
        first touching a new array.
        """
        return self._call("inverse_dynamics", q, qd, qdd, threads=threads, parameters=parameters,
                          out=out)

    def mass_matrix(self, q: np.ndarray, *, threads: int = 1, parameters: ParameterValues = None,
                    out: np.ndarray | None = None) -> np.ndarray:
        """Joint-space inertia (rotor inertia included), (n, n) or (N, n, n)."""
        return self._call("mass_matrix", q, threads=threads, parameters=parameters, out=out)

    def gravity(self, q: np.ndarray, *, threads: int = 1, parameters: ParameterValues = None,
                out: np.ndarray | None = None) -> np.ndarray:
        """Gravity load ``g(q)``: the torques that hold the arm still, shape like ``q``."""
        return self._call("gravity", q, threads=threads, parameters=parameters, out=out)

    def coriolis(self, q: np.ndarray, qd: np.ndarray, *, threads: int = 1,
                 parameters: ParameterValues = None, out: np.ndarray | None = None) -> np.ndarray:
        """Coriolis and centrifugal torques ``C(q, qd) qd``, shape like ``q``."""
        return self._call("coriolis", q, qd, threads=threads, parameters=parameters, out=out)

    def forward_dynamics(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray, *,
                         threads: int = 1, parameters: ParameterValues = None,
                         out: np.ndarray | None = None) -> np.ndarray:
        """Joint accelerations ``qdd = M^-1 (tau - C qd - g - friction)``, shape like ``q``.

        Raises
        ------
        SingularMassMatrixError
            When ``M(q)`` is singular at a state (finite inputs, non-finite result).
        """
        self._require_dynamics()
        qdd, bad = self._call_counted("forward_dynamics", q, qd, tau, threads=threads,
                                      parameters=parameters, out=out)
        return self._nonsingular(qdd, q, parameters, bad)

    def state_derivative(self, x: np.ndarray, tau: np.ndarray, *, threads: int = 1,
                         parameters: ParameterValues = None,
                         out: np.ndarray | None = None) -> np.ndarray:
        """``[qd, qdd]`` of the state ``x = [q, qd]``, (2 n,) or (N, 2 n).

        Raises
        ------
        SingularMassMatrixError
            When ``M(q)`` is singular at a state (finite inputs, non-finite result).
        """
        self._require_dynamics()
        xd, bad = self._call_counted("state_derivative", x, tau, threads=threads,
                                     parameters=parameters, out=out)
        return self._nonsingular(xd, np.asarray(x, dtype=float)[..., : self.dof], parameters, bad)

    def check_mass_matrix(self, q: np.ndarray, parameters: ParameterValues = None) -> None:
        """Raise :class:`SingularMassMatrixError` when ``M(q)`` is not positive definite.

        Parameters
        ----------
        q : (n,)
            Joint positions (rad, m); non-finite positions are not checked.
        parameters : one set of runtime parameter values, optional
        """
        q = np.asarray(q, dtype=float)
        if not np.all(np.isfinite(q)):
            return
        m = self.mass_matrix(q, parameters=parameters)
        if not np.all(np.isfinite(m)):
            raise SingularMassMatrixError(f"{self.robot.name}: the mass matrix is not finite at "
                                          f"q = {np.array2string(q, precision=4)}")
        lam, vec = np.linalg.eigh(0.5 * (m + m.T))
        # singular when the smallest eigenvalue is rounding noise next to the largest
        if lam[0] > 1e-12 * max(abs(lam[-1]), 1e-300):
            return
        j = int(np.argmax(np.abs(vec[:, 0])))
        joint = self.robot.joints[j].name
        raise SingularMassMatrixError(
            f"{self.robot.name}: the mass matrix is singular at q = "
            f"{np.array2string(q, precision=4)} (smallest eigenvalue {lam[0]:.3g} against "
            f"{lam[-1]:.3g}, mostly joint {joint!r}): joint velocities along "
            f"{np.array2string(vec[:, 0], precision=3)} move no mass or inertia here (a massless "
            "link, a point mass on a joint axis), so the forward dynamics has no solution; give "
            "the links mass and inertia, or the joints rotor inertia")

    def _require_dynamics(self) -> None:
        """Raise :class:`SingularMassMatrixError` for a model without forward dynamics."""
        if self.singular is not None:
            raise SingularMassMatrixError(self.singular)

    def _nonsingular(self, out: np.ndarray, q: np.ndarray, parameters: ParameterValues = None,
                     nonfinite: int | None = None) -> np.ndarray:
        """``out`` unchanged when finite; otherwise check ``M`` at the first non-finite row.
        ``nonfinite``: the kernel's own count of blocks with a non-finite output (0: finite,
        nothing read back; None: not counted)."""
        if nonfinite == 0 or np.all(np.isfinite(out)):
            return out
        rows = np.atleast_2d(np.asarray(q, dtype=float))
        bad = ~np.all(np.isfinite(out.reshape(rows.shape[0], -1)), axis=1)
        i = int(np.argmax(bad))
        p = None
        if self.runtime_parameters:
            p = self.parameter_input(parameters, np.shape(q)[:-1], "check_mass_matrix")
            p = p[i] if p.ndim == 2 else p
        self.check_mass_matrix(rows[i], p)
        return out

    def forward_kinematics(self, q: np.ndarray, *, threads: int = 1,
                           parameters: ParameterValues = None) -> np.ndarray:
        """End-effector pose in the base frame, (4, 4) or (N, 4, 4).

        When the description carries joint-reading corrections (a calibration's compliance and
        transmission errors, ``robot.corrections``), ``q`` are the joint readings and the pose is
        that of the corrected link angles (:func:`robodyn.numeric.joint_corrections.link_positions`).
        """
        if self.robot.corrections is not None:
            q = link_positions(self.robot, q)
        return self._call("forward_kinematics", q, threads=threads, parameters=parameters)

    def jacobian(self, q: np.ndarray, *, threads: int = 1,
                 parameters: ParameterValues = None) -> np.ndarray:
        """Geometric Jacobian ``[v; omega]`` of the tool origin, base frame, (6, n) or (N, 6, n).

        With joint-reading corrections (see :meth:`forward_kinematics`), with respect to the
        readings: ``J(x) dx/dq``.
        """
        if self.robot.corrections is None:
            return self._call("jacobian", q, threads=threads, parameters=parameters)
        x, dx = link_positions(self.robot, q, derivative=True)
        return self._call("jacobian", x, threads=threads, parameters=parameters) @ dx

    def regressor(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, *,
                  threads: int = 1, parameters: ParameterValues = None,
                  out: np.ndarray | None = None) -> np.ndarray:
        """Regressor ``Y`` with ``Y @ params == tau``, (n, 15 n) or (N, n, 15 n).

        ``out``: a C-contiguous float64 array of the result's size (any shape, e.g. the stacked
        (N n, 15 n)) that receives the result and is returned (reshaped to the result's shape, a
        view): repeated stacking reuses its memory instead of allocating (and first touching)
        a new array.
        """
        return self._call("regressor", q, qd, qdd, threads=threads, parameters=parameters, out=out)

    def inverse_dynamics_derivatives(self, q: np.ndarray, qd: np.ndarray,
                                     qdd: np.ndarray, *, threads: int = 1,
                                     parameters: ParameterValues = None,
                                     out: np.ndarray | None = None,
                                     ) -> tuple[np.ndarray, np.ndarray]:
        """Partial derivatives of the full inverse dynamics ``tau(q, qd, qdd)``.

        Adjoints of the recorded Newton-Euler program (:mod:`robodyn.symbolic.reverse_mode`),
        compiled on the first call (cached). Viscous friction adds ``Fv`` to ``d tau/dqd``;
        Coulomb friction is a step in ``qd`` with derivative 0 (exact away from ``qd = 0``, where
        it has none). Rotor inertia and, under water, the hydrodynamic terms are differentiated
        too. ``d tau/dqdd`` is the mass matrix (:meth:`mass_matrix`).

        Parameters
        ----------
        q, qd, qdd : (n,) or (N, n)
            Joint positions (rad, m), velocities, accelerations.
        out : array of N n 2n float64, optional
            Receives ``[dtau_dq | dtau_dqd]`` (as ``out=`` of :meth:`regressor`).

        Returns
        -------
        dtau_dq, dtau_dqd : (n, n) or (N, n, n)
            ``[..., i, j] = d tau_i / d q_j`` (N m/rad, N/m) and ``d tau_i / d qd_j``; views into
            one array.
        """
        d = self._derivative_model._call("inverse_dynamics_derivatives", q, qd, qdd, threads=threads,
                                         parameters=parameters, out=out)
        n = self.dof
        return d[..., :n], d[..., n:]

    def forward_dynamics_derivatives(self, q: np.ndarray, qd: np.ndarray,
                                     tau: np.ndarray, *, threads: int = 1,
                                     parameters: ParameterValues = None,
                                     out: np.ndarray | None = None,
                                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Partial derivatives of the forward dynamics ``qdd = FD(q, qd, tau)``.

        Differentiating ``tau(q, qd, qdd) = u``: ``d qdd/dx = -M^-1 d tau/dx`` (x = q or qd)
        evaluated at ``qdd = FD(q, qd, tau)``, and ``d qdd/dtau = M^-1``, all in one generated
        kernel through the Cholesky factor of ``M`` (no inverse). Friction as in
        :meth:`inverse_dynamics_derivatives` (Coulomb step: derivative 0 away from ``qd = 0``).

        Parameters
        ----------
        q, qd : (n,) or (N, n)
        tau : (n,) or (N, n)
            Joint torques (N m) or forces (N).
        out : array of N n 3n float64, optional
            Receives ``[dqdd_dq | dqdd_dqd | dqdd_dtau]`` (as ``out=`` of :meth:`regressor`):
            repeated batches reuse its memory.

        Returns
        -------
        dqdd_dq, dqdd_dqd, dqdd_dtau : (n, n) or (N, n, n)
            ``[..., i, j] = d qdd_i / d x_j``; views into one array.

        Raises
        ------
        SingularMassMatrixError
            When ``M(q)`` is singular at a state (finite inputs, non-finite result).
        """
        self._require_dynamics()
        d, bad = self._derivative_model._call_counted("forward_dynamics_derivatives", q, qd, tau,
                                                      threads=threads, parameters=parameters, out=out)
        n = self.dof
        # singular M: 1/L_jj and so (M^-1)_jj are non-finite; the diagonal spares reading it all
        self._nonsingular(np.diagonal(d[..., 2 * n:], axis1=-2, axis2=-1), q, parameters, bad)
        return d[..., :n], d[..., n:2 * n], d[..., 2 * n:]

    def regressor_derivatives(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, *,
                              threads: int = 1, parameters: ParameterValues = None,
                              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Partial derivatives of the regressor ``Y(q, qd, qdd)`` (:meth:`regressor`).

        Generated by forward-mode differentiation of the regressor's recorded program (as
        :meth:`inverse_dynamics_derivatives`), compiled on the first call (cached, a library of
        its own). The Coulomb and offset friction columns are steps in ``qd``: derivative 0
        (exact away from ``qd = 0``). ``dY/dqdd`` does not depend on ``qdd`` (Y is linear in it).

        Parameters
        ----------
        q, qd, qdd : (n,) or (N, n)

        Returns
        -------
        dY_dq, dY_dqd, dY_dqdd : (n, 15 n, n) or (N, n, 15 n, n)
            ``[..., i, c, j] = d Y_ic / d x_j``; views into one array.
        """
        d = self._regressor_derivative_model._call("regressor_derivatives", q, qd, qdd,
                                                   threads=threads, parameters=parameters)
        n = self.dof
        d = d.reshape(d.shape[:-2] + (n, 15 * n, 3 * n))
        return d[..., :n], d[..., n:2 * n], d[..., 2 * n:]

    @cached_property
    def _derivative_model(self) -> Model:
        """The derivative kernels of this robot, generated and loaded on first use (cached)."""
        return _compile_derivatives(self)

    @cached_property
    def _regressor_derivative_model(self) -> Model:
        """The regressor-derivative kernel, generated and loaded on first use (cached)."""
        return _compile_derivatives(self, REGRESSOR_DERIVATIVE_KERNEL_NAMES, "regderiv")

    # --- plumbing ------------------------------------------------------------------------------
    @cached_property
    def _functions(self) -> frozenset[str]:
        """The library's function names, listed once (a failed ``getattr`` costs cffi 4 us)."""
        return frozenset() if isinstance(self._impl, ModuleType) else frozenset(dir(self._impl.lib))

    def parameter_input(self, value: ParameterValues, batch: tuple[int, ...] = (),
                        where: str = "parameters") -> np.ndarray:
        """The kernels' runtime-parameter input for ``batch`` states, checked.

        Parameters
        ----------
        value : mapping, sequence of N mappings, (P,) or (N, P) array, or None
            See :data:`ParameterValues` (None: the defaults).
        batch : () or (N,)
        where : str
            The caller, for messages.

        Returns
        -------
        (P,) or (N, P) array, columns in the order of :attr:`runtime_parameters`.
        """
        if not self.runtime_parameters:
            raise InputError(f"{where}: parameters=... needs a model compiled with runtime "
                             "parameters (compile_model(robot, runtime_parameters=True or names)); "
                             f"this {self.robot.name} model has its parameter values compiled in")
        return parameter_array(self.runtime_parameters, self.parameters, value, batch,
                               f"{where}(parameters=...)")

    def _call(self, name: str, *arrays: np.ndarray, threads: int = 1,
              parameters: ParameterValues = None, out: np.ndarray | None = None) -> np.ndarray:
        return self._call_counted(name, *arrays, threads=threads, parameters=parameters, out=out)[0]

    def _call_counted(self, name: str, *arrays: np.ndarray, threads: int = 1,
                      parameters: ParameterValues = None, out: np.ndarray | None = None
                      ) -> tuple[np.ndarray, int | None]:
        """Kernel ``name`` on ``arrays``; with the number of blocks whose outputs are not all
        finite where the compiled batch counts them (``PREFIXk_batch_nonfinite``), else None."""
        threads = thread_count(threads)
        inputs, result_shape = kernel_signature(name, self.dof)
        args, batch_shape = batch_inputs(name, inputs, arrays)
        if self.runtime_parameters or parameters is not None:
            args.append(self.parameter_input(parameters, batch_shape, name))
        out_shape = batch_shape + result_shape
        target = None if out is None else out_buffer(out, out_shape, args, name)
        if isinstance(self._impl, ModuleType):
            # a singular M divides by zero: the callers check the result, not NumPy's warnings
            with np.errstate(divide="ignore", invalid="ignore"):
                result = getattr(self._impl, name)(*args).reshape(out_shape)
            if target is None:
                return result, None
            target[...] = result
            return target, None
        ffi, lib = self._impl.ffi, self._impl.lib
        # C-contiguous float64 inputs are passed without a copy
        args = [np.ascontiguousarray(a) for a in args]
        out = np.empty(out_shape) if target is None else target
        ptrs = [ffi.from_buffer("double[]", a) for a in args]
        out_ptr = ffi.from_buffer("double[]", out)
        stream_name, counted = f"{_PREFIX}{name}_batch_stream", f"{_PREFIX}{name}_batch_nonfinite"
        # streaming stores into a large reused matrix; cached ones into fresh memory, whose
        # lines the operating system has just zeroed through the cache
        stream = int(target is not None and out.nbytes >= STREAM_MIN_BYTES)
        if batch_shape and counted in self._functions:
            return out, int(getattr(lib, counted)(batch_shape[0], threads, stream, *ptrs, out_ptr))
        if batch_shape and stream_name in self._functions:
            getattr(lib, stream_name)(batch_shape[0], threads, stream, *ptrs, out_ptr)
        elif batch_shape and threads > 1:
            getattr(lib, f"{_PREFIX}{name}_batch_threads")(batch_shape[0], threads, *ptrs, out_ptr)
        elif batch_shape:
            getattr(lib, f"{_PREFIX}{name}_batch")(batch_shape[0], *ptrs, out_ptr)
        else:
            getattr(lib, f"{_PREFIX}{name}")(*ptrs, out_ptr)
        return out, None


def compile_model(robot: Robot, backend: Backend = "c", *,
                  parameters: Mapping[str, float] | None = None,
                  runtime_parameters: bool | Sequence[str] = False) -> Model:
    """Generate, compile (cached) and load the numeric model of ``robot``.

    Parameters
    ----------
    robot : Robot
    backend : {"c", "numpy"}
        "c": generated C99 compiled with the system compiler into the cache (see
        :func:`robodyn.codegen.build.cache_dir`), called through cffi. "numpy": the generated
        NumPy module, no compiler needed.
    parameters : mapping of str to float, optional
        Values overriding the robot's parameter defaults.
    runtime_parameters : bool or sequence of str
        Named parameters (``robot.parameters``) that stay inputs of the generated kernels
        instead of being folded in as constants: True for all of them, or their names. Every
        method of the model then takes ``parameters=`` (one set, or one per state), and
        :func:`robodyn.simulation.rollouts.rollout` and :func:`robodyn.simulate` one set per
        trajectory of an ensemble, all in one C call. ``parameters`` gives their default values. The code is
        slower than with folded constants (no constant folding), and a state's bits may
        differ from a model compiled with the same values in the last places (other rounding
        order; the tests hold them to 1e-12 relative).

    Returns
    -------
    Model

    Raises
    ------
    CompilerNotFoundError
        With ``backend="c"`` and no C compiler (the message names the NumPy fallback).
    SingularMassMatrixError
        When the mass matrix is singular whatever the configuration (a joint that moves no mass,
        inertia or rotor inertia, e.g. a massless final link): no forward dynamics exists.
    """
    if backend not in ("c", "numpy"):
        raise InputError(f"unknown backend {backend!r}; choose 'c' (compiled) or 'numpy'")
    # unknown names, non-finite values and impossible physics at the new values are refused
    values = checked_parameter_values(robot, parameters, where="compile_model(parameters=...)")
    runtime = runtime_names(robot, runtime_parameters)
    # generated sources are cached by (description, folded values, runtime names, generator)
    folded = sorted((k, v) for k, v in values.items() if k not in runtime)
    key = hashlib.sha256(repr((_code_hash(robot), folded, backend, _generator_hash())
                              + ((runtime,) if runtime else ())).encode()).hexdigest()[:24]
    directory = cache_dir()
    marker = directory / f"rd_model_{key}.singular"
    if backend == "c":
        src, decl = directory / f"rd_model_{key}.c", directory / f"rd_model_{key}.cdef"

        def write_c() -> None:
            kset = _kinematic_safe(robot, values, runtime, marker)
            printer = CPrinter(_PREFIX)
            _write_atomic(decl, printer.declarations(kset))
            _write_atomic(src, printer.source(kset))

        impl: CompiledLibrary | ModuleType = _from_cache(
            (src, decl), write_c,
            lambda: compile_library(src.read_text(), decl.read_text(), flags=openmp_flags()))
        sources: tuple[Path, ...] = (src, decl)
    else:
        path = directory / f"rd_model_{key}.py"

        def write_py() -> None:
            kset = _kinematic_safe(robot, values, runtime, marker)
            _write_checked(path, PythonPrinter().module(kset))

        impl = _from_cache((path,), write_py, lambda: _import_file(path, f"robodyn_generated_{key}"))
        sources = (path,)
    singular = marker.read_text(encoding="utf-8") if marker.exists() else None
    if singular is not None:
        sources += (marker,)
    return Model(robot, backend, tuple(sorted(values.items())), impl, runtime, singular, sources)


def _kinematic_safe(robot: Robot, values: Mapping[str, float], runtime: tuple[str, ...],
                    marker: Path) -> KernelSet:
    """The kernels to print; for a mass matrix singular in every configuration (a kinematics-only
    description, e.g. a calibration's) the non-finite forward-dynamics entries become NaN and
    ``marker`` records why, so kinematics and inverse dynamics work and forward dynamics
    raises :class:`SingularMassMatrixError` with that reason."""
    kset = _kernels_cached(robot, values, runtime)
    message = structural_singularity(robot, kset, values)
    if message is None:
        marker.unlink(missing_ok=True)
        return kset
    _write_atomic(marker, message)
    return without_infinities(kset)


def _compile_derivatives(model: Model, names: tuple[str, ...] = DERIVATIVE_KERNEL_NAMES,
                         tag: str = "deriv") -> Model:
    """A :class:`Model` over kernels ``names`` only (default :data:`DERIVATIVE_KERNEL_NAMES`)."""
    robot, values, backend = model.robot, model.parameters, model.backend
    runtime = model.runtime_parameters
    folded = sorted((k, v) for k, v in values.items() if k not in runtime)
    what = "derivatives" if tag == "deriv" else tag
    key = hashlib.sha256(repr((_code_hash(robot), folded, backend, what,
                               _generator_hash()) + ((runtime,) if runtime else ()))
                         .encode()).hexdigest()[:24]
    directory = cache_dir()
    if backend == "c":
        src, decl = directory / f"rd_{tag}_{key}.c", directory / f"rd_{tag}_{key}.cdef"

        def write_c() -> None:
            kset = build_kernels(robot, values, names=names, runtime=runtime)
            printer = CPrinter(_PREFIX)
            _write_atomic(decl, printer.declarations(kset, with_simulation=False))
            _write_atomic(src, printer.source(kset, with_simulation=False))

        impl: CompiledLibrary | ModuleType = _from_cache(
            (src, decl), write_c, lambda: compile_library(src.read_text(), decl.read_text()))
    else:
        path = directory / f"rd_{tag}_{key}.py"

        def write_py() -> None:
            kset = build_kernels(robot, values, names=names, runtime=runtime)
            _write_checked(path, PythonPrinter().module(kset))

        impl = _from_cache((path,), write_py,
                           lambda: _import_file(path, f"robodyn_generated_{tag}_{key}"))
    return Model(robot, backend, model.parameter_values, impl, runtime)


__all__ = ["Model", "compile_model"]
