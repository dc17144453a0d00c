"""Derivation speed and equation cost, against peers measured in the same run.

Prints:
  1. PUMA 560 by Newton-Euler with symbolic inertial parameters: time to tau, M, g, regressor, C,
     and the operation count of its inverse dynamics; compared like with like (also symbolic
     parameters) with SymPyBotics' 512 mul / 454 add and 6.7 s. SymPyBotics is NOT run here: those
     figures were measured once by this project on a machine of the same kind when the targets were
     set (issue 2); they are neither published by SymPyBotics nor re-measured in this run.
  2. PUMA 560 inverse-dynamics operation counts with numeric parameters, compared only with
     CasADi's graph of the same inverse dynamics with numeric parameters (295 mul, 210 add; also
     recorded in issue 2, not measured in this run).
  3. Lagrange and Kane for the PUMA 560 (targets: under 60 s each).
  4. Newton-Euler inverse dynamics for spatial chains of 6, 12 and 30 joints: time and op count
     per joint (the recursive program alone), and the whole model (tau, M by composite rigid
     bodies, g) for reference: M has n(n+1)/2 entries, so that part cannot grow linearly.
  5. sympy.physics.mechanics KanesMethod on a 6-link spatial chain with symbolic inertia against
     robodyn's Kane and Newton-Euler on the same chain, in this run (ratio printed).
  6. Rendering the PUMA 560 equations as text and LaTeX, against deriving them, in this run.

Run: ``.venv/bin/python benchmarks/bench_derivation.py [--quick]``.
"""

from __future__ import annotations

import argparse
import time

import sympy as sp

import robodyn as rd
from robodyn.robot import placement
from robodyn.robot.chain import ChainElement, assemble
from robodyn.robot.model import Link
from robodyn.symbolic import newton_euler as ne
from robodyn.symbolic.kinematics import joint_symbols
from robodyn.symbolic.opcount import cse_op_count
from robodyn.symbolic.program import Program, Recorder

# Peer figures NOT measured in this run (SymPyBotics and CasADi are not dependencies): recorded by
# this project on a machine of the same kind when the benchmark targets were set (issue 2).
SYMPYBOTICS_OPS = (512, 454)  # mul, add: SymPyBotics PUMA 560 inverse dynamics, symbolic parameters
SYMPYBOTICS_SECONDS = 6.7  # SymPyBotics PUMA 560 tau, M, C, g, regressor (+3.3 s base parameters)
CASADI_OPS = (295, 210)  # mul, add: CasADi graph of PUMA 560 inverse dynamics, numeric parameters
PEER_SOURCE = "recorded in issue 2 on a machine of this kind, not measured in this run"


def timed(fn):
    start = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - start


def spatial_chain(n: int, symbolic: bool) -> rd.Robot:
    """A serial chain whose joint axes cycle z, y, x with offsets; symbolic or numeric inertia."""
    axes = ([0, 0, 1], [0, 1, 0], [1, 0, 0])
    elements, params = [], {}
    for i in range(n):
        k = i + 1
        if symbolic:
            names = [f"m{k}", f"c{k}", f"L{k}", f"Ixx{k}", f"Iyy{k}", f"Izz{k}", f"Ixy{k}",
                     f"Ixz{k}", f"Iyz{k}"]
            m, c, length, ixx, iyy, izz, ixy, ixz, iyz = sp.symbols(names, real=True)
            params.update(dict.fromkeys(names, 0.1))
        else:
            m, c, length = 1.0 + 0.1 * k, 0.2, 0.4
            ixx, iyy, izz, ixy, ixz, iyz = 0.02, 0.03, 0.025, 0.001, 0.0, 0.002
        inertia = sp.ImmutableMatrix([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        link = Link(f"link{k}", sp.sympify(m), sp.ImmutableMatrix([0, 0, c]), inertia)
        xyz = [0, 0, 0] if i == 0 else [0, 0, (sp.Symbol(f"L{i}", real=True) if symbolic else 0.4)]
        pre, axis, post = placement.from_origin(xyz, [0, 0, 0], axes[i % 3])
        elements.append(ChainElement(f"j{k}", "revolute", pre, axis, post, link))
        del length
    return assemble(f"chain{n}", elements, parameters=params)


def inverse_dynamics_program(robot: rd.Robot):
    """The recursive Newton-Euler inverse dynamics of ``robot`` as a pruned Program (as derive)."""
    n = robot.dof
    q, qd, qdd = joint_symbols(n)
    rec = Recorder({s.name for s in q + qd + qdd} | set(robot.parameters))
    out = ne.inverse_dynamics(robot, q, qd, qdd, rec)
    return Program(tuple(rec.assignments), out).pruned()


def sympy_kanes_method_chain(n: int) -> float:
    """Seconds for sympy.physics.mechanics.KanesMethod on the same chain, symbolic inertia."""
    import sympy.physics.mechanics as me

    q = me.dynamicsymbols(f"q1:{n + 1}")
    u = me.dynamicsymbols(f"u1:{n + 1}")
    g = sp.Symbol("g")
    frame_n = me.ReferenceFrame("N")
    origin = me.Point("O")
    origin.set_vel(frame_n, 0)
    parent_frame, parent_point = frame_n, origin
    bodies, loads = [], []
    axes = ("Z", "Y", "X")
    for i in range(n):
        k = i + 1
        m, c, length = sp.symbols(f"m{k} c{k} L{k}")
        ixx, iyy, izz, ixy, ixz, iyz = sp.symbols(f"Ixx{k} Iyy{k} Izz{k} Ixy{k} Ixz{k} Iyz{k}")
        axis = getattr(parent_frame, axes[i % 3].lower())
        frame = parent_frame.orientnew(f"B{k}", "Axis", [q[i], axis])
        frame.set_ang_vel(parent_frame, u[i] * axis)
        joint_point = parent_point if i == 0 else parent_point.locatenew(
            f"J{k}", sp.Symbol(f"L{i}") * parent_frame.z)
        joint_point.v2pt_theory(parent_point, frame_n, parent_frame)
        com = joint_point.locatenew(f"C{k}", c * frame.z)
        com.v2pt_theory(joint_point, frame_n, frame)
        dyadic = me.inertia(frame, ixx, iyy, izz, ixy, iyz, ixz)
        bodies.append(me.RigidBody(f"body{k}", com, frame, m, (dyadic, com)))
        loads.append((com, -m * g * frame_n.z))
        parent_frame, parent_point = frame, joint_point
        del length
    kde = [qi.diff() - ui for qi, ui in zip(q, u, strict=True)]
    start = time.perf_counter()
    km = me.KanesMethod(frame_n, q_ind=q, u_ind=u, kd_eqs=kde)
    km.kanes_equations(bodies, loads)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="skip the 30-joint chain and Lagrange")
    args = parser.parse_args()
    puma = rd.load("puma560")

    print("== 1. PUMA 560, Newton-Euler, symbolic inertial parameters ==")
    eom, t_core = timed(lambda: rd.derive(puma, "newton_euler", symbolic_inertia=True))
    _, t_tau = timed(lambda: (eom.tau, eom.M, eom.g))
    _, t_y = timed(lambda: eom.Y)
    _, t_c = timed(lambda: eom.C)
    total = t_core + t_tau + t_y + t_c
    print(f"tau (recursive + expanded), M, g: {t_core + t_tau:.2f} s; regressor: {t_y:.2f} s; "
          f"C (Christoffel): {t_c:.2f} s; complete: {total:.2f} s")
    print(f"  SymPyBotics {SYMPYBOTICS_SECONDS} s (+3.3 s base parameters; {PEER_SOURCE}) -> "
          f"ratio {SYMPYBOTICS_SECONDS / total:.1f}x; target < 2 s for tau, M, g, regressor: "
          f"{t_core + t_tau + t_y:.2f} s")
    sym_rigid = cse_op_count(list(eom.program.outputs), eom.program.assignments)
    print(f"inverse dynamics, symbolic inertial parameters, rigid body, after CSE: "
          f"{sym_rigid.multiplications} mul, {sym_rigid.additions} add, {sym_rigid.functions} functions")
    mul, add = SYMPYBOTICS_OPS
    print(f"  vs SymPyBotics {mul} mul / {add} add (also symbolic parameters; {PEER_SOURCE}): "
          f"ratio {mul / sym_rigid.multiplications:.2f}x mul, {add / sym_rigid.additions:.2f}x add")

    print("\n== 2. PUMA 560 inverse dynamics op counts (numeric parameters, after CSE) ==")
    eom_num = rd.derive(puma, "newton_euler")
    rigid = cse_op_count(list(eom_num.program.outputs), eom_num.program.assignments)
    full = eom_num.op_counts()["tau"]
    print(f"robodyn rigid-body: {rigid.multiplications} mul, {rigid.additions} add, "
          f"{rigid.functions} functions")
    print(f"robodyn full (rotor + friction): {full.multiplications} mul, {full.additions} add, "
          f"{full.functions} functions")
    mul, add = CASADI_OPS
    print(f"  vs CasADi's numeric graph {mul} mul / {add} add ({PEER_SOURCE}): ratio "
          f"{mul / rigid.multiplications:.2f}x mul, {add / rigid.additions:.2f}x add "
          "(SymPyBotics' figure is for symbolic parameters: compared in section 1 only)")

    print("\n== 3. PUMA 560, Lagrange and Kane (target < 60 s each) ==")
    for method in (("kane",) if args.quick else ("kane", "lagrange")):
        e, t = timed(lambda m=method: rd.derive(puma, m))
        print(f"{method}: {t:.2f} s (M, g, tau)")

    print("\n== 4. Newton-Euler on spatial chains (numeric inertia): linear growth ==")
    sizes = (6, 12) if args.quick else (6, 12, 30)
    previous = None
    for n in sizes:
        robot = spatial_chain(n, symbolic=False)
        prog, t = timed(lambda r=robot: inverse_dynamics_program(r))
        ops = cse_op_count(list(prog.outputs), prog.assignments)
        _, t_all = timed(lambda r=robot: rd.derive(r, "newton_euler"))
        print(f"n={n:3d}: inverse dynamics {t:6.2f} s ({t / n * 1e3:5.1f} ms/joint); "
              f"{ops.multiplications} mul ({ops.multiplications / n:.1f}/joint), {ops.additions} add "
              f"({ops.additions / n:.1f}/joint); whole model (tau, M, g) {t_all:6.2f} s")
        if previous is not None:
            # marginal cost of the joints added since the previous size: constant if linear
            n0, t0, m0 = previous
            print(f"        joints {n0 + 1}-{n}: {(t - t0) / (n - n0) * 1e3:5.1f} ms and "
                  f"{(ops.multiplications - m0) / (n - n0):.1f} mul per added joint")
        previous = (n, t, ops.multiplications)

    print("\n== 5. 6-link spatial chain, symbolic inertia: sympy KanesMethod vs robodyn ==")
    chain = spatial_chain(6, symbolic=True)
    t_sympy = sympy_kanes_method_chain(6)
    _, t_kane = timed(lambda: rd.derive(chain, "kane"))
    _, t_ne = timed(lambda: rd.derive(chain, "newton_euler"))
    print(f"sympy KanesMethod: {t_sympy:.2f} s; robodyn kane: {t_kane:.2f} s "
          f"(ratio {t_sympy / t_kane:.1f}x); robodyn newton_euler: {t_ne:.2f} s "
          f"(ratio {t_sympy / t_ne:.1f}x)")

    print("\n== 6. PUMA 560 equations rendered as text and LaTeX (numeric parameters) ==")
    from robodyn.symbolic.render import render_latex, render_text

    _, t_derive = timed(lambda: rd.derive(puma, "newton_euler"))
    _, t_text = timed(lambda: render_text(eom_num))
    _, t_tex = timed(lambda: render_latex(eom_num))
    print(f"render_text {t_text:.2f} s, render_latex {t_tex:.2f} s; deriving the same equations "
          f"{t_derive:.2f} s in this run (rendering / deriving {(t_text + t_tex) / t_derive:.1f}x)")


if __name__ == "__main__":
    main()
