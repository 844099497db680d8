"""Fault time profiles at their boundaries (onset, end, period, duty), against values worked out by
hand from the definitions phi(t) = 0 before the onset and from the end on, else: step 1; ramp
min((t - onset) / duration, 1); incipient 1 - exp(-rate (t - onset)); intermittent 1 for the first
duty * period of every period after the onset."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import FaultError
from uvsym.faults import TIME_TOLERANCE, ActuatorFault, Profile, SensorFault, apply_actuator_faults, apply_sensor_faults


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


@pytest.mark.parametrize("profile, t, expected", [
    (Profile("ramp", onset=1.0, duration=4.0, end=3.0), 2.999, 1.999 / 4.0),  # cut off half-way up the ramp
    (Profile("ramp", onset=1.0, duration=4.0, end=3.0), 3.0, 0.0),
    (Profile("incipient", onset=1.0, rate=2.0, end=2.0), 1.5, 1.0 - math.exp(-1.0)),
    (Profile("incipient", onset=1.0, rate=2.0, end=2.0), 2.0, 0.0),
    (Profile("intermittent", onset=0.0, period=2.0, duty=0.75, end=1.0), 0.999, 1.0),  # ends while on
    (Profile("intermittent", onset=0.0, period=2.0, duty=0.75, end=1.0), 1.0, 0.0),
    (Profile("intermittent", onset=0.0, period=2.0, duty=0.75, end=9.0), 3.499, 1.0),  # 2 + 0.75 * 2 = 3.5
    (Profile("intermittent", onset=0.0, period=2.0, duty=0.75, end=9.0), 3.5, 0.0),
    (Profile("intermittent", onset=0.0, period=2.0, duty=0.75, end=9.0), 4.0, 1.0),  # the third period
])
def test_every_profile_stops_at_its_end(profile, t, expected):
    assert phi(profile, t) == pytest.approx(expected, rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("kind, value, delivered", [
    ("proportional", 0.8, 10.0 * (1 + 0.5 * (0.8 - 1))),  # half-way up the ramp: v + phi (f v - v)
    ("bias", 13.0, 10.0 + 0.5 * 13.0),
    ("constant", 2.0, 10.0 + 0.5 * (2.0 - 10.0)),
    ("loss_of_effectiveness", 0.3, 10.0 * (1 - 0.5 * 0.3)),
])
def test_each_actuator_kind_is_blended_in_by_its_profile(kind, value, delivered):
    fault = ActuatorFault(0, kind, value, Profile("ramp", onset=1.0, duration=2.0))
    assert float(apply_actuator_faults(ca.DM([10.0]), 2.0, (fault,))) == pytest.approx(delivered, rel=1e-14)
    assert float(apply_actuator_faults(ca.DM([10.0]), 0.999, (fault,))) == 10.0


def test_two_faults_on_one_actuator_apply_in_order():
    faults = (ActuatorFault(0, "proportional", 0.5), ActuatorFault(0, "bias", 3.0))
    assert float(apply_actuator_faults(ca.DM([10.0, 1.0]), 0.0, faults)[0]) == 0.5 * 10.0 + 3.0
    assert float(apply_actuator_faults(ca.DM([10.0, 1.0]), 0.0, faults[::-1])[0]) == 0.5 * (10.0 + 3.0)


@pytest.mark.parametrize("kind, value, expected", [
    ("bias", 0.4, 5.0 + 0.5 * 0.4),
    ("drift", 0.2, 5.0 + 0.5 * 0.2 * (2.0 - 1.0)),  # drift measured from the onset, not from t = 0
    ("noise", 0.3, 5.0 + 0.5 * 0.3 * -2.0),
])
def test_each_sensor_kind_is_blended_in_by_its_profile(kind, value, expected):
    fault = SensorFault(0, kind, value, Profile("ramp", onset=1.0, duration=2.0))
    measured, held = apply_sensor_faults(ca.DM([5.0]), 2.0, (fault,), ca.DM([-7.0]), ca.DM([-2.0]))
    assert float(measured) == pytest.approx(expected, rel=1e-14) and float(held) == 5.0


def test_a_stuck_sensor_holds_until_the_end_and_measures_again_after():
    fault = SensorFault(0, "stuck", profile=Profile("step", onset=1.0, end=2.0))
    measured = [apply_sensor_faults(ca.DM([v]), t, (fault,), ca.DM([4.0]), ca.DM([0.0]))
                for t, v in ((0.5, 3.0), (1.0, 9.0), (1.999, 9.5), (2.0, 10.0))]
    assert [(float(y), float(h)) for y, h in measured] == [(3.0, 3.0), (4.0, 4.0), (4.0, 4.0), (10.0, 10.0)]


@pytest.mark.parametrize("make, message", [
    (lambda: apply_actuator_faults(ca.DM([1.0, 2.0]), 0.0, (ActuatorFault(2, "bias", 1.0),)),
     "actuator index 2 is out of range for 2 actuators"),
    (lambda: apply_sensor_faults(ca.DM([1.0]), 0.0, (SensorFault(1, "bias", 1.0),), ca.DM([0.0]), ca.DM([0.0])),
     "measured output index 1 is out of range for 1 measured outputs"),
    (lambda: ActuatorFault(True, "bias", 1.0), "fault actuator must be an integer index"),
    (lambda: SensorFault(0.0, "bias", 1.0), "fault channel must be an integer index"),
    (lambda: Profile("step", onset=-0.1), "onset must be a finite time >= 0 s"),
    (lambda: Profile("step", onset=math.inf), "onset must be a finite time >= 0 s"),
    (lambda: Profile("step", onset=1.0, end=1.0), r"end \(1.0 s\) must be after its onset \(1.0 s\)"),
    (lambda: Profile("ramp", duration=math.inf), "duration must be positive and finite, got inf"),
    (lambda: Profile("incipient", rate=0.0), "rate must be positive and finite, got 0.0"),
    (lambda: Profile("intermittent", period=-1.0), "period must be positive and finite, got -1.0"),
    (lambda: Profile("intermittent", duty=0.0), r"duty must be in \(0, 1\], got 0.0"),
    (lambda: Profile("step", onset=True), "onset must be a number"),
    (lambda: Profile("step", end=math.nan), "end must be a number"),
    (lambda: Profile("sawtooth"), "unknown fault profile 'sawtooth'; known: step, ramp, incipient, intermittent"),
])
def test_fault_definitions_out_of_range_are_refused_by_name(make, message):
    with pytest.raises(FaultError, match=message):
        make()


def test_profile_edges_that_are_allowed():
    assert phi(Profile("intermittent", onset=0.0, period=1.0, duty=1.0), 0.999) == 1.0
    assert phi(Profile("step", onset=0.0), 0.0) == 1.0
    assert phi(Profile("step", onset=3.0, end=math.inf), 1e9) == 1.0


@pytest.mark.parametrize("profile", [
    Profile("step", onset=0.73), Profile("step", onset=0.5, end=1.37),
    Profile("ramp", onset=0.2, duration=0.5, end=2.05),
    Profile("incipient", onset=0.31, rate=4.0), Profile("intermittent", onset=0.25, period=0.3, duty=0.4, end=2.62),
    Profile("intermittent", onset=0.1, period=0.2, duty=1.0)])
def test_jumps_are_the_samples_over_which_phi_is_discontinuous(profile):
    """phi evaluated on a grid 1000 times finer than the samples: a sample holds a jump exactly where two
    neighbouring fine values differ by more than a continuous profile could change over the fine step."""
    dt, N, fine = 0.1, 30, 1000
    t = dt * np.arange(N)
    values = np.asarray(ca.evalf(profile.phi(ca.DM(np.linspace(0.0, N * dt, N * fine + 1))))).ravel()
    steps = np.abs(np.diff(values)) > 0.05  # a ramp or incipient moves at most 4 * 1e-4 per fine step here
    expected = np.array([steps[k * fine:(k + 1) * fine].any() for k in range(N)])
    assert profile.jumps(t, dt).tolist() == expected.tolist()
