"""Fault time profiles at their boundaries (onset, end, period, duty), against values worked out by
hand from the definitions phi(t) = 0 before the onset and from the end on, else: step 1; ramp
min((t - onset) / duration, 1); incipient 1 - exp(-rate (t - onset)); intermittent 1 for the first
duty * period of every period after the onset."""

from __future__ import annotations

import math

import casadi as ca
import pytest

from uvsym.faults import TIME_TOLERANCE, Profile


def phi(profile: Profile, t: float) -> float:
    return float(ca.evalf(profile.phi(ca.DM(t))))


@pytest.mark.parametrize("t, expected", [(1.999, 0.0), (2.0, 1.0), (2.0 - TIME_TOLERANCE / 2, 1.0), (4.999, 1.0),
                                         (5.0, 0.0), (7.0, 0.0)])
def test_a_step_acts_from_its_onset_up_to_its_end(t, expected):
    assert phi(Profile("step", onset=2.0, end=5.0), t) == expected


@pytest.mark.parametrize("t, expected", [(1.0, 0.0), (1.5, 0.25), (2.0, 0.5), (3.0, 1.0), (10.0, 1.0)])
def test_a_ramp_rises_over_its_duration(t, expected):
    assert phi(Profile("ramp", onset=1.0, duration=2.0), t) == pytest.approx(expected, abs=1e-15)


@pytest.mark.parametrize("t", [1.0, 1.5, 2.0, 6.0])
def test_an_incipient_fault_follows_its_exponential(t):
    assert phi(Profile("incipient", onset=1.0, rate=0.8), t) == pytest.approx(1.0 - math.exp(-0.8 * (t - 1.0)),
                                                                               rel=1e-14, abs=1e-15)


@pytest.mark.parametrize("t, expected", [
    (0.99, 0.0),                  # before the onset
    (1.0, 1.0), (1.2, 1.0),       # first period: on for duty * period = 0.25 s (a period of 1 would hide duty * period)
    (1.26, 0.0), (3.4, 0.0),      # off for the rest of the 4 s period
    (5.0, 1.0), (5.24, 1.0),      # second period starts at 1 + 4 = 5 s, on again
    (5.26, 0.0)])
def test_an_intermittent_fault_is_on_for_duty_times_period_of_every_period(t, expected):
    assert phi(Profile("intermittent", onset=1.0, period=4.0, duty=1 / 16), t) == expected


def test_a_full_duty_intermittent_fault_never_switches_off_before_its_end():
    profile = Profile("intermittent", onset=0.5, period=0.3, duty=1.0, end=2.0)
    assert [phi(profile, t) for t in (0.5, 0.79, 0.8, 1.99, 2.0)] == [1.0, 1.0, 1.0, 1.0, 0.0]
