"""The friction offset at rest, the Coulomb dead band and the cross-validated preprocessing choices.

Simulated data with known truth: the torque is built in the test from a true standard parameter
vector that differs from the description (the prior) in the friction terms, so a parameter
left at its prior shows up as a wrong prediction.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.consistent import EPS, _project_link, pseudo_inertia
from robodyn.identification.pipeline import nominal_standard
from robodyn.robot.errors import IdentificationError, RecordingWarning
from robodyn.robot.validation import inertia_problems
from robodyn.robot.yaml_writer import dump_yaml
from robodyn.symbolic.regressor import INERTIAL_NAMES, PER_JOINT
from tests.identification.helpers import fourier, load_quiet

FO = len(INERTIAL_NAMES) + 4  # offset within a joint's 15 parameters (Ia, Fv, Fcp, Fcn, Fo)


@pytest.fixture(scope="module")
def planar():
    robot = load_quiet("planar_2r")
    return robot, rd.compile_model(robot)


def _truth(robot) -> np.ndarray:
    """The description's standard parameters with every friction offset moved by 0.7 N m."""
    p = nominal_standard(robot).copy()
    for j in range(robot.dof):
        p[PER_JOINT * j + FO] += 0.7
    return p


def _held_run(model, seconds: float, dt: float, seed: int, held: int) -> tuple[np.ndarray, ...]:
    """Fourier motion of every joint but ``held``, which stands still at its start position."""
    t = np.arange(0.0, seconds, dt)
    q, qd, qdd = fourier(t, model.dof, np.random.default_rng(seed))
    q[:, held] = q[0, held]
    qd[:, held] = 0.0
    qdd[:, held] = 0.0
    return t, q, qd, qdd


def _recording(model, t, q, qd, qdd, tau, source):
    return rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=tau, joint_names=model.robot.joint_names,
                        source=source)


def test_offset_of_a_joint_held_still_is_identified(planar):
    robot, model = planar
    p_true = _truth(robot)
    runs = []
    for seed, held in ((1, None), (2, 1)):
        t = np.arange(0.0, 20.0, 0.01)
        if held is None:
            q, qd, qdd = fourier(t, 2, np.random.default_rng(seed))
        else:
            t, q, qd, qdd = _held_run(model, 20.0, 0.01, seed, held)
        tau = model.regressor(q, qd, qdd) @ p_true
        runs.append(_recording(model, t, q, qd, qdd, tau, f"run{seed}"))
    ident = rd.identify(robot, runs, method="ols", cutoff=None, regularization=None, model=model)
    # joint 2 was at rest in half the data: its offset is a base parameter of its own
    assert "Fo2" in ident.relations.names
    # a new jointwise run: joint 1 moves, joint 2 is held; at rest the friction torque is the
    # true offset alone (Heaviside(0) = 0 in both Coulomb terms), so the held joint's torque is
    # its nominal rigid-body torque plus the true offset: nominal offset + 0.7 N m
    t, q, qd, qdd = _held_run(model, 5.0, 0.01, 3, 1)
    pred = ident.predict(_recording(model, t, q, qd, qdd, None, "check"))
    nominal = model.inverse_dynamics(q, qd, qdd)
    np.testing.assert_allclose(pred[:, 1] - nominal[:, 1], 0.7, atol=1e-8)


def test_offset_regroups_when_no_joint_rests(planar):
    robot, model = planar
    t = np.arange(0.0, 10.0, 0.01)
    q, qd, qdd = fourier(t, 2, np.random.default_rng(4))
    rec = _recording(model, t, q, qd, qdd, model.inverse_dynamics(q, qd, qdd), "moving")
    ident = rd.identify(robot, rec, method="ols", cutoff=None, regularization=None, model=model)
    # without samples at rest Fcp, Fcn and Fo cannot be told apart: Fo regroups into them
    assert not any(name.startswith("Fo") for name in ident.relations.names)
    assert ident.base_parameters.identifiable.all()


def test_dead_band_is_applied_alike_in_fit_and_prediction(planar):
    robot, model = planar
    p_true = _truth(robot)
    for j, level in enumerate((1.5, 0.8)):  # Coulomb levels Fcp = Fcn, N m
        c = PER_JOINT * j + len(INERTIAL_NAMES) + 2
        p_true[c:c + 2] = level
    band = 0.05
    t = np.arange(0.0, 20.0, 0.01)
    q, qd, qdd = fourier(t, 2, np.random.default_rng(5), amplitude=0.3)
    # the plant: Coulomb friction only outside the dead band (written here with a mask)
    y = model.regressor(q, qd, qdd)
    for j in range(2):
        c = PER_JOINT * j + len(INERTIAL_NAMES) + 2
        y[np.abs(qd[:, j]) < band, j, c:c + 2] = 0.0
    tau = y @ p_true
    assert np.mean(np.abs(qd) < band) > 0.02  # the band is visited
    rec = _recording(model, t, q, qd, qdd, tau, "band")
    ident = rd.identify(robot, rec, method="ols", cutoff=None, regularization=None, model=model,
                        dead_band=band)
    assert ident.preprocess.dead_band == band
    np.testing.assert_allclose(ident.predict(rec), tau, rtol=0, atol=1e-8 * np.abs(tau).max())
    # without the dead band the same data cannot be reproduced
    plain = rd.identify(robot, rec, method="ols", cutoff=None, regularization=None, model=model)
    assert np.max(np.abs(plain.predict(rec) - tau)) > 1e-3 * np.abs(tau).max()


@pytest.mark.parametrize("bad", [-1e-3, float("nan"), "wide"])
def test_bad_dead_band_is_refused(planar, bad):
    robot, model = planar
    t = np.arange(0.0, 2.0, 0.01)
    q, qd, qdd = fourier(t, 2, np.random.default_rng(6))
    rec = _recording(model, t, q, qd, qdd, model.inverse_dynamics(q, qd, qdd), "r")
    with pytest.raises(IdentificationError, match="dead_band"):
        rd.identify(robot, rec, cutoff=None, model=model, dead_band=bad)


def _velocity_case(model, seed: int, quantum: float, qd_noise: float) -> rd.Recording:
    """200 Hz recording: positions quantised to ``quantum`` rad, measured velocity with white
    noise of ``qd_noise`` rad/s, exact torque."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 30.0, 0.005)
    q, qd, qdd = fourier(t, 2, rng, f0=0.1)
    tau = model.inverse_dynamics(q, qd, qdd)
    q_meas = np.round(q / quantum) * quantum if quantum else q
    return rd.Recording(t=t, q=q_meas, qd=qd + qd_noise * rng.standard_normal(qd.shape), tau=tau,
                        joint_names=model.robot.joint_names, source=f"v{seed}")


def test_velocity_source_chosen_by_the_finished_models(planar):
    """Coarse encoder with a clean tachometer, and a fine encoder with a very noisy one: the
    source kept is the one whose finished model leaves the smaller residual on the fit data,
    each source's own model finished (both residuals reported), and it is the source the data
    favour by construction."""
    robot, model = planar
    coarse = _velocity_case(model, 7, quantum=0.02, qd_noise=0.0)
    ident = rd.identify(robot, coarse, model=model, velocity="auto", cutoff=5.0)
    assert ident.choices.velocity == "measured"
    assert ident.preprocess.velocity == "measured"
    assert len(ident.choices.candidates) == 2
    scores = dict(ident.choices.velocity_scores)
    assert set(scores) == {"measured", "position"} and scores["measured"] < scores["position"]
    assert "velocity source measured (residual of each source's model" in ident.choices.summary()
    # each source's score is that of the model identified with it alone and the friction law
    # chosen on the first source: its residual on the fit data (without the local correction)
    plain = rd.identify(robot, coarse, model=model, local=False, velocity="position", cutoff=5.0,
                        friction=ident.choices.friction)
    y = coarse.tau
    assert scores["position"] == pytest.approx(
        np.linalg.norm(y - plain.predict(coarse)) / np.linalg.norm(y), rel=1e-9)
    noisy = _velocity_case(model, 8, quantum=0.0, qd_noise=2.0)
    ident = rd.identify(robot, noisy, model=model, velocity="auto", cutoff=5.0)
    assert ident.choices.velocity == "position"
    scores = dict(ident.choices.velocity_scores)
    assert scores["position"] < scores["measured"]
    blocks = {c.velocity: c.score for c in ident.choices.candidates}
    assert blocks["position"] < blocks["measured"]  # the held-out blocks agree here


def test_a_fixed_setting_is_reported_as_given(planar):
    robot, model = planar
    rec = _velocity_case(model, 9, quantum=0.0, qd_noise=0.0)
    ident = rd.identify(robot, rec, model=model, velocity="position", cutoff=4.0)
    assert ident.choices.reason.startswith("as given")
    assert len(ident.choices.candidates) == 1
    assert ident.choices.regularization == ident.regularization
    assert ident.choices.cutoff == ident.preprocess.cutoff


def test_boundary_link_is_projected_into_the_consistent_set():
    # a point mass of 28 kg at (0.1, 0, 0.2) whose inertia about its centre came back from the
    # solver at -1e-7 kg m^2: J = m [c; 1][c; 1]^T, then Sigma nudged off the boundary
    m, c = 28.0, np.array([0.1, 0.0, 0.2])
    sigma = m * np.outer(c, c) - 1e-7 * np.eye(3)
    inertia = np.trace(sigma) * np.eye(3) - sigma  # I = tr(Sigma) 1 - Sigma, about the origin
    p = np.zeros(PER_JOINT)
    p[:10] = (inertia[0, 0], inertia[0, 1], inertia[0, 2], inertia[1, 1], inertia[1, 2],
              inertia[2, 2], *(m * c), m)
    before = p.copy()
    _project_link(p, 0)
    assert np.linalg.eigvalsh(pseudo_inertia(p, 0)).min() >= 0.99 * EPS
    i_c = _inertia_about_com(p)
    assert inertia_problems(i_c) == []
    assert np.max(np.abs(p - before)) <= 1e-5  # moved by the solver's tolerance, not more


def _inertia_about_com(p: np.ndarray) -> np.ndarray:
    xx, xy, xz, yy, yz, zz, mx, my, mz, m = p[:10]
    c = np.array([mx, my, mz]) / m
    i_o = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    # parallel-axis theorem: I_c = I_o - m (|c|^2 1 - c c^T)
    return i_o - m * (float(c @ c) * np.eye(3) - np.outer(c, c))


def _thermal_run(model, seed: int, temp: float, cv: np.ndarray, cc: np.ndarray, t_ref: np.ndarray):
    """A run at drive temperature ``temp`` whose friction changes by (T - T_ref)(cv qd + cc sgn qd)."""
    t = np.arange(0.0, 15.0, 0.01)
    q, qd, qdd = fourier(t, 2, np.random.default_rng(seed))
    temps = np.full(q.shape, temp) + 0.1 * np.sin(0.3 * t)[:, None]  # a slow drift
    # the thermal torque, written out here
    tau = model.inverse_dynamics(q, qd, qdd) + (temps - t_ref) * (cv * qd + cc * np.sign(qd))
    return rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=tau, temperature=temps,
                        joint_names=model.robot.joint_names, source=f"T{temp:g}"), tau


def _thermal_runs(model):
    """``cv``, ``cc``, ``T_ref`` and two runs at 25 and 40 deg C (T_ref: their mean temperature)."""
    cv, cc = np.array([-0.02, -0.01]), np.array([-0.03, 0.015])
    t = np.arange(0.0, 15.0, 0.01)
    t_ref = np.full(2, np.mean([25.0 + 0.1 * np.sin(0.3 * t), 40.0 + 0.1 * np.sin(0.3 * t)]))
    runs = [_thermal_run(model, seed, temp, cv, cc, t_ref)[0] for seed, temp in ((11, 25.0), (12, 40.0))]
    return cv, cc, t_ref, runs


def test_thermal_friction_recovered_and_predicted_at_another_temperature(planar):
    robot, model = planar
    cv, cc, t_ref, runs = _thermal_runs(model)
    ident = rd.identify(robot, runs, method="ols", cutoff=None, regularization=None, model=model,
                        thermal=True)
    fit = ident.thermal_fit
    np.testing.assert_allclose(fit.t_ref, t_ref, rtol=1e-12)
    np.testing.assert_allclose(fit.viscous, cv, atol=1e-9)
    np.testing.assert_allclose(fit.coulomb, cc, atol=1e-9)
    assert ident.choices.thermal
    # friction="auto" (the default) keeps the linear law that the thermal terms extend
    assert ident.choices.friction == "linear" and ident.choices.friction_scores == ()
    assert "friction law linear (with the thermal friction" in ident.choices.summary()
    # a third run at 32 deg C: predicted exactly, and not without the thermal term
    rec, tau = _thermal_run(model, 13, 32.0, cv, cc, t_ref)
    np.testing.assert_allclose(ident.predict(rec), tau, rtol=0, atol=1e-8 * np.abs(tau).max())
    plain = rd.identify(robot, runs, method="ols", cutoff=None, regularization=None, model=model)
    assert np.max(np.abs(plain.predict(rec) - tau)) > 1e-3


def test_the_ripple_does_not_take_up_the_thermal_friction(planar):
    # the terms fitted after the linear step see what it leaves, the thermal torque taken off as
    # it took it off: on these runs (a plant without ripple) a forced ripple comes out at rounding
    # level and the prediction stays exact (before: 0.016 N m amplitudes from the thermal torque,
    # predictions off by 0.018 N m)
    robot, model = planar
    cv, cc, t_ref, runs = _thermal_runs(model)
    ident = rd.identify(robot, runs, method="ols", cutoff=None, regularization=None, model=model,
                        thermal=True, ripple=True)
    assert ident.ripple_fit is not None
    assert np.abs(np.hypot(ident.ripple_fit.sine, ident.ripple_fit.cosine)).max() < 1e-9
    rec, tau = _thermal_run(model, 13, 32.0, cv, cc, t_ref)
    np.testing.assert_allclose(ident.predict(rec), tau, rtol=0, atol=1e-8 * np.abs(tau).max())


def test_thermal_friction_needs_temperatures(planar):
    robot, model = planar
    t = np.arange(0.0, 5.0, 0.01)
    q, qd, qdd = fourier(t, 2, np.random.default_rng(14))
    rec = _recording(model, t, q, qd, qdd, model.inverse_dynamics(q, qd, qdd), "cold.csv")
    with pytest.raises(IdentificationError, match=r"cold.csv: temperature: thermal friction needs"):
        rd.identify(robot, rec, cutoff=None, model=model, thermal=True)
    # "auto" without temperatures: the plain candidate only
    assert not rd.identify(robot, rec, cutoff=None, model=model, thermal="auto").choices.thermal
    with pytest.raises(IdentificationError, match="thermal: expected"):
        rd.identify(robot, rec, cutoff=None, model=model, thermal="yes")


def test_cutoff_candidates_are_the_rule_and_a_wider_one(planar):
    from robodyn.identification.choices import CUTOFF_WIDER, cutoff_candidates
    from robodyn.identification.preprocess import resolve_preprocess

    robot, model = planar
    rec = _velocity_case(model, 10, quantum=0.0, qd_noise=0.0)
    rule = resolve_preprocess([rec], "auto", "auto").cutoff
    assert cutoff_candidates([rec], "auto") == ("auto", CUTOFF_WIDER * rule)
    # the rule computed once (auto_cutoff) and handed on gives the same settings
    from robodyn.identification.preprocess import auto_cutoff

    assert auto_cutoff([rec]) == rule
    assert resolve_preprocess([rec], "auto", "auto", auto=auto_cutoff([rec])) == \
        resolve_preprocess([rec], "auto", "auto")
    assert cutoff_candidates([rec], "auto", rule) == ("auto", CUTOFF_WIDER * rule)
    assert cutoff_candidates([rec], 3.0) == (3.0,)
    ident = rd.identify(robot, rec, model=model, velocity="position")
    labels = [c.label for c in ident.choices.candidates]
    assert len(labels) == 2 and "cutoff=auto" in labels[0]
    # exact positions: the wider filter distorts the motion less, and wins
    assert ident.preprocess.cutoff == CUTOFF_WIDER * rule
    # a coarse encoder (0.02 rad steps): its differentiated noise grows with the cut-off, the
    # rule's cut-off stays
    coarse = _velocity_case(model, 10, quantum=0.02, qd_noise=0.0)
    ident = rd.identify(robot, coarse, model=model, velocity="position")
    assert ident.preprocess.cutoff == resolve_preprocess([coarse], "auto", "auto").cutoff


def test_current_running_against_the_torque_gets_a_negative_gain(planar):
    # a motor-side current sensor on a drive turning against its joint (gear_ratio < 0 in a
    # description) logs I = tau / (-|K|): the identification takes the sense from the data
    robot, model = planar
    t = np.arange(0.0, 20.0, 0.01)
    q, qd, qdd = fourier(t, 2, np.random.default_rng(15))
    tau = model.inverse_dynamics(q, qd, qdd)
    k_true = np.array([-4.0, 2.5])
    rec = rd.Recording(t=t, q=q, qd=qd, qdd=qdd, current=tau / k_true,
                       joint_names=robot.joint_names, source="reversed")
    ident = rd.identify(robot, rec, target="current", method="ols", cutoff=None,
                        regularization=None, model=model)
    assert "current reversed: q1" in ident.gains_source and "q2" not in ident.gains_source.split(":")[-1]
    assert ident.gains[0] < 0 < ident.gains[1]
    np.testing.assert_allclose(ident.predict(rec), rec.current, rtol=0,
                               atol=1e-8 * np.abs(rec.current).max())


@pytest.fixture(scope="module")
def puma():
    robot = load_quiet("puma560")
    return robot, rd.compile_model(robot)


def _log(model, t: np.ndarray, seed: int, decimals: int | None = None):
    """Exact Fourier motion at stamps ``t`` and its torque, optionally printed to ``decimals``."""
    q, qd, qdd = fourier(t, model.dof, np.random.default_rng(seed), f0=0.05)
    tau = model.inverse_dynamics(q, qd, qdd)
    if decimals is not None:
        q, logged = np.round(q, decimals), np.round(tau, decimals)
    else:
        logged = tau
    return rd.Recording(t=t, q=q, tau=logged, joint_names=model.robot.joint_names), tau


def _cobot_stamps(seconds: float, rng: np.random.Generator) -> np.ndarray:
    """A logger's stamps: steps of 10 or 12 ms at random (about 91 Hz), two gaps of 0.1 and 0.35 s."""
    t = np.cumsum(rng.choice([0.010, 0.012], int(seconds / 0.010)))
    t = t[t < seconds]
    keep = np.ones(t.size, bool)
    keep[1000:1010] = keep[3000:3030] = False
    return t[keep]


@pytest.mark.parametrize("decimals", [None, 4])
def test_irregular_stamps_with_gaps_and_quantised_values(puma, decimals):
    robot, model = puma
    t = _cobot_stamps(60.0, np.random.default_rng(3))
    fit, _ = _log(model, t, 1, decimals)
    check, exact = _log(model, t, 2, decimals)
    ident = rd.identify(robot, fit, model=model)
    pred = ident.predict(check)
    assert pred.shape == exact.shape  # one prediction per stamp: nothing assumes a uniform grid
    rel = np.linalg.norm(pred - exact) / np.linalg.norm(exact)
    # exact motion on these stamps is predicted to a few per cent (filter edges, Coulomb steps
    # under a 3-5 Hz low-pass); printing to 4 decimals (0.1 mrad steps) adds little
    assert rel < (0.03 if decimals is None else 0.04)
    # the same samples taken as uniform at their median period: the gaps shift the time base
    # and the prediction falls apart, so the bound above is not met by ignoring the stamps
    uniform = np.median(np.diff(t)) * np.arange(t.size)
    naive = rd.identify(robot, rd.Recording(t=uniform, q=fit.q, tau=fit.tau,
                                            joint_names=robot.joint_names), model=model)
    wrong = naive.predict(rd.Recording(t=uniform, q=check.q, joint_names=robot.joint_names))
    assert np.linalg.norm(wrong - exact) / np.linalg.norm(exact) > 2 * rel


def test_link_side_torque_sensor_drops_the_rotor_inertia(puma):
    # a joint torque sensor after the gear does not see the rotor: the plant's measured torque
    # has no reflected rotor inertia although the description has drives
    robot, model = puma
    p_true = nominal_standard(robot).copy()
    ia = p_true[len(INERTIAL_NAMES)::PER_JOINT].copy()
    assert np.all(ia > 0)  # the PUMA 560's description carries rotor inertia
    p_true[len(INERTIAL_NAMES)::PER_JOINT] = 0.0
    t = np.arange(0.0, 20.0, 0.01)
    q, qd, qdd = fourier(t, 6, np.random.default_rng(16))
    tau = model.regressor(q, qd, qdd) @ p_true
    rec = _recording(model, t, q, qd, qdd, tau, "link_sensor")
    ident = rd.identify(robot, rec, method="ols", cutoff=None, regularization=None, model=model,
                        sensor="link")
    assert not any(name.startswith("Ia") for name in ident.relations.names)
    np.testing.assert_array_equal(ident.standard[len(INERTIAL_NAMES)::PER_JOINT], 0.0)
    np.testing.assert_allclose(ident.predict(rec), tau, rtol=0, atol=1e-8 * np.abs(tau).max())
    with pytest.raises(IdentificationError, match="sensor: 'link'.*needs target='tau'"):
        rd.identify(robot, rd.Recording(t=t, q=q, qd=qd, qdd=qdd, current=tau,
                                        joint_names=robot.joint_names), target="current",
                    model=model, sensor="link")


def test_friction_law_chosen_by_held_out_blocks(planar):
    from robodyn.identification.friction import _law

    robot, model = planar
    t = np.arange(0.0, 30.0, 0.01)
    q, qd, qdd = fourier(t, 2, np.random.default_rng(17), amplitude=0.6)
    rigid = model.regressor(q, qd, qdd) @ _without_friction_truth(robot)
    rng = np.random.default_rng(18)
    # a strong Stribeck hump (Fs = 3 Fc at low speed), written out with the library's law
    stribeck = np.column_stack([_law("stribeck", np.array([1.0, 3.0, 0.08, 0.4, 0.2]), qd[:, j],
                                     rigid[:, j]) for j in range(2)])
    # a plain Coulomb step (1 N m) with viscous friction, which the Stribeck law can only
    # round off near zero velocity
    step = 1.0 * np.sign(qd) + 0.4 * qd
    noise = 0.01 * rng.standard_normal(q.shape)
    frictionless = model.inverse_dynamics(q, qd, qdd) + noise  # planar_2r has no friction
    for tau, expected in ((rigid + stribeck + noise, "stribeck"), (rigid + step + noise, "linear"),
                          (frictionless, "linear")):
        rec = _recording(model, t, q, qd, qdd, tau, expected)
        ident = rd.identify(robot, rec, cutoff=None, model=model)  # friction="auto" by default
        assert ident.choices.friction == expected, ident.choices.summary()
        assert (ident.friction_fit is not None) == (expected == "stribeck")
        scores = dict(ident.choices.friction_scores)
        assert set(scores) == {"linear", "stribeck"}
    # without friction the laws tie and the plain one, linear, is kept: it predicts no more
    # friction than the noise level
    assert np.abs(ident.predict(rec) - (frictionless - noise)).max() < 0.05


def _without_friction_truth(robot):
    from robodyn.identification.friction import without_friction

    p = without_friction(nominal_standard(robot))
    p[len(INERTIAL_NAMES)::PER_JOINT] = nominal_standard(robot)[len(INERTIAL_NAMES)::PER_JOINT]
    return p


def test_a_few_corrupt_rows_are_dropped_as_spikes(puma):
    # issue 20 item 3: real logs carry a few corrupt rows within plausible bounds (an encoder
    # glitch, a torque spike, a row of zeros). Kept, five of 6000 rows double the held-out error
    # on exact motion; spikes="drop" finds and drops them (and nothing else here), and the fit is
    # the clean one again; so does the default, spikes="auto", which drops gross glitches only
    # (these are: a third of a radian, twenty times the torque, a row of zeros), with a warning.
    robot, model = puma
    t = np.arange(0.0, 30.0, 0.005)
    fit, _ = _log(model, t, 1)
    rng = np.random.default_rng(9)
    noisy_tau = fit.tau + 0.5 * rng.standard_normal(fit.tau.shape)  # N m, every sample
    check, exact = _log(model, np.arange(0.0, 10.0, 0.005), 2)

    def held_out(q: np.ndarray, tau: np.ndarray, spikes: str = "drop") -> float:
        # fixed processing and no prior: the rows alone make the difference (with the
        # cross-validated choices a one-sample change can tip a close choice either way)
        ident = rd.identify(robot, rd.Recording(t=t, q=q, tau=tau, joint_names=robot.joint_names),
                            model=model, spikes=spikes, cutoff=5.0, regularization=None,
                            velocity="position", friction="linear")
        return float(np.linalg.norm(ident.predict(check) - exact) / np.linalg.norm(exact))

    clean = held_out(fit.q, noisy_tau, "keep")
    rows = rng.choice(t.size, 5, replace=False)  # 5 of 6000 rows
    q, tau = fit.q.copy(), noisy_tau.copy()
    q[rows[:2], 1] += 0.3  # position glitches, rad
    tau[rows[2:4], 2] *= 20.0  # torque spikes
    q[rows[4]] = 0.0  # a row of zeros
    assert clean < 0.06  # the clean fit (0.5 N m noise, no prior) predicts the exact motion to 5 %
    assert held_out(q, tau, "keep") > 1.5 * clean  # the glitches steer the fit
    from robodyn.identification.spikes import GROSS_THRESHOLD, spike_rows

    found = spike_rows(t, q, tau)
    assert set(np.flatnonzero(found)) == set(rows)  # the five rows, and only they
    assert not spike_rows(t, fit.q, noisy_tau).any()  # clean data: nothing
    assert held_out(q, tau) < 1.02 * clean
    assert set(np.flatnonzero(spike_rows(t, q, tau, threshold=GROSS_THRESHOLD))) == set(rows)
    with pytest.warns(RecordingWarning, match=r"5 row\(s\) dropped as glitches"):
        assert held_out(q, tau, "auto") < 1.02 * clean


def test_least_squares_writes_a_physical_completion_when_one_exists(puma, tmp_path):
    # issue 25 item 6 (the other half): the PUMA 560's own description gives its first link
    # principal moments 0, 0, 0.35 (triangle inequality broken); only Izz of that link reaches the
    # base parameters, so the plain completion with the description's values wrote an impossible
    # link although a physical one with the same base parameters (the same predictions) exists
    from robodyn.identification.completion import completed, physical

    robot, model = puma
    t = np.arange(0.0, 20.0, 0.01)
    q, qd, qdd = fourier(t, robot.dof, np.random.default_rng(4))
    rec = rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=model.inverse_dynamics(q, qd, qdd),
                       joint_names=robot.joint_names)
    ident = rd.identify(robot, rec, model=model, cutoff=None, regularization=None, method="ols")
    theta = ident.relations.to_base(ident.standard)
    plain = completed(ident.relations, theta, nominal_standard(robot))
    assert not physical(plain, robot.dof)  # what was written before
    assert physical(ident.standard, robot.dof)
    np.testing.assert_allclose(theta, ident.relations.to_base(plain), rtol=1e-7, atol=1e-9)
    # the written description loads strictly and predicts what the identification predicts
    path = tmp_path / "puma_identified.yaml"
    path.write_text(dump_yaml(ident.robot))
    again = rd.load(str(path), strict=True)
    np.testing.assert_allclose(rd.compile_model(again).inverse_dynamics(q[:200], qd[:200], qdd[:200]),
                               ident.predict(rec)[:200], rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("law", ["stribeck", "load", "polynomial"])
def test_friction_law_jacobian_matches_central_differences(law):
    """The analytic Jacobian the nonlinear friction fits use, against central differences of the
    law itself at random velocities (both signs, near and far from the Stribeck velocity)."""
    from robodyn.identification.friction import _law, _law_jacobian

    rng = np.random.default_rng(11)
    v = rng.uniform(-0.5, 0.5, 200)
    load = rng.uniform(-20, 20, 200)
    x = {"stribeck": np.array([0.8, 1.3, 0.07, 0.4, -0.1]), "load": np.array([0.8, 0.02, 0.4, -0.1]),
         "polynomial": np.array([0.8, 0.4, -0.3, 0.2, -0.1])}[law]
    jac = _law_jacobian(law, x, v, load)
    h = 1e-6 * np.maximum(np.abs(x), 1e-3)
    numeric = np.column_stack([(_law(law, x + h[k] * np.eye(x.size)[k], v, load)
                                - _law(law, x - h[k] * np.eye(x.size)[k], v, load)) / (2 * h[k])
                               for k in range(x.size)])
    # central differences: error O(h^2 f''') and rounding ~1e-16 |f| / h, well under 1e-6 here
    np.testing.assert_allclose(jac, numeric, rtol=1e-6, atol=1e-7)


def test_friction_choice_does_not_score_a_direction_seen_only_in_the_held_out_block(planar):
    # the Kinova runs turn most joints back only in their first fifth: with that block held out,
    # a joint's negative Coulomb column is fitted to the filter's leakage alone, and its level in
    # the held-out block was a guess (relative errors of 30-360 there, a friction score of 2.7);
    # such folds are not scored, and the scores stay those of the folds that test the laws
    robot, model = planar
    t = np.arange(0.0, 30.0, 0.01)
    w = 2 * np.pi * np.array([0.31, 0.23])
    # qd < 0 for t < 3 s (inside the first of five blocks), > 0 after
    qd = np.tanh((t[:, None] - 3.0) / 0.5) * (0.6 + 0.3 * np.sin(w * t[:, None]))
    qdd = np.gradient(qd, t, axis=0)
    q = np.cumsum(qd, axis=0) * 0.01
    rng = np.random.default_rng(21)
    # asymmetric Coulomb friction: 1 N m turning forward, 2 N m back, and viscous 0.4 N m s/rad
    fric = np.where(qd > 0, 1.0, -2.0) + 0.4 * qd
    tau = model.inverse_dynamics(q, qd, qdd) + fric + 0.01 * rng.standard_normal(q.shape)
    rec = rd.Recording(t=t, q=q, tau=tau, joint_names=robot.joint_names, source="one way")
    ident = rd.identify(robot, rec, model=model, cutoff=5.0, velocity="position")
    scores = dict(ident.choices.friction_scores)
    assert ident.choices.friction == "linear", ident.choices.summary()
    # the linear law is the truth: on the folds that can test it, it predicts the friction
    # residual to a few per cent, well below the zero-friction prediction (score 1)
    assert 0 < scores["linear"] < 0.2, scores
    assert np.isfinite(scores["stribeck"]) and scores["stribeck"] < 1.0, scores
