"""What several ``robodyn`` commands share: the robot argument's help and argument types.

Every command module registers itself with ``register(sub, fmt)`` (``sub``: the main parser's
subcommands; ``fmt``: the help formatter class) and takes these from here.
"""

from __future__ import annotations

import argparse

import numpy as np

from robodyn.robot.errors import InputError
from robodyn.text import err

__all__ = ["BACKENDS", "BACKEND_HELP", "ROBOT_HELP", "floats", "lock", "locked_joints", "resolve_backend"]

#: Help of every command's ROBOT argument.
ROBOT_HELP = "built-in robot name (see 'robodyn list') or path to a .yaml/.yml/.urdf description"


def positive_int(text: str) -> int:
    """An argparse type: an integer of at least 1 (a count: samples, workers, a batch size)."""
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text}")
    return value


def floats(text: str) -> np.ndarray:
    """A comma-separated list of numbers (``0,0.5,-1``); an argparse type."""
    try:
        return np.array([float(v) for v in text.replace(" ", "").split(",") if v], dtype=float)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") from None


def lock(text: str) -> tuple[str, float]:
    """``JOINT=VALUE`` (a joint name and its position, rad or m); an argparse type."""
    name, sep, value = text.partition("=")
    try:
        number = float(value)
    except ValueError:
        number = float("nan")
    if not sep or not name.strip() or not np.isfinite(number):
        raise argparse.ArgumentTypeError(f"expected JOINT=VALUE (a joint name and a position in "
                                         f"rad or m, e.g. finger_joint1=0.04), got {text!r}")
    return name.strip(), number


def locked_joints(args: argparse.Namespace) -> dict[str, float] | None:
    """The ``--lock`` options as ``rd.load``'s ``locked`` (None when none is given)."""
    pairs = getattr(args, "lock", None) or []
    out: dict[str, float] = {}
    for name, value in pairs:
        if name in out and out[name] != value:
            raise InputError(f"--lock: joint {name!r} given twice ({out[name]:g} and {value:g})")
        out[name] = value
    return out or None


#: ``--backend`` choices of the commands that compile a model; "auto": C when a compiler is found.
BACKENDS = ("auto", "c", "numpy")
BACKEND_HELP = ("compiled C (needs a C compiler), pure NumPy (no compiler; same results, slower), "
                "or auto: C when a compiler is found, else NumPy with a note (default: %(default)s)")


def resolve_backend(choice: str) -> str:
    """``"c"`` or ``"numpy"`` for a ``--backend`` choice: "auto" is C when a C compiler is found,
    else NumPy, said in a note on stderr."""
    if choice != "auto":
        return choice
    from robodyn.codegen.build import CompilerNotFoundError, find_compiler

    try:
        find_compiler()
    except CompilerNotFoundError as exc:
        err(f"robodyn: note: {' '.join(str(exc).split())}; using the NumPy backend (same results, "
            "slower)")
        return "numpy"
    return "c"
