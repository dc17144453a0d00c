"""Study files and ``robodyn sweep``: bad files refused with file, field and reason (exit 2)."""

from __future__ import annotations

import pandas as pd
import pytest

from robodyn.cli import main
from robodyn.robot.errors import StudyError
from robodyn.studies import expand_cases
from robodyn.studies.study_file import read_study

GOOD = """
task: actuator_sizing
robot: aa300
settings: {dt: 0.005}
parameters:
  payload: [0, 50]
  bandwidth_hz: {min: 2, max: 8}
  zeta: {min: 0.5, max: 1.0, steps: 3}
sampler: {kind: random, n: 2}
seed: 4
"""


def _write(tmp_path, text, name="study.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_study_file_expands_grid_times_samples(tmp_path):
    study = read_study(_write(tmp_path, GOOD))
    cases = expand_cases(study.cases, study.seed)
    assert len(cases) == 2 * 3 * 2
    assert sorted({c["zeta"] for c in cases}) == [0.5, 0.75, 1.0]
    assert all(2 <= c["bandwidth_hz"] <= 8 for c in cases) and study.varying == (
        "payload", "bandwidth_hz", "zeta")
    assert expand_cases(read_study(_write(tmp_path, GOOD)).cases, 4) == cases  # deterministic


@pytest.mark.parametrize("change, message", [
    (("  payload: [0, 50]", "  payload_kg: [0, 50]"),
     r"study.yaml: parameters.payload_kg: unknown parameter 'payload_kg' for actuator sizing of aa300"),
    (("{min: 2, max: 8}", "{min: 8, max: 2}"), r"study.yaml: parameters.bandwidth_hz: min 8 > max 2"),
    (("sampler: {kind: random, n: 2}", "sampler: {kind: sobol, n: 2}"), r"sampler.kind: expected"),
    (("sampler: {kind: random, n: 2}", ""), r"sampler: ranges \['bandwidth_hz'\] need a sampler"),
    (("seed: 4", "seeds: 4"), r"study.yaml: unknown key 'seeds'"),
    (("task: actuator_sizing", "task: sizing"), r"study.yaml: task: expected one of"),
    (("settings: {dt: 0.005}", "settings: {step: 0.005}"), r"study.yaml: settings: .*'step'"),
    # case-count bombs, refused before any case is built (issue 23: 15-23 GB before)
    (("sampler: {kind: random, n: 2}", "sampler: {kind: random, n: 1000000000}"),
     r"study.yaml: parameters.payload = 2 times parameters.zeta.steps = 3 times "
     r"sampler.n = 1000000000: 6e\+09 cases, more than 1,000,000"),
    (("seed: 4", "seed: 4\nrepeat: 1000000000"),
     r"study.yaml: .* times repeat = 1000000000: 1.2e\+10 cases, more than"),
    # probe 23: steps: 1e12 was a 7 TiB linspace (MemoryError), 1e8 took > 4 GB before refusal
    (("steps: 3}", "steps: 1000000000000}"),
     r"study.yaml: parameters.payload = 2 times parameters.zeta.steps = 1000000000000 times "
     r"sampler.n = 2: 4e\+12 cases, more than 1,000,000 \(fewer values"),
    (("steps: 3}", "steps: 100000000}"), r"study.yaml: .*zeta.steps = 100000000 .*: 4e\+08 cases"),
])
def test_bad_study_file_is_named(tmp_path, change, message):
    path = _write(tmp_path, GOOD.replace(*change))
    with pytest.raises(StudyError, match=message):
        read_study(path)


def test_cli_bad_study_is_exit_2_in_one_line(tmp_path, capsys):
    path = _write(tmp_path, GOOD.replace("{min: 2, max: 8}", "{min: 8, max: 2}"))
    assert main(["sweep", str(path), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "parameters.bandwidth_hz: min 8 > max 2" in err[0]
    assert not (tmp_path / "out").exists()


def test_cli_unreachable_scheduler_is_exit_2(tmp_path, capsys):
    path = _write(tmp_path, GOOD)
    code = main(["sweep", str(path), "--scheduler", "tcp://127.0.0.1:9", "--timeout", "1",
                 "-o", str(tmp_path / "out")])
    assert code == 2
    assert "cannot reach the Dask scheduler at 'tcp://127.0.0.1:9'" in capsys.readouterr().err


SIZING = """
task: actuator_sizing
robot: aa300
settings: {trajectory: trapezoid, q_start: [0, 0.6, 1], q_goal: [0.5, 0.9, 1],
           vmax: [1, 0.5, 1.5], amax: [2, 2, 4], dt: 0.005, settle: 0.1}
"""


@pytest.mark.slow
def test_cli_sweep_writes_table_figures_and_report(tmp_path, capsys):
    path = _write(tmp_path, SIZING + "parameters:\n  payload: [0, 50]\n  bandwidth_hz: [3, 5]\n")
    assert main(["sweep", str(path), "--workers", "1", "-o", str(tmp_path / "out")]) == 0
    out = tmp_path / "out"
    table = pd.read_parquet(out / "results.parquet")
    assert list(table.index) == [0, 1, 2, 3] and table["error"].isna().all()
    assert list(table["payload"]) == [0, 0, 50, 50]
    csv = pd.read_csv(out / "results.csv", index_col="case")
    assert (csv["peak_torque.upper_arm"] == table["peak_torque.upper_arm"]).all()
    html = (out / "study.html").read_text()
    assert "4 cases" in html and "0 failed" in html and "data:image/png" in html
    assert (out / "study_map.png").is_file() and (out / "study_histogram.png").is_file()


def test_identification_and_underwater_tasks_run_from_study_files(tmp_path):
    from robodyn.studies import run_serial
    from robodyn.studies.identification_mc import IdentificationMonteCarlo
    from robodyn.studies.underwater_task import UnderwaterEffects

    ident = read_study(_write(tmp_path, "task: identification_monte_carlo\nrobot: planar_2r\n"
                              "parameters:\n  torque_noise: [0.0, 0.5]\nseed: 1\n", "ident.yaml"))
    assert isinstance(ident.task, IdentificationMonteCarlo)
    table = run_serial(ident.task, ident.cases, seed=ident.seed)
    assert list(table["torque_noise"]) == [0.0, 0.5] and table["error"].isna().all()
    # more torque noise, larger parameter error
    assert table["inertial_error"].iloc[1] > table["inertial_error"].iloc[0]
    uw = read_study(_write(tmp_path, "task: underwater_effects\nparameters:\n  Cd: [0.5, 4.0]\n",
                           "uw.yaml"))
    assert isinstance(uw.task, UnderwaterEffects)
    with pytest.raises(StudyError, match="task: expected one of .*identification_monte_carlo"):
        read_study(_write(tmp_path, "task: nonesuch\nparameters:\n  a: [1]\n", "bad.yaml"))


@pytest.mark.slow
def test_cli_sweep_where_every_case_failed_exits_1_with_the_table(tmp_path, capsys):
    path = _write(tmp_path, SIZING + "parameters:\n  payload: [-50, -60]\n")
    assert main(["sweep", str(path), "--workers", "1", "-o", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert "every case failed (the first: InputError: payload mass must be >= 0 kg" in err
    table = pd.read_parquet(tmp_path / "out" / "results.parquet")
    assert len(table) == 2 and table["error"].notna().all()
    failures = pd.read_csv(tmp_path / "out" / "failures.csv", index_col="case")
    assert list(failures.index) == [0, 1] and failures["error"].str.contains("payload mass").all()


def test_grid_bomb_refused_before_expansion(tmp_path, monkeypatch):
    values = "[" + ", ".join(str(k) for k in range(1000)) + "]"
    text = GOOD.replace("  payload: [0, 50]", f"  payload: {values}").replace(
        "  bandwidth_hz: {min: 2, max: 8}\n", f"  bandwidth_hz: {values}\n").replace(
        "sampler: {kind: random, n: 2}\n", "")
    with pytest.raises(StudyError, match=r"study.yaml: parameters.payload = 1000 times parameters."
                                         r"bandwidth_hz = 1000 times parameters.zeta.steps = 3: "
                                         r"3e\+06 cases, more than 1,000,000 .*ROBODYN_MAX_CASES"):
        read_study(_write(tmp_path, text))
    monkeypatch.setenv("ROBODYN_MAX_CASES", "5000000")  # the limit a deliberate study raises
    assert read_study(_write(tmp_path, text)).varying == ("payload", "bandwidth_hz", "zeta")


@pytest.mark.parametrize("field, text", [
    ("parameters.bandwidth_hz.steps = 1000000000000",
     "  bandwidth_hz: {min: 2.0, max: 8.0, steps: 1000000000000}\n"),
    ("parameters.bandwidth_hz.steps = 100000000",
     "  bandwidth_hz: {min: 2.0, max: 8.0, steps: 100000000}\n"),
    ("sampler.n = 1000000000000", "  bandwidth_hz: {min: 2.0, max: 8.0}\nsampler: {n: 1000000000000}\n"),
])
def test_cli_declared_case_count_refused_before_anything_is_built(tmp_path, capsys, monkeypatch,
                                                                   field, text):
    # probe 23: steps: 1e12 exited 1 with "MemoryError ... 7.28 TiB"; the count is now the
    # product of the declared sizes, refused before any value list or array exists
    from robodyn.studies import study_file

    def no_values(*args, **kwargs):
        raise AssertionError("the values were built before the case count was checked")

    monkeypatch.setattr(study_file, "_split_parameters", no_values)
    path = _write(tmp_path, SIZING + "parameters:\n  payload: [0]\n" + text)
    assert main(["sweep", str(path), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"study.yaml: {field}: " in err[0]
    assert "cases, more than 1,000,000 (fewer values or sample points" in err[0]
    assert not (tmp_path / "out").exists()
