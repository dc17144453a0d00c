"""CSV recordings: sensor conversions against hand-computed values, the Kinova Gen3 logs, round trips."""

import gzip
from pathlib import Path

import numpy as np
import pytest

import robodyn as rd
from robodyn.measure.conversions import (
    counts_to_angle,
    current_to_torque,
    estimate_period,
    unwrap_counter,
)
from robodyn.measure.csv_io import write_csv
from robodyn.measure.filtering import differentiate
from robodyn.robot.errors import RecordingError

DATA = Path(__file__).resolve().parents[3] / "shared" / "data" / "kinova-gen3"
if not DATA.is_dir():
    DATA = Path("/work/shared/data/kinova-gen3")
KINOVA = sorted(DATA.glob("*/*.csv.gz"))
KINOVA_NAMES = [p.name for p in KINOVA] or ["none"]


def test_counter_wrapping_several_times():
    # a 12-bit counter (4096) driven through 5.3 turns forward and back
    bits, span = 12, 4096
    top = 100 + 5.3 * span
    true = np.concatenate([np.linspace(100, top, 2000), np.linspace(top, -900, 2000)])
    raw = np.mod(np.round(true), span)
    assert (np.abs(np.diff(raw)) > span / 2).sum() >= 10  # it really wraps, many times
    unwrapped = unwrap_counter(raw, bits)
    assert np.array_equal(unwrapped - unwrapped[0], np.round(true) - np.round(true)[0])
    # counts -> rad: 2 pi c / (counts_per_rev * gear)
    assert counts_to_angle(np.array([[4096.0 * 50]]), np.array([4096.0]), np.array([50.0]))[0, 0] \
        == pytest.approx(2 * np.pi)


def test_spec_encoder_volts_torque_hand_computed(tmp_path):
    # joint 1: 24-bit counter, 2^20 counts/rev, gear 100, sign -1, offset 0.5 rad
    # joint 2: degrees, coupled: q2_true = q2 + q1
    n = 50
    turns = np.linspace(0.0, 250.0, n)  # motor turns of joint 1: 250 turns = 2.5 joint turns
    counts = np.mod(np.round(turns * 2**20), 2**24)  # wraps 15 times
    deg = np.linspace(0.0, 90.0, n)
    volts = np.linspace(2.4, 2.6, n)  # transducer: I = (V - 2.5) / 0.1
    rows = ["idx;enc1;deg2;v1;v2"] + [
        f"{k};{int(counts[k])};{float(deg[k])!r};{float(volts[k])!r};2.5" for k in range(n)]
    path = tmp_path / "arm.txt"
    path.write_text("\n".join(rows) + "\n")
    spec = {
        "delimiter": ";", "joints": ["a", "b"],
        "time": {"column": "idx", "unit": "index", "period": 0.004},
        "position": {"columns": ["enc1", "deg2"], "unit": "counts", "counts_per_rev": [2**20, 1],
                     "gear_ratio": [100, 1], "wrap_bits": 24, "sign": [-1, 1], "offset": [0.5, 0]},
        "current": {"columns": ["v1", "v2"], "unit": "V", "offset": 2.5, "gain": 0.1},
        "torque": {"from": "current", "gear_ratio": [100, 1], "torque_constant": [0.05, 0.2]},
        "couplings": [{"joint": "b", "add": {"a": 1.0}}],
    }
    # counts are not degrees: joint 2 needs its own unit, so read it as counts of 360 per rev
    spec["position"]["counts_per_rev"] = [2**20, 360]
    rec = rd.read_recording(path, spec=spec)
    q1 = -(2 * np.pi * np.round(turns * 2**20) / 2**20 / 100) + 0.5
    assert np.allclose(rec.q[:, 0], q1, atol=1e-12, rtol=0)
    assert np.allclose(rec.q[:, 1], np.deg2rad(deg) + q1, atol=1e-12, rtol=0)
    current = (volts - 2.5) / 0.1
    assert np.allclose(rec.current[:, 0], current, atol=1e-12)
    assert np.allclose(rec.tau[:, 0], current * 100 * 0.05, atol=1e-12)  # tau = N k_t I
    assert np.allclose(rec.tau[:, 1], 0.0)
    assert np.allclose(rec.t, 0.004 * np.arange(n))


def test_headerless_whitespace_log(tmp_path):
    # a controller's text log: no header, fields aligned with runs of spaces and tabs
    t = 0.002 * np.arange(12)
    q = np.column_stack([np.linspace(0.1, 0.6, 12), np.linspace(-1.0, -0.5, 12)])
    amps = np.column_stack([np.linspace(0.5, 1.0, 12), np.linspace(2.0, 1.5, 12)])
    lines = [f"  {t[k]:.3f}\t {q[k, 0]:.4f}   {q[k, 1]:.4f} \t{amps[k, 0]:.3f}  {amps[k, 1]:.3f}"
             for k in range(12)]
    path = tmp_path / "robot.log"
    path.write_text("\n".join(lines) + "\n")
    spec = {"delimiter": "whitespace", "header": False, "joints": 2,
            "time": {"column": 0, "unit": "s"},
            "position": {"columns": [1, 2], "unit": "rad"},
            "current": {"columns": [3, 4], "unit": "A"}}
    rec = rd.read_recording(path, spec=spec)
    np.testing.assert_allclose(rec.t, t, atol=1e-12)
    np.testing.assert_allclose(rec.q, np.round(q, 4), atol=1e-12)
    np.testing.assert_allclose(rec.current, np.round(amps, 3), atol=1e-12)
    # a row with a missing field is named by its line
    path.write_text("\n".join(lines[:3] + ["  0.006  0.4000  -0.7000  0.800"] + lines[4:]) + "\n")
    with pytest.raises(RecordingError, match=r"robot.log: line 4: 4 fields, but the first row"):
        rd.read_recording(path, spec=spec)
    with pytest.raises(RecordingError, match=r"delimiter: expected one character or 'whitespace'"):
        rd.read_recording(path, spec={**spec, "delimiter": "spaces"})


def test_period_estimate_recovers_known_period():
    rng = np.random.default_rng(0)
    period = 1.0074e-3
    t = period * np.arange(3000)
    q = np.sin(np.outer(t, [3.0, 5.0]))
    qd = np.cos(np.outer(t, [3.0, 5.0])) * [3.0, 5.0] + 1e-3 * rng.standard_normal((3000, 2))
    assert estimate_period(q, qd) == pytest.approx(period, rel=1e-4)


def test_current_to_torque():
    assert current_to_torque(np.array([[2.0, -1.0]]), np.array([100.0, 50.0]),
                             np.array([0.1, 0.2])).tolist() == [[20.0, -10.0]]


@pytest.mark.data(DATA)
@pytest.mark.parametrize("name", KINOVA_NAMES)
def test_every_kinova_file_loads_and_velocity_agrees(name):
    path = next(p for p in KINOVA if p.name == name)
    before = path.read_bytes()
    rec = rd.read_recording(path, spec="kinova_gen3")
    assert path.read_bytes() == before
    assert rec.dof == 7 and rec.joint_names[0] == "joint_1"
    assert "qd" not in rec.estimated and "qdd" in rec.estimated
    # README: period 1.002-1.013 ms (estimated the same way); here 1.000-1.014 ms
    assert 0.999e-3 < rec.dt < 1.015e-3
    assert rec.current is not None and np.isfinite(rec.current).all()
    if name == "RunTrajectory1.csv.gz":  # the only file with torque sensors, none on joint 1
        assert np.isnan(rec.tau[:, 0]).all() and np.isfinite(rec.tau[:, 1:]).all()
    else:
        assert rec.tau is None  # never the Torque columns (a model output)
    # measured velocity against the zero-phase derivative of the measured position, on the
    # joints that move (range > 0.05 rad): RMS difference / RMS velocity. Measured 0.019-0.047
    # (the measured velocity's periodic spikes dominate); a plain central difference: 0.058-0.11
    _, v, _ = differentiate(rec.t, rec.q)
    moving = np.ptp(rec.q, axis=0) > 0.05
    rms = np.sqrt(np.mean(rec.qd[:, moving] ** 2))
    err = np.sqrt(np.mean((v - rec.qd)[:, moving] ** 2)) / rms
    naive = np.sqrt(np.mean((np.gradient(rec.q, rec.t, axis=0) - rec.qd)[:, moving] ** 2)) / rms
    assert err < 0.05
    assert err < 0.6 * naive


@pytest.mark.data(DATA)
def test_kinova_with_robot_keeps_chain_order():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("kinova_gen3")
    path = DATA / "identification_data" / "Trajectory1.csv.gz"
    rec = rd.read_recording(path, spec="kinova_gen3", robot=robot)
    assert rec.joint_names == robot.joint_names


def _sample_recording(with_tool=True):
    rng = np.random.default_rng(3)
    t = 1e-3 * np.arange(400) + 0.1234567
    q = np.sin(np.outer(t, [1.0, 2.0, 3.0])) + 1e-7 * rng.standard_normal((400, 3))
    tau = rng.standard_normal((400, 3))
    tau[:, 2] = np.nan  # no sensor on the third joint
    kw = {}
    if with_tool:
        kw = {"tool_t": 0.01 * np.arange(30) + 0.105, "tool_points": rng.standard_normal((30, 3))}
    return rd.Recording(t=t, q=q, tau=tau, current=rng.standard_normal((400, 3)),
                        joint_names=("j1", "j2", "j3"), **kw)


@pytest.mark.parametrize("suffix", [".csv", ".csv.gz"])
def test_csv_round_trip_identical(tmp_path, suffix):
    rec = _sample_recording()
    path = write_csv(rec, tmp_path / f"rec{suffix}")
    if suffix.endswith(".gz"):
        assert gzip.decompress(path.read_bytes()).startswith(b"t,q[j1]")
    back = rd.read_recording(path)
    assert back.joint_names == rec.joint_names and back.estimated == rec.estimated
    for field in ("t", "q", "qd", "qdd", "current", "tool_t", "tool_points"):
        assert np.array_equal(getattr(back, field), getattr(rec, field)), field
    assert np.array_equal(back.tau, rec.tau, equal_nan=True)
    assert back.temperature is None


def test_period_estimate_and_a_corrupt_cell():
    # one position cell of 1e308 once set the estimated period (and so the duration) to 1e304 s
    rng = np.random.default_rng(5)
    period = 1.003e-3
    t = period * np.arange(3000)
    q = np.column_stack([np.sin(2 * t), np.cos(3 * t)])
    qd = np.column_stack([2 * np.cos(2 * t), -3 * np.sin(3 * t)]) + rng.normal(0, 1e-4, (3000, 2))
    clean = estimate_period(q, qd)
    assert clean == pytest.approx(period, rel=1e-4)
    q_bad = q.copy()
    q_bad[1200, 0] = 1e308
    assert estimate_period(q_bad, qd) == pytest.approx(clean, rel=1e-6)
    # and the recording itself names the cell
    with pytest.raises(RecordingError, match=r"q: 1e\+308 at row 1200, column 0 \('q1'\) is not a "
                                             r"plausible joint position"):
        rd.Recording(t=t, q=q_bad, qd=qd)
