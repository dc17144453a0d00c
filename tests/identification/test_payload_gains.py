"""Drive gains separated from inertia by a run with a known payload (target="current").

Truth: a planar 2R whose link inertias differ from the description (+15 % link 1, -10 % link 2)
and whose drive gains differ from the description's (1 N m/A) by the virtual laboratory's
torque-constant errors; a second plant carries a known payload on link 2. Current alone fixes
the gains only up to a common scale (absorbed, reported as not identified); with the payload
run the gains come back exactly on noise-free data and within 3 reported standard deviations
with current noise.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.payload import payload_standard
from robodyn.identification.pipeline import nominal_standard
from robodyn.identification.to_robot import robot_with_parameters
from robodyn.robot.errors import IdentificationError
from robodyn.simulation.trajectory import via_points
from robodyn.studies.virtual_lab import Sensors, virtual_lab
from robodyn.symbolic.regressor import PER_JOINT
from tests.identification.helpers import load_quiet

PAYLOAD = rd.Payload(mass=0.8, com=[0.1, 0.05, 0.02], inertia=np.diag([0.004, 0.006, 0.008]))
EXACT = Sensors(sample_period=5e-3, jitter=0.0, counts_per_rev=0.0, current_noise=0.0,
                current_offset=0.05, torque_constant_error=0.15, torque_noise=None,
                tracker_period=0.0)
LAB_SEED = 4  # one set of drives: the same seed draws the same gains and offsets in every run


@pytest.fixture(scope="module")
def lab():
    robot = load_quiet("planar_2r")
    n = robot.dof
    true = nominal_standard(robot).copy()
    true[:10] *= 1.15  # link 1's inertial parameters, scaled (still a rigid body)
    true[PER_JOINT:PER_JOINT + 10] *= 0.9
    loaded = true.copy()
    loaded[PER_JOINT * (n - 1):PER_JOINT * (n - 1) + 10] += payload_standard(robot, PAYLOAD)
    runs = []
    for k, p in enumerate((true, loaded)):
        plant = rd.compile_model(robot_with_parameters(robot, p))
        rng = np.random.default_rng(30 + k)
        points = rng.uniform(-2.0, 2.0, (9, n))
        traj = via_points(points, np.linspace(0.0, 12.0, 9), dt=EXACT.sample_period)
        runs.append(virtual_lab(plant, traj, sensors=EXACT, seed=LAB_SEED))
    return robot, rd.compile_model(robot), runs, true


def _recording(run, current, name):
    """Exact states and the given current, from the second sample on: at the first the arm is
    at rest, ``qd = 0`` exactly, where the base relations (drawn at random, non-zero
    velocities) do not carry the current offset (``Fo`` is regrouped into ``Fcp``/``Fcn``)."""
    tr = run.truth
    return rd.Recording(t=tr.t[1:], q=tr.q[1:], qd=tr.qd[1:], qdd=tr.qdd[1:], current=current[1:],
                        source=name)


def test_lab_truth_is_the_plant_inverse_dynamics(lab):
    """The oracle itself: current = tau / K + offset, tau the exact inverse dynamics."""
    robot, _, runs, true = lab
    plant = rd.compile_model(robot_with_parameters(robot, true))
    tr = runs[0].truth
    np.testing.assert_allclose(runs[0].recording.current - tr.current_offset,
                               plant.inverse_dynamics(tr.q, tr.qd, tr.qdd) / tr.drive_gain,
                               rtol=0, atol=1e-9)
    np.testing.assert_array_equal(runs[0].truth.drive_gain, runs[1].truth.drive_gain)
    assert np.all(np.abs(tr.drive_gain - 1.0) > 0.02)  # the description's gains (1) are wrong


def test_noise_free_payload_run_recovers_the_gains(lab):
    robot, model, runs, true = lab
    gain = runs[0].truth.drive_gain
    recs = [_recording(r, r.recording.current, f"run{k}") for k, r in enumerate(runs)]
    ident = rd.identify(robot, recs, target="current", method="ols", cutoff=None,
                        regularization=None, model=model, payloads=[None, PAYLOAD])
    assert ident.gains_source == "payload" and ident.gains_identified
    rel = np.abs(ident.gains / gain - 1.0)
    print("gains", ident.gains, "truth", gain, "relative error", rel)
    assert rel.max() < 1e-6
    # the inertial base parameters are then the plant's own (torque units), not rescaled ones
    theta_true = ident.relations.to_base(true)
    inertial = ident.relations.independent % PER_JOINT < 10
    err = np.abs(ident.base_parameters.values - theta_true)[inertial]
    assert err.max() < 1e-6 * np.abs(theta_true[inertial]).max()
    # the identified robot stores them in its drives: G * torque_constant = K
    kt = [float(j.drive.gear_ratio * j.drive.torque_constant) for j in ident.robot.joints]
    np.testing.assert_allclose(kt, ident.gains, rtol=1e-12)
    # and the prediction with the payload reproduces the payload run's current
    np.testing.assert_allclose(ident.predict(recs[1], payload=PAYLOAD), recs[1].current,
                               rtol=0, atol=1e-7 * np.abs(recs[1].current).max())


def test_the_terms_after_the_linear_step_see_the_target_without_the_payload(lab):
    # the friction law, the ripple and the other terms fitted after the linear step are fitted
    # on what it leaves of the target; the linear step took the payload's torque off, so must
    # they: on these noise-free runs (a plant without ripple) a forced ripple then comes out at
    # rounding level (1e-15; before, the payload's torque was in its residual: amplitudes of
    # 1.2 and 2.3 A on joint 2), and the friction laws' held-out residual is 0 (before: 1.01
    # linear, 0.995 Stribeck: the payload's torque, nearly taken for a Stribeck hump)
    robot, model, runs, _ = lab
    recs = [_recording(r, r.recording.current, f"run{k}") for k, r in enumerate(runs)]
    ident = rd.identify(robot, recs, target="current", method="ols", cutoff=None,
                        regularization=None, model=model, payloads=[None, PAYLOAD], ripple=True)
    assert ident.ripple_fit is not None and ident.ripple_fit.revolute[1]  # joint 2 carries one
    amplitude = np.hypot(ident.ripple_fit.sine, ident.ripple_fit.cosine)
    assert amplitude.max() < 1e-9 * np.abs(recs[1].current).max()
    assert max(v for _, v in ident.choices.friction_scores) < 1e-6


def test_the_prior_does_not_take_a_known_payload_for_friction(lab):
    # the per-joint friction fit of the prior (the pull of the regularisation) explains the
    # target by the description's torque; a known payload's torque belongs to that explained
    # part: the same motion run with and without it gives the same prior and the same fit
    # (before, the payload's gravity went into the prior's friction, offset and rotor terms)
    robot, model, runs, true = lab
    loaded = true.copy()
    loaded[PER_JOINT:PER_JOINT + 10] += payload_standard(robot, PAYLOAD)
    tr = runs[0].truth
    recs = [rd.Recording(t=tr.t[1:], q=tr.q[1:], qd=tr.qd[1:], qdd=tr.qdd[1:], source=f"run {k}",
                         tau=rd.compile_model(robot_with_parameters(robot, p)).inverse_dynamics(
                             tr.q, tr.qd, tr.qdd)[1:]) for k, p in enumerate((true, loaded))]
    assert np.abs(recs[1].tau - recs[0].tau).max() > 0.5  # the payload's torque is not small
    plain = rd.identify(robot, recs[0], target="tau", cutoff=None, model=model, ripple=False)
    with_payload = rd.identify(robot, recs[1], target="tau", cutoff=None, model=model,
                               ripple=False, payloads=[PAYLOAD])
    a, b = plain.base_parameters, with_payload.base_parameters
    np.testing.assert_allclose(b.nominal, a.nominal, rtol=0, atol=1e-9 * np.abs(a.nominal).max())
    np.testing.assert_allclose(b.values, a.values, rtol=0, atol=1e-6 * np.abs(a.values).max())


def test_without_payload_the_gains_are_absorbed_and_reported_so(lab):
    robot, model, runs, _ = lab
    gain = runs[0].truth.drive_gain
    rec = _recording(runs[0], runs[0].recording.current, "run0")
    ident = rd.identify(robot, rec, target="current", method="ols", cutoff=None,
                        regularization=None, model=model)
    assert ident.gains_source == "absorbed" and not ident.gains_identified
    assert np.all(np.isinf(ident.gains_std))
    # absorbed gains carry the description's inertia error: not the drives' gains
    assert np.abs(ident.gains / gain - 1.0).max() > 0.05


def test_payload_runs_alone_cannot_separate_the_gains(lab):
    robot, model, runs, _ = lab
    rec = _recording(runs[1], runs[1].recording.current, "run1")
    with pytest.raises(IdentificationError, match="not identifiable from these runs"):
        rd.identify(robot, [rec], target="current", cutoff=None, model=model, payloads=[PAYLOAD])


def test_noisy_current_gains_within_three_sigma(lab):
    """Current noise 0.02 A (about 1 % of the peak current), independent in each run."""
    robot, model, runs, _ = lab
    gain = runs[0].truth.drive_gain
    rng = np.random.default_rng(5)
    recs = [_recording(r, r.recording.current + rng.normal(0.0, 0.02, r.truth.current.shape),
                       f"run{k}") for k, r in enumerate(runs)]
    ident = rd.identify(robot, recs, target="current", method="wls", cutoff=None,
                        regularization=None, model=model, payloads=[None, PAYLOAD])
    z = (ident.gains - gain) / ident.gains_std
    print("gains", ident.gains, "std", ident.gains_std, "truth", gain, "z", z)
    assert np.all(np.abs(z) < 3.0)
    assert np.all(ident.gains_std < 0.02 * np.abs(gain))  # and the estimate is informative


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"mass": 0.0}, r"Payload.mass: must be > 0 kg"),
    ({"mass": float("nan")}, r"Payload.mass: not finite"),
    ({"mass": 1.0, "com": [0.0, 0.1]}, r"Payload.com: expected shape \(3,\)"),
    ({"mass": 1.0, "inertia": [[1, 0.1, 0], [0, 1, 0], [0, 0, 1]]}, r"Payload.inertia: not symmetric"),
    ({"mass": 1.0, "inertia": np.diag([1.0, -0.1, 1.0])}, r"not positive semi-definite"),
    ({"mass": 1.0, "inertia": np.diag([0.1, 0.1, 1.0])}, r"triangle inequality"),
    ({"mass": 1.0, "frame": "world"}, r"Payload.frame: expected one of"),
])
def test_payload_validation(kwargs, message):
    with pytest.raises(IdentificationError, match=message):
        rd.Payload(**kwargs)


def test_payload_keeps_the_users_arrays():
    com = np.array([0.1, 0.0, 0.0])
    inertia = np.eye(3) * 0.01
    pay = rd.Payload(mass=1.0, com=com, inertia=inertia)
    com[0] = 5.0
    assert pay.com[0] == 0.1 and com.flags.writeable
    assert not pay.com.flags.writeable


def test_point_mass_at_the_tool_point():
    """A point mass at the tool frame origin: first moments m p, inertia m (|p|^2 1 - p p^T)."""
    robot = load_quiet("puma560")
    tool = np.array(robot.tool.xreplace(robot.defaults()), dtype=float)
    p = tool[:3, 3]
    pi = payload_standard(robot, rd.Payload(mass=2.0, frame="tool"))
    i_o = 2.0 * (p @ p * np.eye(3) - np.outer(p, p))
    np.testing.assert_allclose(pi, [i_o[0, 0], i_o[0, 1], i_o[0, 2], i_o[1, 1], i_o[1, 2],
                                    i_o[2, 2], *(2.0 * p), 2.0], rtol=0, atol=1e-15)


def test_payload_list_errors(lab):
    robot, model, runs, _ = lab
    rec = _recording(runs[0], runs[0].recording.current, "run0")
    with pytest.raises(IdentificationError, match=r"payloads: expected one per recording \(1\), got 2"):
        rd.identify(robot, [rec], target="current", cutoff=None, model=model, payloads=[None, None])
    with pytest.raises(IdentificationError, match=r"payloads\[0\]: expected a Payload or None, got dict"):
        rd.identify(robot, [rec], target="current", cutoff=None, model=model, payloads=[{"mass": 1}])


def test_cli_payload_run_gives_the_gains(lab, tmp_path, capsys):
    """``robodyn identify --payload-data ... --payload ...``: the same separation from files, with
    the CLI's default preprocessing (filtered positions, differentiated), so to 1 % not 1e-6."""
    from robodyn.cli import main
    from robodyn.measure.csv_io import write_csv

    robot, _, runs, _ = lab
    gain = runs[0].truth.drive_gain
    files = []
    for k, r in enumerate(runs):
        rec = _recording(r, r.recording.current, f"run{k}")
        rec = rd.Recording(t=rec.t, q=rec.q, qd=rec.qd, current=rec.current,
                           joint_names=robot.joint_names)
        files.append(write_csv(rec, tmp_path / f"run{k}.csv"))
    flat = [PAYLOAD.mass, *PAYLOAD.com, *np.diag(PAYLOAD.inertia)]
    rc = main(["identify", "planar_2r", "--target", "current", "--data", str(files[0]),
               "--payload-data", str(files[1]), "--payload", ",".join(repr(float(v)) for v in flat),
               "--payload-frame", "link", "--method", "consistent", "-o", str(tmp_path / "out")])
    assert rc == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("drive gains"))
    found = np.array([float(part.split("+-")[0]) for part in line.split(":", 1)[1].split(",")])
    np.testing.assert_allclose(found, gain, rtol=1e-2)


def test_cli_payload_options_go_together(lab, tmp_path, capsys):
    from robodyn.cli import main

    rc = main(["identify", "planar_2r", "--data", "x.csv", "--payload", "1,0,0,0",
               "-o", str(tmp_path)])
    assert rc == 2
    assert "--payload and --payload-data go together" in capsys.readouterr().err
    rc = main(["identify", "planar_2r", "--data", "x.csv", "--payload-data", "y.csv",
               "--payload", "1,0,0", "-o", str(tmp_path)])
    assert rc == 2
    assert "--payload: expected KG,X,Y,Z" in capsys.readouterr().err
