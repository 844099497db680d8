"""The calibrated MMAE decisions (``rule = "evidence"``, :class:`uvsym.diagnosis.hypotheses.EvidenceSwitch`):
thresholds from the designed false-alarm rate, release after a loss ends, ``unexplained`` for two
lost thrusters, on short runs of the FUKF-MMAE study's scenario (UKF bank only)."""

import numpy as np
import pytest
from scipy.stats import chi2

from derivations.usv_fukf_mmae import experiment
from derivations.usv_fukf_mmae.scenario import parsed, read
from uvsym.diagnosis.hypotheses import EvidenceSwitch
from uvsym.errors import DiagnosisError, ScenarioError

MODELS = (("nofault", ()), ("left", ("T_L",)), ("right", ("T_R",)))


def test_thresholds_follow_from_the_designed_rate_and_the_sample_period():
    d = EvidenceSwitch("d", "bank", MODELS, dt=0.05, n_y=6, false_alarms_per_hour=1.0, nis_window=20)
    a = 1.0 * 0.05 / 3600.0 / 2.0  # per sample and test: half of one alarm per hour at 20 samples per second
    assert d.budget == pytest.approx(a)
    assert np.exp(-d.cusum_threshold) * 2 == pytest.approx(a)  # Lorden: two fault models, ARL >= e^h each
    assert chi2.sf(d.nis_threshold, 120) == pytest.approx(a, rel=1e-6)
    slower = EvidenceSwitch("d", "bank", MODELS, dt=0.5, n_y=6, false_alarms_per_hour=1.0)
    assert slower.cusum_threshold == pytest.approx(d.cusum_threshold - np.log(10.0))
    with pytest.raises(DiagnosisError, match="false_alarms_per_hour"):
        EvidenceSwitch("d", "bank", MODELS, dt=0.05, n_y=6, false_alarms_per_hour=-1.0)
    with pytest.raises(DiagnosisError, match="clear_window"):
        EvidenceSwitch("d", "bank", MODELS, dt=0.05, n_y=6, clear_window=0)


def _run(faults, duration, **detector):
    table = read()
    table.update(duration=duration, faults=faults)
    table["blocks"] = [b for b in table["blocks"] if b["name"] != "ekf"]
    table["detectors"] = [{"type": "mmae", "name": "ev", "bank": "ukf", "rule": "evidence", "ignore_before": 5.0,
                           **detector}]
    return [(e["t"], e["event"], e["target"]) for e in experiment.run(parsed(table)).events
            if e["event"] != "identified"]


def _loss(thruster, value, onset, end):
    return {"actuator": thruster, "kind": "proportional", "value": value, "onset": onset, "end": end}


@pytest.mark.parametrize("thruster, value", [("T_L", 0.9), ("T_R", 0.7)])
def test_a_loss_is_isolated_and_released_within_5_s_of_its_end(thruster, value):
    events = _run([_loss(thruster, value, 20.0, 40.0)], 60.0)
    alarms = [e for e in events if e[1] in ("detected", "isolated")]
    assert alarms and all(20.0 <= t < 40.0 and target == thruster for t, _, target in alarms)
    last = max(t for t, event, _ in events if event in ("detected", "isolated", "unexplained"))
    cleared = [t for t, event, _ in events if event == "cleared" and t >= last]
    assert cleared and cleared[-1] <= 45.0  # back to no fault within 5 s


def test_both_thrusters_at_half_are_unexplained_not_one_culprit():
    events = _run([_loss("T_L", 0.5, 20.0, 60.0), _loss("T_R", 0.5, 20.0, 60.0)], 60.0)
    assert ("unexplained" in [e[1] for e in events]) and not [e for e in events if e[1] in ("detected", "isolated")]


def test_a_healthy_run_decides_nothing_and_an_unknown_rule_is_named():
    assert _run([], 120.0) == []
    with pytest.raises(ScenarioError, match="rule: unknown value 'bayes'"):
        _run([], 1.0, rule="bayes")
