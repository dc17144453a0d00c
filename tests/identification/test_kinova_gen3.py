"""Kinova Gen3, real recordings: held-out motor-current error against the README's baseline.

Data: ../shared/data/kinova-gen3 (README: motor current ``Cur`` is the dependable target; the
``Torque`` columns are a model output and are never used here). Fit on the first 70 % of each
whole-arm run, predict the last 30 % and every jointwise run (the moving joint); and across runs.

README baseline on the same split: 0.32 relative error against the raw current, 0.22 against
the zero-phase-filtered current; noise floor (raw minus filtered) about 0.26. "Filtered" is
robodyn's reference filter (``robodyn.validation.heldout``: zero-phase Butterworth, order 4, at
2.5 Hz, the cut-off that reproduces the README's noise floor), the one ``rd.validate`` and the
CLI use. Figures measured by these tests are quoted in docs/identification.md.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.consistent import pseudo_inertia
from robodyn.identification.preprocess import preprocess
from robodyn.robot.yaml_writer import dump_yaml
from robodyn.validation.heldout import held_out_error, moving_joints
from tests.identification.helpers import load_quiet
from tests.identification.kinova import JOINTWISE_FILES, WHOLE_ARM, WHOLE_ARM_FILES, read, split

BASELINE_RAW = 0.32
BASELINE_FILTERED = 0.22
#: the controller's current-to-torque constants (data README), N m/A
CONTROLLER_GAINS = np.array([9.13, 9.13, 9.13, 9.13, 5.852, 5.852, 5.852])
data = pytest.mark.data(*WHOLE_ARM_FILES, *JOINTWISE_FILES)


@pytest.fixture(scope="module")
def gen3():
    robot = load_quiet("kinova_gen3")
    model = rd.compile_model(robot)
    runs = [read(p) for p in WHOLE_ARM_FILES]
    train = [split(r)[0] for r in runs]
    test = [split(r)[1] for r in runs]
    return robot, model, train, test


@pytest.fixture(scope="module")
def default_fit(gen3):
    robot, model, train, _ = gen3
    return rd.identify(robot, train, target="current", model=model)


def _errors(ident, recs, joint=None):
    """(raw, filtered, noise floor) of ``ident`` pooled over ``recs`` (reference filter)."""
    fig = held_out_error([r.t for r in recs], [r.current for r in recs], [ident.predict(r) for r in recs],
                         ident.robot.joint_names, None if joint is None else [joint])
    return fig.raw, fig.filtered, fig.noise_floor


@pytest.mark.slow
@data
def test_held_out_current_error_beats_the_readme_baseline(gen3):
    robot, model, train, test = gen3
    figures = {}
    for friction in ("none", "linear", "load"):
        ident = rd.identify(robot, train, target="current", friction=friction, model=model)
        figures[friction] = _errors(ident, test)
        print(f"{friction:>7}: raw {figures[friction][0]:.3f}  filtered {figures[friction][1]:.3f}  "
              f"noise floor {figures[friction][2]:.3f}  (cut-off {ident.preprocess.cutoff:g} Hz, "
              f"decimate {ident.preprocess.decimate}, lambda {ident.regularization:.3g}, "
              f"cond {ident.condition:.3g})")
    # measured (2026-12-07, the default with its drive modes): linear 0.260 / 0.207, load
    # 0.276 / 0.226, none 0.902 / 0.902 (2026-12-06: linear 0.259 / 0.202, load 0.284 / 0.233,
    # none 0.909; without the drive modes 0.286 / 0.176 and 0.303 / 0.205)
    raw, filtered, floor = figures["linear"]
    assert raw < BASELINE_RAW
    assert filtered < BASELINE_FILTERED
    assert 0.25 < floor < 0.27  # the README's "about 0.26" (measured 0.261)
    assert figures["load"][0] < 0.5 * figures["none"][0]  # yet it carries the friction
    # friction is the decisive term: without it the error nearly doubles
    assert figures["none"][0] > 1.5 * figures["linear"][0]


# Each whole-arm run's last 30 % alone, default fit (consistent, cross-validated Tikhonov weight
# 0.01, measured velocity): each below the README's pooled raw baseline on its own (measured
# 2026-12-06 with the two-stage consistent program: 0.281 / 0.170, 0.247 / 0.228 and
# 0.257 / 0.213, noise floors 0.246, 0.243, 0.274). The README's filtered figure (0.22) is for
# the pooled split, asserted by the test above; Trajectory1's split alone was 0.219 with the
# earlier program's tie-break (a pull toward the description on every parameter) and is 0.228
# without it, so it is not asserted per run. With the earlier default (WLS with a Tikhonov
# weight toward the description) the two short runs were above the raw baseline (0.353 / 0.269
# and 0.351 / 0.283).
@pytest.mark.slow
@data
@pytest.mark.parametrize("run", [0, 1, 2], ids=WHOLE_ARM)
def test_each_whole_arm_run_held_out(gen3, default_fit, run):
    _, _, _, test = gen3
    raw, filtered, floor = _errors(default_fit, [test[run]])
    print(f"{WHOLE_ARM[run]}: raw {raw:.3f}  filtered {filtered:.3f}  noise floor {floor:.3f}")
    assert raw < BASELINE_RAW


@data
def test_each_jointwise_run_for_its_moving_joint(default_fit):
    """Never used in fitting; the moving joint's current. Raw: below the baseline, or, where the
    run's noise floor alone exceeds it (joint 7: 0.498), within 0.01 of that floor."""
    for path in JOINTWISE_FILES:
        rec = read(path)
        (k,) = moving_joints(rec.q)
        assert path.name == f"joint_{k + 1}_trapez.csv.gz"
        raw, filtered, floor = _errors(default_fit, [rec], joint=int(k))
        print(f"{path.name}: joint {k + 1}: raw {raw:.3f}  filtered {filtered:.3f}  noise floor {floor:.3f}")
        assert raw < max(BASELINE_RAW, floor + 0.01), path.name
        assert filtered < BASELINE_FILTERED, path.name


@pytest.mark.slow
@data
def test_cross_run_fit_on_the_short_runs_predicts_the_long_run(gen3):
    """Fit on the whole of RunTrajectory1 and Trajectory1, predict the whole of
    RecordTrajectory_quadratic (a different motion, recorded about 10 deg C colder): worse than
    the held-out split (measured 0.398 / 0.325, noise floor 0.266), yet better than the
    manufacturer's URDF with the controller's constants on the same run (an independent model)."""
    robot, model, _, _ = gen3
    runs = [read(p) for p in WHOLE_ARM_FILES]
    from robodyn.identification.prior import IdentificationWarning

    with pytest.warns(IdentificationWarning, match=r"'joint_7' cannot be absorbed"):
        ident = rd.identify(robot, runs[:2], target="current", model=model)
    raw, filtered, floor = _errors(ident, [runs[2]])
    s = preprocess(runs[2], ident.preprocess, None)
    urdf = held_out_error(runs[2].t, runs[2].current, model.inverse_dynamics(s.q, s.qd, s.qdd)
                          / CONTROLLER_GAINS, robot.joint_names)
    print(f"cross-run: raw {raw:.3f}  filtered {filtered:.3f}  noise floor {floor:.3f}; "
          f"manufacturer URDF raw {urdf.raw:.3f} filtered {urdf.filtered:.3f}")
    assert raw < urdf.raw and filtered < urdf.filtered  # noqa: PT018
    held = _errors(rd.identify(robot, [split(r)[0] for r in runs], target="current", model=model),
                   [split(runs[2])[1]])
    assert raw > held[0]  # a different excitation: worse than the same run's last 30 %


@data
def test_consistent_estimate_on_real_data_loads_strict(gen3, tmp_path):
    robot, model, train, test = gen3
    ident = rd.identify(robot, train, target="current", method="consistent", model=model)
    for j in range(robot.dof):
        assert np.linalg.eigvalsh(pseudo_inertia(ident.standard, j)).min() > 0
    path = tmp_path / "gen3_identified.yaml"
    path.write_text(dump_yaml(ident.robot))
    rd.load(str(path), strict=True)  # the manufacturer's URDF itself fails this (joint 1 inertia)
    raw, filtered, floor = _errors(ident, test)
    print(f"consistent: raw {raw:.3f}  filtered {filtered:.3f}  noise floor {floor:.3f}")
    assert raw < BASELINE_RAW and filtered < BASELINE_FILTERED  # noqa: PT018 (measured 0.286 / 0.176)


@data
def test_gain_that_cannot_be_absorbed_falls_back_with_a_warning(gen3):
    """On the full runs joint 7's nominal torque cannot explain its current (1/K < 0)."""
    from robodyn.identification.prior import IdentificationWarning

    robot, model, _, _ = gen3
    runs = [read(p) for p in WHOLE_ARM_FILES]
    with pytest.warns(IdentificationWarning, match=r"'joint_7' cannot be absorbed"):
        ident = rd.identify(robot, runs, target="current", method="ols", model=model)
    assert np.all(ident.gains > 0) and "joint_7" in ident.gains_source  # noqa: PT018
    others = np.delete(ident.gains, 6)
    assert ident.gains[6] == pytest.approx(np.exp(np.mean(np.log(others))))
