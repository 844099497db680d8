"""Which runs of the actuator-fault campaign count, and its figures, on hand-made rows and signals."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from derivations.actuator_observers.campaign import counts, metrics, size_intervals, targets
from uvsym.faults import ActuatorFault, Profile
from uvsym.sim.scenario import load_scenario


def _row(**fields):
    row = {"status": "ok", "true_actuator": "X", "true_kind": "bias", "identifiable": True, "excited": True,
           "isolated_target": "X", "isolated_kind": "bias", "size_error_rel": 0.01, "isolation_delay_s": 1.0,
           "false_alarms": 0}
    return row | fields


def test_counts_use_only_identifiable_excited_runs_and_fault_free_false_alarms():
    rows = [_row(), _row(size_error_rel=0.03, isolation_delay_s=3.0),  # counted: one right, one too far off
            _row(excited=False, isolated_target=None, isolated_kind=None, size_error_rel=None),  # left out
            _row(true_actuator=None, true_kind=None, false_alarms=2),  # fault-free run with two alarms
            _row(status="error")]
    figures = counts(rows)
    assert figures["campaign_counted_runs"] == 2
    assert figures["campaign_correct_fraction"] == 0.5
    assert figures["campaign_correct_fraction_all_faults"] == pytest.approx(1 / 3)
    assert figures["campaign_false_alarms_no_fault"] == 2
    assert figures["campaign_crashes"] == 1
    assert figures["campaign_median_isolation_delay_s"] == 2.0 and figures["campaign_max_isolation_delay_s"] == 3.0
    met = targets(figures)
    assert not met["correct fraction >= 0.95 (identifiable, excited)"] and not met["no run crashed"]
    assert met["median isolation delay <= 5 s"]


def test_a_campaign_whose_every_run_crashed_is_reported_as_such_without_a_nan(tmp_path):
    """Every run an error row (e.g. its worker could not import uvsym): the figures of no run are None, every
    target that needs a run is missed, and results.json and the confusion figure are written."""
    import json
    from collections import Counter

    from derivations.actuator_observers.figures import campaign_confusion_figure
    from uvsym.report.markdown import write_json

    figures = counts([_row(status="error"), _row(status="error", true_actuator=None, true_kind=None)])
    assert figures["campaign_crashes"] == 2 and figures["campaign_counted_runs"] == 0
    for key in ("campaign_correct_fraction", "campaign_correct_fraction_all_faults",
                "campaign_median_isolation_delay_s", "campaign_max_isolation_delay_s"):
        assert figures[key] is None, key
    met = targets(figures)
    assert [name for name, ok in met.items() if ok] == ["no false alarm without a fault"]  # no run to alarm
    write_json(tmp_path / "results.json", figures)
    assert json.loads((tmp_path / "results.json").read_text())["campaign_max_isolation_delay_s"] is None
    campaign_confusion_figure(Counter(), tmp_path / "confusion.svg")
    assert (tmp_path / "confusion.svg").read_text().startswith("<?xml")


def test_json_with_a_nan_is_refused_naming_the_entry_before_the_file_is_written(tmp_path):
    from uvsym.errors import FileFormatError
    from uvsym.report.markdown import write_json

    with pytest.raises(FileFormatError, match=r"results.json: campaign.delays\[1\] is nan, which JSON cannot hold"):
        write_json(tmp_path / "results.json", {"campaign": {"runs": 2, "delays": [1.0, float("nan")]}})
    with pytest.raises(FileFormatError, match=r"inf"):
        write_json(tmp_path / "results.json", [np.float64("inf")])
    assert not (tmp_path / "results.json").exists()


def test_size_intervals_count_right_decisions_against_tolerance_and_stated_std():
    rows = [_row(case="a", size_error_std=0.5), _row(case="a", size_error_rel=0.03, size_error_std=2.5),
            _row(case="a", isolated_kind="proportional", size_error_std=9.0),  # wrong kind: not a size case
            _row(case="a", excited=False, size_error_std=9.0),                 # not counted
            _row(case="b", size_error_std=None)]                               # no std stated
    a, b = size_intervals(rows)
    assert a == {"case": "a", "runs": 2, "within_tolerance": 1, "with_std": 2, "within_2_std": 1,
                 "max_error_std": 2.5}
    assert b == {"case": "b", "runs": 1, "within_tolerance": 1, "with_std": 0, "within_2_std": 0,
                 "max_error_std": None}


class _Result:
    """The part of a SimResult the hook reads: t and u_expected, the third input (delta_ru) set to ``command``."""

    def __init__(self, command: np.ndarray, t: np.ndarray):
        self.t, self._values = t, np.zeros((len(t), 4))
        self._values[:, 2] = command

    def __getitem__(self, name):
        assert name == "u_expected"
        return SimpleNamespace(values=self._values)


def test_excitation_is_judged_from_the_command_after_the_onset():
    base = load_scenario("docking_faults")
    rudder = base.model.input_labels.index("delta_ru")
    scenario = replace(base, actuator_faults=(ActuatorFault(rudder, "proportional", 0.5, Profile(onset=5.0)),))
    t = np.arange(0.0, 20.0, 0.01)
    steady = metrics(scenario, _Result(np.full(t.size, 0.1), t), [])
    assert steady["identifiable"]  # the two rudders differ in roll
    assert not steady["excited"] and steady["command_variation"] < 1e-12
    # a command swinging +-0.1 rad (std 0.0707 rad of a 0.524 rad range) after the onset excites it
    moving = metrics(scenario, _Result(0.1 * np.sin(t), t), [])
    assert moving["excited"] and moving["command_variation"] == pytest.approx(0.0707 / 0.5236, rel=0.05)
    # a proportional fault on a command at zero has no effect to see
    assert not metrics(scenario, _Result(np.zeros(t.size), t), [])["excited"]


def test_the_limits_compare_ten_hour_settings_with_the_designed_rate_and_name_the_short_ones():
    """A setting of 10 fault-free hours or more is measured against the designed rate (a rate above it is
    named); a shorter one is said to be too short, not compared."""
    from derivations.actuator_observers.report import limits_section

    figures = {"limits": {}, "designed_false_alarms_per_hour": 0.036, "decision_period_s": 0.1,
               "window_false_alarm_rate": 1e-6, "campaign_false_alarms_before_onset": 0,
               "fault_free": [{"noise": "none", "hours": 0.04, "false_alarms": 0, "per_hour": 0.0},
                              {"noise": "told", "hours": 10.0, "false_alarms": 0, "per_hour": 0.0},
                              {"noise": "told x2", "hours": 10.0, "false_alarms": 3, "per_hour": 0.3}]}
    text = " ".join(limits_section(figures).split())
    assert "at most 0.036 false alarms per hour" in text
    assert "told: 0 in 10 h; told x2: 3 in 10 h; above the designed rate at told x2" in text
    assert "too few fault-free hours to confirm that rate (none (0.04 h))" in text
    figures["fault_free"][2] |= {"false_alarms": 0, "per_hour": 0.0}
    assert "none above the designed rate" in " ".join(limits_section(figures).split())
