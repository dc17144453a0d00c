"""Assemble a :class:`~robodyn.robot.model.Robot` from a chain that may contain fixed joints.

Loaders describe the chain element by element (joint + the link it carries); fixed joints are
merged here: the fixed link's mass and inertia are added to the link it is welded to, and its
transform is folded into the next joint's ``pre`` (or into the tool frame after the last joint,
or dropped into the base when it comes before the first moving joint, where its mass is carried
by the ground).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.errors import InputError
from robodyn.robot.model import IDENTITY4, Joint, Link, Robot


@dataclass(frozen=True)
class ChainElement:
    """One joint of a description with the link it carries, before fixed joints are merged.

    ``joint_type`` is "revolute", "prismatic" or "fixed"; ``joint_fields`` are passed to
    :class:`Joint` (limits, drive, friction, convention, source_params).
    """

    joint_name: str
    joint_type: str
    pre: sp.ImmutableMatrix
    axis: sp.ImmutableMatrix
    post: sp.ImmutableMatrix
    link: Link
    joint_fields: Mapping[str, Any] = field(default_factory=dict)


def combine_links(parent: Link, child: Link, t: sp.ImmutableMatrix) -> Link:
    """Rigidly attach ``child`` (frame placed by ``t`` in ``parent``'s frame) to ``parent``.

    Returns the combined link in the parent frame, shape conventions as :class:`Link`.
    """
    r, p = S.rotation(t), S.translation(t)
    m_a, m_b = parent.mass, child.mass
    c_a = parent.com
    c_b = r * child.com + p
    m = m_a + m_b
    # com = (m_a c_a + m_b c_b) / m  (zero when the total mass is zero)
    com = (m_a * c_a + m_b * c_b) / m if m != 0 else sp.zeros(3, 1)

    def shift(mass: sp.Expr, d: sp.Matrix) -> sp.Matrix:
        # parallel axis: m (|d|^2 I - d d^T)
        return mass * ((d.T * d)[0, 0] * sp.eye(3) - d * d.T)

    inertia = parent.inertia + shift(m_a, c_a - com) + r * child.inertia * r.T + shift(m_b, c_b - com)
    return Link(
        name=parent.name,
        mass=sp.simplify(m) if m.free_symbols else m,
        com=sp.ImmutableMatrix(com.applyfunc(_tidy)),
        inertia=sp.ImmutableMatrix(inertia.applyfunc(_tidy)),
        hydro=parent.hydro,
    )


def _tidy(e: sp.Expr) -> sp.Expr:
    """Cheap normalisation of a combined inertial quantity."""
    e = sp.sympify(e)
    return e if not e.free_symbols else sp.cancel(e)


def assemble(
    name: str,
    elements: Sequence[ChainElement],
    *,
    base: sp.ImmutableMatrix = IDENTITY4,
    tool: sp.ImmutableMatrix = IDENTITY4,
    gravity: sp.ImmutableMatrix | None = None,
    parameters: Mapping[str, float] | None = None,
    source: str = "<memory>",
) -> Robot:
    """Merge fixed joints and build the immutable :class:`Robot`.

    Parameters
    ----------
    elements : sequence of ChainElement
        Base outwards.
    base, tool : (4, 4) transforms
        Base pose in the world and tool pose in the frame of the last element's link.
    """
    joints: list[Joint] = []
    links: list[Link] = []
    pending = sp.ImmutableMatrix(sp.eye(4))  # fixed transform not yet folded into a joint
    base_acc = sp.ImmutableMatrix(base)
    for el in elements:
        if el.joint_type == "fixed":
            t = sp.ImmutableMatrix(el.pre * el.post)
            if links:
                links[-1] = combine_links(links[-1], el.link, sp.ImmutableMatrix(pending * t))
                pending = sp.ImmutableMatrix(pending * t)
            else:
                base_acc = sp.ImmutableMatrix(base_acc * t)
            continue
        fields = dict(el.joint_fields)
        joints.append(
            Joint(
                name=el.joint_name,
                type=el.joint_type,  # type: ignore[arg-type]
                pre=sp.ImmutableMatrix(pending * el.pre),
                axis=el.axis,
                post=el.post,
                **fields,
            )
        )
        links.append(el.link)
        pending = sp.ImmutableMatrix(sp.eye(4))
    if not joints:
        raise InputError(f"{source}: robot {name!r} has no moving joint")
    kwargs: dict[str, Any] = {}
    if gravity is not None:
        kwargs["gravity"] = gravity
    return Robot(
        name=name,
        joints=tuple(joints),
        links=tuple(links),
        base=base_acc,
        tool=sp.ImmutableMatrix(pending * tool),
        parameters=dict(parameters or {}),
        source=source,
        **kwargs,
    )


def with_parameters(robot: Robot, values: Mapping[str, float]) -> Robot:
    """A copy of ``robot`` with new default values for some named parameters."""
    unknown = set(values) - set(robot.parameters)
    if unknown:
        raise InputError(f"{robot.source}: unknown parameter(s) {sorted(unknown)}")
    merged = {**robot.parameters, **{k: float(v) for k, v in values.items()}}
    return replace(robot, parameters=merged)
