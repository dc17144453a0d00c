"""Identification of inertial, drive and friction parameters from measured motion (thesis ch. 5).

Public entry point: :func:`identify` (``rd.identify``), returning an :class:`Identification`.
"""

from robodyn.identification.base import BaseRelations, base_relations
from robodyn.identification.friction import FrictionFit, fit_friction
from robodyn.identification.friction_comparison import friction_table
from robodyn.identification.jointwise import JointIdentification, identify_joint
from robodyn.identification.options import IdentifyOptions
from robodyn.identification.payload import Payload
from robodyn.identification.pipeline import identify
from robodyn.identification.preprocess import Preprocess
from robodyn.identification.result import BaseParameters, Identification

__all__ = [
    "BaseParameters",
    "BaseRelations",
    "FrictionFit",
    "Identification",
    "IdentifyOptions",
    "JointIdentification",
    "Payload",
    "Preprocess",
    "base_relations",
    "fit_friction",
    "friction_table",
    "identify",
    "identify_joint",
]
