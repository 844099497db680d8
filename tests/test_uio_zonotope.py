"""The quadrotor UIO-bank study: its plant, the paper's failing set-up, scenarios run by uvsym simulate."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from derivations.uio_zonotope import DERIVATION
from derivations.uio_zonotope.design import ATTITUDE, DT, sampled
from derivations.uio_zonotope.scenario import parse, simulate
from uvsym.errors import ScenarioError, UIOConditionError
from uvsym.observers.uio import uio_conditions


def test_sampled_plant_is_the_zero_order_hold_of_the_hover_model():
    """Hand ZOH of the double integrators: G = I + dt A (A^2 = 0), H = dt B + dt^2/2 A B."""
    plant, G, H, _ = sampled()
    from derivations.uio_zonotope.design import linear_plant

    lin = linear_plant().linearize()
    assert plant.dt == DT
    np.testing.assert_allclose(lin.A @ lin.A, 0, atol=1e-15)
    np.testing.assert_allclose(G, np.eye(8) + DT * lin.A, atol=1e-14)
    np.testing.assert_allclose(H, DT * lin.B + DT ** 2 / 2 * lin.A @ lin.B, rtol=1e-12, atol=1e-16)


def test_angle_only_set_up_fails_at_the_sampling_zero():
    _, G, _, D1 = sampled(ATTITUDE)
    with pytest.raises(UIOConditionError) as info:
        uio_conditions(G, np.eye(6)[:3], D1)
    assert any(abs(v + 1) < 1e-6 for v in info.value.eigenvalues)


def test_shipped_scenarios_parse_and_bad_fields_are_named():
    assert set(DERIVATION.scenarios) == {"abrupt_actuator1", "drift_actuator2"}
    for path in DERIVATION.scenarios.values():
        table = tomllib.loads(path.read_text())
        assert table.pop("study") == "uio-zonotope"
        parse(table)
    good = {"samples": 100, "fault": {"actuator": "Vf", "kind": "abrupt", "size": 10.0, "onset": 50}}
    for field, table in (("fault.kind", {**good, "fault": {**good["fault"], "kind": "wobble"}}),
                         ("fault.actuator", {**good, "fault": {**good["fault"], "actuator": "V9"}}),
                         ("fault.onset", {**good, "fault": {**good["fault"], "onset": 100}}),
                         ("fault.size", {**good, "fault": {**good["fault"], "size": float("nan")}}),
                         ("samples", {**good, "samples": 1.5}),
                         ("colour", {**good, "colour": "red"})):
        with pytest.raises(ScenarioError, match=field.replace(".", r"\.")):
            parse(table)
    with pytest.raises(ScenarioError, match="method"):
        simulate(good, method="cvodes")


def test_abrupt_fault_alarms_every_observer_but_the_decoupling_one():
    result = simulate({"samples": 80, "seed": 3, "fault": {"actuator": "Vr", "kind": "abrupt", "size": 10.0,
                                                           "onset": 40}}, name="test")
    assert result.t.shape == (80,)
    for name in ("uio_Vf", "uio_Vb", "uio_Vr", "uio_Vl"):
        alarm = result[f"alarm/{name}"]["alarm"]
        assert not alarm[:40].any()
        assert alarm[40:44].any() == (name != "uio_Vr")
    inside = (result["r/uio_Vr"].values >= result["lower/uio_Vr"].values) & \
        (result["r/uio_Vr"].values <= result["upper/uio_Vr"].values)
    assert inside.all()
