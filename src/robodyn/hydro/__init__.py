"""Hydrodynamics of manipulator links in water (thesis ch. 7): buoyancy, added mass, drag, lift.

Modules, one per effect: :mod:`~robodyn.hydro.schema` (the ``fluid``/``hydro`` description
blocks), :mod:`~robodyn.hydro.geometry` (cylinder kinematics), :mod:`~robodyn.hydro.quadrature`,
:mod:`~robodyn.hydro.buoyancy`, :mod:`~robodyn.hydro.added_mass`, :mod:`~robodyn.hydro.drag`,
:mod:`~robodyn.hydro.lift`, and :mod:`~robodyn.hydro.terms` which assembles them
(``eom.hydro``). Equations: ``docs/underwater.md``.
"""
