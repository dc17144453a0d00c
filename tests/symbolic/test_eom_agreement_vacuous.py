"""``robodyn check``: identically zero M and tau (or a singular M) are never reported as agreeing."""

from __future__ import annotations

import robodyn as rd
from robodyn.cli import main
from robodyn.report.agreement import Agreement, agreement, agreement_rows, verdict

MASSLESS = """
name: massless
gravity: [0, 0, -9.81]
joints:
  - name: q1
    type: revolute
    dh: {a: 1.0, alpha: 0, d: 0, theta: 0}
    link:
      name: nothing
      mass: 0
      com: [0, 0, 0]
      inertia: {ixx: 0, iyy: 0, izz: 0, ixy: 0, ixz: 0, iyz: 0}
"""


def test_identically_zero_equations_are_not_agreement(tmp_path, capsys):
    path = tmp_path / "massless.yaml"
    path.write_text(MASSLESS)
    robot = rd.load(path)
    eoms = [rd.derive(robot, m) for m in ("newton_euler", "lagrange", "kane")]
    results = agreement(eoms, samples=5)
    for r in results:
        # every difference is 0 / 0: before, that read as "agree"
        assert r.zero == ("M", "g", "tau") and not r.ok
    assert "NOTHING COMPARED" in agreement_rows(results)[0][-1]
    assert "compared nothing" in verdict(results)
    assert main(["check", str(path), "--samples", "3"]) == 1
    assert "0 (both zero)" in capsys.readouterr().out


def test_a_zero_gravity_load_alone_still_agrees():
    # a horizontal arm has g = 0 identically: that is physics, not a vacuous comparison
    r = Agreement("newton_euler", "kane", {"M": 1e-16, "g": 0.0, "tau": 2e-16}, zero=("g",))
    assert r.ok
    assert agreement_rows([r])[0][2] == "0 (both zero)"


def test_a_singular_mass_matrix_is_reported(tmp_path):
    # a point mass on joint 2's axis: M = diag(m l1^2, 0), singular everywhere but not zero
    path = tmp_path / "on_axis.yaml"
    path.write_text(MASSLESS.replace("name: massless", "name: on_axis").replace(
        "      name: nothing\n      mass: 0", "      name: nothing\n      mass: 1.0") + """
  - name: q2
    type: revolute
    dh: {a: 0.0, alpha: 0, d: 0, theta: 0}
    link:
      name: ball
      mass: 2.0
      com: [0, 0, 0]
      inertia: {ixx: 0, iyy: 0, izz: 0, ixy: 0, ixz: 0, iyz: 0}
""")
    robot = rd.load(path)
    eoms = [rd.derive(robot, m) for m in ("newton_euler", "kane")]
    (r,) = agreement(eoms, samples=5)
    # (gravity along the joint axes: g = 0 identically, which is physics)
    assert r.zero == ("g",) and r.singular and not r.ok
    assert max(r.relative.values()) < 1e-12
    assert agreement_rows([r])[0][-1] == "M SINGULAR"
    assert "singular" in verdict([r])
    # the planar 2R arm: regular, and it agrees
    eoms = [rd.derive(rd.load("planar_2r"), m) for m in ("newton_euler", "kane")]
    (r,) = agreement(eoms, samples=5)
    assert r.ok and not r.singular and r.zero == () and verdict([r]) == "the three formulations agree"
