"""An order of a straight-line program's statements that keeps few values live at once.

The generated cores are straight-line code of a few hundred to several thousand assignments, in
the order common-subexpression elimination left them: a value is often computed long before its
first use. GCC on x86 does not reorder instructions before register allocation (``-O3`` runs no
first scheduling pass there), so the source order is, nearly, the order of the machine code:
every value live across a stretch of code needs a register, and beyond the 16 vector
registers of AVX2 (32 with AVX-512) it is stored to the stack and loaded back.

:func:`low_pressure_order` is a greedy list scheduler that minimises the number of values live
(a classic heuristic, e.g. Goodman and Hsu's "integrated prepass scheduling" in its
register-pressure mode): among the statements whose operands are all computed, it emits the one
that frees the most values (operands it is the last user of) less the one it creates, ties
going to the statement that uses the most recently computed value (to finish a chain while its
values are still in registers), then to the earlier statement. Stores of outputs therefore
move to just after their value (and loads of inputs, given as statements, to their first use;
robodyn's C printer keeps its loads first instead, see :mod:`robodyn.codegen.c`). Only the
order changes:
every statement, and so every rounding, is the same (the compiler may still fuse a product and
a sum across statements differently, as it may for any order; the tests compare to 1e-14).

robodyn's C printer (:func:`robodyn.codegen.c._statement_order`) leaves cores that divide or
take roots in CSE's order, which measured faster for the forward dynamics, also against a
variant of this scheduler that kept a division's users ten statements away from it.

Measured on the AMD EPYC with AVX2 (2026-12-06, ``benchmarks/bench_schedule.py``, 16 states per
block, ns per state, median of three code layouts), inverse dynamics in CSE's order and
scheduled: PUMA 560 36.9 -> 35.6 (34.0 -> 32.7 with the inputs transposed by shuffles), Kinova
Gen3 82.4 -> 68.4 (79.4 -> 64.8). The largest number of values live at once in those cores (the
loads of inputs, printed first, not counted):
81 -> 63 and 132 -> 84.
"""

from __future__ import annotations

import heapq
from collections.abc import Sequence

__all__ = ["live_values", "low_pressure_order"]


def low_pressure_order(operands: Sequence[Sequence[int]], produces: Sequence[bool]) -> list[int]:
    """A dependency-respecting order of statements that keeps few values live.

    Parameters
    ----------
    operands : sequence of n sequences of int
        ``operands[i]``: the statements whose values statement ``i`` reads (each earlier than
        ``i`` in the given order: the given order is a valid one).
    produces : sequence of n bool
        Whether statement ``i`` defines a value (an assignment or a load; a store defines none).

    Returns
    -------
    list of int, length n
        The statements' indices in the new order: each after all its operands.
    """
    n = len(operands)
    deps = [sorted(set(d)) for d in operands]
    users: list[list[int]] = [[] for _ in range(n)]
    for i, d in enumerate(deps):
        for j in d:
            if not 0 <= j < i:
                raise ValueError(f"statement {i} reads statement {j}, which is not before it")
            users[j].append(i)
    remaining = [len(u) for u in users]  # users not yet emitted
    waiting = [len(d) for d in deps]  # operands not yet emitted
    position = [-1] * n  # where each emitted statement went
    recency = [-1] * n  # position of a ready statement's latest operand

    def key(i: int) -> tuple[int, int, int]:
        frees = sum(1 for j in deps[i] if remaining[j] == 1)
        # heapq pops the smallest: most freed less created, latest operand, earliest statement
        return (-(frees - int(produces[i] and bool(users[i]))), -recency[i], i)

    heap = [key(i) for i in range(n) if waiting[i] == 0]
    heapq.heapify(heap)
    order: list[int] = []
    while heap:
        entry = heapq.heappop(heap)
        i = entry[2]
        if position[i] >= 0 or entry != key(i):
            continue  # emitted, or a stale entry (its statement was pushed again with its key)
        position[i] = len(order)
        order.append(i)
        for j in deps[i]:
            remaining[j] -= 1
            if remaining[j] == 1:
                # the last user of j now frees it: its key improved (if it is ready)
                last = next(u for u in users[j] if position[u] < 0)
                if waiting[last] == 0:
                    heapq.heappush(heap, key(last))
        for u in users[i]:
            waiting[u] -= 1
            if waiting[u] == 0:
                recency[u] = position[i]
                heapq.heappush(heap, key(u))
    return order  # every statement: its operands come before it, so all become ready


def live_values(operands: Sequence[Sequence[int]], order: Sequence[int]) -> int:
    """The largest number of values live at once when the statements run in ``order``.

    A value is live from its statement to its last user (a value without users is not counted).
    """
    where = {s: k for k, s in enumerate(order)}
    last = [-1] * len(operands)
    for i, d in enumerate(operands):
        for j in d:
            last[j] = max(last[j], where[i])
    change = [0] * (len(order) + 1)
    for i, end in enumerate(last):
        if end >= 0:
            change[where[i]] += 1
            change[end] -= 1
    live = most = 0
    for c in change:
        live += c
        most = max(most, live)
    return most
