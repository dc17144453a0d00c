"""Bad fluid/hydro blocks: each error names the file, the field and the reason."""

from __future__ import annotations

import dataclasses
import re

import pytest

from robodyn.robot.errors import DescriptionError
from robodyn.robot.yaml_loader import load_yaml_text

CYL = "{radius: 0.05, length: 1, axis: [1, 0, 0]}"


def doc(hydro: str, fluid: str | None = "fluid: {density: 1000}") -> str:
    head = "name: a\n" + (fluid + "\n" if fluid else "")
    return head + ("joints: [{name: j, type: revolute, dh: {}, link: {mass: 1, hydro: " + hydro
                   + "}}]\n")


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        (doc("{cylinders: [" + CYL + "]}", "fluid: {density: -5}"),
         r"w\.yaml: fluid\.density: density must be positive \(got -5"),
        (doc("{cylinders: [" + CYL + "]}", "fluid: {density: 1000, salinity: 35}"),
         r"w\.yaml: fluid: unknown key\(s\) 'salinity'"),
        (doc("{cylinders: [" + CYL + "]}", "fluid: {current: [1, 0]}"),
         r"w\.yaml: fluid\.current: expected a list of 3 numbers"),
        (doc("{cylinders: [{radius: -0.05, length: 1, axis: [1, 0, 0]}]}"),
         r"w\.yaml: joints\[0\]\.link\.hydro\.cylinders\[0\]\.radius: radius must be positive "
         r"\(got -0\.05"),
        (doc("{cylinders: [{radius: 0.05, length: 0, axis: [1, 0, 0]}]}"),
         r"joints\[0\]\.link\.hydro\.cylinders\[0\]\.length: length must be positive"),
        (doc("{cylinders: [{radius: 0.05, length: 1, axis: [0, 0, 0]}]}"),
         r"joints\[0\]\.link\.hydro\.cylinders\[0\]\.axis: axis \[0, 0, 0\] has zero length"),
        (doc("{cylinders: [{radius: 0.05, length: 1}]}"),
         r"joints\[0\]\.link\.hydro\.cylinders\[0\]\.axis: required field is missing"),
        (doc("{cylinders: [" + CYL + "], drag: -1.2}"),
         r"joints\[0\]\.link\.hydro\.drag: coefficient drag must not be negative"),
        (doc("{cylinders: [" + CYL + "], volume: -0.1}"),
         r"joints\[0\]\.link\.hydro\.volume: volume must not be negative"),
        (doc("{cylinders: [" + CYL + "], cd: 1}"),
         r"joints\[0\]\.link\.hydro: unknown key\(s\) 'cd' \(allowed: cylinders, added_mass"),
        (doc("{volume: 0.01}"),
         r"joints\[0\]\.link\.hydro: a volume without cylinders needs a center_of_buoyancy"),
        (doc("{cylinders: [" + CYL + "], quadrature: 0}"),
         r"joints\[0\]\.link\.hydro\.quadrature: expected a whole number of points 1\.\.64"),
        (doc("{cylinders: [" + CYL + "], drag: Cx}"),
         r"joints\[0\]\.link\.hydro\.drag: invalid expression 'Cx'"),
        ("name: a\nfluid: {density: 1000}\njoints: [{name: j, type: revolute, dh: {}, "
         "link: {mass: 1}}]\n", r"w\.yaml: fluid: no link has a hydro block"),
    ],
)
def test_bad_blocks_are_named(text: str, pattern: str) -> None:
    with pytest.raises(DescriptionError, match="^" + r"w\.yaml: " + pattern.removeprefix(r"w\.yaml: ")):
        load_yaml_text(text, source="w.yaml")


def test_hydro_without_fluid_block_is_still_fresh_water() -> None:
    from robodyn.robot.hydro import fluid_of

    robot = load_yaml_text(doc("{cylinders: [" + CYL + "]}", None), source="w.yaml")
    fluid = fluid_of(robot)
    assert fluid is not None and float(fluid.density) == 1000.0
    assert list(fluid.current) == [0, 0, 0]


def test_the_user_data_is_not_modified() -> None:
    import yaml

    data = yaml.safe_load(doc("{cylinders: [" + CYL + "], drag: 1.0}"))
    before = repr(data)
    robot = load_yaml_text(yaml.safe_dump(data), source="w.yaml")
    assert repr(data) == before
    with pytest.raises(dataclasses.FrozenInstanceError):
        robot.fluid.density = 1  # type: ignore[misc]
    assert re.fullmatch(r"[0-9a-f]{64}", robot.description_hash)
