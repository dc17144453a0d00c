"""Write a robot's generated code in one language into a directory: :func:`generate`.

Languages and the files written (``<robot>`` is the robot's name as an identifier)::

    "c"        <robot>.c, <robot>.h (functions <robot>_*) and <robot>_sim.c, a standalone program
    "python"   <robot>.py (NumPy, vectorised)
    "octave"   <robot>_<kernel>.m, one MATLAB/Octave function file per kernel
    "fortran"  <robot>.f90 (module <robot>, bind(c) subroutines <robot>_*)
    "julia"    <robot>.jl (module CamelCaseName)
    "latex"    <robot>.tex (standalone document)
    "mex"      <robot>.c, <robot>.h, <robot>_mex.c (MEX gateway) and <robot>_sfun.m (S-function)

Every file starts with a comment naming robodyn, the robot, its description hash and the
parameter values folded in.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path

from robodyn.codegen.base import GeneratedFile, identifier
from robodyn.codegen.c import CPrinter, c_files
from robodyn.codegen.fortran import fortran_files
from robodyn.codegen.julia import julia_files
from robodyn.codegen.kernels import KernelSet, build_kernels
from robodyn.codegen.latex import latex_files
from robodyn.codegen.mex import mex_files
from robodyn.codegen.octave import octave_files
from robodyn.codegen.python import python_files
from robodyn.codegen.singular import structural_singularity
from robodyn.robot.errors import InputError, SingularMassMatrixError
from robodyn.robot.model import Robot

LANGUAGES = ("c", "python", "octave", "fortran", "julia", "latex", "mex")


def simulation_program(kset: KernelSet, prefix: str, header_name: str) -> str:
    """C source of a standalone simulator ``main()`` over the generated ``<prefix>simulate``.

    Usage of the compiled program::

        <robot>_sim [duration [dt [x0_1 ... x0_2n]]]      defaults: 1 s, 1 ms, x0 = 0

    ``x0`` is ``[q; qd]`` (2 n values) or ``q`` alone (n values, at rest). The arm moves under
    zero joint torques (passive: gravity, friction and the rigid-body dynamics only), integrated
    by classical RK4 with the step ``dt``; the program prints CSV ``t,q1..qn,qd1..qdn`` to
    stdout, one row per step including the initial state.
    """
    n = kset.dof
    header = CPrinter(prefix).header(kset).rstrip()
    cols = ",".join([f"q{j}" for j in range(1, n + 1)] + [f"qd{j}" for j in range(1, n + 1)])
    return "\n".join([
        header,
        f"// Standalone simulator of {kset.robot_name}: passive motion (zero joint torques), RK4.",
        f"// Build: cc -O2 -std=c99 {kset.robot_name}_sim.c {kset.robot_name}.c -lm "
        f"-o {identifier(kset.robot_name)}_sim",
        f"// Usage: {identifier(kset.robot_name)}_sim [duration [dt [x0_1 ... x0_{2 * n}]]]   "
        f"(x0 = [q; qd] ({2 * n} values) or q alone ({n}); default 1 s, 1 ms, 0)",
        f"// Output: CSV on stdout; header row t,{cols}; then one row per step, the initial state "
        "first:",
        f"//   t in s, q1..q{n} joint positions (rad or m), qd1..qd{n} joint velocities (rad/s or m/s).",
        "#include <errno.h>",
        "#include <math.h>",
        "#include <stdio.h>",
        "#include <stdlib.h>",
        f'#include "{header_name}"',
        "",
        f"enum {{ N = {n}, NX = {2 * n} }};",
        "",
        "/* argv[k] as a finite double, or exit with a message naming it. */",
        "static double number(const char *text, const char *what) {",
        "    char *end = NULL;",
        "    errno = 0;",
        "    double v = strtod(text, &end);",
        "    if (errno != 0 || end == text || *end != '\\0' || !isfinite(v)) {",
        "        fprintf(stderr, \"error: %s must be a finite number, got '%s'\\n\", what, text);",
        "        exit(2);",
        "    }",
        "    return v;",
        "}",
        "",
        "static void print_row(double t, const double *x) {",
        "    printf(\"%.17g\", t);",
        "    for (int i = 0; i < NX; ++i) printf(\",%.17g\", x[i]);",
        "    printf(\"\\n\");",
        "}",
        "",
        "int main(int argc, char **argv) {",
        "    double duration = argc > 1 ? number(argv[1], \"duration\") : 1.0;",
        "    double dt = argc > 2 ? number(argv[2], \"dt\") : 1e-3;",
        "    double x[NX] = {0}, traj[2 * NX];",
        "    int given = argc > 3 ? argc - 3 : 0;",
        "    if (given != 0 && given != N && given != NX) {",
        "        fprintf(stderr, \"error: give %d values (q) or %d values (q then qd) for x0, got %d\\n\",",
        "                N, NX, given);",
        "        return 2;",
        "    }",
        "    if (duration < 0.0 || dt <= 0.0) {",
        "        fprintf(stderr, \"error: need duration >= 0 and dt > 0, got %g and %g\\n\", duration, dt);",
        "        return 2;",
        "    }",
        "    for (int i = 0; i < given; ++i) x[i] = number(argv[3 + i], \"x0 entry\");",
        "    /* steps = round(duration / dt) */",
        "    long steps = (long)floor(duration / dt + 0.5);",
        f"    printf(\"t,{cols}\\n\");",
        "    print_row(0.0, x);",
        "    for (long k = 0; k < steps; ++k) {",
        "        /* one RK4 step under zero torque: traj = [x_k, x_k+1] */",
        f"        int status = {prefix}simulate(1, dt, 0, x, NULL, NULL, NULL, NULL, 0, NULL, 0, traj,"
        " NULL);",
        "        if (status != 0) {",
        "            fprintf(stderr, \"error: the state stopped being finite at t = %g s\\n\",",
        "                    (k + 1) * dt);",
        "            return 1;",
        "        }",
        "        for (int i = 0; i < NX; ++i) x[i] = traj[NX + i];",
        "        print_row((k + 1) * dt, x);",
        "    }",
        "    return 0;",
        "}",
        "",
    ])


def _c(kset: KernelSet) -> list[GeneratedFile]:
    stem = identifier(kset.robot_name)
    files = c_files(kset, prefix=f"{stem}_")
    if "state_derivative" in kset.names:
        header_name = files[0].name
        files.append(GeneratedFile(f"{stem}_sim.c", simulation_program(kset, f"{stem}_", header_name)))
    return files


def _mex(kset: KernelSet) -> list[GeneratedFile]:
    stem = identifier(kset.robot_name)
    files = c_files(kset, prefix=f"{stem}_")
    return files + mex_files(kset, c_name=files[1].name, prefix=f"{stem}_")


_WRITERS: dict[str, Callable[[KernelSet], list[GeneratedFile]]] = {
    "c": _c,
    "python": python_files,
    "octave": octave_files,
    "fortran": fortran_files,
    "julia": julia_files,
    "latex": latex_files,
    "mex": _mex,
}


def generate(robot_or_kset: Robot | KernelSet, lang: str, directory: str | Path, *,
             parameters: Mapping[str, float] | None = None) -> list[Path]:
    """Write the generated code of a robot in one language.

    Parameters
    ----------
    robot_or_kset : Robot or KernelSet
        A robot (its kernels are built here) or kernels already built by
        :func:`robodyn.codegen.kernels.build_kernels`.
    lang : {"c", "python", "octave", "fortran", "julia", "latex", "mex"}
    directory : str or Path
        Where to write (created when missing; files of the same names are replaced).
    parameters : mapping of str to float, optional
        Overrides of the robot's parameter defaults (only with a Robot).

    Returns
    -------
    list of Path
        The files written, in a fixed order.
    """
    if lang not in _WRITERS:
        raise InputError(f"unknown language {lang!r}; choose one of {', '.join(LANGUAGES)}")
    if isinstance(robot_or_kset, KernelSet):
        if parameters:
            raise InputError("parameters are folded in when kernels are built: pass the Robot, or "
                             "build_kernels(robot, parameters) yourself")
        kset = robot_or_kset
    elif isinstance(robot_or_kset, Robot):
        kset = build_kernels(robot_or_kset, parameters)
        why = structural_singularity(robot_or_kset, kset, {})  # every parameter folded
        if why is not None:
            raise SingularMassMatrixError(why + " (no code is generated for a robot without "
                                                "forward dynamics)")
    else:
        raise TypeError(f"generate needs a Robot or a KernelSet, got {type(robot_or_kset).__name__}")
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for f in _WRITERS[lang](kset):
        if Path(f.name).name != f.name or f.name in ("", ".", ".."):
            raise InputError(f"generated file name {f.name!r} is not a plain file name")
        path = out / f.name
        path.write_text(f.text)
        written.append(path)
    return written
