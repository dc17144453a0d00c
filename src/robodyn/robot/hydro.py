"""The ``fluid`` and ``hydro`` blocks of a description, read into frozen data.

The YAML loader reads both blocks once, strictly, with :func:`parse_fluid` and
:func:`parse_hydro` into :class:`Fluid` (``Robot.fluid``) and :class:`LinkHydro`
(``Link.hydro``), frozen data whose numeric fields are SymPy expressions over the robot's named
parameters, exactly like every other description quantity. A variant (another drag coefficient,
no current) is ``dataclasses.replace`` of them.

Schema (lengths m, density kg/m^3, velocity m/s, coefficients dimensionless)::

    fluid:                                  # robot level; required when a link has hydro data
      density: 1000                         # rho > 0 (default 1000, fresh water)
      current: [0, 0, 0]                    # uniform current velocity, base (world) frame
    hydro:                                  # per link, in the link frame
      cylinders:                            # one or more straight circular cylinders
        - {radius: 0.05, length: 1.0, axis: [1, 0, 0], start: [0, 0, 0]}
      added_mass: 1.0                       # normal added-mass coefficient C_a (default 1)
      axial_added_mass: 0.0                 # axial coefficient C_ax (default 0)
      drag: 1.2                             # normal drag coefficient C_d (default 1.2)
      skin_friction: 0.0                    # axial skin-friction coefficient C_f (default 0)
      lift: 0.0                             # lift coefficient C_L (default 0)
      volume: 0.00785                       # displaced volume V, m^3 (default: the cylinders')
      center_of_buoyancy: [0.5, 0, 0]       # link frame, m (default: the cylinders' centroid)
      quadrature: 6                         # Gauss-Legendre points per cylinder (1..64, default 6)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import sympy as sp

from robodyn.robot.errors import DescriptionError
from robodyn.robot.expressions import parse_value
from robodyn.robot.validation import evaluate

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = [
    "CYLINDER_KEYS",
    "FLUID_KEYS",
    "HYDRO_DEFAULTS",
    "HYDRO_KEYS",
    "Cylinder",
    "Fluid",
    "LinkHydro",
    "fluid_of",
    "hydro_of",
    "parse_fluid",
    "parse_hydro",
    "still_water",
    "with_current",
    "with_values",
]

FLUID_KEYS = ("density", "current")
HYDRO_KEYS = ("cylinders", "added_mass", "axial_added_mass", "drag", "skin_friction", "lift",
              "volume", "center_of_buoyancy", "quadrature")
CYLINDER_KEYS = ("radius", "length", "axis", "start")

#: Coefficients used when a hydro block omits them: C_a = 1 is the potential-flow added mass of a
#: circular cylinder moving normal to its axis; C_d = 1.2 the subcritical (Re ~ 1e4 - 2e5) drag
#: of a circular cylinder in cross flow; no axial added mass, skin friction or lift.
HYDRO_DEFAULTS: Mapping[str, float] = {
    "added_mass": 1.0, "axial_added_mass": 0.0, "drag": 1.2, "skin_friction": 0.0, "lift": 0.0,
}


@dataclass(frozen=True)
class Fluid:
    """The fluid the robot works in.

    Attributes
    ----------
    density : sympy.Expr
        rho, kg/m^3.
    current : sympy.ImmutableMatrix, shape (3, 1)
        Uniform, steady current velocity in the world (base) frame, m/s.
    """

    density: sp.Expr
    current: sp.ImmutableMatrix


@dataclass(frozen=True)
class Cylinder:
    """A straight circular cylinder fixed in a link frame.

    Attributes
    ----------
    radius, length : sympy.Expr
        r and L, m.
    axis : sympy.ImmutableMatrix, shape (3, 1)
        Unit axis a in the link frame (normalised from the description).
    start : sympy.ImmutableMatrix, shape (3, 1)
        Centre of the start face s in the link frame, m; the cylinder spans s + xi a, 0 <= xi <= L.
    """

    radius: sp.Expr
    length: sp.Expr
    axis: sp.ImmutableMatrix
    start: sp.ImmutableMatrix

    @property
    def volume(self) -> sp.Expr:
        """pi r^2 L, m^3."""
        return sp.pi * self.radius**2 * self.length

    @property
    def centre(self) -> sp.ImmutableMatrix:
        """Centroid s + (L/2) a in the link frame, shape (3, 1), m."""
        return sp.ImmutableMatrix(self.start + self.length / 2 * self.axis)


@dataclass(frozen=True)
class LinkHydro:
    """Hydrodynamic data of one link (link frame).

    Attributes
    ----------
    cylinders : tuple of Cylinder
    added_mass, axial_added_mass, drag, skin_friction, lift : sympy.Expr
        C_a, C_ax, C_d, C_f, C_L (dimensionless).
    volume : sympy.Expr
        Displaced volume V, m^3 (the cylinders' unless given).
    center_of_buoyancy : sympy.ImmutableMatrix, shape (3, 1)
        Link frame, m (the cylinders' volume centroid unless given).
    quadrature : int
        Gauss-Legendre points per cylinder for drag and lift.
    """

    cylinders: tuple[Cylinder, ...]
    added_mass: sp.Expr
    axial_added_mass: sp.Expr
    drag: sp.Expr
    skin_friction: sp.Expr
    lift: sp.Expr
    volume: sp.Expr
    center_of_buoyancy: sp.ImmutableMatrix
    quadrature: int = 6


class _Fields:
    """Field-path-aware readers for one block (errors ``"<where>.<field>: <reason>"``)."""

    def __init__(self, where: str, symbols: Mapping[str, sp.Symbol], defaults: Mapping[str, float]):
        self.where, self.symbols, self.defaults = where, symbols, defaults

    def error(self, path: str, reason: str) -> DescriptionError:
        return DescriptionError(f"{self.where}{path}: {reason}")

    def mapping(self, value: Any, path: str, allowed: Sequence[str]) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            raise self.error(path, f"expected a mapping, got {type(value).__name__}")
        unknown = [k for k in value if k not in allowed]
        if unknown:
            raise self.error(path, f"unknown key(s) {', '.join(repr(k) for k in unknown)} "
                                   f"(allowed: {', '.join(allowed)})")
        return value

    def expr(self, value: Any, path: str) -> tuple[sp.Expr, float]:
        e = parse_value(value, self.symbols, where=f"{self.where}{path}")
        return e, evaluate(e, self.defaults, where=f"{self.where}{path}")

    def bounded(self, value: Any, path: str, what: str, *, positive: bool) -> sp.Expr:
        e, v = self.expr(value, path)
        if v < 0 or (positive and v == 0):
            bound = "positive" if positive else "not be negative"
            raise self.error(path, f"{what} must {'be ' if positive else ''}{bound} (got {e} = {v:g})")
        return e

    def vector(self, value: Any, path: str) -> tuple[list[sp.Expr], list[float]]:
        if not isinstance(value, list | tuple) or len(value) != 3:
            raise self.error(path, f"expected a list of 3 numbers, got {value!r}"[:200])
        pairs = [self.expr(v, f"{path}[{k}]") for k, v in enumerate(value)]
        return [p[0] for p in pairs], [p[1] for p in pairs]


def parse_fluid(data: Any, symbols: Mapping[str, sp.Symbol], defaults: Mapping[str, float], *,
                where: str) -> Fluid:
    """Read a ``fluid`` block.

    Parameters
    ----------
    data : mapping
        The block as read from the description.
    symbols, defaults : mapping of str
        The description's parameter symbols and default values.
    where : str
        ``"<file>: fluid"``; starts every error message.

    Returns
    -------
    Fluid

    Raises
    ------
    DescriptionError
        Not a mapping, unknown key, a density that is not positive, a current that is not three
        finite numbers.
    """
    f = _Fields(where, symbols, defaults)
    m = f.mapping(data, "", FLUID_KEYS)
    still = still_water()
    density = (f.bounded(m["density"], ".density", "density", positive=True)
               if "density" in m else still.density)
    current = sp.ImmutableMatrix(f.vector(m["current"], ".current")[0]) if "current" in m else still.current
    return Fluid(density=density, current=current)


def parse_hydro(data: Any, symbols: Mapping[str, sp.Symbol], defaults: Mapping[str, float], *,
                where: str) -> LinkHydro:
    """Read a link's ``hydro`` block.

    Parameters
    ----------
    data : mapping
        The block as read from the description.
    symbols, defaults : mapping of str
        The description's parameter symbols and default values.
    where : str
        ``"<file>: joints[i].link.hydro"``; starts every error message.

    Returns
    -------
    LinkHydro
        Volume ``sum(pi r^2 L)`` and centre of buoyancy ``sum(V_k c_k) / V`` from the cylinders
        unless given.

    Raises
    ------
    DescriptionError
        Unknown key; a radius or length that is not positive; a zero axis; a negative
        coefficient or volume; a volume without cylinders and without a centre of buoyancy.
    """
    f = _Fields(where, symbols, defaults)
    m = f.mapping(data, "", HYDRO_KEYS)
    raw = m.get("cylinders", [])
    if not isinstance(raw, list):
        raise f.error(".cylinders", f"expected a list of cylinders, got {type(raw).__name__}")
    cylinders = tuple(_cylinder(f, c, f".cylinders[{k}]") for k, c in enumerate(raw))
    coeffs = {}
    for key, default in HYDRO_DEFAULTS.items():
        coeffs[key] = (f.bounded(m[key], f".{key}", f"coefficient {key}", positive=False)
                       if key in m else sp.Float(default))
    if "volume" in m:
        volume = f.bounded(m["volume"], ".volume", "volume", positive=False)
    else:
        # V = sum_k pi r_k^2 L_k
        volume = sp.Add(*(c.volume for c in cylinders))
    if "center_of_buoyancy" in m:
        cob = sp.ImmutableMatrix(f.vector(m["center_of_buoyancy"], ".center_of_buoyancy")[0])
    elif cylinders:
        # c_B = sum_k V_k c_k / sum_k V_k (volume centroid of the cylinders)
        total = sp.Add(*(c.volume for c in cylinders))
        cob = sp.ImmutableMatrix(sum((c.volume * c.centre for c in cylinders), sp.zeros(3, 1)) / total)
        cob = cob.applyfunc(sp.simplify) if cob.free_symbols else cob
    elif evaluate(volume, defaults, where=f"{where}.volume") != 0:
        raise f.error("", "a volume without cylinders needs a center_of_buoyancy")
    else:
        cob = sp.ImmutableMatrix([0, 0, 0])
    points = m.get("quadrature", 6)
    if isinstance(points, bool) or not isinstance(points, int) or not 1 <= points <= 64:
        raise f.error(".quadrature", f"expected a whole number of points 1..64, got {points!r}")
    return LinkHydro(cylinders=cylinders, volume=volume, center_of_buoyancy=cob, quadrature=points,
                     **coeffs)


def _cylinder(f: _Fields, value: Any, path: str) -> Cylinder:
    """One ``cylinders[k]`` entry."""
    m = f.mapping(value, path, CYLINDER_KEYS)
    for key in ("radius", "length", "axis"):
        if key not in m:
            raise f.error(f"{path}.{key}", "required field is missing")
    radius = f.bounded(m["radius"], f"{path}.radius", "radius", positive=True)
    length = f.bounded(m["length"], f"{path}.length", "length", positive=True)
    axis, values = f.vector(m["axis"], f"{path}.axis")
    norm = sum(v * v for v in values) ** 0.5
    if norm == 0:
        raise f.error(f"{path}.axis", f"axis {m['axis']!r} has zero length")
    # a = axis / |axis|
    unit = sp.ImmutableMatrix(axis) / sp.sqrt(sum(e**2 for e in axis))
    start = f.vector(m["start"], f"{path}.start")[0] if "start" in m else [sp.Integer(0)] * 3
    return Cylinder(radius=radius, length=length, axis=sp.ImmutableMatrix(unit),
                    start=sp.ImmutableMatrix(start))


def still_water() -> Fluid:
    """Still fresh water: density 1000 kg/m^3, no current (a ``fluid`` block's defaults)."""
    return Fluid(density=sp.Integer(1000), current=sp.ImmutableMatrix([sp.Integer(0)] * 3))


def fluid_of(robot: Robot) -> Fluid | None:
    """The robot's :class:`Fluid`; None when it has neither a ``fluid`` nor any ``hydro`` block.

    A robot with hydro data and no ``fluid`` block works in still fresh water
    (:func:`still_water`).
    """
    if robot.fluid is not None:
        return robot.fluid
    return None if all(link.hydro is None for link in robot.links) else still_water()


def hydro_of(robot: Robot) -> tuple[LinkHydro | None, ...]:
    """Each link's :class:`LinkHydro` (None for a link without a ``hydro`` block), length n."""
    return tuple(link.hydro for link in robot.links)


def with_values(hydro: LinkHydro, values: Mapping[str, float]) -> LinkHydro:
    """``hydro`` (not modified) with coefficients or the volume set to numbers, as a ``hydro``
    block giving them would read (``{"drag": 0.8}``, ``{"volume": 0.0}``)."""
    unknown = [k for k in values if k not in (*HYDRO_DEFAULTS, "volume")]
    if unknown:
        raise DescriptionError(f"hydro values: unknown {', '.join(map(repr, unknown))} (allowed: "
                               f"{', '.join((*HYDRO_DEFAULTS, 'volume'))})")
    return dataclasses.replace(hydro, **{k: sp.Float(float(v)) for k, v in values.items()})


def with_current(fluid: Fluid, current: Sequence[float]) -> Fluid:
    """``fluid`` (not modified) with the current velocity ``current`` (3,), m/s, base frame."""
    return dataclasses.replace(fluid, current=sp.ImmutableMatrix([sp.Float(float(c)) for c in current]))
