"""robodyn YAML descriptions: bad input refused with the file, field and reason; the parser's limits."""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

import pytest

from robodyn.robot.errors import DescriptionError
from robodyn.robot.model import Robot
from robodyn.robot.yaml_loader import load_yaml_file, load_yaml_text
from tests.robot.test_yaml_loader import link_yaml, write

# -- bad input ---------------------------------------------------------------------------------


def bad(text: str, pattern: str, tmp_path: Path) -> None:
    path = write(tmp_path, textwrap.dedent(text))
    with pytest.raises(DescriptionError, match=pattern) as info:
        load_yaml_file(path)
    assert str(info.value).startswith(f"{path}: ")


def one_joint(joint: str) -> str:
    return f"name: a\njoints:\n  - {joint}\n"


J = "name: j, type: revolute, dh: {}, link: {mass: 1}"
J0 = r"joints\[0\]"


def top(extra: str) -> str:
    """A valid one-joint robot with extra top-level lines."""
    return "name: a\n" + extra + "\njoints: [{" + J + "}]\n"


def jt(link: str = "{mass: 1}", extra: str = "", head: str = "name: j, type: revolute, dh: {}"):
    """A one-joint robot with the given link and extra joint fields."""
    return one_joint("{" + head + ", link: " + link + extra + "}")


TOP_CASES = [
    ("name: a\njoints: [\n", r"line \d+, column \d+: YAML syntax error"),
    ("name: a\n  bad: indent\n", r"line 2, column \d+: YAML syntax error"),
    ("name: a\nname: b\njoints: []\n",
     r"line 2, column 1: YAML syntax error: found duplicate key 'name'"),
    ("- 1\n- 2\n", r"the top level must be a mapping .* got a list of 2 entries"),
    ("", r"the top level must be a mapping .* got nothing"),
    ("joints: []\n", r": name: required field is missing"),
    ("name: a\n", r": joints: required field is missing"),
    ("name: a\njoints: []\n", r": joints: expected a non-empty list of joints"),
    ("name: a\nnmae: b\njoints: []\n", r": unknown key\(s\) 'nmae' \(allowed: name, description"),
    ("name: 3\njoints: []\n", r": name: expected a non-empty text, got int 3"),
    ("name: a\njoints: [3]\n", J0 + r": expected a mapping, got int 3"),
    (top("description: [1]"), r"description: expected a text"),
    (top("parameters: [1]"), r"parameters: expected a mapping"),
    (top("parameters: {pi: 3}"), r"parameters: parameter name 'pi' is reserved"),
    (top("parameters: {q1: 3}"), r"parameter name 'q1' is reserved for joint-state"),
    (top("parameters: {l: x}"), r"parameters\.l: invalid expression 'x': name 'x' is not"),
    (top("gravity: [0, -9.81]"), r"gravity: expected a list of 3 numbers, got a list of 2"),
    (top("gravity: [0, 0, -g]"),
     r"gravity\[2\]: invalid expression '-g': name 'g' is not a declared parameter "
     r"\(declared: none\)"),
    (top("base: {xyz: [0, 0, 0], rpz: [0, 0, 0]}"), r"base: unknown key\(s\) 'rpz'"),
    (top("tool: {xyz: [0, 0]}"), r"tool\.xyz: expected a list of 3"),
]

JOINT_CASES = [
    (one_joint("{type: revolute, dh: {}, link: {mass: 1}}"), r"\.name: required field is missing"),
    (one_joint("{name: j, dh: {}, link: {mass: 1}}"), r"\.type: required field is missing"),
    (one_joint("{name: j, type: revolute, dh: {}}"), r"\.link: required field is missing"),
    (jt(head="name: j, type: spherical, dh: {}"),
     r"\.type: unknown joint type 'spherical' "
     r"\(allowed: revolute, continuous, prismatic, fixed\)"),
    (jt(head="name: j, type: revolute"),
     r": exactly one placement \(dh, mdh or origin\) is required, got none"),
    (jt(extra=", mdh: {}"), r": exactly one placement .* got dh and mdh"),
    (jt(extra=", axis: [1, 0, 0]"), r"\.axis: axis is only allowed with an origin placement"),
    (jt(head="name: j, type: revolute, origin: {}, axis: [0, 0, 0]"),
     r"\.axis: axis \[0, 0, 0\] has zero length"),
    (jt(head="name: j, type: revolute, origin: {}, axis: [0, 1]"),
     r"\.axis: expected a list of 3 numbers, got a list of 2 entries"),
    (jt(head="name: j, type: revolute, dh: {a: 1, alfa: 0}"),
     r"\.dh: unknown key\(s\) 'alfa' \(allowed: a, alpha, d, theta\)"),
    (jt(head="name: j, type: revolute, dh: {alpha: pi/2*lx}"),
     r"\.dh\.alpha: invalid expression 'pi/2\*lx': name 'lx' is not a declared"),
    (jt(head="name: j, type: revolute, dh: {a: l.real}"),
     r"\.dh\.a: invalid expression 'l\.real': construct Attribute is not allowed"),
    (jt(head="name: j, type: revolute, dh: {a: yes}"),
     r"\.dh\.a: expected a number or an expression, got the boolean True"),
    (jt(extra=", speed: 3"), r": unknown key\(s\) 'speed'"),
    (jt("{mass: -1.5}"), r"\.link\.mass: mass of link 'j_link' is negative"),
    (jt("{com: [0, 0, 0]}"), r"\.link\.mass: required field is missing"),
    (jt("{mass: 1, com: [0.1, 0]}"),
     r"\.link\.com: expected a list of 3 numbers, got a list of 2 entries"),
    (jt("{mass: 1, colour: red}"),
     r"\.link: unknown key\(s\) 'colour' \(allowed: name, mass, com, inertia, hydro\)"),
    (jt("{mass: 1, inertia: {ixx: 1, iyy: 1}}"),
     r"\.link\.inertia\.izz: required field is missing"),
    (jt("{mass: 1, inertia: {ixx: 1, iyy: 1, izz: 1, iyx: 0}}"),
     r"\.link\.inertia: unknown key\(s\) 'iyx'"),
    (jt("{mass: 1, inertia: [[1, 0.2, 0], [0, 1, 0], [0, 0, 1]]}"),
     r"\.link\.inertia: inertia of link 'j_link' is not symmetric"),
    (jt("{mass: 1, inertia: [[1, 0, 0], [0, 1, 0]]}"),
     r"\.link\.inertia: expected a mapping ixx, .* or a 3x3 list, got a list of 2"),
    (jt("{mass: 1, inertia: [[1, 0], [0, 1, 0], [0, 0, 1]]}"),
     r"\.link\.inertia\[0\]: expected a list of 3 numbers"),
    (jt("{mass: 1, hydro: 3}"), r"\.link\.hydro: expected a mapping"),
    (jt(extra=", limits: {lower: 1, upper: -1}"),
     r"\.limits: lower limit 1 is above upper limit -1"),
    (jt(extra=", limits: {velocity: -2}"),
     r"\.limits\.velocity: velocity limit must not be negative"),
    (jt(extra=", limits: {min: 0}"), r"\.limits: unknown key\(s\) 'min'"),
    (jt(extra=", drive: {gear_ratio: 0}"), r"\.drive\.gear_ratio: gear ratio must not be zero"),
    (jt(extra=", drive: {rotor_inertia: -1e-4}"),
     r"\.drive\.rotor_inertia: rotor inertia must not be negative"),
    (jt(extra=", drive: {ratio: 2}"), r"\.drive: unknown key\(s\) 'ratio'"),
    (jt(extra=", friction: {coulomb: 0.4, coulomb_positive: 0.3}"),
     r"\.friction: give either coulomb .* not coulomb together with coulomb_positive"),
    (jt(extra=", friction: {coulomb_negative: 0.3}"),
     r"\.friction\.coulomb_positive: required together with coulomb_negative"),
    (jt(extra=", friction: {coulomb: -0.4}"),
     r"\.friction\.coulomb: Coulomb friction must not be negative"),
    (jt(extra=", friction: {viscous: -1}"),
     r"\.friction\.viscous: viscous friction must not be negative"),
    (jt(extra=", friction: {side: gearbox}"),
     r"\.friction\.side: expected 'joint' or 'motor', got the text 'gearbox'"),
    (jt(extra=", friction: {side: motor, viscous: 1}"),
     r"\.friction\.side: motor-side friction needs a drive"),
    (jt(extra=", friction: {damping: 1}"), r"\.friction: unknown key\(s\) 'damping'"),
]

CHAIN_CASES = [
    ("name: a\njoints:\n  - {" + J + "}\n"
     "  - {name: f, type: fixed, dh: {}, link: {mass: 1}, limits: {}}\n",
     r"joints\[1\]\.limits: not allowed on a fixed joint"),
    ("name: a\njoints:\n  - {name: f, type: fixed, dh: {}, link: {mass: 1}}\n",
     r"joints: no moving joint: every joint is fixed"),
    ("name: a\njoints:\n  - {" + J + "}\n  - {" + J + "}\n",
     r"joints\[1\]\.name: duplicate joint name 'j' \(first used at joints\[0\]\.name\)"),
    ("name: a\njoints:\n  - {name: j1, type: revolute, dh: {}, link: {name: l, mass: 1}}\n"
     "  - {name: j2, type: revolute, dh: {}, link: {name: l, mass: 1}}\n",
     r"joints\[1\]\.link\.name: duplicate link name 'l' "
     r"\(first used at joints\[0\]\.link\.name\)"),
]


@pytest.mark.parametrize(("text", "pattern"), TOP_CASES + CHAIN_CASES)
def test_bad_input(text: str, pattern: str, tmp_path: Path) -> None:
    bad(text, pattern, tmp_path)


@pytest.mark.parametrize(("text", "pattern"), JOINT_CASES)
def test_bad_joint(text: str, pattern: str, tmp_path: Path) -> None:
    bad(text, J0 + pattern, tmp_path)


def test_negative_mass_from_parameter_default(tmp_path: Path) -> None:
    text = "parameters: {m: -2}\n" + link_yaml("{name: p, mass: m}")
    bad(text, r"joints\[0\]\.link\.mass: mass of link 'p' is negative \(m = -2\)", tmp_path)


def test_not_utf8_file(tmp_path: Path) -> None:
    path = tmp_path / "bin.yaml"
    path.write_bytes(b"name: \xff\xfe\n")
    with pytest.raises(DescriptionError, match=r"bin\.yaml: not a UTF-8 text file"):
        load_yaml_file(path)


def test_text_source_names_errors() -> None:
    with pytest.raises(DescriptionError, match=r"^builtin:x: joints: required field is missing$"):
        load_yaml_text("name: a\n", source="builtin:x")


def alias_bomb(levels: int = 9) -> str:
    """A ~700-byte description whose ``hydro`` block expands to 9**levels entries via aliases."""
    lines = ["name: bomb", "joints:", "  - name: j1", "    type: revolute", "    dh: {a: 1}",
             "    link:", "      mass: 1", "      hydro:",
             "        l0: &l0 [x, x, x, x, x, x, x, x, x]"]
    lines += [f"        l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 9) + "]"
              for i in range(1, levels)]
    return "\n".join(lines) + "\n"


def test_yaml_aliases_are_rejected_with_file_and_line(tmp_path: Path) -> None:
    # 9**9 = 387 million strings once expanded: hashing it through str() exhausted memory
    text = alias_bomb()
    assert len(text) < 1500
    path = write(tmp_path, text)
    pattern = (rf"^{re.escape(str(path))}: line 10, column 18: YAML alias \*l0 is not allowed "
               r"in robot descriptions")
    with pytest.raises(DescriptionError, match=pattern):
        load_yaml_file(path)


def test_merge_key_aliases_are_rejected_too() -> None:
    text = one_joint("{name: j, type: revolute, dh: {}, link: {mass: 1, hydro: {a: &h {r: 1}, "
                     "b: {<<: *h}}}}")
    with pytest.raises(DescriptionError, match=r"YAML alias \*h is not allowed"):
        load_yaml_text(text, source="t.yaml")


def test_deep_yaml_nesting_is_a_clear_error() -> None:
    text = "name: a\njoints: " + "[" * 3000 + "]" * 3000 + "\n"  # RecursionError in PyYAML
    with pytest.raises(DescriptionError, match=r"^t\.yaml: line 2, column \d+: nested more than "
                                               r"32 levels deep$"):
        load_yaml_text(text, source="t.yaml")


@pytest.mark.parametrize(
    ("hydro", "pattern"),
    [
        ("{1: a}", r"\.link\.hydro: keys must be texts, got int 1"),
        ("{when: 2020-01-02}", r"\.link\.hydro\.when: expected a text, number, list or mapping, "
                               r"got date"),
        ("{c: [{r: .nan}]}", r"\.link\.hydro\.c\[0\]\.r: expected a finite number, got nan"),
    ],
)
def test_hydro_must_be_plain_data(hydro: str, pattern: str, tmp_path: Path) -> None:
    bad(jt("{mass: 1, hydro: " + hydro + "}"), J0 + pattern, tmp_path)


def test_description_hash_is_canonical() -> None:
    # the same data in another key order is the same description; another value is not
    def robot(hydro: str) -> Robot:
        return load_yaml_text(jt("{mass: 1, hydro: " + hydro + "}"), source="t.yaml")

    a = robot("{drag: 1.2, cylinders: [{radius: 0.05, length: 1, axis: [1, 0, 0]}]}")
    b = robot("{cylinders: [{axis: [1, 0, 0], length: 1, radius: 0.05}], drag: 1.2}")
    c = robot("{cylinders: [{axis: [1, 0, 0], length: 1, radius: 0.06}], drag: 1.2}")
    assert a.description_hash == b.description_hash
    assert a.description_hash != c.description_hash
    assert re.fullmatch(r"[0-9a-f]{64}", a.description_hash)


def test_oversized_description_file_is_refused_before_reading(tmp_path: Path) -> None:
    from robodyn.robot.yaml_loader import MAX_DESCRIPTION_BYTES

    path = tmp_path / "huge.yaml"
    with path.open("wb") as fh:  # a sparse file: nothing is written but the size
        fh.truncate(MAX_DESCRIPTION_BYTES + 1)
    pattern = rf"^{re.escape(str(path))}: 4,194,305 bytes is too large for a robot description"
    with pytest.raises(DescriptionError, match=pattern):
        load_yaml_file(path)


def test_libyaml_loader_gives_the_pure_python_result() -> None:
    # descriptions are read by libyaml when PyYAML has it (10-20x faster; CLI start-up), with the
    # same checks: the data must be exactly what PyYAML's own pure-Python SafeLoader reads
    import yaml

    from robodyn.robot import safe_yaml, yaml_loader

    assert yaml.__with_libyaml__, "PyYAML without libyaml: the fast loader is not exercised"
    library = Path(yaml_loader.__file__).parent / "library"
    texts = [p.read_text(encoding="utf-8") for p in sorted(library.glob("*.yaml"))]
    assert len(texts) >= 9
    for text in texts:
        expected = yaml.load(text, Loader=yaml.SafeLoader)  # noqa: S506 - PyYAML's safe loader
        assert yaml_loader._parse_yaml(text, "t.yaml") == expected
        assert yaml.load(text, Loader=safe_yaml._CUniqueKeyLoader) == expected  # noqa: S506


def test_libyaml_path_keeps_the_duplicate_key_check() -> None:
    import yaml

    from robodyn.robot import safe_yaml

    with pytest.raises(yaml.constructor.ConstructorError, match="found duplicate key 'name'"):
        yaml.load("name: a\nname: b\n", Loader=safe_yaml._CUniqueKeyLoader)  # noqa: S506
    with pytest.raises(yaml.MarkedYAMLError, match=r"YAML alias \*x is not allowed"):
        safe_yaml._c_events_checked("a: &x [1]\nb: *x\n")
    with pytest.raises(yaml.MarkedYAMLError, match="nested more than 32 levels deep"):
        safe_yaml._c_events_checked("a: " + "[" * 33 + "]" * 33 + "\n")
