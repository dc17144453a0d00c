"""Fuzz the recording readers (``rd.read_recording``): mutated robodyn CSV files and mutated or
truncated MCAP (ROS 2) bags. The only outcomes allowed are a Recording or a
:class:`RecordingError`, within the deadline of each example.
"""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

import robodyn as rd
from robodyn.measure.csv_io import write_csv
from robodyn.measure.mcap_io import write_mcap
from robodyn.robot.errors import RecordingError, RecordingWarning
from tests.fuzz.strategies import MAX_BYTES, fuzz_settings, memory_capped, mutated


def _recording() -> rd.Recording:
    t = np.arange(40) * 0.01
    q = np.column_stack([np.sin(t), np.cos(2 * t)])
    return rd.Recording(t=t, q=q, tau=0.1 * q, joint_names=("j1", "j2"))


def _files() -> tuple[str, bytes]:
    with tempfile.TemporaryDirectory() as tmp:
        csv_text = write_csv(_recording(), Path(tmp) / "run.csv").read_text()
        mcap = write_mcap(_recording(), Path(tmp) / "run.mcap").read_bytes()
    return csv_text, mcap


CSV, MCAP = _files()


def outcome(data: bytes, suffix: str) -> None:
    assert len(data) <= 2 * MAX_BYTES
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"run{suffix}"
        path.write_bytes(data)
        with warnings.catch_warnings(), memory_capped():
            warnings.simplefilter("error")  # a stray RuntimeWarning is a defect too
            warnings.simplefilter("ignore", RecordingWarning)
            try:
                rec = rd.read_recording(path)
            except RecordingError as exc:
                assert "run" in str(exc), str(exc)  # names the file
                return
        assert path.read_bytes() == data
    assert rec.q.ndim == 2 and len(rec.t) == len(rec.q)
    assert np.all(np.isfinite(rec.t)) and np.all(np.isfinite(rec.q))


@fuzz_settings(deadline_s=20)
@given(mutated([CSV]))
def test_mutated_csv_recording(text: str) -> None:
    outcome(text.encode("utf-8", "surrogatepass"), ".csv")


_byte_ops = st.lists(st.tuples(st.sampled_from(["flip", "truncate", "insert", "delete"]),
                               st.integers(0, 1 << 20), st.binary(min_size=1, max_size=8)),
                     min_size=1, max_size=4)


def _mutate_bytes(data: bytes, ops: list[tuple[str, int, bytes]]) -> bytes:
    for op, i, payload in ops:
        k = i % max(len(data), 1)
        if op == "flip":
            data = data[:k] + bytes([data[k] ^ payload[0]]) + data[k + 1:] if data else data
        elif op == "truncate":
            data = data[:k]
        elif op == "insert":
            data = data[:k] + payload + data[k:]
        else:
            data = data[:k] + data[k + len(payload):]
    return data[:MAX_BYTES]


@fuzz_settings(deadline_s=20, report_multiple_bugs=False)  # one exception, for xfail to judge
@given(st.builds(_mutate_bytes, st.just(MCAP), _byte_ops))
def test_mutated_mcap_recording(data: bytes) -> None:
    outcome(data, ".mcap")
