"""Boundaries of fault kinds and profiles: the zero-effect tolerance of identification, a correction with a gain
other than 1 and a shift, and the instants within the time tolerance of a profile's onset and end.

Expected values follow from the definitions in uvsym.faults' docstrings (deliver(v, f) = gain v + shift; a time
within 1e-9 s of onset or end counts as at it; phi is 0 before onset and after end), computed by hand."""

from __future__ import annotations

import math

import casadi as ca
import pytest

from uvsym.errors import IdentifiabilityError
from uvsym.faults import ActuatorKind, Profile, actuator_kind


def test_a_command_exactly_at_the_zero_tolerance_cannot_size_a_proportional_fault():
    """For proportional, f = delivered / command; a command of 1e-12 (the tolerance, inclusive) is taken as zero."""
    message = "^a proportional fault cannot be sized while the desired value is zero$"
    with pytest.raises(IdentifiabilityError, match=message):
        actuator_kind("proportional").identify(5e-13, 1e-12)
    assert actuator_kind("proportional").identify(1e-12, 2e-12) == pytest.approx(0.5, rel=1e-12)


def test_a_correction_divides_the_shift_by_the_gain():
    """deliver(v, f) = 2 v + f: the command u/2 - f/2 delivers u, so (scale, offset) = (1/2, -f/2) = (0.5, -1.5)
    for f = 3; the command it gives for u = 4 (0.5) delivers 2 * 0.5 + 3 = 4."""
    doubled = ActuatorKind("doubled_bias", (-math.inf, math.inf), gain=(2.0, 0.0), shift=(0.0, 1.0), healthy=None)
    scale, offset = doubled.correction(3.0)
    assert (scale, offset) == (0.5, -1.5)
    assert doubled.deliver(scale * 4.0 + offset, 3.0) == 4.0


def test_a_sample_exactly_one_tolerance_before_onset_is_in():
    """onset 1e-9 s, t = 0: t - onset = -1e-9 exactly, within the 1e-9 s tolerance, so phi = 1 (step)."""
    profile = Profile("step", onset=1e-9)
    assert float(profile.phi(0.0)) == 1.0
    t = ca.SX.sym("t")
    assert float(ca.Function("phi", [t], [profile.phi(t)])(0.0)) == 1.0


def test_a_sample_exactly_one_tolerance_before_the_end_is_at_the_end_and_off():
    """end 1 s: t = 1 - 1e-9 counts as at the end, where phi is already 0; a sample 2e-9 s before the end is on."""
    profile = Profile("step", onset=0.0, end=1.0)
    t = ca.SX.sym("t")
    phi = ca.Function("phi", [t], [profile.phi(t)])
    assert float(phi(1.0 - 1e-9)) == 0.0 and float(profile.phi(1.0 - 1e-9)) == 0.0
    assert float(phi(1.0 - 2e-9)) == 1.0


def test_a_fault_without_an_end_never_switches_off():
    """end = inf: phi stays 1 at any time after onset, even t = inf (no end test that an infinite t could fail)."""
    profile = Profile("step", onset=2.0)
    t = ca.SX.sym("t")
    phi = ca.Function("phi", [t], [profile.phi(t)])
    assert float(phi(math.inf)) == 1.0 and float(profile.phi(math.inf)) == 1.0
    assert float(phi(1e300)) == 1.0 and float(phi(1.0)) == 0.0
