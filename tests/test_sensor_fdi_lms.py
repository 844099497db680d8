"""The LMS compass-fault study: the paper's runs (shortened); its scenario files: test_sensor_fdi_lms_scenarios."""

from __future__ import annotations

import numpy as np
import pytest

from derivations.sensor_fdi_lms.design import FAULT_SAMPLE, SET_POINT_DEG, design, heading_gain
from derivations.sensor_fdi_lms.experiment import Run, first_sample, run

SHORT = {"warm_up": 100, "record": 160}
SETTLE = {"warm_up": 100, "record": 320}  # the nonlinear damping makes the loop settle in about 40 s


@pytest.fixture(scope="module")
def fault_run():
    return run(Run(size_deg=30.0, ftc=False, **SETTLE))


def test_both_criteria_fire_at_the_fault_and_the_heading_settles_off_by_the_fault(fault_run):
    k = fault_run.k
    assert first_sample(fault_run.monitor("alarm_eps2_psi"), k) == FAULT_SAMPLE
    assert 71 <= first_sample(fault_run.monitor("alarm_R_psi"), k, FAULT_SAMPLE) <= 80
    # a proportional loop drives the measurement (true + 30 deg) to the set-point: true -> 120 deg
    # (the yaw torque noise moves a 10 s mean by about 1 deg)
    assert np.mean(fault_run.heading_deg()[-50:]) == pytest.approx(SET_POINT_DEG - 30.0, abs=2.0)
    assert np.mean(np.degrees(fault_run.result["y"]["psi"][-50:])) == pytest.approx(SET_POINT_DEG, abs=2.0)


def test_ftc_acts_on_the_substitute_from_the_confirming_sample_and_a_spike_is_a_disturbance():
    ftc = run(Run(size_deg=30.0, **SHORT))
    k = ftc.k
    confirmed = ftc.supervisor.first("R alarm").sample - SHORT["warm_up"]
    assert confirmed == first_sample(ftc.monitor("alarm_R_psi"), k, FAULT_SAMPLE)
    # the controller's reading is the compass before the confirming sample and the frozen filter's
    # substitute from that very sample on; its command is kp (psi_ref - reading) of the same sample
    measured, substitute, used = ftc.result["y"]["psi"], ftc.monitor("psi_sub"), ftc.result["ftc"]["psi_sel"]
    np.testing.assert_array_equal(used[k < confirmed], measured[k < confirmed])
    np.testing.assert_array_equal(used[k >= confirmed], substitute[k >= confirmed])
    assert abs(measured[k == confirmed][0] - substitute[k == confirmed][0]) > np.radians(20.0)  # not the same value
    kp = design().kp
    np.testing.assert_allclose(ftc.result["u"]["u"], np.clip(kp * (np.radians(SET_POINT_DEG) - used), -1, 1),
                               rtol=0, atol=1e-12)
    assert np.array_equal(ftc.substituted(), k >= confirmed)
    spike = run(Run(size_deg=10.0, profile="pulse", **SHORT))
    whats = [e.what for e in spike.supervisor.events if e.sample >= SHORT["warm_up"]]
    assert whats[0].startswith("eps2 alarm") and whats[1].startswith("no R alarm")
    assert not spike.substituted().any()
    np.testing.assert_array_equal(spike.result["ftc"]["psi_sel"], spike.result["y"]["psi"])


def test_heading_gain_sets_the_natural_frequency_of_the_linearised_loop():
    plant = design().plant
    lin = plant.linearize()
    kp = heading_gain(plant, 0.7)
    closed = lin.A - lin.B @ np.array([[kp, 0.0]])
    assert np.prod(np.linalg.eigvals(closed)).real == pytest.approx(0.7 ** 2, rel=1e-9)
