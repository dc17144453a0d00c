"""Compiled models shared by the measurement tests (each compiled once per module; cached on disk)."""

from __future__ import annotations

import warnings

import pytest

import robodyn as rd


@pytest.fixture(scope="module")
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the description's plausibility notes
        return rd.compile_model(rd.load("puma560"))


@pytest.fixture(scope="module")
def planar():
    return rd.compile_model(rd.load("planar_2r"))
