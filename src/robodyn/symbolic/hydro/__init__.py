"""Hydrodynamics of manipulator links in water (thesis ch. 7): buoyancy, added mass, drag, lift.

Part of the symbolic layer: the terms are expressions built from the link kinematics and added to
every formulation's equations; the studies that use them live in :mod:`robodyn.studies`.

Modules, one per effect: :mod:`~robodyn.robot.hydro` (the ``fluid``/``hydro`` description
blocks, parsed), :mod:`.geometry` (cylinder kinematics), :mod:`.quadrature`, :mod:`.buoyancy`,
:mod:`.added_mass`, :mod:`.drag`, :mod:`.lift` (and :mod:`.lift_reach`), :mod:`.textbook`, and
:mod:`.terms` which assembles them
(``eom.hydro``). Equations: ``docs/underwater.md``.
"""
