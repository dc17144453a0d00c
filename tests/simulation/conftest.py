"""Compiled models shared by the simulation tests (each compiled once per session; cached on disk)."""

from __future__ import annotations

import dataclasses
import warnings

import pytest

import robodyn as rd

PENDULUM_YAML = """
name: pendulum
description: single uniform rod swinging in a vertical plane (constant mass matrix)
parameters: {m: 1.0, l: 1.0, g: 9.81}
gravity: [0, -g, 0]
joints:
  - name: q1
    type: revolute
    dh: {a: l, alpha: 0, d: 0, theta: 0}
    link:
      name: rod
      mass: m
      com: [-l/2, 0, 0]
      inertia: {ixx: 0, iyy: m*l**2/12, izz: m*l**2/12, ixy: 0, ixz: 0, iyz: 0}
"""


@pytest.fixture(scope="session")
def trolley():
    return rd.compile_model(rd.load("trolley_double_pendulum"))


@pytest.fixture(scope="session")
def planar():
    return rd.compile_model(rd.load("planar_2r"))


@pytest.fixture(scope="session")
def aa300():
    return rd.compile_model(rd.load("aa300"))


@pytest.fixture(scope="session")
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rd.compile_model(rd.load("puma560"))


@pytest.fixture(scope="session")
def puma_rigid():
    """The PUMA 560 without friction (rigid body + rotor inertia): Coulomb friction is a step in
    the velocity that no sampled controller can cancel exactly."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    joints = tuple(dataclasses.replace(j, friction=rd.Friction()) for j in robot.joints)
    return rd.compile_model(dataclasses.replace(robot, joints=joints))


@pytest.fixture(scope="session")
def pendulum(tmp_path_factory):
    path = tmp_path_factory.mktemp("robots") / "pendulum.yaml"
    path.write_text(PENDULUM_YAML)
    return rd.compile_model(rd.load(path))
