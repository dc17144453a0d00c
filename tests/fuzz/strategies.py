"""Hypothesis strategies shared by the loader fuzz tests: mutated files and settings.

Every generated file is bounded in size (``MAX_BYTES``); the number of examples per test is
``FUZZ_EXAMPLES`` (environment ``ROBODYN_FUZZ_EXAMPLES``, default 40, CI-sized) and each example
has a deadline, so a loader that hangs or explodes on a small input fails the test. The examples
are the same on every run (derandomised; ``ROBODYN_FUZZ_RANDOM=1`` searches anew).
"""

from __future__ import annotations

import os
import tracemalloc
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import timedelta

from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

#: Largest generated or mutated file, bytes.
MAX_BYTES = 64 * 1024

#: Largest peak of memory one reader or command may allocate on a generated input, bytes
#: (``tracemalloc`` sees NumPy's arrays too): a small input that expands into gigabytes fails.
MEMORY_CAP = 256 * 2**20


@contextmanager
def memory_capped() -> Iterator[None]:
    """Assert that the block allocates at most :data:`MEMORY_CAP` at its peak."""
    tracemalloc.start()
    try:
        yield
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert peak < MEMORY_CAP, f"{peak / 2**20:.0f} MiB allocated"


#: Examples per fuzz test (``ROBODYN_FUZZ_EXAMPLES`` raises it for a longer local run).
FUZZ_EXAMPLES = int(os.environ.get("ROBODYN_FUZZ_EXAMPLES", "40"))
#: A new random search on each run (``ROBODYN_FUZZ_RANDOM=1``) instead of the fixed one.
FUZZ_RANDOM = os.environ.get("ROBODYN_FUZZ_RANDOM", "") == "1"


def fuzz_settings(deadline_s: float, *, report_multiple_bugs: bool = True) -> settings:
    """Bounded example count and time per example; no example database in the repository; the
    same examples on every run (a test suite that cannot flake) unless ``ROBODYN_FUZZ_RANDOM=1``
    asks for a new search (a longer local run, with ``ROBODYN_FUZZ_EXAMPLES``)."""
    return settings(
        derandomize=not FUZZ_RANDOM,
        max_examples=FUZZ_EXAMPLES,
        deadline=timedelta(seconds=deadline_s),
        database=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
        report_multiple_bugs=report_multiple_bugs,
    )


#: Text fragments that have broken parsers before: YAML/XML/CSV syntax, special numbers,
#: aliases, tags, control and non-ASCII characters, huge literals.
TOKENS = [
    "", "0", "-1", "-0.0", "1e308", "1e-320", "nan", ".nan", "inf", "-.inf", "9" * 400,
    "'", '"', ",", ";", ":", "- ", "{", "}", "[", "]", "#", "&a", "*a", "<<: *a", "!!binary",
    "!!python/object/apply:os.system ['true']", "---", "...", "\t", "\r", "\n", "\x00", "\x0b",
    "\ufeff", "é", "\u2028", "😀", "null", "~", "true", "yes", "2020-01-02", "0x1F", "1_000",
    "<", ">", "&", "&amp;", "<!--", "-->", "<![CDATA[", "]]>", '<!DOCTYPE r [<!ENTITY e "x">]>',
    "&e;", "</robot>", "<link/>", "sqrt(", "**", "^", "-" * 300 + "1", "pi", "__import__",
]

_payload = st.one_of(
    st.sampled_from(TOKENS),
    st.text(max_size=40),
    st.binary(max_size=24).map(lambda b: b.decode("latin-1")),
)

_ops = st.tuples(
    st.sampled_from(["delete", "insert", "replace", "dup_line", "drop_line", "swap_lines",
                     "replace_number", "truncate"]),
    st.integers(min_value=0, max_value=1 << 20),
    st.integers(min_value=0, max_value=1 << 20),
    _payload,
)


def _mutate(text: str, ops: list[tuple[str, int, int, str]]) -> str:
    """Apply the drawn edit operations to ``text`` (positions wrap around its length)."""
    import re

    for op, i, j, payload in ops:
        n = max(len(text), 1)
        a, b = sorted((i % n, j % n))
        b = min(b, a + 200)
        lines = text.split("\n")
        k, m = i % len(lines), j % len(lines)
        if op == "delete":
            text = text[:a] + text[b:]
        elif op == "insert":
            text = text[:a] + payload + text[a:]
        elif op == "replace":
            text = text[:a] + payload + text[b:]
        elif op == "dup_line":
            text = "\n".join(lines[: k + 1] + lines[k:])
        elif op == "drop_line":
            text = "\n".join(lines[:k] + lines[k + 1:])
        elif op == "swap_lines":
            lines[k], lines[m] = lines[m], lines[k]
            text = "\n".join(lines)
        elif op == "replace_number":
            numbers = list(re.finditer(r"-?\d+(\.\d+)?(e-?\d+)?", text))
            if numbers:
                hit = numbers[i % len(numbers)]
                text = text[:hit.start()] + payload + text[hit.end():]
        else:
            text = text[:a]
    return text[:MAX_BYTES]


def mutated(texts: list[str]) -> st.SearchStrategy[str]:
    """One of ``texts`` with up to four random edits."""
    return st.builds(_mutate, st.sampled_from(texts), st.lists(_ops, max_size=4))
