"""Finite Fourier series joint trajectories (Swevers et al.): the parametrisation of an excitation
design, zero velocity and acceleration at the period's ends, scaled into the joint limits."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from robodyn.studies.excitation_limits import ExcitationLimits, _frozen

__all__ = ["FourierTrajectory", "random_fourier"]

# ----------------------------------------------------------------------------------------------
# Fourier series
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class FourierTrajectory:
    """Finite Fourier series joint motion (module docstring), periodic with period ``1 / f``.

    Attributes
    ----------
    a, b : (n, L) ndarray
        Sine-side and cosine-side coefficients of the velocity, rad/s (m/s).
    offset : (n,) ndarray
        ``q0``, rad (m).
    base_frequency : float
        ``f``, Hz.
    """

    a: np.ndarray
    b: np.ndarray
    offset: np.ndarray
    base_frequency: float

    @property
    def harmonics(self) -> int:
        """Number of harmonics L."""
        return self.a.shape[1]

    @property
    def period(self) -> float:
        """``1 / f``, s."""
        return 1.0 / self.base_frequency

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, qd, qdd)`` at times ``t`` (N,), each (N, n)."""
        t = np.asarray(t, dtype=float)
        coef = np.concatenate([self.a, self.b], axis=1).T  # (2 L, n)
        out = tuple(np.empty((t.size, coef.shape[1])) for _ in range(3))
        # a block of samples at a time: the basis is 12 L values a sample, more than the result
        for start in range(0, t.size, _BLOCK):
            rows = slice(start, start + _BLOCK)
            for value, basis in zip(out, _basis(t[rows], self.harmonics, self.base_frequency),
                                    strict=True):
                np.matmul(basis, coef, out=value[rows])
        out[0][:] += self.offset
        return out  # type: ignore[return-value]

    def scaled(self, s: float) -> FourierTrajectory:
        """The same motion with its oscillation about the offset scaled by ``s``."""
        return FourierTrajectory(_frozen(s * self.a), _frozen(s * self.b), self.offset, self.base_frequency)


#: Samples evaluated at a time by :meth:`FourierTrajectory.evaluate`.
_BLOCK = 32_768


def _basis(t: np.ndarray, harmonics: int, f: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Matrices (N, 2 L) mapping ``[a; b]`` of one joint to q - q0, qd and qdd at ``t``."""
    w = 2.0 * np.pi * f
    wl = w * np.arange(1, harmonics + 1)
    s, c = np.sin(np.outer(t, wl)), np.cos(np.outer(t, wl))
    # q - q0 = a/(w l) sin - b/(w l) cos;  qd = a cos + b sin;  qdd = -a w l sin + b w l cos
    return (np.hstack([s / wl, -c / wl]), np.hstack([c, s]), np.hstack([-s * wl, c * wl]))


def _null_bases(harmonics: int, f: float) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal bases (L, L-1) of ``sum a = 0`` and (L, L-2) of the two ``b`` constraints."""
    wl = 2.0 * np.pi * f * np.arange(1, harmonics + 1)
    na = scipy.linalg.null_space(np.ones((1, harmonics)))
    # sum b/(w l) = 0 (q(0) = q0) and sum b w l = 0 (qdd(0) = 0)
    nb = scipy.linalg.null_space(np.vstack([1.0 / wl, wl]))
    return na, nb


@dataclass(frozen=True)
class _Layout:
    """Map from the optimisation vector x to Fourier coefficients: x_i = [q0_i, z_a (L-1), z_b (L-2)]."""

    n: int
    harmonics: int
    na: np.ndarray
    nb: np.ndarray

    @property
    def per_joint(self) -> int:
        return 1 + self.na.shape[1] + self.nb.shape[1]

    def joint_map(self) -> np.ndarray:
        """(2 L, per_joint - 1) matrix taking [z_a; z_b] to [a; b]."""
        return scipy.linalg.block_diag(self.na, self.nb)

    def split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(offset (n,), coef (n, 2 L))`` of the vector x."""
        xs = x.reshape(self.n, self.per_joint)
        return xs[:, 0], xs[:, 1:] @ self.joint_map().T

    def series(self, x: np.ndarray, f: float) -> FourierTrajectory:
        off, coef = self.split(x)
        L = self.harmonics
        return FourierTrajectory(_frozen(coef[:, :L]), _frozen(coef[:, L:]), _frozen(off), f)

    def pack(self, traj: FourierTrajectory) -> np.ndarray:
        """Inverse of :meth:`series` for coefficients that satisfy the rest constraints."""
        za = traj.a @ self.na
        zb = traj.b @ self.nb
        return np.hstack([traj.offset[:, None], za, zb]).ravel()


def random_fourier(limits: ExcitationLimits, harmonics: int, base_frequency: float,
                   rng: np.random.Generator, *, samples: int | None = None) -> FourierTrajectory:
    """A random rest-to-rest Fourier trajectory scaled to touch its tightest limit.

    Offsets are uniform in the middle half of each joint's range; coefficients standard normal in
    the constraint null space, then the oscillation is scaled so that the largest ratio of
    ``|q - q0|`` to the room left about the offset, ``|qd|`` to the speed limit and ``|qdd|`` to
    the acceleration limit, over ``samples`` points of a period, is exactly 1.
    """
    na, nb = _null_bases(harmonics, base_frequency)
    n = limits.dof
    mid, half = 0.5 * (limits.lower + limits.upper), 0.5 * (limits.upper - limits.lower)
    off = mid + 0.5 * half * rng.uniform(-1.0, 1.0, n)
    a = rng.standard_normal((n, na.shape[1])) @ na.T
    b = rng.standard_normal((n, nb.shape[1])) @ nb.T
    traj = FourierTrajectory(_frozen(a), _frozen(b), _frozen(off), base_frequency)
    return _fit_to_limits(traj, limits, samples or 40 * harmonics)


def _fit_to_limits(traj: FourierTrajectory, limits: ExcitationLimits, samples: int,
                   shrink_only: bool = False) -> FourierTrajectory:
    """Scale the oscillation so the samples just meet the tightest limit (only shrink if asked)."""
    t = np.arange(samples) * traj.period / samples
    q, qd, qdd = traj.evaluate(t)
    dq = q - traj.offset
    room_up, room_down = limits.upper - traj.offset, traj.offset - limits.lower
    ratio = max(np.max(np.where(dq > 0, dq / room_up, -dq / room_down)),
                np.max(np.abs(qd) / limits.velocity), np.max(np.abs(qdd) / limits.acceleration))
    if ratio <= 0 or (shrink_only and ratio <= 1.0):
        return traj
    return traj.scaled(1.0 / ratio)
