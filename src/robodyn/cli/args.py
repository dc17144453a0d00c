"""What several ``robodyn`` commands share: the robot argument's help and argument types.

Every command module registers itself with ``register(sub, fmt)`` (``sub``: the main parser's
subcommands; ``fmt``: the help formatter class) and takes these from here.
"""

from __future__ import annotations

import argparse

import numpy as np

__all__ = ["ROBOT_HELP", "floats"]

#: Help of every command's ROBOT argument.
ROBOT_HELP = "built-in robot name (see 'robodyn list') or path to a .yaml/.yml/.urdf description"


def floats(text: str) -> np.ndarray:
    """A comma-separated list of numbers (``0,0.5,-1``); an argparse type."""
    try:
        return np.array([float(v) for v in text.replace(" ", "").split(",") if v], dtype=float)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") from None
