"""The underwater effect series: each effect changes what physics says it should."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.report.underwater import study_section, write_study
from robodyn.robot.errors import StudyError
from robodyn.robot.yaml_loader import load_yaml_text
from robodyn.studies.underwater import (
    EFFECTS,
    LIFT_DROPPED,
    LIFT_IN_CURRENT,
    LIFT_NOT_IN_CURRENT,
    effect_series,
    effect_variant,
)
from robodyn.symbolic.hydro.lift_reach import lift_reaches_joints
from tests.hydro.test_link_frame import SPATIAL

RHO, CA, CD = 1000.0, 1.0, 1.2
R1, L1, R2, L2 = 0.06, 1.0, 0.05, 0.8
END = np.array([0.8, 0.8])
CURRENT = (0.5, 0.0, 0.0)


@pytest.fixture(scope="module")
def series():
    # short runs; the compiled variants are cached by description and values
    return effect_series(rd.load("underwater_2r"), end=END, move_time=1.0, hold_time=0.5,
                         free_time=1.5, current=CURRENT)


def test_series_runs_every_variant_and_fills_the_table(series) -> None:
    # lift cannot reach a planar arm's joints in an in-plane current: its row is dropped
    shown = [e for e in EFFECTS if e != "lift"]
    assert [r.effect for r in series.runs] == shown
    table = series.table
    assert len(table) == len(shown) * 2
    numbers = table.drop(columns=["variant", "effect", "joint"]).to_numpy()
    assert np.all(np.isfinite(numbers))
    dry = table[table.effect == "dry"]
    assert (dry[["diff_vs_dry", "free_diff_vs_dry", "effect_peak_tau"]].to_numpy() == 0).all()
    # every effect changes the motion
    for effect in ("buoyancy", "added_mass", "drag", "current"):
        rows = table[table.effect == effect]
        assert (rows["effect_peak_tau"] > 1.0).all(), effect
    # the same PD controller in every variant: its torque is what the table reports
    run = series.run("drag")
    np.testing.assert_array_equal(table[table.effect == "drag"]["peak_tau"].to_numpy(),
                                  np.abs(run.tracked.tau).max(axis=0))
    assert "| + added mass | added_mass | q2 |" in series.markdown()


def test_section_escapes_the_robot_name_and_keeps_the_settings(series) -> None:
    # the section is a Jinja2 template (report/templates/underwater.html.j2): text from the
    # description is escaped, the numbers are those of the run
    html = study_section(dataclasses.replace(series, robot="arm <b>&"))
    assert "Underwater effect series: arm &lt;b&gt;&amp;</h2>" in html
    assert f"RK4 at {series.dt:g} s" in html and "lift coefficient: the description's" in html
    assert html.count("<tr>") == len(series.table) + 1


def test_lift_row_is_dropped_with_the_reason_where_lift_cannot_act(series) -> None:
    # a planar arm in an in-plane current: lift (along e x u_n) is normal to the plane
    assert series.notes == (LIFT_DROPPED + LIFT_NOT_IN_CURRENT,)
    assert "lift cannot change any of this arm's joint torques" in series.markdown()
    assert "normal to the plane" in study_section(series)
    # with a current out of the plane the note says that the '+ current' row carries the lift
    wet = effect_series(rd.load("underwater_2r"), end=END, move_time=0.2, hold_time=0.1,
                        free_time=0.1, current=(0.5, 0.0, 0.4), lift=0.5,
                        effects=("drag", "lift"))
    assert wet.notes == (LIFT_DROPPED + LIFT_IN_CURRENT,)


@pytest.mark.slow
def test_lift_reaches_joints_is_physics_not_a_blanket_rule() -> None:
    planar = rd.load("underwater_2r")
    assert not lift_reaches_joints(planar, (0.0, 0.0, 0.0))
    assert not lift_reaches_joints(planar, (0.5, -0.3, 0.0))
    # an out-of-plane current gives u_n a component along the joint axes, e x u_n one in the plane
    assert lift_reaches_joints(planar, (0.5, 0.0, 0.4))
    # and a spatial arm feels lift from its own motion in still water
    spatial = load_yaml_text(SPATIAL, source="spatial.yaml")
    assert lift_reaches_joints(spatial, (0.0, 0.0, 0.0))


def test_drag_dissipates_free_motion(series) -> None:
    no_drag, drag = series.run("added_mass").free, series.run("drag").free
    rows = series.table.set_index(["effect", "joint"])["free_amplitude"]
    for joint in ("q1", "q2"):
        assert rows["drag", joint] < 0.5 * rows["added_mass", joint]
    assert np.abs(drag.qd).max() < 0.7 * np.abs(no_drag.qd).max()


def test_added_mass_of_link_2_about_joint_2_equals_strip_theory(series) -> None:
    # same acceleration, more torque: M_22 grows by C_a rho pi r2^2 L2^3 / 3 (link 2 turning
    # about its own end), independently of q
    before = rd.compile_model(series.run("buoyancy").robot)
    after = rd.compile_model(series.run("added_mass").robot)
    expected = CA * RHO * math.pi * R2**2 * L2**3 / 3
    for q in ([0.0, 0.0], [0.7, -1.9], [-2.0, 2.5]):
        dm = after.mass_matrix(np.array(q)) - before.mass_matrix(np.array(q))
        assert dm[1, 1] == pytest.approx(expected, rel=1e-12)
        assert np.all(np.linalg.eigvalsh(dm) > -1e-12) and np.linalg.eigvalsh(dm).max() > 0.1
    # along the plan the inverse-dynamics torque is larger on both joints (RMS)
    rows = series.table.set_index(["effect", "joint"])["ideal_rms_tau"]
    for joint in ("q1", "q2"):
        assert rows["added_mass", joint] > rows["buoyancy", joint]


def test_a_current_on_the_arm_at_rest_needs_the_strip_integrated_drag_torque(series) -> None:
    # at the end of the plan the arm is at rest; link 2 (angle phi = q1 + q2 from base x) sees
    # the normal current c_n = c sin(phi): joint 2 must resist 1/2 rho C_d D |c_n| c sin(phi) L^2/2
    phi = END.sum()
    c_n = CURRENT[0] * abs(math.sin(phi))
    drag = 0.5 * RHO * CD * 2 * R2 * c_n * CURRENT[0] * math.sin(phi) * L2**2 / 2
    # plus the added mass's Munk moment -1/2 dk/dq2, k = C_a rho pi r2^2 L2 (c sin phi)^2: the
    # link is turned broadside to the flow (the motion relative to the water, as in Fossen)
    munk = -0.5 * CA * RHO * math.pi * R2**2 * L2 * CURRENT[0] ** 2 * math.sin(2 * phi)
    d_tau = series.run("current").ideal_tau[-1] - series.run("drag").ideal_tau[-1]
    assert d_tau[1] == pytest.approx(drag + munk, rel=1e-9)
    assert abs(munk) > 1e-3 * abs(drag)  # far above the tolerance: the test sees it


def test_buoyancy_of_a_neutrally_buoyant_arm_removes_the_gravity_torque() -> None:
    # each link as dense as the water, centre of mass at the centre of buoyancy
    neutral = {"m1": RHO * math.pi * R1**2 * L1, "m2": RHO * math.pi * R2**2 * L2}
    s = effect_series(rd.load("underwater_2r"), end=END, move_time=0.5, hold_time=0.1,
                      free_time=0.5, parameters=neutral, effects=("buoyancy",))
    assert [r.effect for r in s.runs] == ["dry", "buoyancy"]
    dry, wet = s.run("dry"), s.run("buoyancy")
    assert np.abs(dry.free.q[-1] - dry.free.q[0]).max() > 0.1  # in air it falls
    assert np.abs(wet.free.q - wet.free.q[0]).max() < 1e-12  # in water it stays
    model = rd.compile_model(dry.robot, parameters=neutral)
    q_r = s.reference.at(dry.tracked.t)[0]
    # only the inertial torque remains: tau_wet = tau_dry - g_dry(q)
    np.testing.assert_allclose(wet.ideal_tau, dry.ideal_tau - model.gravity(q_r), atol=1e-9)


def test_variants_are_new_robots_and_the_input_is_untouched() -> None:
    robot = rd.load("underwater_2r")
    before = robot.description_hash
    hashes = {effect_variant(robot, e, current=CURRENT).description_hash for e in EFFECTS}
    assert len(hashes) == len(EFFECTS) and robot.description_hash == before
    dry = effect_variant(robot, "dry")
    assert dry.fluid is None and all(lk.hydro is None for lk in dry.links)
    wet = effect_variant(robot, "drag")
    cd, cl = sp.Symbol("Cd", real=True), sp.Symbol("CL", real=True)
    assert wet.links[0].hydro.lift == 0.0 and wet.links[0].hydro.drag == cd
    assert wet.fluid.current == sp.ImmutableMatrix([0.0, 0.0, 0.0])
    assert robot.links[0].hydro.lift == cl


def test_robot_without_hydro_blocks_is_refused_by_name() -> None:
    with pytest.raises(StudyError, match=r"builtin:planar_2r: robot 'planar_2r' has no hydro "
                                         r"blocks"):
        effect_series(rd.load("planar_2r"))
    with pytest.raises(StudyError, match="unknown effect"):
        effect_series(rd.load("underwater_2r"), effects=("sonar",))


def test_write_study_files(series, tmp_path) -> None:
    files = write_study(series, tmp_path / "out")
    names = {p.name for p in files}
    assert {"effects.csv", "effects.md", "tracking_q.png", "free_q.png",
            "underwater.html", "underwater_section.html"} <= names
    assert all(p.stat().st_size > 0 for p in files)
    html = (tmp_path / "out" / "underwater.html").read_text()
    assert "+ added mass" in html and "data:image/png;base64," in html
