"""The Tikhonov weight rule (least weight within one standard error of the best) and the
prediction cut-off (``prediction_cutoff=``, robodyn.identification.bandwidth)."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.bandwidth import prediction_candidates
from robodyn.identification.estimate import LAMBDA_GRID, cv_weight
from robodyn.identification.preprocess import Samples
from robodyn.robot.errors import IdentificationError
from tests.identification.helpers import load_quiet


def test_weight_rule_prefers_the_data_unless_the_prior_is_clearly_better():
    rng = np.random.default_rng(0)
    k, count = 10, LAMBDA_GRID.size
    # larger weights gain 0.1 % per grid step in total, but the blocks disagree by +-20 %
    # (alternating): the gain is within one SE of the paired differences, the least weight wins
    sign = np.where(np.arange(k) % 2 == 0, 1.0, -1.0)[:, None]
    steps = np.arange(count)[None, :]
    drift = 1.0 + 0.2 * sign * steps / (count - 1) - 0.001 * steps
    assert int(np.argmin(drift.sum(axis=0))) == count - 1
    assert cv_weight(drift) == 0.0
    # the largest weight is better in every block by far more than the spread: it is taken
    clear = np.ones((k, count)) + 0.01 * rng.standard_normal((k, count))
    clear[:, -1] -= 0.5
    assert cv_weight(clear) == LAMBDA_GRID[-1]
    # a gain of 1 % in total with block differences of +-20 %: within one SE, the least weight
    noisy = np.ones((k, count))
    noisy[:, 5] = 1.0 - 0.01 + 0.2 * np.where(np.arange(k) % 2 == 0, 1.0, -1.0)
    assert cv_weight(noisy) == 0.0


def test_prediction_candidates_stop_below_a_fifth_of_the_rate():
    assert prediction_candidates(5.0, 1000.0) == [5.0, 8.0, 12.5, 20.0]
    assert prediction_candidates(5.0, 94.0) == pytest.approx([5.0, 8.0, 12.5, 18.8])
    assert prediction_candidates(5.0, 25.0) == [5.0]


def _sines(t, freqs, rng):
    """Six joints from random offsets plus sines at ``freqs`` ((Hz, rad) pairs, random signs):
    positions, velocities and accelerations (N, 6), exact."""
    q = np.zeros((t.size, 6)) + rng.uniform(-1, 1, 6)
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    for f, size in freqs:
        w = 2 * np.pi * f
        a = size * rng.choice([-1.0, 1.0], 6)
        q += a * np.sin(w * t)[:, None]
        qd += a * w * np.cos(w * t)[:, None]
        qdd += -a * w * w * np.sin(w * t)[:, None]
    return q, qd, qdd


@pytest.fixture(scope="module")
def fast_run():
    """PUMA 560 moving with content at 3-6 Hz, logged at 500 Hz with exact positions and 0.05 N m
    torque noise; the fit is forced to a 1.5 Hz cut-off, below the motion."""
    robot = load_quiet("puma560")
    model = rd.compile_model(robot)
    t = np.arange(0.0, 20.0, 0.002)
    rng = np.random.default_rng(3)
    q, qd, qdd = _sines(t, ((0.1, 0.5), (0.3, 0.3), (3.0, 0.02), (6.0, 0.01)), rng)
    tau = model.inverse_dynamics(q, qd, qdd)
    noisy = tau + 0.05 * rng.standard_normal(tau.shape)
    rec = rd.Recording(t=t, q=q, tau=noisy, joint_names=robot.joint_names, source="fast run")
    return robot, model, rec, tau


def test_auto_prediction_cutoff_widens_to_the_motion_and_predicts_it_better(fast_run):
    robot, model, rec, tau = fast_run
    fit = rd.identify(robot, rec, target="tau", cutoff=1.5, model=model, ripple=False, resonance=False,
                      friction="linear", local=False)
    auto = rd.identify(robot, rec, target="tau", cutoff=1.5, model=model, ripple=False, resonance=False,
                       friction="linear", prediction_cutoff="auto", local=False)
    assert fit.choices.prediction_cutoff is None and fit.prediction is None
    # the motion reaches 6 Hz: the chosen cut-off is wider than the fit's
    assert auto.choices.prediction_cutoff > 1.5
    assert auto.prediction_settings.cutoff == auto.choices.prediction_cutoff
    assert dict(auto.choices.prediction_scores).keys() >= {"1.5 Hz", "2.4 Hz"}
    assert "prediction cut-off" in auto.choices.summary()
    # the same parameters, evaluated on the wider states, are closer to the noise-free torque
    err = [float(np.linalg.norm(i.predict(rec) - tau) / np.linalg.norm(tau)) for i in (fit, auto)]
    assert err[1] < 0.5 * err[0]
    np.testing.assert_array_equal(auto.standard, fit.standard)
    # a fixed cut-off is used as given
    fixed = rd.identify(robot, rec, target="tau", cutoff=1.5, model=model, ripple=False, resonance=False,
                        friction="linear", prediction_cutoff=9.0, local=False)
    assert fixed.prediction_settings.cutoff == 9.0 and fixed.preprocess.cutoff == 1.5
    # a cut-off given to predict alone: the same prediction as a fit whose band it is, closer to
    # the noise-free torque than the fit's 1.5 Hz band, and the parameters untouched
    np.testing.assert_array_equal(fit.predict(rec, cutoff=9.0), fixed.predict(rec))
    wide = float(np.linalg.norm(fit.predict(rec, cutoff=9.0) - tau) / np.linalg.norm(tau))
    assert wide < 0.5 * err[0]
    np.testing.assert_array_equal(fit.predict(rec), fit.predict(rec, cutoff=None))


@pytest.mark.parametrize("value, message", [("wide", "expected a positive frequency in Hz"),
                                            (float("nan"), "expected a positive frequency in Hz"),
                                            (-3.0, "expected a positive frequency in Hz"),
                                            (True, "expected a positive frequency in Hz"),
                                            (1e6, "must lie in")])
def test_bad_predict_cutoff_is_refused(fast_run, value, message):
    robot, model, rec, _ = fast_run
    short = rec.slice(0.0, 2.0)
    ident = rd.identify(robot, short, target="tau", model=model, ripple=False, resonance=False,
                        friction="linear")
    with pytest.raises(IdentificationError, match=f"prediction_cutoff: {message}"):
        ident.predict(short, cutoff=value)


@pytest.mark.parametrize("value, message", [("wide", "expected a frequency in Hz, 'motion', 'auto' or 'fit'"),
                                            (-3.0, "expected a positive frequency"),
                                            (True, "expected a positive frequency in Hz"),
                                            (1e6, "must lie in")])
def test_bad_prediction_cutoff_is_refused(fast_run, value, message):
    robot, model, rec, _ = fast_run
    with pytest.raises(IdentificationError, match=f"prediction_cutoff: {message}"):
        rd.identify(robot, rec.slice(0.0, 2.0), target="tau", model=model, prediction_cutoff=value)


def _run(robot, model, freqs, seed, source):
    """PUMA 560 at 500 Hz moving at ``freqs`` ((Hz, rad) pairs), positions from a 4096-count
    encoder, torque with 0.05 N m noise; and the exact states (t, q, qd, qdd) as Samples."""
    t = np.arange(0.0, 20.0, 0.002)
    rng = np.random.default_rng(seed)
    q, qd, qdd = _sines(t, freqs, rng)
    tau = model.inverse_dynamics(q, qd, qdd)
    step = 2 * np.pi / 4096
    rec = rd.Recording(t=t, q=np.round(q / step) * step, tau=tau + 0.05 * rng.standard_normal(tau.shape),
                       joint_names=robot.joint_names, source=source)
    return rec, Samples(t, q, qd, qdd, None, "exact")


def test_a_recording_faster_than_the_fit_data_is_predicted_in_its_own_band():
    # the default prediction_cutoff="motion": a fit on slow motion (the cut-off rule's 2 Hz)
    # predicts a faster run at that run's own rule, not below its motion
    robot = load_quiet("puma560")
    model = rd.compile_model(robot)
    slow, _ = _run(robot, model, ((0.1, 0.5), (0.3, 0.3)), 4, "slow run")
    fast, exact = _run(robot, model, ((0.1, 0.5), (0.3, 0.3), (2.5, 0.04), (3.5, 0.02)), 5, "fast run")
    kw = {"target": "tau", "model": model, "ripple": False, "resonance": False, "friction": "linear"}
    ident = rd.identify(robot, slow, **kw)
    fit_only = rd.identify(robot, slow, prediction_cutoff="fit", **kw)
    cut = ident.preprocess.cutoff
    assert ident.options.prediction_cutoff == "motion" and ident.prediction is None
    assert ident.recording_cutoff(slow) == cut == fit_only.recording_cutoff(fast)
    own = ident.recording_cutoff(fast)
    assert own > 1.5 * cut
    np.testing.assert_array_equal(ident.predict(fast), ident.predict(fast, cutoff=own))
    np.testing.assert_array_equal(ident.predict(slow), fit_only.predict(slow))
    np.testing.assert_array_equal(ident.standard, fit_only.standard)
    # the same parameters at the exact states: what a prediction of the fast run can reach;
    # its own band comes closer to it than the fit's
    best = ident.effort(exact)
    err = [float(np.linalg.norm(i.predict(fast) - best) / np.linalg.norm(best))
           for i in (ident, fit_only)]
    assert err[0] < 0.5 * err[1]
    # a fit cut-off given as a number is kept as given
    fixed = rd.identify(robot, slow, cutoff=cut, **kw)
    assert fixed.recording_cutoff(fast) == cut
    # the CLI's note on its written predictions names the widened recording (and then offers
    # no `robodyn validate` command at one cut-off as reproducing them)
    from pathlib import Path

    from robodyn.cli.identify import _prediction_note

    note = _prediction_note(ident, Path("x.yaml"), [slow, fast])
    assert f"{own:.3g} Hz for fast run" in note and "slow run" not in note
    assert "reproduces" not in note
