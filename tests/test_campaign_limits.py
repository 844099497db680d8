"""A detector's limits from campaign rows: smallest size seen in every run of it and above, the largest missed,
delays and false alarms per hour by noise level, and named errors for missing columns."""

from __future__ import annotations

import pytest

from uvsym.campaign.limits import channel_limits, every_size_from, false_alarm_rates, false_alarm_table, limits_table
from uvsym.errors import CampaignError


def _row(size, detected, delay=None, channel="X", noise=0.1, faults=1, hours=0.01, alarms=0, status="ok"):
    return {"case": "c", "status": status, "n_faults": faults, "true_actuator": channel if faults else None,
            "true_sensor": None, "true_kind": "bias" if faults else None, "true_value": size if faults else None,
            "d:detected": detected, "d:detection_delay_s": delay, "d:false_alarms": alarms,
            "duration_s": hours * 3600.0, "noise": noise}


def test_the_smallest_size_seen_is_the_one_from_which_every_run_of_every_larger_size_is_detected():
    rows = [_row(1.0, False), _row(1.0, False), _row(2.0, True, 0.5), _row(2.0, False), _row(3.0, True, 0.4),
            _row(3.0, True, 0.2), _row(-5.0, True, 0.1), _row(5.0, True, 0.3), _row(4.0, False, status="error")]
    (limit,) = channel_limits(rows, "d")
    assert limit["sizes"] == [(1.0, 2, 0), (2.0, 2, 1), (3.0, 2, 2), (5.0, 2, 2)]
    assert (limit["seen_from"], limit["missed_up_to"]) == (3.0, 2.0)
    assert limit["median_delay_s"] == pytest.approx(0.3)  # of 0.5, 0.4, 0.2, 0.1, 0.3
    assert limits_table([limit], "N")[0][3:] == ["3 N", "2 N", "0.3"]


def test_a_largest_size_missed_means_nothing_is_seen_from_and_channels_are_apart():
    rows = [_row(1.0, True, 0.1), _row(9.0, False), _row(1.0, True, 0.2, channel="Y")]
    limits = {item["channel"]: item for item in channel_limits(rows, "d")}
    assert limits["X"]["seen_from"] is None and limits["X"]["missed_up_to"] == 9.0
    assert limits["Y"]["seen_from"] == 1.0 and limits["Y"]["missed_up_to"] is None


def test_false_alarms_per_hour_by_noise_level_count_fault_free_runs_only():
    rows = [_row(None, False, faults=0, noise=0.1, hours=2.0, alarms=1), _row(None, False, faults=0, noise=0.1,
                                                                              hours=3.0, alarms=4),
            _row(None, False, faults=0, noise=0.2, hours=1.0, alarms=0), _row(5.0, True, 0.1, alarms=7)]
    rates = false_alarm_rates(rows, "noise", "d")
    assert [(r["noise"], r["hours"], r["false_alarms"]) for r in rates] == [(0.1, 5.0, 5), (0.2, 1.0, 0)]
    assert rates[0]["per_hour"] == pytest.approx(1.0)
    assert false_alarm_table(rates)[1] == ["0.2", "1", "0", "0"]


def test_missing_columns_are_named():
    with pytest.raises(CampaignError, match="no column 'e:detected'.*detectors: \\['d'\\]"):
        channel_limits([_row(1.0, True)], "e")
    with pytest.raises(CampaignError, match="no grid field 'sigma'"):
        false_alarm_rates([_row(1.0, True)], "sigma", "d")


def test_a_size_function_measures_factors_from_one_and_leaves_out_what_it_gives_none():
    rows = [dict(_row(0.8, True, 1.0), true_kind="proportional"), dict(_row(0.5, True, 2.0), true_kind="proportional"),
            dict(_row(20.0, True, 3.0), true_kind="constant")]
    limits = channel_limits(rows, "d", size=lambda r: abs(1 - r["true_value"]) if r["true_kind"] == "proportional"
                            else None)
    assert [(item["kind"], [s for s, _, _ in item["sizes"]]) for item in limits] == [("proportional",
                                                                                      [pytest.approx(0.2), 0.5])]


def test_every_size_from_is_the_smallest_size_above_the_last_that_fails():
    assert every_size_from([(1.0, True), (2.0, False), (3.0, True), (4.0, True)]) == 3.0
    assert every_size_from([(1.0, True), (2.0, True)]) == 1.0
    assert every_size_from([(1.0, True), (2.0, False)]) is None and every_size_from([]) is None
