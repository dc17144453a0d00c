"""A description's numbers (robodyn.robot.numbers) and their cache (robodyn.robot.numbers_cache).

The numbers are checked against the description evaluated by SymPy along another path
(``subs`` and ``N`` at 30 digits instead of ``xreplace`` and ``evalf``), the cache against the
numbers of a fresh load: bit for bit, from a process that never imports SymPy, and loaded again
whenever the description, the tool link or the entry changes.
"""

from __future__ import annotations

import json
import subprocess
import sys
import warnings
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.codegen.build import cache_info, clear_cache
from robodyn.robot.errors import DescriptionWarning
from robodyn.robot.numbers import RobotNumbers, full_robot, robot_numbers
from robodyn.robot.numbers_cache import load_numbers, numbers_key

ARRAYS = ("base", "pres", "axes", "posts", "tool", "lower", "upper", "gear_ratios", "masses", "coms",
          "gravity")


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    path = tmp_path / "cache"
    monkeypatch.setenv("ROBODYN_CACHE", str(path))
    return path


def _builtin_copy(name: str, folder: Path) -> Path:
    path = folder / f"{name}.yaml"
    path.write_text((resources.files("robodyn.robot.library") / f"{name}.yaml").read_text())
    return path


def _quiet_load(source) -> rd.Robot:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        return rd.load(source)


def _n(expr, subs) -> np.ndarray:
    return np.array(sp.N(sp.Matrix(expr).subs(subs), 30), dtype=float)


@pytest.mark.parametrize("name", ["puma560", "kinova_gen3"])
def test_numbers_are_the_description_at_its_defaults(name):
    robot = _quiet_load(name)
    num = robot_numbers(robot)
    subs = robot.defaults()
    assert num.joint_names == robot.joint_names and num.dof == robot.dof
    for j, joint in enumerate(robot.joints):
        np.testing.assert_allclose(num.pres[j], _n(joint.pre, subs), rtol=0, atol=1e-15)
        np.testing.assert_allclose(num.posts[j], _n(joint.post, subs), rtol=0, atol=1e-15)
        np.testing.assert_allclose(num.axes[j], _n(joint.axis, subs).ravel(), rtol=0, atol=1e-15)
        for got, limit in ((num.lower[j], joint.lower), (num.upper[j], joint.upper)):
            assert np.isnan(got) if limit is None else got == pytest.approx(float(sp.N(limit.subs(subs))))
        assert num.gear_ratios[j] == pytest.approx(float(sp.N(joint.drive.gear_ratio.subs(subs))))
        link = robot.links[j]
        assert num.masses[j] == pytest.approx(float(sp.N(link.mass.subs(subs))))
        np.testing.assert_allclose(num.coms[j], _n(link.com, subs).ravel(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(num.gravity, _n(robot.gravity, subs).ravel(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(num.tool, _n(robot.tool, subs), rtol=0, atol=1e-15)
    assert robot_numbers(robot) is num and robot_numbers(num) is num  # evaluated once
    assert full_robot(num) is robot and full_robot(robot) is robot
    assert not num.pres.flags.writeable


def test_the_puma_560_has_gear_ratios_and_limits():
    """The fields the calibration reads are really carried (a PUMA 560 has both)."""
    num = robot_numbers(_quiet_load("puma560"))
    assert np.all(np.abs(num.gear_ratios) > 50)
    assert np.all(np.isfinite(num.lower)) and np.all(num.lower < num.upper)
    assert num.masses[1] == pytest.approx(17.4)


_SECOND = """
import json, sys
import numpy as np
from robodyn.robot.numbers_cache import load_numbers
n = load_numbers(sys.argv[1])
fields = {k: np.asarray(getattr(n, k)).tolist() for k in sys.argv[2].split(",")}
print(json.dumps({"sympy": "sympy" in sys.modules, "hash": n.description_hash, "fields": fields,
                  "names": list(n.joint_names), "types": list(n.joint_types)}))
"""


@pytest.mark.parametrize("name", ["puma560", "kinova_gen3"])
def test_a_second_load_reads_the_cache_and_imports_no_sympy(cache, name):
    first = load_numbers(name)
    assert len(list(cache.glob("rd_robot_*.json"))) == 1
    out = subprocess.run([sys.executable, "-c", _SECOND, name, ",".join(ARRAYS)], check=True,
                         capture_output=True, text=True)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["sympy"] is False
    robot = _quiet_load(name)
    assert got["hash"] == robot.description_hash == first.description_hash
    assert tuple(got["names"]) == robot.joint_names
    expected = robot_numbers(robot)
    assert tuple(got["types"]) == expected.joint_types
    for k in ARRAYS:  # JSON round trip of floats: bit for bit (NaN limits as null)
        a = np.array(got["fields"][k], dtype=float)
        np.testing.assert_array_equal(a, getattr(expected, k), err_msg=k)


def test_full_robot_of_cached_numbers_is_the_description_loaded_once(cache, tmp_path):
    path = _builtin_copy("puma560", tmp_path)  # a user file: its load warns
    with pytest.warns(DescriptionWarning):
        load_numbers(path)
    with pytest.warns(DescriptionWarning):
        hit = load_numbers(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # given when the numbers were read, not again
        robot = full_robot(hit)
    assert isinstance(robot, rd.Robot) and robot.description_hash == hit.description_hash
    assert full_robot(hit) is robot  # one load for every calibration of a terms check


def test_an_edited_description_is_loaded_again(cache, tmp_path):
    path = _builtin_copy("planar_2r", tmp_path)
    assert load_numbers(path).masses[0] == 1.0
    path.write_text(path.read_text().replace("m1: 1.0", "m1: 2.5"))
    edited = load_numbers(path)
    assert edited.masses[0] == 2.5
    assert len(list(cache.glob("rd_robot_*.json"))) == 2
    assert load_numbers(path).masses[0] == 2.5  # now from the cache


def test_numbers_refuse_a_description_changed_since_they_were_read(cache, tmp_path):
    path = _builtin_copy("planar_2r", tmp_path)
    load_numbers(path)
    hit = load_numbers(path)  # from the cache: full_robot loads the file again
    path.write_text(path.read_text().replace("l1: 1.0", "l1: 1.2"))
    with pytest.raises(ValueError, match="description changed"):
        full_robot(hit)


def test_the_key_covers_content_origin_and_tool():
    data = b"name: x\n"
    key = numbers_key("/a/x.urdf", data, None)
    assert len(key) == 24 and int(key, 16) >= 0
    assert numbers_key("/a/x.urdf", data, None) == key
    assert numbers_key("/a/x.urdf", data, "tool0") != key
    assert numbers_key("/b/x.urdf", data, None) != key
    assert numbers_key("/a/x.urdf", data + b" ", None) != key


def test_a_corrupt_entry_is_ignored_and_written_again(cache):
    load_numbers("planar_2r")
    (entry,) = cache.glob("rd_robot_*.json")
    entry.write_text('{"format": 1, "name": "planar_2r", "joint')
    again = load_numbers("planar_2r")
    assert again.masses.tolist() == [1.0, 1.0]
    assert json.loads(entry.read_text())["name"] == "planar_2r"


def test_the_loads_warnings_are_given_again_from_the_cache(cache, tmp_path, monkeypatch):
    # a user file with the PUMA 560's published link inertias: the plausibility check warns
    path = _builtin_copy("puma560", tmp_path)
    with pytest.warns(DescriptionWarning, match="triangle inequality") as first:
        load_numbers(path)
    import robodyn.robot.numbers_cache as numbers_cache

    def no_full_load(*args, **kwargs):
        raise AssertionError("loaded in full: the cache was not used")

    monkeypatch.setattr(numbers_cache, "load", no_full_load)
    with pytest.warns(DescriptionWarning, match="triangle inequality") as again:
        hit = load_numbers(path)
    assert [str(w.message) for w in again] == [str(w.message) for w in first
                                             if issubclass(w.category, DescriptionWarning)]
    assert isinstance(hit, RobotNumbers)


def test_errors_of_a_missing_file_come_from_the_full_load(cache, tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        load_numbers(tmp_path / "missing.yaml")
    assert not cache.exists() or not list(cache.glob("rd_robot_*.json"))


def test_the_cache_commands_count_and_remove_the_entries(cache):
    load_numbers("planar_2r")
    (entry,) = cache.glob("rd_robot_*.json")
    other = cache / "rd_measurements.json"  # a user's file in the folder is never touched
    other.write_text("{}")
    size = entry.stat().st_size
    assert (cache_info().files, cache_info().size) == (1, size)
    assert clear_cache() == (1, size)
    assert not entry.exists() and other.exists()
