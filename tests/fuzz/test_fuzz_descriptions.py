"""Fuzz the description loaders: mutated built-in YAML files, generated YAML documents, mutated
URDF files. The only outcomes allowed are a Robot or a :class:`DescriptionError` (with
:class:`DescriptionWarning` for implausible inertia), within the deadline of each example.
"""

from __future__ import annotations

import tempfile
import warnings
from importlib import resources
from pathlib import Path

import numpy as np
import yaml
from hypothesis import given
from hypothesis import strategies as st

import robodyn as rd
from robodyn.robot.errors import DescriptionError, DescriptionWarning
from tests.fuzz.strategies import MAX_BYTES, TOKENS, fuzz_settings, mutated
from tests.urdf_chains import random_urdf

# the small built-ins (the 3 s aa300 and the 7-joint Gen3 would dominate the time budget)
_SMALL = ("planar_2r", "puma560", "trolley_pendulum", "trolley_double_pendulum", "puma560_akb",
          "underwater_2r")
LIBRARY = [(resources.files("robodyn.robot.library") / f"{n}.yaml").read_text() for n in _SMALL]


def _urdfs() -> list[str]:
    from robodyn.export.urdf import to_urdf

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        texts = [to_urdf(rd.load(n)) for n in ("planar_2r", "puma560")]
    return texts + [random_urdf(np.random.default_rng(seed), 3) for seed in (1, 2)]


URDFS = _urdfs()


def load_outcome(text: str | bytes, suffix: str) -> rd.Robot | None:
    """Load ``text`` from a file; None for a DescriptionError, anything else propagates."""
    data = text if isinstance(text, bytes) else text.encode("utf-8", "surrogatepass")
    assert len(data) <= 4 * MAX_BYTES
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"robot{suffix}"
        path.write_bytes(data)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a stray RuntimeWarning is a defect too
            warnings.simplefilter("ignore", DescriptionWarning)
            try:
                robot = rd.load(path)
            except DescriptionError as exc:
                message = str(exc)
                assert message.startswith(str(path)), message  # names the file
                return None
        assert path.read_bytes() == data  # input never modified
    assert robot.dof >= 1 and len(robot.description_hash) == 64
    return robot


@fuzz_settings(deadline_s=20)
@given(mutated(LIBRARY))
def test_mutated_builtin_yaml(text: str) -> None:
    load_outcome(text, ".yaml")


_scalar = st.one_of(
    st.integers(-10**6, 10**6), st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(TOKENS), st.text(max_size=20), st.booleans(), st.none(),
    st.sampled_from(["l/2", "-m*g", "sqrt(2)", "pi/2", "m", "1/0", "l^2", "-" * 200 + "1"]),
)
_data = st.recursive(
    _scalar,
    lambda inner: st.one_of(st.lists(inner, max_size=4),
                            st.dictionaries(st.text(max_size=8), inner, max_size=4)),
    max_leaves=30,
)
_vector = st.one_of(st.lists(_scalar, min_size=3, max_size=3), _data)
_link = st.fixed_dictionaries(
    {"mass": _scalar},
    optional={"name": _scalar, "com": _vector, "inertia": st.one_of(
        st.fixed_dictionaries({"ixx": _scalar, "iyy": _scalar, "izz": _scalar},
                              optional={"ixy": _scalar, "iyz": _scalar}), _data),
              "hydro": _data},
)
_joint = st.fixed_dictionaries(
    {"name": st.one_of(st.sampled_from(["j1", "j2", "j3"]), _scalar),
     "type": st.sampled_from(["revolute", "prismatic", "continuous", "fixed", "ball", None]),
     "link": st.one_of(_link, _data)},
    optional={"dh": st.dictionaries(st.sampled_from(["a", "alpha", "d", "theta", "x"]), _scalar),
              "mdh": st.dictionaries(st.sampled_from(["a", "alpha", "d", "theta"]), _scalar),
              "origin": st.dictionaries(st.sampled_from(["xyz", "rpy"]), _vector),
              "axis": _vector, "limits": st.dictionaries(
                  st.sampled_from(["lower", "upper", "velocity", "effort"]), _scalar),
              "drive": st.dictionaries(
                  st.sampled_from(["gear_ratio", "rotor_inertia", "torque_constant"]), _scalar),
              "friction": st.dictionaries(
                  st.sampled_from(["side", "viscous", "coulomb", "coulomb_positive",
                                   "coulomb_negative", "offset"]), _scalar)},
)
_document = st.fixed_dictionaries(
    {"name": _scalar, "joints": st.one_of(st.lists(_joint, max_size=3), _data)},
    optional={"parameters": st.dictionaries(st.sampled_from(["m", "l", "g", "pi", "q1", "x y"]),
                                            _scalar),
              "gravity": _vector, "base": _data, "tool": _data, "description": _scalar},
)


@fuzz_settings(deadline_s=20)
@given(_document)
def test_generated_yaml_documents(document: dict) -> None:
    load_outcome(yaml.safe_dump(document, allow_unicode=True), ".yaml")


@fuzz_settings(deadline_s=20)
@given(st.binary(max_size=2048))
def test_arbitrary_bytes_as_yaml(data: bytes) -> None:
    load_outcome(data, ".yaml")


@fuzz_settings(deadline_s=20)
@given(mutated(URDFS))
def test_mutated_urdf(text: str) -> None:
    load_outcome(text, ".urdf")
