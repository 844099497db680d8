"""Campaign runs in lanes (execute_many): the same rows as one run at a time, a failing run its own row,
runs that cannot share a step (another method) run alone."""

from __future__ import annotations

import math

import pytest

from uvsym.campaign import parse_campaign
from uvsym.campaign.worker import execute, execute_many


def _campaign(**simulation):
    return parse_campaign({"name": "lanes", "simulation": simulation, "case": [
        {"name": "docking", "scenario": "docking_faults", "set": {"duration": 6.0},
         "grid": {"current.speed": [0.0, 0.1], "faults[0].value": [5.0, 20.0], "seed": [1, 2]}},
        {"name": "remus", "scenario": "remus100_stern_plane_bias", "set": {"duration": 4.0},
         "grid": {"seed": [1, 2]}},
        {"name": "rov", "scenario": "rov_yaw_compass_bias", "set": {"duration": 20.0},
         "grid": {"faults[0].value": [0.2, 0.349], "faults[0].onset": [10.0], "seed": [1, 2]}}]})


def _same(lane_row: dict, alone_row: dict) -> None:
    assert lane_row.keys() == alone_row.keys()
    for key, value in alone_row.items():
        if key == "wall_s" or key.endswith("_cpu_s"):  # timings
            continue
        if isinstance(value, float) and isinstance(lane_row[key], float):
            assert math.isclose(lane_row[key], value, rel_tol=1e-7, abs_tol=1e-9), (key, lane_row[key], value)
        else:
            assert lane_row[key] == value, (key, lane_row[key], value)


def test_rows_in_lanes_equal_rows_run_one_at_a_time():
    campaign = _campaign()
    lanes = execute_many(campaign.runs, campaign.settings)
    alone = [execute(run, campaign.settings) for run in campaign.runs]
    assert [r["status"] for r in lanes] == ["ok"] * len(campaign.runs)
    assert [r["run_id"] for r in lanes] == [run.id for run in campaign.runs]
    for lane_row, alone_row in zip(lanes, alone):
        _same(lane_row, alone_row)


def test_a_run_whose_hook_fails_is_its_own_error_row_and_the_batch_still_answers():
    campaign = _campaign()

    def hook(scenario, result, events):
        if scenario.seed == 2 and getattr(scenario, "current", (0.0,))[0] == 0.1:  # 2 docking runs
            raise RuntimeError("this run's hook fails")
        return {"final_t_s": float(result.t[-1])}

    rows = execute_many(campaign.runs, campaign.settings, hook)
    failed = [r for r in rows if r["status"] == "error"]
    assert len(failed) == 2 and all(r["error"] == "RuntimeError: this run's hook fails" for r in failed)
    ok = [r for r in rows if r["status"] == "ok"]
    assert len(ok) == len(rows) - 2 and all(r["final_t_s"] > 0 for r in ok)


@pytest.mark.parametrize("simulation", [{"method": "rk"}, {"compiled": False}])
def test_runs_the_lanes_cannot_take_and_the_interpreted_path_give_the_same_rows(simulation):
    campaign = _campaign(**simulation)
    runs = campaign.runs[:3]
    for lane_row, alone_row in zip(execute_many(runs, campaign.settings), [execute(r, campaign.settings)
                                                                           for r in runs]):
        _same(lane_row, alone_row)
