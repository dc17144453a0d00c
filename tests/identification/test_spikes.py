"""Bursts of corrupt rows (robodyn.identification.spikes.burst_rows): a sensor reading a constant
for a few cycles, found beside the one-sample spikes and dropped before the fit."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.spikes import GROSS_THRESHOLD, MAX_BURST, burst_rows, spike_rows
from robodyn.robot.errors import RecordingWarning
from tests.identification.helpers import fourier, load_quiet


def _signal(seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Two smooth columns (a slow sine, a Fourier series) with 1e-3 white noise, 100 Hz, 20 s."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 20.0, 0.01)
    x = np.column_stack([np.sin(0.7 * t), fourier(t, 1, rng, f0=0.1)[0][:, 0]])
    return t, x + 1e-3 * rng.standard_normal(x.shape)


@pytest.mark.parametrize("length", [3, 4, MAX_BURST])
def test_a_burst_of_constant_rows_is_found_and_nothing_else(length):
    t, x = _signal()
    assert not spike_rows(t, x, threshold=GROSS_THRESHOLD).any()  # clean: nothing
    bad = x.copy()
    bad[700:700 + length, 1] = 0.0 if length % 2 else 25.0  # a sensor reading 0 (or 25)
    found = np.flatnonzero(spike_rows(t, bad, threshold=GROSS_THRESHOLD))
    if length % 2:  # reading 0 where the signal is far from it
        assert np.min(np.abs(x[700:700 + length, 1])) > 0.1
    assert set(found) == set(range(700, 700 + length))


def test_a_step_or_a_longer_plateau_is_not_a_burst():
    t, x = _signal(1)
    stepped = x.copy()
    stepped[900:, 0] += 5.0  # a step (a Coulomb reversal in a torque): kept
    assert not burst_rows(t, stepped, GROSS_THRESHOLD).any()
    assert not spike_rows(t, stepped, threshold=GROSS_THRESHOLD).any()
    longer = x.copy()
    longer[900:900 + MAX_BURST + 3, 0] = 30.0  # longer than a burst: not this rule's business
    assert not burst_rows(t, longer, GROSS_THRESHOLD).any()


def test_a_burst_in_the_torque_is_dropped_before_the_fit():
    # three rows of 1e4 N m in one joint's torque made the held-out error 0.27 against the clean
    # fit's 0.0026 (PUMA 560, 100 Hz, exact motion, 0.05 N m noise): dropped by the default
    # spikes="auto" with a warning, the fit is the one on the recording without those rows
    robot = load_quiet("puma560")
    model = rd.compile_model(robot)
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 30.0, 0.01)
    q, qd, qdd = fourier(t, robot.dof, rng, f0=1 / 30)
    tau = model.inverse_dynamics(q, qd, qdd) + 0.05 * rng.standard_normal((t.size, robot.dof))
    bad = tau.copy()
    bad[1000:1003, 2] = 1e4
    rec = rd.Recording(t=t, q=q, tau=bad, joint_names=robot.joint_names, source="burst")
    kwargs = dict(model=model, cutoff=5.0, regularization=None, velocity="position",
                  friction="linear", ripple=False, resonance=False)
    with pytest.warns(RecordingWarning, match=r"burst: 3 row\(s\) dropped as glitches"):
        ident = rd.identify(robot, rec, **kwargs)
    keep = np.ones(t.size, bool)
    keep[1000:1003] = False
    with pytest.warns(RecordingWarning, match="gap"):  # the three rows' stamps are missing
        clean = rd.identify(robot, rd.Recording(t=t[keep], q=q[keep], tau=tau[keep],
                                                joint_names=robot.joint_names, source="clean"),
                            spikes="keep", **kwargs)
    np.testing.assert_allclose(ident.standard, clean.standard, rtol=1e-9, atol=1e-9)
