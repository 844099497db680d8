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


def test_the_limits_block_states_the_campaigns_figures():
    """Built from fabricated results: each figure of the block is the one given, in one linkless marked block."""
    from derivations.sensor_fdi_lms.text import DETECTOR_NAMES, limits_section
    from uvsym.report import LIMITS_MARKERS

    def item(seen, missed, delay):
        return [{"channel": "psi", "kind": "bias", "sizes": [(1.0, 4, 0), (7.0, 4, 4)], "seen_from": seen,
                 "missed_up_to": missed, "median_delay_s": delay}]

    def healthy(noise, alarms):  # 16 runs, 8 h per noise level
        return {"noise_deg": noise, **{d: {"runs": 16, "healthy_hours": 8.0, "false_alarms": a,
                                           "false_alarms_per_hour": a / 8.0} for d, a in zip(DETECTOR_NAMES, alarms)}}

    def case(detected):
        return {d: {"fault_runs": 5, "missed_detections": 5 - n, "runs": 5, "false_alarms": n}
                for d, n in zip(DETECTOR_NAMES, detected)}

    campaign = {
        "runs": 123, "designed_per_hour": {"double_criterion": None, "error_threshold": 2.5, "step_test": 0.25},
        "bias_limits": [{"noise_deg": 0.5, "double_criterion": item(7.0, 1.0, 0.9),
                         "error_threshold": item(7.0, 1.0, 0.4), "step_test": item(None, 7.0, 1.3)}],
        "healthy_by_noise": [healthy(0.5, (0, 4, 0)), healthy(1.0, (16, 12, 1))],
        "cases": {"set-point changes, no fault": case((9, 8, 0)), "ramp": case((1, 2, 0)), "incipient": case((3, 3, 0)),
                  "drift": case((4, 1, 0)), "stuck": case((0, 0, 0))},
        "pulses": [{"samples": 2, "runs": 6, "double_criterion": 0, "error_threshold": 1, "step_test": 0}]}
    calibrated = {"window": [10, 8, 3], "power": {"sizes": [4.0, 12.0], "smallest_size_reaching": {"0.5": 12.0,
                                                                                                   "0.9": None}}}
    text = limits_section({"R_first_alarm_sample": 74, "campaign": campaign, "calibrated": calibrated})
    heading, block = text.split(LIMITS_MARKERS[0])
    assert heading.startswith("## Limits") and block.count(LIMITS_MARKERS[1]) == 1 and "](" not in block
    assert not any(line.startswith(("# ", "## ")) for line in block.splitlines())
    prose = " ".join(block.split())  # the sentences, whatever their line breaks
    assert "123 runs" in prose and "1, 7 deg, 4 runs per size" in prose
    assert "| 0.5 | psi | 7 deg; 0.9 s | 7 deg; 0.4 s | none (missed at 7 deg); 1.3 s |" in block
    assert "4 samples (0.8 s) after the onset" in prose  # the paper run's confirmation, 74 - 70
    assert "half the steps of 12 noise std (6 deg) and nine in ten of more than 12 noise std" in prose
    assert "0.5 deg and 2 times it" in prose  # the noise levels, as multiples of the study's 0.5 deg
    assert "| 1 | 16 | 16 in 8 h: 2 | 12 in 8 h: 1.5 | 1 in 8 h: 0.125 |" in block
    assert "| designed |  | - | 2.5 | 0.25 |" in block
    assert "at 1 deg every run alarmed" in prose  # 16 alarms of the latching double criterion in 16 runs
    assert "(5 runs) raise these false alarms: double criterion (the paper's): 9, error threshold alone: 8" in prose
    assert "| 2 | 6 | 0 | 1 | 0 |" in block
    assert "ramps (1/5, 2/5, 0/5)" in prose and "drifts (4/5, 1/5, 0/5)" in prose
    assert "stuck compass** (0/5, 0/5, 0/5)" in prose
