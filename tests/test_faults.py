"""Fault kinds as objects: what each kind delivers or measures, its correction, its checks, the registries."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import FaultError, IdentifiabilityError
from uvsym.faults import (
    ACTUATOR_KINDS,
    SENSOR_KINDS,
    ActuatorFault,
    Profile,
    SensorFault,
    actuator_kind,
    apply_actuator_faults,
    apply_sensor_faults,
    sensor_kind,
)

# (kind, value, command, delivered), worked out by hand from Definition 1
DELIVERED = [
    ("proportional", 0.8, 50.0, 40.0),
    ("proportional", 0.8, -12.5, -10.0),
    ("bias", 13.0, 50.0, 63.0),
    ("bias", -0.05, 0.2, 0.15),
    ("constant", 2.5, 50.0, 2.5),
    ("constant", 2.5, -7.0, 2.5),
    ("loss_of_effectiveness", 0.3, 50.0, 35.0),
    ("loss_of_effectiveness", 1.0, 50.0, 0.0),
]


@pytest.mark.parametrize("kind, value, command, delivered", DELIVERED)
def test_each_actuator_kind_delivers_its_definition(kind, value, command, delivered):
    assert actuator_kind(kind).deliver(command, value) == pytest.approx(delivered, abs=1e-12)


@pytest.mark.parametrize("kind, value, command, delivered", DELIVERED)
def test_actuator_kinds_are_symbolic_and_injected_from_the_onset(kind, value, command, delivered):
    v = ca.SX.sym("v")
    symbolic = ca.Function("deliver", [v], [actuator_kind(kind).deliver(v, value)])
    assert float(symbolic(command)) == pytest.approx(delivered, abs=1e-12)
    fault = (ActuatorFault(1, kind, value, Profile("step", onset=2.0)),)
    u = ca.DM([3.0, command])
    np.testing.assert_allclose(np.asarray(apply_actuator_faults(u, 1.0, fault)).ravel(), [3.0, command])
    np.testing.assert_allclose(np.asarray(apply_actuator_faults(u, 2.0, fault)).ravel(), [3.0, delivered],
                               atol=1e-12)


@pytest.mark.parametrize("kind, value", [("proportional", 0.7), ("proportional", -1.3), ("bias", 13.0),
                                         ("bias", -0.05), ("loss_of_effectiveness", 0.25)])
def test_correction_undoes_the_fault(kind, value):
    faulty = actuator_kind(kind)
    scale, offset = faulty.correction(value)
    for wanted in (40.0, -3.0, 0.0, 1e-3):
        assert faulty.deliver(scale * wanted + offset, value) == pytest.approx(wanted, rel=1e-12, abs=1e-12)


def test_a_fault_that_ignores_the_command_cannot_be_corrected_in_place():
    assert actuator_kind("constant").correction(4.0) is None
    with pytest.raises(IdentifiabilityError, match="proportional fault of 0.0"):
        actuator_kind("proportional").correction(0.0)


@pytest.mark.parametrize("kind, value, command, delivered", DELIVERED[:-1])
def test_identification_recovers_the_value(kind, value, command, delivered):
    assert actuator_kind(kind).identify(delivered, command) == pytest.approx(value, rel=1e-12)


def test_a_scaling_fault_cannot_be_sized_at_zero_command():
    with pytest.raises(IdentifiabilityError, match="desired value is zero"):
        actuator_kind("proportional").identify(3.0, 0.0)
    assert actuator_kind("bias").identify(3.0, 0.0) == 3.0


def test_healthy_value_severity_and_unit():
    for name, healthy in (("proportional", 1.0), ("bias", 0.0), ("loss_of_effectiveness", 0.0)):
        assert actuator_kind(name).healthy == healthy
        assert actuator_kind(name).deliver(17.0, healthy) == 17.0
    assert actuator_kind("constant").healthy is None
    assert actuator_kind("proportional").severity(0.8) == pytest.approx(0.2)
    assert actuator_kind("bias").severity(-3.0) == 3.0
    assert actuator_kind("loss_of_effectiveness").severity(0.4) == 0.4
    assert actuator_kind("constant").severity(5.0, command=7.0) == 2.0
    with pytest.raises(FaultError, match="constant"):
        actuator_kind("constant").severity(5.0)
    units = {name: kind.unit("N") for name, kind in ACTUATOR_KINDS.items()}
    assert units == {"proportional": "-", "bias": "N", "constant": "N", "loss_of_effectiveness": "-"}


@pytest.mark.parametrize("lookup, registry, target", [(actuator_kind, ACTUATOR_KINDS, "actuator"),
                                                      (sensor_kind, SENSOR_KINDS, "sensor")])
def test_unknown_kind_names_itself_and_lists_the_known_ones(lookup, registry, target):
    with pytest.raises(FaultError) as info:
        lookup("wobble")
    message = str(info.value)
    assert f"unknown {target} fault kind 'wobble'" in message
    assert all(name in message for name in registry)
    with pytest.raises(FaultError, match="unknown actuator fault kind 'stuck'"):
        ActuatorFault(0, "stuck", 1.0)
    with pytest.raises(FaultError, match="unknown sensor fault kind 'proportional'"):
        SensorFault(0, "proportional", 1.0)


@pytest.mark.parametrize("value", [-0.1, 1.5])
def test_loss_of_effectiveness_outside_0_1_is_refused(value):
    with pytest.raises(FaultError, match=rf"loss_of_effectiveness fault value must be in \[0, 1\], got {value}"):
        ActuatorFault(0, "loss_of_effectiveness", value)


def test_bounds_and_finiteness_are_checked():
    for value in (0.5, 1.0):
        ActuatorFault(0, "loss_of_effectiveness", value)
    for kind, value in (("loss_of_effectiveness", 0.0), ("bias", 0.0), ("proportional", 1.0)):
        with pytest.raises(FaultError, match=f"a {kind} actuator fault of {value!r} changes nothing"):
            ActuatorFault(0, kind, value)
    for kind in ("bias", "drift", "noise", "uniform_noise"):
        with pytest.raises(FaultError, match=f"a {kind} sensor fault of 0 changes nothing"):
            SensorFault(0, kind)
    assert SensorFault(0, "stuck").value == 0.0  # stuck holds the last measurement: its value is not used
    for value in (math.nan, math.inf, "13"):
        with pytest.raises(FaultError, match="bias fault value must be a finite number"):
            ActuatorFault(0, "bias", value)
    with pytest.raises(FaultError, match="sensor noise fault value must be in"):
        SensorFault(0, "noise", -0.2)


def _measure(fault: SensorFault, y, t, held, noise):
    y_f, held_next = apply_sensor_faults(ca.DM(y), t, (fault,), ca.DM(held), ca.DM(noise))
    return np.asarray(y_f).ravel(), np.asarray(held_next).ravel()


@pytest.mark.parametrize("kind, value, expected", [
    ("bias", 0.2, 2.2),  # y + 0.2
    ("drift", 0.1, 2.25),  # y + 0.1 * (3.5 - 1.0)
    ("noise", 0.5, 3.0),  # y + 0.5 * 2.0
])
def test_each_sensor_kind_measures_its_definition(kind, value, expected):
    fault = SensorFault(1, kind, value, Profile("step", onset=1.0))
    before, _ = _measure(fault, [5.0, 2.0], 0.5, [0.0, 0.0], [0.0, 2.0])
    after, held = _measure(fault, [5.0, 2.0], 3.5, [0.0, 0.0], [0.0, 2.0])
    np.testing.assert_allclose(before, [5.0, 2.0])
    np.testing.assert_allclose(after, [5.0, expected], rtol=1e-12)
    np.testing.assert_allclose(held, [5.0, 2.0])  # only stuck sensors latch


def test_stuck_sensor_latches_the_last_healthy_sample():
    fault = SensorFault(0, "stuck", profile=Profile("step", onset=1.0))
    held = np.zeros(1)
    measured = []
    for k, t in enumerate(np.arange(0.0, 2.0, 0.25)):
        y, held = _measure(fault, [10.0 + k], t, held, [0.0])
        measured.append(y[0])
    # 10, 11, 12, 13 before t = 1 s; from then on the sample at t = 0.75 s (13) for ever
    assert measured == [10.0, 11.0, 12.0, 13.0, 13.0, 13.0, 13.0, 13.0]


def test_registries_round_trip_and_are_read_only():
    for name, kind in ACTUATOR_KINDS.items():
        assert actuator_kind(name) is kind and kind.name == name
        assert ActuatorFault(0, name, 0.5).kind_object is kind
    for name, kind in SENSOR_KINDS.items():
        assert sensor_kind(name) is kind and kind.name == name
        assert SensorFault(0, name, 0.5).kind_object is kind
    assert set(ACTUATOR_KINDS) == {"proportional", "bias", "constant", "loss_of_effectiveness"}
    assert set(SENSOR_KINDS) == {"bias", "drift", "stuck", "noise", "uniform_noise"}
    with pytest.raises(TypeError):
        ACTUATOR_KINDS["wobble"] = ACTUATOR_KINDS["bias"]


def test_a_kind_with_a_fixed_offset_is_identified_and_corrected_through_its_four_numbers():
    """deliver(v, f) = v + 2 + f (gain (1, 0), shift (2, 1)): f = delivered - v - 2, and the command v - 2 - f
    delivers v; no kind in the registry has an s0, so this one is made here."""
    from uvsym.faults import ActuatorKind

    offset = ActuatorKind("offset", (-math.inf, math.inf), gain=(1.0, 0.0), shift=(2.0, 1.0), healthy=-2.0)
    assert offset.deliver(5.0, 3.0) == 10.0
    assert offset.identify(10.0, 5.0) == 3.0
    assert offset.correction(3.0) == (1.0, -5.0)


def test_a_gain_at_the_tolerance_leaves_nothing_to_correct():
    with pytest.raises(IdentifiabilityError, match="proportional fault of 1e-09 leaves the command no effect"):
        actuator_kind("proportional").correction(1e-9)
    assert actuator_kind("proportional").correction(2e-9) == (pytest.approx(5e8), 0.0)


def test_uniform_noise_maps_standard_normal_draws_into_its_bound():
    """erf(n / sqrt 2) of a standard normal n is uniform in [-1, 1]: the quartiles of n (+-0.6745) land at
    +-1/2, the median at 0, and no draw leaves the bound."""
    kind = sensor_kind("uniform_noise")
    assert kind.noise and sensor_kind("noise").noise and not sensor_kind("bias").noise
    for n, expected in ((0.0, 0.0), (0.6744897501960817, 0.5), (-0.6744897501960817, -0.5), (40.0, 1.0)):
        assert float(kind.measure(1.0, 0.2, 0.0, 0.0, 0.0, n)) == pytest.approx(1.0 + 0.2 * expected, abs=1e-12)
