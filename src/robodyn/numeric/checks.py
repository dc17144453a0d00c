"""Checks of the compiled model's inputs and generated structure (helpers of :mod:`.model`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from robodyn.codegen.kernels import KernelSet
from robodyn.codegen.singular import structural_singularity, without_infinities
from robodyn.robot.errors import InputError, SingularMassMatrixError
from robodyn.robot.model import Robot

__all__ = ["batch_inputs", "check_structure", "out_buffer", "structural_singularity", "thread_count",
           "without_infinities"]


def batch_inputs(name: str, inputs: Sequence[tuple[str, int]], arrays: Sequence[np.ndarray]
                 ) -> tuple[list[np.ndarray], tuple[int, ...]]:
    """The inputs of kernel ``name`` as float64 arrays, (width,) or (N, width) each as ``inputs``
    ((name, width) per argument) says, and their common batch shape (() or (N,))."""
    batch_shape: tuple[int, ...] | None = None
    args = []
    for (arg_name, width), value in zip(inputs, arrays, strict=True):
        arr = np.asarray(value, dtype=np.float64)
        if arr.ndim not in (1, 2) or arr.shape[-1] != width:
            raise InputError(f"{name}: {arg_name} must have shape ({width},) or (N, {width}), "
                             f"got {arr.shape}")
        if batch_shape is None:
            batch_shape = arr.shape[:-1]
        elif arr.shape[:-1] != batch_shape:
            raise InputError(f"{name}: {arg_name} has shape {arr.shape}, but the first "
                             f"argument's batch shape is {batch_shape}")
        args.append(arr)
    assert batch_shape is not None
    return args, batch_shape


def out_buffer(out: np.ndarray, shape: tuple[int, ...], inputs: Sequence[np.ndarray],
               name: str) -> np.ndarray:
    """``out`` as a view of ``shape``, checked: float64, C-contiguous, writeable, right size."""
    if not isinstance(out, np.ndarray) or out.dtype != np.float64 or not out.flags.c_contiguous \
            or not out.flags.writeable:
        raise InputError(f"{name}(out=...): expected a writeable C-contiguous float64 NumPy array, "
                         f"got {type(out).__name__}"
                         + (f" of dtype {out.dtype}" if isinstance(out, np.ndarray) else ""))
    size = int(np.prod(shape))
    if out.size != size:
        raise InputError(f"{name}(out=...): the result has shape {shape} ({size} values), out has "
                         f"shape {out.shape} ({out.size} values)")
    if any(np.shares_memory(out, a) for a in inputs):
        raise InputError(f"{name}(out=...): out overlaps an input array")
    return out.reshape(shape)


def check_structure(robot: Robot, kset: KernelSet, values: Mapping[str, float]) -> None:
    """Refuse a mass matrix that is singular everywhere: the Cholesky pivot folds to ``1/0``."""
    message = structural_singularity(robot, kset, values)
    if message is not None:
        raise SingularMassMatrixError(message)




def thread_count(threads: int) -> int:
    """``threads`` checked: a positive integer."""
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise InputError(f"threads must be a positive integer, got {threads!r}")
    return int(threads)
