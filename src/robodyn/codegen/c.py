"""C99: reentrant kernels (no globals, no allocation), batched, vectorised and threaded loops.

For each kernel ``k`` the source defines::

    void PREFIXk(const double *in1, ..., double *out);                    one state
    void PREFIXk_batch(long count, const double *in1, ..., double *out);  count states
    void PREFIXk_batch_threads(long count, int threads, ...);             the same on threads

and ``long PREFIXk_batch_nonfinite(...)``, the batch counting its blocks with a non-finite
output, for the kernels a singular mass matrix breaks (``c_outputs.FINITE_CHECKED``), plus
:func:`simulation_source`'s ``PREFIXsimulate`` (a whole trajectory, RK4 or semi-implicit
Euler, under a sampled state-feedback law, in one call) and ``PREFIXsimulate_ensemble`` (many
trajectories at once, a block of them per vector loop).

Every kernel is evaluated a block of :data:`BLOCK` states at a time. The states of a block are
transposed into structure-of-arrays buffers (entry i of state k at ``[BLOCK * i + k]``; by
vector shuffles where there is AVX, :mod:`robodyn.codegen.c_transpose`), then
``PREFIXk_block`` runs the whole straight-line body in one loop over the block's states: loads
and stores are consecutive across states, the body has no calls (the sines and cosines were
evaluated before, see below; sqrt and division are vector instructions) and no branches (the
conditionals are selects), so the compiler vectorises the body itself, 4 or 8 states per
instruction. The body's statements are printed in an order that keeps few values live
(:mod:`robodyn.codegen.schedule`; cores of at most :data:`SCHEDULE_LIMIT` statements). The
outputs are transposed back.

The sines and cosines of the joint angles come from ``PREFIXsincos_block``: one branch-free loop
of polynomial code per angle (Cody-Waite reduction by pi/2 in three parts and fdlibm's minimax
kernels, within 2 ulp of libm; beyond 1e5 rad, infinities and NaN go to libm; the quadrant's
swap and signs are bit operations on the sum that rounded the quadrant number). Compiled by GCC,
that one loop is scheduled before register allocation (``optimize("schedule-insns",
"sched-pressure")``, a function attribute: GCC does not schedule before allocation on x86 by
default), which interleaves the sine's and the cosine's dependency chains; the arithmetic, and so
every bit, is unchanged. Measured on the AMD EPYC with AVX2 (2026-12-06, 10^5 states through
``Model``, builds taking turns, ns per state): PUMA 560 inverse dynamics 40.6-40.8 -> 36.8-38.4,
Kinova Gen3 98.6-101.3 -> 97.2-98.9, the other kernels unchanged within the noise. The same flags
for the whole file helped the PUMA 560's forward dynamics too but cost the Gen3's 15 % and its
derivatives 18 %, and doubled its compile time: hence the one loop. Coulomb
friction's ``qd > 0`` switches are computed while the block is transposed, as selects rather than
mispredicted branches.

The one-state function is the range of one state through the same code: the loop's scalar
remainder runs the same operations as its vector lanes, in IEEE arithmetic, but the compiler may
fuse a product and a sum (``-ffp-contract=fast``) in one and not the other, so a state alone and
the same state in a full block agree to rounding, not always to the bit (measured: the Kinova
regressor at block width 8, last bits of 50 of 735 entries; the tests check 1e-14 of the
largest entry). Within full blocks, the bits depend neither on a state's position in the batch
nor on the number of threads. Threads (OpenMP, when compiled with ``-fopenmp``)
take pieces of whole blocks. All of it is plain C99 with ordinary IEEE arithmetic, no special
flags (vectorisation needs only -O3 and a SIMD target); the one pragma is OpenMP's, inside
``#ifdef _OPENMP``; the compiler-specific attributes (GCC's ``noinline`` on large cores and its
scheduling ``optimize`` on the sine/cosine loop) sit under ``#if defined(__GNUC__)`` and change no
result. The two uses of intrinsics move no value through arithmetic: the inputs' transposition
under ``#if defined(__AVX__)`` (:mod:`robodyn.codegen.c_transpose`), and large outputs
with constant entries (the regressor), which are staged and, for batches too large for the cache,
copied out with streaming stores under ``#if defined(__SSE2__)`` (:mod:`robodyn.codegen.c_outputs`).
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.c import C99CodePrinter

from robodyn.codegen.base import GeneratedFile, Printer, identifier
from robodyn.codegen.c_outputs import (
    FINITE_CHECKED,
    STREAM_MIN_BYTES,
    copy_out_source,
    nonfinite_lines,
    output_lines,
    staged_outputs,
)
from robodyn.codegen.c_simulation import (
    ensemble_signature,
    ensemble_source,
    simulate_signature,
    simulation_source,
)
from robodyn.codegen.c_transpose import gather_source, scatter_source
from robodyn.codegen.cpu import BLOCK  # states per block: 16 with AVX2 or AVX-512, else 8, or ROBODYN_BLOCK
from robodyn.codegen.kernels import Argument, Kernel, KernelSet
from robodyn.codegen.schedule import live_values, low_pressure_order

#: Cores with more assignments than this are not inlined into their batch loop (compile time).
INLINE_LIMIT = 400

#: Outputs of at least this many entries per state (the regressor, the derivatives) can be stored
#: by the core straight into the caller's rows (strided, vector scatter stores) instead of through
#: a structure-of-arrays buffer and a transposition. Off (None): measured 1.46x faster stacking of
#: the Gen3 regressor into a reused matrix, but GCC then evaluates one state alone and the same
#: state in a block differently in the last bit (1 ulp in 2 of 540 PUMA regressor entries), and
#: the batch kernels keep one state's bits whatever the batch (tests/numeric/test_model.py).
DIRECT_MIN: int | None = None

#: Order of the statements in a core: "pressure" (:func:`robodyn.codegen.schedule.low_pressure_order`,
#: few values live at once) or "source" (loads, then the assignments as CSE left them, then the
#: stores; kept for ``benchmarks/bench_schedule.py``, which compares the two).
SCHEDULE = "pressure"

#: Cores of more statements than this keep the given order: measured on the AVX2 EPYC, the
#: Gen3's forward-dynamics derivatives (thousands of statements) ran 5 % slower reordered and its
#: largest kernels took GCC about 30 % longer to compile. Cores that divide or take roots (the
#: forward dynamics' factorisation) keep it too: CSE's order interleaves the factorisation with
#: the bias terms, which hides the latency of its divisions and roots (reordered, even with that
#: latency modelled, the PUMA 560's forward dynamics at 16 states per block took 4 % longer).
SCHEDULE_LIMIT = 600

#: States per thread's piece of a threaded batch (whole blocks, so the same blocks as one thread).
THREAD_CHUNK = 64 * BLOCK

#: Beyond this |angle| (rad), and for infinities and NaN, the block's sine and cosine come from libm.
_POLY_LIMIT = "1.0e5"
#: 1.5 2^52 (see :data:`_SINCOS`).
_ROUND = "6755399441055744.0"

# Constants from fdlibm (e_rem_pio2.c, k_sin.c, k_cos.c): pi/2 in three 33-bit parts plus a
# tail, and the minimax coefficients of sin and cos on [-pi/4, pi/4] (errors below 2^-58).
# ROUND is 1.5 2^52: for |y| < 2^51, y + ROUND rounds y to the nearest integer (ties to even, as
# nearbyint) and leaves that integer's low bits in the last bits of the sum's representation.
_SINCOS = """\
#include <stdint.h>
#include <string.h>

/* s[k] = sin(x[k]), c[k] = cos(x[k]) for k < count: branch-free, so the loop vectorises.
 * x = n pi/2 + r, |r| <= pi/4, with pi/2 in three exact parts (|x| <= 1e5); fdlibm's polynomials
 * for sin r and cos r, then the quadrant n mod 4, read from the bits of the sum that rounded
 * n (memcpy: the compiler's vector bit operations, no integer conversion). Larger |x|,
 * infinities and NaN: libm. */
#if defined(__GNUC__) && !defined(__clang__)
/* GCC: this loop alone is scheduled before register allocation (which GCC does not do by
 * default on x86): the two polynomials' dependency chains interleave (module docstring of
 * robodyn.codegen.c); the arithmetic, and so every bit, is unchanged. */
__attribute__((optimize("schedule-insns", "sched-pressure")))
#endif
static void PREFIXsincos_block(int count, const double *restrict x, double *restrict s,
                               double *restrict c) {
    int big = 0; /* any |x| beyond the polynomials' range (or not a number) */
    for (int k = 0; k < count; ++k) {
        const double a = x[k];
        big |= !(fabs(a) <= LIMIT);
        /* n = a 2/pi rounded to an integer, also held in the low bits of t */
        const double t = a * 6.36619772367581382433e-01 + ROUND;
        const double n = t - ROUND;
        const double r = (((a - n * 1.57079632673412561417e+00) - n * 6.07710050630396597660e-11)
                          - n * 2.02226624871116645580e-21) - n * 8.47842766036889956997e-32;
        const double z = r * r;
        const double w = z * z;
        const double ps = 8.33333333332248946124e-03 + z * (-1.98412698298579493134e-04
                          + z * (2.75573137070700676789e-06 + z * (-2.50507602534068634195e-08
                          + z * 1.58969099521155010221e-10)));
        const double sr = r + z * r * (-1.66666666666666324348e-01 + z * ps);
        const double pc = z * (4.16666666666666019037e-02 + z * (-1.38888888888741095749e-03
                          + z * 2.48015872894767294178e-05)) + w * w * (-2.75573143513906633035e-07
                          + z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11));
        const double hz = 0.5 * z;
        const double v = 1.0 - hz;
        const double cr = v + (((1.0 - v) - hz) + z * pc);
        /* quadrant n mod 4 (t's last two bits): odd ones swap sine and cosine; the sine changes
         * sign in quadrants 2 and 3, the cosine in 1 and 2 (the sign bit flipped) */
        uint64_t qb, sb, cb;
        memcpy(&qb, &t, sizeof qb);
        const double ts = (qb & 1) ? cr : sr, tc = (qb & 1) ? sr : cr;
        memcpy(&sb, &ts, sizeof sb);
        memcpy(&cb, &tc, sizeof cb);
        sb ^= (qb & 2) << 62;
        cb ^= ((qb + 1) & 2) << 62;
        memcpy(&s[k], &sb, sizeof sb);
        memcpy(&c[k], &cb, sizeof cb);
    }
    for (int k = 0; big && k < count; ++k) {
        if (!(fabs(x[k]) <= LIMIT)) {
            s[k] = sin(x[k]);
            c[k] = cos(x[k]);
        }
    }
}
"""


class _CExpr(C99CodePrinter):
    """SymPy's C99 printer with one-line conditionals and exact doubles."""

    def _print_Piecewise(self, expr: sp.Piecewise) -> str:  # noqa: N802 - SymPy's hook name
        (value, cond), (otherwise, _) = expr.args
        return (f"(({self._print(cond)}) ? {self._print(sp.Float(value))} : "
                f"{self._print(sp.Float(otherwise))})")


class CPrinter(Printer):
    """C99 printer; ``prefix`` starts every exported function name."""

    language = "C99"
    comment = "//"

    def __init__(self, prefix: str = "robodyn_") -> None:
        super().__init__(prefix)
        self._printer = _CExpr({"precision": 17})

    def expr(self, e: sp.Expr) -> str:
        return self._printer.doprint(e)

    def signature(self, kernel: Kernel, batch: bool = False, threads: bool = False) -> str:
        """The C prototype (without the trailing semicolon)."""
        args = _parameters(kernel)
        if batch and threads:
            return (f"void {self.prefix}{kernel.name}_batch_threads(long count, int threads, "
                    f"{', '.join(args)})")
        if batch:
            return f"void {self.prefix}{kernel.name}_batch(long count, {', '.join(args)})"
        return f"void {self.prefix}{kernel.name}({', '.join(args)})"

    def open_function(self, kernel: Kernel) -> list[str]:
        shapes = ", ".join(f"{a.name}{list(a.shape)}" for a in (*kernel.inputs, *kernel.outputs))
        return [f"/* {kernel.summary}. Arrays: {shapes}. */", self.signature(kernel) + " {"]

    def close_function(self, kernel: Kernel) -> list[str]:
        return ["}"]

    def unpack(self, arg: Argument, index: int, symbol: sp.Symbol) -> str:
        return f"const double {symbol.name} = {arg.name}[{index}];"

    def assign(self, symbol: sp.Symbol, e: sp.Expr) -> str:
        return f"const double {symbol.name} = {self.expr(e)};"

    def store(self, arg: Argument, index: tuple[int, ...], e: sp.Expr) -> str:
        flat = index[0] if len(index) == 1 else index[0] * arg.shape[1] + index[1]
        return f"{arg.name}[{flat}] = {self.expr(e)};"

    def kernel_source(self, kernel: Kernel) -> str:
        """Block core, range loop, batch, threaded batch and one-state functions of ``kernel``.

        The core (``PREFIXk_block``) evaluates the kernel body for ``m_ <= BLOCK`` states held
        structure-of-arrays (entry i of state k at ``[BLOCK * i + k]``) in one loop whose body
        is straight-line code: the compiler vectorises it across the states. The switches
        (Coulomb friction's ``qd > 0``) are the first assignments of that body: vector compares
        and selects there, not a staged array the range loop fills state by state (which cost
        PUMA 560's inverse dynamics about 15 % in scalar stores).
        """
        angles, steps = _angles(kernel), _steps(kernel)
        sines = [sp.Symbol(f"sin_{a.name}_", real=True) for a, _, _ in angles]
        cosines = [sp.Symbol(f"cos_{a.name}_", real=True) for a, _, _ in angles]
        given: dict[sp.Expr, sp.Expr] = {}
        for (a, _, _), s, c in zip(angles, sines, cosines, strict=True):
            given[sp.sin(a)] = s
            given[sp.cos(a)] = c
        switches = [sp.Symbol(f"step{i}_", real=True) for i in range(len(steps))]
        # step_i = (condition on the inputs) ? 1 : 0, evaluated in the vector loop
        first = tuple((w, st.xreplace(given)) for w, st in zip(switches, steps, strict=True))
        given.update(zip(steps, switches, strict=True))
        outputs = tuple(Argument(o.name, o.shape, tuple(sp.sympify(e).xreplace(given) for e in o.entries))
                        for o in kernel.outputs)
        # outputs with constant entries (the regressor's zeros): the core computes only the
        # others, and each state's row is written from a constant template, then those entries
        computed = {o.name: [i for i, e in enumerate(o.entries) if not e.is_Number] for o in outputs}
        outputs = tuple(Argument(o.name, (len(computed[o.name]),),
                                 tuple(o.entries[i] for i in computed[o.name]))
                        if 0 < len(computed[o.name]) < o.size else o for o in outputs)
        body = first + tuple((s, e.xreplace(given)) for s, e in kernel.body)
        used: set[sp.Basic] = set()
        for e in [e for _, e in body] + [sp.sympify(e) for o in outputs for e in o.entries]:
            used |= e.free_symbols
        extra = [_arg("sin_", sines), _arg("cos_", cosines)]
        # only the arrays the core reads (unused parameters would trip -Wextra)
        inputs = tuple(a for a in (*kernel.inputs, *extra) if used.intersection(a.entries))
        core = Kernel(f"{kernel.name}_block", kernel.summary, inputs, outputs, body)
        single = "\n".join([
            *self.open_function(kernel),
            f"    {self.prefix}{kernel.name}_range(0, 1, {', '.join(_names(kernel))}, 0);",
            "}",
        ]) + "\n"
        direct = {o.name: (o.size, computed[o.name] if 0 < len(computed[o.name]) < o.size
                           else list(range(o.size)))
                  for o in kernel.outputs if DIRECT_MIN is not None and o.size >= DIRECT_MIN}
        return "\n".join([self.block_function(core, len(kernel.body) > INLINE_LIMIT, direct),
                          self.blocked_batch(kernel, core, angles, computed, direct),
                          self.threaded_batch(kernel), single])

    def block_function(self, core: Kernel, noinline: bool = False,
                       direct: dict[str, tuple[int, list[int]]] | None = None) -> str:
        """``static void PREFIXk_block(int m_, ...)``: the body for m_ states, one vector loop.

        Every array is structure-of-arrays with stride :data:`BLOCK` (entry i of state k at
        ``[BLOCK * i + k]``): the loads and stores of one entry are consecutive across the
        states, and the body has no calls but sqrt and no branches but selects. An output in
        ``direct`` (name: (row size, positions of the computed entries)) is the caller's rows
        instead: entry ``c`` of state k stored at ``[size * k + position_c]``.
        """
        direct = direct or {}
        inline = f"{self.prefix.upper()}NOINLINE " if noinline else ""
        args = _parameters(core)
        lines = [f"/* {core.summary}, for m_ <= {BLOCK} states stored structure-of-arrays. */",
                 f"{inline}static void {self.prefix}{core.name}(int m_, {', '.join(args)}) {{",
                 "    for (int k_ = 0; k_ < m_; ++k_) {"]
        # the loads first, in the inputs' order (loads sunk to their first use among the spills'
        # stores made the PUMA 560's inverse dynamics 25 % slower in some code layouts)
        lines += [f"        const double {sym.name} = {arg.name}[{BLOCK * k} + k_];"
                  for arg, k, sym in core.used_inputs()]
        # then (symbol defined or None, statement, expression read): assignments and stores
        statements: list[tuple[sp.Symbol | None, str, sp.Expr]] = [
            (s, self.assign(s, e), e) for s, e in core.body]
        for arg in core.outputs:
            size, where = direct.get(arg.name, (None, None))
            for k, e in enumerate(arg.entries):
                place = f"{size} * k_ + {where[k]}" if where is not None else f"{BLOCK * k} + k_"
                statements.append((None, f"{arg.name}[{place}] = {self.expr(sp.sympify(e))};",
                                   sp.sympify(e)))
        lines += ["        " + statements[i][1] for i in _statement_order(statements)]
        return "\n".join([*lines, "    }", "}"]) + "\n"

    def blocked_batch(self, kernel: Kernel, core: Kernel, angles: list[tuple[sp.Symbol, str, int]],
                      computed: dict[str, list[int]] | None = None,
                      direct: dict[str, tuple[int, list[int]]] | None = None) -> str:
        """``PREFIXk_range`` (states [begin, end), a block at a time) and ``PREFIXk_batch``.

        Per block: the inputs are transposed into structure-of-arrays buffers; then vector
        loops give the sines and cosines (:func:`_trig_lines`), the core runs, and the outputs are
        transposed back (:func:`robodyn.codegen.c_outputs.output_lines`). ``stream_`` (set
        by the batch functions for large batches) makes staged outputs use streaming stores.
        """
        na = len(angles)
        direct = direct or {}
        core_inputs = {a.name for a in core.inputs}
        gathered = [a for a in kernel.inputs
                    if a.name in core_inputs or any(name == a.name for _, name, _ in angles)]
        gather = [f"        {self.prefix}gather(m_, {a.size}, {a.name} + {a.size} * k0_, {a.name}_b_);"
                  for a in gathered]
        out = output_lines(self.prefix, self.expr, kernel, core, computed or {}, direct, BLOCK)
        sizes = {a.name: a.size for a in core.outputs}
        arrays = [f"{a.name}_b_[{sizes.get(a.name, a.size) * BLOCK}]"
                  for a in (*gathered, *kernel.outputs) if a.name not in direct]
        arrays += [f"sin_[{na * BLOCK}]", f"cos_[{na * BLOCK}]"] if na else []
        trig = _trig_lines(self.prefix, angles)
        args = [a.name if a.name in ("sin_", "cos_") else f"{a.name}_b_"
                for a in core.inputs]
        args += [f"{a.name} + {direct[a.name][0]} * k0_" if a.name in direct else f"{a.name}_b_"
                 for a in core.outputs]
        # (a kernel whose outputs are constants reads no input)
        transpose = ["        /* transpose the block's inputs: x_b_[BLOCK i + k] = x[size (k0 + k) + i] */",
                     *gather] if gather else []
        params = ", ".join(_parameters(kernel))
        stream = (f"count >= {-(-STREAM_MIN_BYTES // out.staged_bytes)}L" if out.staged_bytes
                  else "(void)count, 0")
        checked = kernel.name in FINITE_CHECKED
        return "\n".join([
            *out.tables,
            f"/* {kernel.name} for the states begin <= j < end stored one after another, {BLOCK} at a "
            "time; returns " + ("the number of blocks with a non-finite output. */" if checked
                                else "0. */"),
            f"static long {self.prefix}{kernel.name}_range(long begin, long end, {params}, int stream_) {{",
            f"    double {', '.join(arrays + out.arrays)};",
            "    long nonfinite_ = 0;",
            *(out.start or ["    (void)stream_;"]),
            f"    for (long k0_ = begin; k0_ < end; k0_ += {BLOCK}) {{",
            f"        const int m_ = end - k0_ < {BLOCK} ? (int)(end - k0_) : {BLOCK};",
            *transpose,
            *trig,
            *out.fill,
            f"        {self.prefix}{core.name}(m_, {', '.join(args)});",
            *(nonfinite_lines(kernel, core, computed or {}, BLOCK) if checked else []),
            *(["        for (int k_ = 0; k_ < m_; ++k_) {",
               "            const long j_ = k0_ + k_;",
               *out.scatter,
               "        }"] if out.scatter else []),
            *out.per_block,
            "    }",
            *([f"    if (stream_) {self.prefix}stream_fence();"] if out.staged_bytes else []),
            "    return nonfinite_;",
            "}",
            "",
            f"/* Whether a batch of count states writes {kernel.name}'s staged outputs by streaming "
            "stores. */",
            f"static int {self.prefix}{kernel.name}_stream_(long count) {{",
            f"    return {stream};",
            "}",
            "",
            f"/* {kernel.name} for count states stored one after another. */",
            self.signature(kernel, batch=True) + " {",
            f"    {self.prefix}{kernel.name}_range(0, count, {', '.join(_names(kernel))}, "
            f"{self.prefix}{kernel.name}_stream_(count));",
            "}",
        ]) + "\n"

    @staticmethod
    def _direct(kernel: Kernel) -> list[str]:
        """Outputs of ``kernel`` stored by its core straight into the caller's rows."""
        return [o.name for o in kernel.outputs if DIRECT_MIN is not None and o.size >= DIRECT_MIN]

    def threaded_batch(self, kernel: Kernel) -> str:
        """``PREFIXk_batch_threads`` (and ``PREFIXk_batch_stream``): the batch on threads.

        The work is cut into pieces of whole blocks from state 0 (at most :data:`THREAD_CHUNK`
        states, fewer when the threads would otherwise not all get one): the same blocks,
        computed by the same code, as on one thread, so the result bits do not depend on the
        thread count. Compiled without OpenMP it is the plain batch. ``_batch_stream``, for
        kernels with staged outputs, lets the caller choose the store mode (streaming for a
        large reused matrix; not for fresh memory, whose lines the operating system has just
        zeroed through the cache).
        """
        names = ", ".join(_names(kernel))
        rng = f"{self.prefix}{kernel.name}_range"
        inner = f"{self.prefix}{kernel.name}_threads_"
        params = ", ".join(_parameters(kernel))
        lines = [
            f"/* {kernel.name} for count states on `threads` threads (OpenMP; one without); the "
            "ranges' count. */",
            f"static long {inner}(long count, int threads, int stream, {params}) {{",
            "#ifdef _OPENMP",
            f"    if (threads > 1 && count > {BLOCK}) {{",
            "        /* whole blocks, at most THREAD_CHUNK states, at least one piece per thread */",
            f"        const long share = (count / threads + {BLOCK - 1}) / {BLOCK} * {BLOCK};",
            f"        const long piece = share < {THREAD_CHUNK} ? share : {THREAD_CHUNK};",
            "        const long pieces = (count + piece - 1) / piece;",
            "        long nonfinite = 0;",
            "#pragma omp parallel for num_threads(threads) schedule(static) reduction(+:nonfinite)",
            "        for (long p_ = 0; p_ < pieces; ++p_) {",
            "            const long end = piece * p_ + piece < count ? piece * p_ + piece : count;",
            f"            nonfinite += {rng}(piece * p_, end, {names}, stream);",
            "        }",
            "        return nonfinite;",
            "    }",
            "#endif",
            "    (void)threads;",
            f"    return {rng}(0, count, {names}, stream);",
            "}",
            "",
            self.signature(kernel, batch=True, threads=True) + " {",
            f"    {inner}(count, threads, {self.prefix}{kernel.name}_stream_(count), {names});",
            "}",
        ]
        if staged_outputs(kernel, self._direct(kernel)):
            lines += ["", f"/* {kernel.name}'s batch with the store mode chosen: stream 1 for "
                      "streaming stores, 0 for cached. */",
                      self.stream_signature(kernel) + " {",
                      f"    {inner}(count, threads, stream, {names});",
                      "}"]
        if kernel.name in FINITE_CHECKED:
            lines += ["", f"/* {kernel.name}'s batch (stream as for _batch_stream, ignored without "
                      "staged outputs): the number of blocks with a non-finite output. */",
                      self.nonfinite_signature(kernel) + " {",
                      f"    return {inner}(count, threads, stream, {names});",
                      "}"]
        return "\n".join(lines) + "\n"

    def nonfinite_signature(self, kernel: Kernel) -> str:
        """The C prototype of ``PREFIXk_batch_nonfinite`` (without the trailing semicolon)."""
        return (f"long {self.prefix}{kernel.name}_batch_nonfinite(long count, int threads, "
                f"int stream, {', '.join(_parameters(kernel))})")

    def stream_signature(self, kernel: Kernel) -> str:
        """The C prototype of ``PREFIXk_batch_stream`` (without the trailing semicolon)."""
        args = _parameters(kernel)
        return (f"void {self.prefix}{kernel.name}_batch_stream(long count, int threads, int stream, "
                f"{', '.join(args)})")

    def declarations(self, kset: KernelSet, with_simulation: bool = True) -> str:
        """Prototypes of every exported function, one per line (a header, and cffi's cdef)."""
        lines = []
        for kernel in kset.kernels:
            lines.append(self.signature(kernel).replace("restrict ", "") + ";")
            lines.append(self.signature(kernel, batch=True).replace("restrict ", "") + ";")
            lines.append(self.signature(kernel, batch=True, threads=True).replace("restrict ", "") + ";")
            if staged_outputs(kernel, self._direct(kernel)):
                lines.append(self.stream_signature(kernel).replace("restrict ", "") + ";")
            if kernel.name in FINITE_CHECKED:
                lines.append(self.nonfinite_signature(kernel).replace("restrict ", "") + ";")
        if with_simulation and "state_derivative" in kset.names:
            runtime = len(kset.runtime_parameters)
            lines.append(simulate_signature(self.prefix, runtime) + ";")
            lines.append(ensemble_signature(self.prefix, runtime) + ";")
        return "\n".join(lines) + "\n"

    def source(self, kset: KernelSet, with_simulation: bool = True) -> str:
        """The whole translation unit."""
        parts = [self.header(kset), "#include <math.h>\n"]
        if any(_angles(k) for k in kset.kernels):
            parts.append(sincos_source(self.prefix))
        if any(len(k.body) > INLINE_LIMIT for k in kset.kernels):
            macro = f"{self.prefix.upper()}NOINLINE"
            parts.append(f"#if defined(__GNUC__)\n#define {macro} __attribute__((noinline))\n#else\n"
                         f"#define {macro}\n#endif\n")
        kernels = [self.kernel_source(kernel) for kernel in kset.kernels]
        if any(f"{self.prefix}gather(" in k for k in kernels):
            parts.append(gather_source(self.prefix, BLOCK))
        if any(f"{self.prefix}scatter(" in k for k in kernels):
            parts.append(scatter_source(self.prefix, BLOCK))
        if any(f"{self.prefix}copy_out(" in k for k in kernels):
            parts.append(copy_out_source(self.prefix))
        parts.extend(kernels)
        if with_simulation and "state_derivative" in kset.names:
            runtime = len(kset.runtime_parameters)
            parts.append(simulation_source(kset.dof, self.prefix, "gravity" in kset.names,
                                           "mass_matrix" in kset.names, runtime))
            parts.append(ensemble_source(kset.dof, self.prefix, runtime))
        return "\n".join(parts)


def _trig_lines(prefix: str, angles: list[tuple[sp.Symbol, str, int]]) -> list[str]:
    """The calls of ``PREFIXsincos_block`` in a block of ``m_`` states: angle ``i`` (entry
    ``idx`` of input ``name``) gives ``sin_``/``cos_`` at ``BLOCK i``. Angles that are consecutive
    entries of one input lie one after another in its buffer as in ``sin_``/``cos_``, so a full
    block takes one loop over all of them (5 x 8 states of the PUMA 560: 5 % of its inverse
    dynamics against a loop per angle, measured on an AMD EPYC with AVX2); a partial block, whose
    buffers have unused lanes between the angles, one loop per angle."""
    runs: list[list[tuple[int, str, int]]] = []
    for i, (_, name, idx) in enumerate(angles):
        if runs and runs[-1][-1][1] == name and runs[-1][-1][2] == idx - 1:
            runs[-1].append((i, name, idx))
        else:
            runs.append([(i, name, idx)])
    lines = []
    for run in runs:
        each = [f"{prefix}sincos_block(m_, {name}_b_ + {BLOCK * idx}, sin_ + {BLOCK * i}, "
                f"cos_ + {BLOCK * i});" for i, name, idx in run]
        if len(run) == 1:
            lines.append(f"        {each[0]}")
            continue
        i, name, idx = run[0]
        lines += [f"        if (m_ == {BLOCK}) {prefix}sincos_block({len(run) * BLOCK}, {name}_b_ + "
                  f"{BLOCK * idx}, sin_ + {BLOCK * i}, cos_ + {BLOCK * i});",
                  "        else {", *(f"            {e}" for e in each), "        }"]
    return lines


def sincos_source(prefix: str) -> str:
    """C source of ``static void PREFIXsincos_block(int count, const double *x, double *s, double *c)``.

    ``s[k] = sin(x[k])`` and ``c[k] = cos(x[k])`` for ``k < count`` by one branch-free loop that
    the compiler vectorises (see the module docstring), within 2 ulp of libm (1 ulp for
    |x| <= 100).
    """
    return (_SINCOS.replace("PREFIX", prefix).replace("LIMIT", _POLY_LIMIT)
            .replace("ROUND", _ROUND))


def _angles(kernel: Kernel) -> list[tuple[sp.Symbol, str, int]]:
    """``(symbol, input array, index)`` of every input whose sine or cosine the kernel takes."""
    taken: set[sp.Expr] = set()
    for _, e in kernel.body:
        taken |= {f.args[0] for f in e.atoms(sp.sin, sp.cos)}
    for arg in kernel.outputs:
        for e in arg.entries:
            taken |= {f.args[0] for f in sp.sympify(e).atoms(sp.sin, sp.cos)}
    found = []
    for arg in kernel.inputs:
        for k, sym in enumerate(arg.entries):
            if sym in taken and not any(sym == f for f, _, _ in found):
                found.append((sym, arg.name, k))
    return found


def _steps(kernel: Kernel) -> list[sp.Piecewise]:
    """The conditionals (Coulomb friction's steps) of the kernel that depend on inputs only."""
    inputs = {s for a in kernel.inputs for s in a.entries}
    found: set[sp.Piecewise] = set()
    for e in [e for _, e in kernel.body] + [sp.sympify(e) for a in kernel.outputs for e in a.entries]:
        found |= {p for p in e.atoms(sp.Piecewise) if p.free_symbols <= inputs}
    return sorted(found, key=sp.default_sort_key)


def _parameters(kernel: Kernel) -> list[str]:
    """C parameter declarations of ``kernel``'s arrays: its inputs (const), then its outputs."""
    return ([f"const double *restrict {a.name}" for a in kernel.inputs]
            + [f"double *restrict {a.name}" for a in kernel.outputs])


def _arg(name: str, symbols: list[sp.Symbol]) -> Argument:
    return Argument(name, (len(symbols),), tuple(symbols))


def _names(kernel: Kernel) -> list[str]:
    return [a.name for a in (*kernel.inputs, *kernel.outputs)]


def c_files(kset: KernelSet, prefix: str = "robodyn_", with_simulation: bool = True) -> list[GeneratedFile]:
    """``<robot>.h`` and ``<robot>.c`` for a kernel set."""
    printer = CPrinter(prefix)
    stem = identifier(kset.robot_name)  # the robot's name is data, never a path
    guard = f"ROBODYN_{stem.upper()}_H"
    header = "\n".join([printer.header(kset).rstrip(), f"#ifndef {guard}", f"#define {guard}",
                        printer.declarations(kset, with_simulation).rstrip(), "#endif", ""])
    source = printer.source(kset, with_simulation)
    return [GeneratedFile(f"{stem}.h", header), GeneratedFile(f"{stem}.c", source)]


def _statement_order(statements: list[tuple[sp.Symbol | None, str, sp.Expr]]) -> list[int]:
    """The order in which a core's statements are printed (:data:`SCHEDULE`)."""
    source = list(range(len(statements)))
    if SCHEDULE == "source" or len(statements) > SCHEDULE_LIMIT \
            or any(_slow(e) for _, _, e in statements):
        return source
    defined = {sym: i for i, (sym, _, _) in enumerate(statements) if sym is not None}
    operands = [[defined[x] for x in e.free_symbols if x in defined] for _, _, e in statements]
    order = low_pressure_order(operands, [sym is not None for sym, _, _ in statements])
    # the greedy order is kept where it has fewer values live at its peak than the given one
    # (a mass matrix's many shared terms can make it open more values than it closes)
    return order if live_values(operands, order) < live_values(operands, source) else source


def _slow(e: sp.Expr) -> bool:
    """Whether ``e`` divides or takes a root (a division or square-root instruction)."""
    return any(not (p.exp.is_Integer and p.exp > 0) for p in e.atoms(sp.Pow))
