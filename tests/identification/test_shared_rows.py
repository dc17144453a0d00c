"""The fit rows built in two steps (without the dead band, then the band on the Coulomb columns)
against the definition (the band applied to the whole regressor, then every column filtered),
and the rows shared by the candidates of rd.identify that differ only in the dead band."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification import preprocess as pp
from robodyn.identification.preprocess import (
    Preprocess,
    Samples,
    SharedRows,
    banded_rows,
    coulomb_dead_band,
    evaluation_step,
    filtered_rows,
    regressor_rows,
    unbanded_rows,
)
from robodyn.identification.stacking import regressor_rows_of


@pytest.fixture(scope="module")
def model():
    return rd.compile_model(rd.load("puma560"))


def _samples(n: int, irregular: bool, count: int = 3000) -> Samples:
    """1 kHz samples (or jittered stamps) in which joint 0 rests for a while (|qd| below the band),
    joint 1 reverses slowly through zero, the others move."""
    rng = np.random.default_rng(3)
    t = np.arange(count) * 1e-3
    if irregular:
        t = t + rng.uniform(0, 4e-4, count)
    w = 2 * np.pi * 0.5
    q = np.stack([0.3 * np.sin(w * t + k) for k in range(n)], axis=1)
    qd = np.stack([0.3 * w * np.cos(w * t + k) for k in range(n)], axis=1)
    qdd = -w * w * q
    rest = slice(count // 3, count // 2)
    qd[rest, 0] = rng.uniform(-5e-4, 5e-4, rest.stop - rest.start)  # inside the 1e-3 band
    q[rest, 0], qdd[rest, 0] = 0.1, 0.0
    return Samples(t, q, qd, qdd, None, "test")


def _definition(model, s: Samples, settings: Preprocess) -> np.ndarray:
    """The band applied to the whole regressor, then every varying column filtered."""
    m = evaluation_step(s.t, settings, settings.decimate)
    y = coulomb_dead_band(regressor_rows_of(model, s.q[::m], s.qd[::m], s.qdd[::m]), s.qd[::m],
                          settings.dead_band)
    return filtered_rows(s.t[::m], y, settings, settings.decimate // m)


@pytest.mark.parametrize("irregular", [False, True])
@pytest.mark.parametrize(("cutoff", "decimate"), [(None, 1), (None, 4), (2.0, 1), (2.0, 20)])
@pytest.mark.parametrize("band", [0.0, 1e-3, 0.5])
def test_two_steps_equal_the_definition(model, irregular, cutoff, decimate, band):
    s = _samples(model.dof, irregular)
    settings = Preprocess(cutoff=cutoff, decimate=decimate, dead_band=band)
    got = regressor_rows(model, s, settings)
    want = _definition(model, s, settings)
    # each column is filtered on its own: the same bits, not only close
    np.testing.assert_array_equal(got, want)
    if band > 0:  # the band changed something, or the check above would not test it
        assert not np.array_equal(got, regressor_rows(model, s, Preprocess(
            cutoff=cutoff, decimate=decimate, dead_band=0.0)))


def test_banding_leaves_the_unbanded_rows_as_they_were(model):
    s = _samples(model.dof, False)
    u = unbanded_rows(model, s, Preprocess(cutoff=2.0, decimate=20, dead_band=0.0))
    before = u.rows.copy()
    banded = banded_rows(u, Preprocess(cutoff=2.0, decimate=20, dead_band=0.5))
    np.testing.assert_array_equal(u.rows, before)
    assert banded is not u.rows
    # no sample inside a zero band: the rows themselves
    assert banded_rows(u, Preprocess(cutoff=2.0, decimate=20, dead_band=0.0)) is u.rows


def test_candidates_differing_in_the_band_share_samples_and_regressor(model, monkeypatch):
    s = _samples(model.dof, False)
    rec = rd.Recording(t=s.t, q=s.q, qd=s.qd, tau=np.zeros_like(s.q), source="test")
    calls = {"preprocess": 0, "regressor": 0}
    real_pre, real_rows = pp.preprocess, pp.regressor_rows_of

    def counted_pre(*a, **k):
        calls["preprocess"] += 1
        return real_pre(*a, **k)

    def counted_rows(*a, **k):
        calls["regressor"] += 1
        return real_rows(*a, **k)

    monkeypatch.setattr(pp, "preprocess", counted_pre)
    monkeypatch.setattr(pp, "regressor_rows_of", counted_rows)
    shared = SharedRows(model)
    got = {}
    for band in (0.0, 1e-3, 0.5):
        settings = Preprocess(cutoff=2.0, decimate=20, dead_band=band)
        full, rows = shared.get([rec], settings, "tau")
        got[band] = (full[0], rows[0], settings)
    assert calls == {"preprocess": 1, "regressor": 1}
    # each equals what the band's own settings give from scratch
    for _, (full, rows, settings) in got.items():
        assert full is got[0.0][0]
        np.testing.assert_array_equal(rows, _definition(model, real_pre(rec, settings, "tau"),
                                                        settings))
    # another velocity source or cut-off is another entry
    shared.get([rec], Preprocess(cutoff=3.0, decimate=20, dead_band=0.0), "tau")
    assert calls == {"preprocess": 2, "regressor": 2}
    shared.clear()
    shared.get([rec], Preprocess(cutoff=2.0, decimate=20, dead_band=0.0), "tau")
    assert calls == {"preprocess": 3, "regressor": 3}


@pytest.mark.parametrize("irregular", [False, True])
@pytest.mark.parametrize(("cutoff", "decimate"), [(None, 4), (2.0, 1), (2.0, 20)])
def test_long_logs_evaluated_in_column_groups_give_the_same_bits(model, monkeypatch, irregular,
                                                                 cutoff, decimate):
    s = _samples(model.dof, irregular)
    settings = Preprocess(cutoff=cutoff, decimate=decimate, dead_band=0.0)
    whole = unbanded_rows(model, s, settings)
    calls = []
    real = pp.regressor_rows_of

    def counted(*a, **k):
        calls.append(np.shape(a[1])[0])
        return real(*a, **k)

    m = evaluation_step(s.t, settings, decimate)
    count, n = s.q[::m].shape
    # a budget of a fifth of the rows: 5 or 6 column groups, each evaluated 1/20 of the samples
    # at a time
    monkeypatch.setattr(pp, "ROWS_BYTES", count * n * 15 * n * 8 // 5)
    monkeypatch.setattr(pp, "regressor_rows_of", counted)
    grouped = unbanded_rows(model, s, settings)
    assert len(calls) > 5 and max(calls) < count  # the grouped path ran, in blocks of samples
    for name in ("rows", "t", "qd", "coulomb"):
        np.testing.assert_array_equal(getattr(grouped, name), getattr(whole, name))
    assert grouped.keep == whole.keep
