"""Identification of inertial, drive and friction parameters from measured motion (thesis ch. 5).

Public entry point: :func:`identify` (``rd.identify``), returning an :class:`Identification`.
"""

from robodyn.identify.base import BaseRelations, base_relations
from robodyn.identify.friction import FrictionFit, fit_friction, friction_table
from robodyn.identify.jointwise import JointIdentification, identify_joint
from robodyn.identify.payload import Payload
from robodyn.identify.pipeline import identify
from robodyn.identify.preprocess import Preprocess
from robodyn.identify.result import BaseParameters, Identification

__all__ = [
    "BaseParameters",
    "BaseRelations",
    "FrictionFit",
    "Identification",
    "JointIdentification",
    "Payload",
    "Preprocess",
    "base_relations",
    "fit_friction",
    "friction_table",
    "identify",
    "identify_joint",
]
