"""ISO 9283 performance characteristics: pose accuracy and repeatability, test cube, overshoot.

Definitions (ISO 9283:1998, sections 6-7), for one commanded pose measured over ``n`` cycles with
attained positions ``x_j``:

* barycentre ``x_bar = mean_j x_j``;
* position accuracy ``AP_P = |x_bar - x_c|`` with components ``AP_x = x_bar - x_c`` (etc.);
* position repeatability ``RP_l = l_bar + 3 S_l``, where ``l_j = |x_j - x_bar|``,
  ``l_bar = mean_j l_j`` and ``S_l = sqrt(sum (l_j - l_bar)^2 / (n - 1))``;
* orientation accuracy ``AP_a = mean_j a_j - a_c`` (and b, c) and repeatability
  ``RP_a = +-3 S_a`` with ``S_a`` the sample standard deviation of ``a_j`` (when measured).

Test cube (section 6.2): a cube of edge ``size`` in the working space; the measuring plane is the
diagonal plane ``C1-C2-C7-C8``; ``P1`` is the cube's centre; ``P2..P5`` lie on the plane's
diagonals at ``fraction`` (10 % +- 2 %) of the diagonal length from the corners. Our corner
numbering (ISO's figure numbers corners but coordinates depend on its drawing): with the cube
centred at ``c`` and half edge ``h``, ``C1..C4`` are the bottom face ``z = -h`` counter-clockwise
from ``(-h, -h)`` and ``C5..C8`` the top face above them, so ``C1 = (-,-,-)``, ``C2 = (+,-,-)``,
``C7 = (+,+,+)``, ``C8 = (-,+,+)`` (the plane rising along +y); ``P2`` is near ``C1``, ``P3`` near
``C2``, ``P4`` near ``C7``, ``P5`` near ``C8``. A rotation can place the cube in other
orientations.

Overshoot and stabilisation (sections 7.5, 7.6), from one measured approach to a pose
(``t``, ``x(t)``): the attained pose ``x_a`` is the mean of the final settled samples; ``d(t) =
|x(t) - x_a|``; the stabilisation band is a given limit (ISO: the RP value or the manufacturer's
figure). The pose stabilisation time is the time from the first entry into the band until the
last exit from it (zero if the robot never leaves after entering); the position overshoot is the
largest ``d(t)`` after the robot first crosses the attained pose along its approach direction
(``(x(t) - x_a) . u <= 0``, ``u`` the unit vector from ``x_a`` to the start), zero if it never
crosses.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robodyn.robot.errors import InputError

__all__ = [
    "Overshoot",
    "PoseCharacteristics",
    "cube_corners",
    "cube_points",
    "overshoot_from_csv",
    "overshoot_stabilisation",
    "pose_characteristics",
    "pose_characteristics_from_csv",
]


@dataclass(frozen=True, eq=False)
class PoseCharacteristics:
    """Pose accuracy and repeatability of P commanded poses over n cycles (metres, radians).

    Attributes
    ----------
    commanded : numpy.ndarray, shape (P, 3)
    barycentre : numpy.ndarray, shape (P, 3)
    ap : numpy.ndarray, shape (P,)
        Position accuracy ``AP_P``.
    ap_xyz : numpy.ndarray, shape (P, 3)
        ``AP_x, AP_y, AP_z``.
    rp : numpy.ndarray, shape (P,)
        Position repeatability ``RP_l``.
    l_mean, s_l : numpy.ndarray, shape (P,)
        ``l_bar`` and ``S_l``.
    ap_abc, rp_abc : numpy.ndarray or None, shape (P, 3)
        Orientation accuracy and repeatability (half-width ``3 S``) about a, b, c, rad.
    cycles : int
    labels : tuple of str
    """

    commanded: np.ndarray
    barycentre: np.ndarray
    ap: np.ndarray
    ap_xyz: np.ndarray
    rp: np.ndarray
    l_mean: np.ndarray
    s_l: np.ndarray
    ap_abc: np.ndarray | None
    rp_abc: np.ndarray | None
    cycles: int
    labels: tuple[str, ...]

    def text(self) -> str:
        """A table in millimetres."""
        rows = [f"{'pose':<8}{'AP_P/mm':>10}{'AP_x':>9}{'AP_y':>9}{'AP_z':>9}{'RP_l/mm':>10}"]
        for k, lab in enumerate(self.labels):
            ax, ay, az = self.ap_xyz[k] * 1e3
            rows.append(f"{lab:<8}{self.ap[k] * 1e3:>10.4f}{ax:>9.4f}{ay:>9.4f}{az:>9.4f}"
                        f"{self.rp[k] * 1e3:>10.4f}")
        return "\n".join(rows)


def pose_characteristics(commanded, attained, *, commanded_abc=None, attained_abc=None,
                         labels=None) -> PoseCharacteristics:
    """AP and RP for P poses measured over n cycles.

    Parameters
    ----------
    commanded : array_like, shape (P, 3)
        Commanded positions, m.
    attained : array_like, shape (P, n, 3)
        Attained (measured) positions per cycle, m; n >= 2.
    commanded_abc, attained_abc : array_like, shapes (P, 3) and (P, n, 3), optional
        Orientation angles a, b, c (rad), commanded and attained.
    labels : sequence of str, optional

    Returns
    -------
    PoseCharacteristics
    """
    xc = np.asarray(commanded, dtype=float)
    x = np.asarray(attained, dtype=float)
    if x.ndim != 3 or x.shape[2] != 3 or xc.shape != (x.shape[0], 3):
        raise InputError(f"commanded must be (P, 3) and attained (P, n, 3); got {xc.shape} and {x.shape}")
    if x.shape[1] < 2:
        raise InputError("repeatability needs at least 2 cycles per pose")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(xc))):
        raise InputError("pose data contain NaN or infinite values")
    bar = x.mean(axis=1)
    ap_xyz = bar - xc  # AP_x = x_bar - x_c
    ap = np.linalg.norm(ap_xyz, axis=1)
    dist = np.linalg.norm(x - bar[:, None], axis=2)  # l_j = |x_j - x_bar|
    l_mean = dist.mean(axis=1)
    s_l = np.std(dist, axis=1, ddof=1)
    ap_abc = rp_abc = None
    if attained_abc is not None:
        a = np.asarray(attained_abc, dtype=float)
        ac = np.asarray(commanded_abc, dtype=float)
        ap_abc = a.mean(axis=1) - ac  # AP_a = a_bar - a_c
        rp_abc = 3 * np.std(a, axis=1, ddof=1)  # RP_a = +-3 S_a
    labels = tuple(labels) if labels is not None else tuple(f"P{k + 1}" for k in range(len(xc)))
    return PoseCharacteristics(xc, bar, ap, ap_xyz, l_mean + 3 * s_l, l_mean, s_l, ap_abc, rp_abc,
                               x.shape[1], labels)


def cube_corners(center, size: float, rotation=None) -> np.ndarray:
    """Corners C1..C8 of the test cube (see the module docstring), shape (8, 3), m."""
    h = size / 2
    signs = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
             (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
    r = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
    return np.asarray(center, dtype=float) + (h * np.array(signs, dtype=float)) @ r.T


def cube_points(center, size: float = 0.5, *, fraction: float = 0.1, rotation=None) -> np.ndarray:
    """ISO 9283 test points P1..P5 in the measuring plane C1-C2-C7-C8, shape (5, 3), m.

    Parameters
    ----------
    center : array_like, shape (3,)
        Cube centre, m.
    size : float
        Edge length, m (the thesis used 0.5 m).
    fraction : float
        Distance of P2..P5 from the corners as a fraction of the diagonal (ISO: 0.10 +- 0.02).
    rotation : array_like, shape (3, 3), optional
        Orientation of the cube.

    Raises
    ------
    InputError
        When ``size`` is not a positive finite number, or ``fraction`` is outside 0.08..0.12.
    """
    if isinstance(size, bool) or not isinstance(size, int | float | np.number) or not 0 < size < np.inf:
        raise InputError(f"ISO 9283 cube: size must be a positive finite edge length in m, got {size!r}")
    if not 0.08 <= fraction <= 0.12:
        raise InputError(f"ISO 9283 puts P2..P5 at 10 % +- 2 % of the diagonal; got {fraction:.3g}")
    c = cube_corners(center, size, rotation)
    c1, c2, c7, c8 = c[0], c[1], c[6], c[7]
    p1 = (c1 + c7) / 2
    return np.array([
        p1,
        c1 + fraction * (c7 - c1),  # P2 near C1 on diagonal C1-C7
        c2 + fraction * (c8 - c2),  # P3 near C2 on diagonal C2-C8
        c7 + fraction * (c1 - c7),  # P4 near C7
        c8 + fraction * (c2 - c8),  # P5 near C8
    ])


@dataclass(frozen=True)
class Overshoot:
    """Position overshoot and stabilisation of one approach (m, s).

    Attributes
    ----------
    overshoot : float
        Largest distance from the attained pose after first crossing it, m.
    stabilisation_time : float
        Time from first entering the band to settling in it for good, s.
    attained : tuple of float
        Attained position, m.
    band : float
        Stabilisation band radius, m.
    settled : bool
        Whether the last sample is inside the band.
    """

    overshoot: float
    stabilisation_time: float
    attained: tuple[float, float, float]
    band: float
    settled: bool


def overshoot_stabilisation(t, x, *, band: float, attained=None, settle_fraction: float = 0.1,
                            ) -> Overshoot:
    """Position overshoot and stabilisation time of a measured approach trajectory.

    Parameters
    ----------
    t : array_like, shape (T,)
        Sample times, s, increasing.
    x : array_like, shape (T, 3)
        Measured positions, m.
    band : float
        Stabilisation band radius, m (ISO: the RP value or the manufacturer's limit).
    attained : array_like, shape (3,), optional
        Attained position; default the mean of the last ``settle_fraction`` of the samples.
    settle_fraction : float

    Returns
    -------
    Overshoot
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if t.ndim != 1 or x.shape != (len(t), 3) or len(t) < 3:
        raise InputError(f"t must be (T,) and x (T, 3) with T >= 3; got {t.shape} and {x.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(x))):
        raise InputError("trajectory contains NaN or infinite values")
    if np.any(np.diff(t) <= 0):
        raise InputError("trajectory times must increase")
    if not band > 0:
        raise InputError("band must be positive")
    if attained is None:
        k = max(1, int(round(settle_fraction * len(t))))
        xa = x[-k:].mean(axis=0)
    else:
        xa = np.asarray(attained, dtype=float)
    d = np.linalg.norm(x - xa, axis=1)
    inside = d <= band
    if not inside.any():
        return Overshoot(float("nan"), float("nan"), tuple(xa), band, False)
    first_in = int(np.argmax(inside))
    outside_after = np.flatnonzero(~inside[first_in:])
    settle_idx = first_in + outside_after[-1] + 1 if outside_after.size else first_in
    settled = bool(inside[-1])
    stab = float(t[settle_idx] - t[first_in]) if settled and settle_idx < len(t) else float("nan")
    u = x[0] - xa
    norm = np.linalg.norm(u)
    overshoot = 0.0
    if norm > 0:
        u /= norm
        crossed = np.flatnonzero((x - xa) @ u <= 0)
        if crossed.size:
            overshoot = float(d[crossed[0]:].max())
    return Overshoot(overshoot, stab, tuple(float(v) for v in xa), float(band), settled)


def pose_characteristics_from_csv(path: str | Path) -> PoseCharacteristics:
    """AP and RP from a CSV file of repeated cycles.

    Columns (header row, any order; ``#`` lines are comments): ``pose`` (a label), ``x_cmd``,
    ``y_cmd``, ``z_cmd`` (commanded position, m) and ``x``, ``y``, ``z`` (attained, m); one row per
    measurement; every pose needs the same number (>= 2) of cycles and one commanded position;
    values are at most :data:`robodyn.calibration.io.MAX_ABS_VALUE` in magnitude.

    Raises
    ------
    FileNotFoundError, DataFileError
        See :func:`robodyn.calibration.io.read_table`; also a pose with two commanded positions,
        poses with different numbers of cycles, or a single cycle.
    """
    from robodyn.calibration.io import MAX_ABS_VALUE, read_table
    from robodyn.robot.errors import DataFileError

    table = read_table(path, ["pose", "x_cmd", "y_cmd", "z_cmd", "x", "y", "z"], text_columns=("pose",),
                       max_abs=MAX_ABS_VALUE)
    labels = list(dict.fromkeys(table["pose"]))
    cmd, att = [], []
    for lab in labels:
        rows = [k for k, v in enumerate(table["pose"]) if v == lab]
        c = np.column_stack([np.asarray(table[k])[rows] for k in ("x_cmd", "y_cmd", "z_cmd")])
        if np.ptp(c, axis=0).max() > 0:
            raise DataFileError(f"{path}: pose {lab!r} has more than one commanded position")
        cmd.append(c[0])
        att.append(np.column_stack([np.asarray(table[k])[rows] for k in ("x", "y", "z")]))
    counts = {len(a) for a in att}
    if len(counts) != 1:
        raise DataFileError(f"{path}: poses have different numbers of cycles ({sorted(counts)})")
    if counts == {1}:
        raise DataFileError(f"{path}: one cycle per pose; repeatability needs at least 2")
    return pose_characteristics(np.array(cmd), np.array(att), labels=labels)


def overshoot_from_csv(path: str | Path, *, band: float, attained=None) -> Overshoot:
    """Overshoot and stabilisation time of a measured approach read from a CSV file.

    Columns (header row, any order; ``#`` lines are comments): ``t`` (s, increasing) and ``x``,
    ``y``, ``z`` (m), at least 3 rows; values at most
    :data:`robodyn.calibration.io.MAX_ABS_VALUE` in magnitude. ``band`` and ``attained`` as in
    :func:`overshoot_stabilisation`.

    Raises
    ------
    FileNotFoundError, DataFileError
        See :func:`robodyn.calibration.io.read_table`; also too few rows or times that do not
        increase (the message names the file).
    """
    from robodyn.calibration.io import MAX_ABS_VALUE, _read_table
    from robodyn.robot.errors import DataFileError

    table, lines = _read_table(path, ["t", "x", "y", "z"], (), (), MAX_ABS_VALUE)
    t = np.asarray(table["t"])
    x = np.column_stack([table[c] for c in ("x", "y", "z")])
    if len(t) < 3:
        raise DataFileError(f"{path}: {len(t)} data row(s); an approach needs at least 3")
    if np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise DataFileError(f"{path}: line {lines[k + 1]}, column 't': times must increase "
                            f"({t[k + 1]:g} after {t[k]:g})")
    return overshoot_stabilisation(t, x, band=band, attained=attained)
