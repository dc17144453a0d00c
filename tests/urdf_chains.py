"""Random serial URDF chains and Pinocchio configuration vectors, shared by the oracle tests."""

from __future__ import annotations

import numpy as np


def random_urdf(rng: np.random.Generator, n: int) -> str:
    """A serial chain of n moving joints (revolute, prismatic, continuous) plus fixed joints."""

    def vec(scale):
        return " ".join(f"{v:.6f}" for v in rng.uniform(-scale, scale, 3))

    def inertial():
        a = rng.uniform(0.05, 0.5, 3)  # principal moments that satisfy the triangle inequality
        a = np.sort(a)
        a[2] = min(a[2], a[0] + a[1] - 1e-3)
        return (f'<inertial><origin xyz="{vec(0.2)}" rpy="{vec(np.pi)}"/>'
                f'<mass value="{rng.uniform(0.5, 5):.6f}"/>'
                f'<inertia ixx="{a[0]:.6f}" iyy="{a[1]:.6f}" izz="{a[2]:.6f}" '
                f'ixy="0" ixz="0" iyz="0"/></inertial>')

    links = ['<link name="base"/>']
    joints = []
    parent = "base"
    k = 0
    for i in range(n):
        if rng.uniform() < 0.3:  # a fixed joint with a massive link in between
            k += 1
            name = f"fixed_link{k}"
            links.append(f'<link name="{name}">{inertial()}</link>')
            joints.append(f'<joint name="fix{k}" type="fixed"><parent link="{parent}"/>'
                          f'<child link="{name}"/><origin xyz="{vec(0.3)}" rpy="{vec(np.pi)}"/>'
                          f'</joint>')
            parent = name
        jtype = rng.choice(["revolute", "prismatic", "continuous"])
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        name = f"link{i + 1}"
        links.append(f'<link name="{name}">{inertial()}</link>')
        limit = '<limit lower="-3" upper="3" effort="100" velocity="5"/>' if jtype != "continuous" else ""
        joints.append(f'<joint name="j{i + 1}" type="{jtype}"><parent link="{parent}"/>'
                      f'<child link="{name}"/><origin xyz="{vec(0.3)}" rpy="{vec(np.pi)}"/>'
                      f'<axis xyz="{axis[0]:.9f} {axis[1]:.9f} {axis[2]:.9f}"/>{limit}</joint>')
        parent = name
    return f'<robot name="random">{"".join(links)}{"".join(joints)}</robot>'


def pin_q(model, q):
    """Pinocchio configuration vector: continuous joints use (cos, sin)."""
    out = []
    for jid in range(1, model.njoints):
        joint = model.joints[jid]
        qi = q[jid - 1]
        if joint.nq == 2:
            out += [np.cos(qi), np.sin(qi)]
        else:
            out.append(qi)
    return np.array(out)
