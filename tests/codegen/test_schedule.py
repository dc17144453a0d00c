"""The statement order of the generated cores and the transposition of a block's inputs.

``robodyn.codegen.schedule.low_pressure_order`` reorders straight-line code; it must keep every
statement after its operands and lower the values live at once where the given order is
wasteful. ``PREFIXgather``
(``robodyn.codegen.c_transpose``) must copy a block's rows into structure-of-arrays buffers bit
for bit, for every row size and partial blocks, on the vector path and off it; ``PREFIXscatter``
must put a block's computed entries back at their positions in the rows, leaving the others.
"""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.codegen.build import compile_library
from robodyn.codegen.c_transpose import gather_source, scatter_source
from robodyn.codegen.schedule import live_values, low_pressure_order


def _random_program(rng: np.random.Generator, n: int) -> list[list[int]]:
    """Statement i reads up to 3 earlier statements (none for the first few: the loads)."""
    return [sorted(set(rng.integers(0, i, rng.integers(0, 4)).tolist())) if i > 3 else []
            for i in range(n)]


@pytest.mark.parametrize("seed", range(5))
def test_the_order_is_a_permutation_with_every_statement_after_its_operands(seed):
    rng = np.random.default_rng(seed)
    operands = _random_program(rng, 300)
    produces = [bool(x) for x in rng.integers(0, 5, 300)]  # some statements are stores
    order = low_pressure_order(operands, produces)
    assert sorted(order) == list(range(300))
    where = {s: k for k, s in enumerate(order)}
    assert all(where[j] < where[i] for i, d in enumerate(operands) for j in d)


def test_loads_move_to_their_use_and_free_their_values():
    # the shape CSE leaves: 20 values computed first, each used once by one of 20 stores after
    # them: 20 live at once in that order; loaded and stored in pairs, one
    operands = [[] for _ in range(20)] + [[i] for i in range(20)]
    produces = [True] * 20 + [False] * 20
    given = list(range(40))
    order = low_pressure_order(operands, produces)
    assert live_values(operands, given) == 20
    assert live_values(operands, order) == 1


def test_an_operand_after_its_reader_is_refused():
    with pytest.raises(ValueError, match="not before it"):
        low_pressure_order([[1], []], [True, True])


_WRAPPER = """
void t_gather_call(int m, int size, const double *x, double *xb) { t_gather(m, size, x, xb); }
"""


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("block", [1, 4, 8, 16])
def test_gather_copies_a_block_into_structure_of_arrays_bit_for_bit(block):
    lib = compile_library("#include <math.h>\n" + gather_source("t_", block) + _WRAPPER,
                          "void t_gather_call(int m, int size, const double *x, double *xb);")
    rng = np.random.default_rng(block)
    for size in range(1, 11):
        for m in sorted({m for m in (1, 3, block - 1, block) if 1 <= m <= block}):
            x = rng.standard_normal((m, size))
            x[0, 0] = -0.0  # signs and special values copied as they are
            x[-1, -1] = np.nan
            xb = np.full(block * size, 7.0)
            lib.lib.t_gather_call(m, size, lib.ffi.from_buffer("double[]", x),
                                  lib.ffi.from_buffer("double[]", xb))
            got = xb.reshape(size, block)
            expected = x.T
            assert got[:, :m].tobytes() == np.ascontiguousarray(expected).tobytes()
            assert np.all(got[:, m:] == 7.0)  # lanes past the block's states untouched


_SCATTER_WRAPPER = """
void t_scatter_call(int m, int size, int count, const int *index, const double *b, double *row) {
    t_scatter(m, size, count, index, b, row);
}
"""


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("block", [1, 4, 8, 16])
def test_scatter_puts_computed_entries_at_their_positions_bit_for_bit(block):
    lib = compile_library("#include <math.h>\n" + scatter_source("t_", block) + _SCATTER_WRAPPER,
                          "void t_scatter_call(int m, int size, int count, const int *index, "
                          "const double *b, double *row);")
    rng = np.random.default_rng(100 + block)
    size = 23
    # runs of 1 to 6 consecutive positions with gaps: the vector path's 4-runs and the rest
    layouts = [np.arange(size), np.array([0, 1, 2, 3, 5, 6, 7, 8, 9, 11, 12, 13, 20, 21, 22]),
               np.array([1, 3, 4, 5, 6, 7, 8, 15]), np.sort(rng.choice(size, 11, replace=False))]
    for index in layouts:
        for m in sorted({m for m in (1, 3, block - 1, block) if 1 <= m <= block}):
            b = rng.standard_normal((len(index), block))
            b[0, 0] = -0.0
            rows = np.full((m, size), 7.0)
            lib.lib.t_scatter_call(m, size, len(index),
                                   lib.ffi.from_buffer("int[]", index.astype(np.int32)),
                                   lib.ffi.from_buffer("double[]", b),
                                   lib.ffi.from_buffer("double[]", rows))
            expected = np.full((m, size), 7.0)
            expected[:, index] = b[:, :m].T
            assert rows.tobytes() == expected.tobytes()
