"""Recording: validation messages, estimation of missing derivatives, slice/select/resample."""

import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import RecordingError, RecordingWarning


def _arrays(n_samples=1000, dt=1e-3):
    t = dt * np.arange(n_samples)
    w = 2 * np.pi * np.array([0.5, 1.0])
    q = np.sin(np.outer(t, w))
    qd = w * np.cos(np.outer(t, w))
    qdd = -(w**2) * np.sin(np.outer(t, w))
    return t, q, qd, qdd


def test_estimates_missing_derivatives_and_marks_them():
    t, q, qd, qdd = _arrays(3000)
    rec = rd.Recording(t=t, q=q)
    assert rec.estimated == frozenset({"qd", "qdd"})
    inner = slice(200, -200)
    assert np.abs(rec.qd - qd)[inner].max() < 1e-4 * np.abs(qd).max()
    assert np.abs(rec.qdd - qdd)[inner].max() < 1e-3 * np.abs(qdd).max()
    measured = rd.Recording(t=t, q=q, qd=qd)
    assert measured.estimated == frozenset({"qdd"})
    assert np.array_equal(measured.qd, qd)
    assert rec.joint_names == ("q1", "q2")
    assert rec.dof == 2 and rec.n_samples == 3000 and rec.dt == pytest.approx(1e-3)
    assert rec.units["q"] == "rad" and rec.units["tau"] == "N m"


def test_frozen_and_read_only_and_input_untouched():
    t, q, qd, qdd = _arrays()
    q_copy = q.copy()
    rec = rd.Recording(t=t, q=q, qd=qd, qdd=qdd)
    assert np.array_equal(q, q_copy)
    with pytest.raises(ValueError):
        rec.q[0, 0] = 1.0
    with pytest.raises(AttributeError):
        rec.q = q


def test_validation_messages():
    t, q, qd, qdd = _arrays()
    with pytest.raises(RecordingError, match=r"Recording.q: expected shape \(N, n\) with N = 1000"):
        rd.Recording(t=t, q=q[:-1])
    tb = t.copy()
    tb[10] = tb[9]
    with pytest.raises(RecordingError, match=r"Recording.t: not strictly increasing at row 10"):
        rd.Recording(t=tb, q=q)
    qb = q.copy()
    qb[17, 1] = np.nan
    with pytest.raises(RecordingError, match=r"Recording.q: nan at row 17, column 1 \('b'\)"):
        rd.Recording(t=t, q=qb, joint_names=["a", "b"])
    with pytest.raises(RecordingError, match=r"run.csv: tau: inf at row 3, column 0"):
        tau = np.zeros_like(q)
        tau[3, 0] = np.inf
        rd.Recording(t=t, q=q, tau=tau, source="run.csv")
    with pytest.raises(RecordingError, match="repeated names"):
        rd.Recording(t=t, q=q, joint_names=["a", "a"])
    with pytest.raises(RecordingError, match=r"tool_points: expected shape \(5, 3\)"):
        rd.Recording(t=t, q=q, tool_t=np.arange(5.0), tool_points=np.zeros((5, 2)))


def test_all_nan_sensor_column_means_no_sensor():
    t, q, qd, qdd = _arrays()
    tau = np.ones_like(q)
    tau[:, 0] = np.nan
    rec = rd.Recording(t=t, q=q, tau=tau)
    assert np.isnan(rec.tau[:, 0]).all()
    tau[5, 1] = np.nan
    with pytest.raises(RecordingError, match="tau: nan at row 5, column 1"):
        rd.Recording(t=t, q=q, tau=tau)


def test_gaps_reported_not_filled():
    t, q, qd, qdd = _arrays()
    t = t.copy()
    t[500:] += 0.01
    with pytest.warns(RecordingWarning, match="1 gap"):
        rec = rd.Recording(t=t, q=q, qd=qd, qdd=qdd)
    assert rec.gaps == ((499, pytest.approx(0.011)),)
    assert rec.n_samples == 1000


def test_stamps_that_are_not_seconds_are_warned_about():
    # 10 ms stamps logged in milliseconds read as a 0.1 Hz recording: identification would
    # then see velocities 1000 times too small (held-out error 2e4 on a PUMA run, 2026-12-07)
    t = np.arange(0.0, 5.0, 0.01)
    q = np.column_stack([np.sin(t), np.cos(t)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rd.Recording(t=t, q=q)  # seconds: no warning
    for scale in (1e3, 1e9):
        with pytest.warns(RecordingWarning, match=r"stamps are seconds: if these are milliseconds"):
            rec = rd.Recording(t=t * scale, q=q, source="log.csv")
        assert rec.dt == pytest.approx(0.01 * scale)  # kept as given


def test_slice_select_resample():
    t, q, qd, qdd = _arrays(2000)
    tau = np.c_[np.cos(t), np.full(t.size, np.nan)]
    rec = rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=tau, joint_names=["a", "b"],
                       tool_t=np.linspace(0, 2, 50), tool_points=np.zeros((50, 3)))
    s = rec.slice(0.5, 1.0)
    assert s.t[0] == pytest.approx(0.5) and s.t[-1] == pytest.approx(1.0) and s.n_samples == 501
    assert s.tool_t.min() >= 0.5 and s.tool_t.max() <= 1.0
    b = rec.select(["b"])
    assert b.joint_names == ("b",) and np.array_equal(b.q[:, 0], q[:, 1])
    r = rec.resample(2e-3)
    assert r.n_samples == 1000 and np.allclose(np.diff(r.t), 2e-3)
    assert np.abs(r.q - np.sin(np.outer(r.t, 2 * np.pi * np.array([0.5, 1.0]))))[50:-50].max() < 1e-6
    assert np.isnan(r.tau[:, 1]).all()
    with pytest.raises(RecordingError, match="no joint 'c'"):
        rec.select(["c"])
    with pytest.raises(RecordingError, match="keeps 0 sample"):
        rec.slice(5.0, 6.0)


def test_rows_keeps_measured_fields_and_re_estimates_the_estimated():
    t = np.arange(200) * 0.01
    q = np.column_stack([np.sin(t), np.cos(t)])
    q_bad = q.copy()
    q_bad[100, 0] += 0.5  # a glitch
    rec = rd.Recording(t=t, q=q_bad, tau=np.ones_like(q))
    assert {"qd", "qdd"} <= rec.estimated
    keep = np.ones(t.size, bool)
    keep[100] = False
    clean = rec.rows(keep)
    assert clean.n_samples == 199 and np.array_equal(clean.tau, np.ones((199, 2)))
    # the velocities are estimated again from the kept rows: the glitch leaves no bump
    again = rd.Recording(t=t[keep], q=q[keep], tau=np.ones((199, 2)))
    np.testing.assert_allclose(clean.qd, again.qd, rtol=0, atol=1e-12)
    measured = rd.Recording(t=t, q=q, qd=np.zeros_like(q), tau=np.ones_like(q))
    assert np.array_equal(measured.rows(keep).qd, np.zeros((199, 2)))  # measured: kept as given
    with pytest.raises(RecordingError, match="rows\\(\\) keeps 1 of 200 samples"):
        rec.rows(np.arange(200) == 3)
