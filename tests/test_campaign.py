"""uvsym campaign: dotted paths and grid expansion, bad input, metrics from hand-written event logs,
tiny real campaigns on local processes and on a Dask LocalCluster, resume after the driver is
killed, and a worker process that dies during a run."""

import json
import math
import os
import signal
import subprocess
import sys
import time
import uuid

import numpy as np
import pyarrow.parquet as pq
import pytest

from uvsym.campaign import event_metrics, load_campaign, run_campaign, run_metrics, truth
from uvsym.campaign.dotted import parse_path, set_path
from uvsym.cli import main
from uvsym.errors import CampaignError, CampaignSizeError, ExecutorError, PathError
from uvsym.sim.result import Signal, SimResult
from uvsym.sim.scenario import load_scenario, parse_scenario, read_scenario_file, shipped_scenarios

GRID = """
name = "grid"
[[case]]
name = "thruster"
scenario = "docking_faults"
set = { "duration" = 30.0 }
[case.grid]
"faults" = [[]]
"faults[0].actuator" = ["X"]
"faults[0]" = [{kind = "bias", value = 10.0}, {kind = "proportional", value = 0.6}]
"faults[0].onset" = [5.0, 20.0]
"seed" = [1, 2]
"""

# two 2 s runs, interpreted (a short run is cheaper than compiling its loop), one process, a chunk per run
TINY = """
name = "tiny"
metrics = "{hooks}:{function}"
[executor]
workers = 1
chunk_size = 1
[simulation]
compiled = false
[[case]]
name = "thruster"
scenario = "docking_faults"
set = {{ "duration" = 2.0, "faults" = [{{ actuator = "X", kind = "bias", value = 10.0, onset = 1.0 }}] }}
[case.grid]
"seed" = {seeds}
"""

HOOKS = '''
import os, time
from pathlib import Path

LOG = Path(__file__).with_name("executed.log")


def _log(scenario):
    with open(LOG, "a") as log:
        log.write(f"{scenario.seed}\\n")


def metrics(scenario, result, events):
    _log(scenario)
    return {"final_u_mps": float(result["x"]["u"][-1])}


def slow(scenario, result, events):
    time.sleep(0.5)
    return metrics(scenario, result, events)


def killer(scenario, result, events):
    if scenario.seed == 2:
        os._exit(3)
    return metrics(scenario, result, events)


def environment(scenario, result, events):
    return {"worker_" + key.lower(): os.environ.get(key, "unset")
            for key in ("OPENBLAS_NUM_THREADS", "PYTHONSAFEPATH", "MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_")}


def shadowing(scenario, result, events):
    return {"seed": 0}


def huge(scenario, result, events):
    return {"count": 2 ** 64}


def failing(scenario, result, events):
    raise RuntimeError("no such sensor")


def flaky(scenario, result, events):
    """Kills its worker the first time it runs seed 2 (a marker file remembers), runs normally after."""
    marker = LOG.with_name("died.marker")
    if scenario.seed == 2 and not marker.exists():
        marker.write_text("died")
        os._exit(9)
    return metrics(scenario, result, events)
'''


def _write(folder, text: str, name: str = "campaign.toml"):
    path = folder / name
    path.write_text(text)
    return path


def _tiny(folder, function: str = "metrics", seeds=(1, 2)):
    """A TINY campaign file in ``folder`` with its own hook module (a fresh name: the driver imports it)."""
    hooks = f"hooks_{uuid.uuid4().hex[:8]}"
    (folder / f"{hooks}.py").write_text(HOOKS)
    return _write(folder, TINY.format(hooks=hooks, function=function, seeds=list(seeds)))


def _executed(folder) -> list[int]:
    log = folder / "executed.log"
    return [int(line) for line in log.read_text().split()] if log.exists() else []


# dotted paths and expansion


def test_dotted_paths_create_merge_and_replace():
    assert parse_path("faults[0].onset") == ("faults", 0, "onset")
    data = {"faults": [{"actuator": "X", "kind": "bias", "value": 13.0}], "duration": 90.0}
    set_path(data, "current.speed", 0.1)                 # missing table made
    set_path(data, "faults", [])                         # a value replaces
    set_path(data, "faults[0].actuator", "delta_ru")     # the missing entry made as a table
    set_path(data, "faults[0]", {"kind": "proportional", "value": 0.6})  # a table merges
    assert data == {"faults": [{"actuator": "delta_ru", "kind": "proportional", "value": 0.6}],
                    "duration": 90.0, "current": {"speed": 0.1}}
    with pytest.raises(CampaignError, match=r"faults\[2\].*1 entries.*gap"):
        set_path(data, "faults[2].onset", 1.0)
    with pytest.raises(CampaignError, match="duration.*float, not a table"):
        set_path(data, "duration.x", 1.0)
    with pytest.raises(CampaignError, match="malformed"):
        parse_path("faults..onset")


def test_a_path_into_an_entry_the_scenario_lacks_is_named_as_such(tmp_path):
    from uvsym.campaign.dotted import new_entry

    assert new_entry({"faults": [{}]}, "faults[1].value") == "faults[1]"
    assert new_entry({"faults": [{}]}, "faults[0].value") is None
    assert new_entry({}, "current.speed") is None
    text = GRID.replace('"faults" = [[]]\n', "").replace('"faults[0].actuator" = ["X"]', '"faults[3].value" = [1.0]')
    with pytest.raises(CampaignError, match=r"faults\[3\]: give either .*\(faults\[3\] is not in the scenario: the "
                                            r"case's paths made it"):
        load_campaign(_write(tmp_path, text))


def test_grid_is_the_product_of_the_axes_in_file_order(tmp_path):
    campaign = load_campaign(_write(tmp_path, GRID))
    assert len(campaign.runs) == 1 * 1 * 2 * 2 * 2
    # the last axis varies fastest: run 0 bias/5 s/seed 1, run 1 seed 2, run 2 onset 20 s, run 4 proportional
    expected = [("bias", 10.0, 5.0, 1), ("bias", 10.0, 5.0, 2), ("bias", 10.0, 20.0, 1), ("bias", 10.0, 20.0, 2),
                ("proportional", 0.6, 5.0, 1), ("proportional", 0.6, 5.0, 2), ("proportional", 0.6, 20.0, 1),
                ("proportional", 0.6, 20.0, 2)]
    for run, (kind, value, onset, seed) in zip(campaign.runs, expected):
        assert run.scenario["faults"] == [{"actuator": "X", "kind": kind, "value": value, "onset": onset}]
        assert run.scenario["seed"] == seed and run.scenario["duration"] == 30.0
        assert run.fields == {"faults": [], "faults[0].actuator": "X", "faults[0].kind": kind,
                              "faults[0].value": value, "faults[0].onset": onset, "seed": seed}
    assert len({run.id for run in campaign.runs}) == 8
    assert [r.id for r in load_campaign(tmp_path / "campaign.toml").runs] == [r.id for r in campaign.runs]


def test_monte_carlo_draws_are_reproducible_and_in_range(tmp_path):
    draws = """
[case.monte_carlo]
runs = 3
seed = {seed}
"current.speed" = {{ uniform = [0.0, 0.2] }}
"faults[0].onset" = {{ choice = [5.0, 10.0, 15.0] }}
"""
    first = load_campaign(_write(tmp_path, GRID + draws.format(seed=0), "a.toml"))
    again = load_campaign(_write(tmp_path, GRID + draws.format(seed=0), "b.toml"))
    other = load_campaign(_write(tmp_path, GRID + draws.format(seed=1), "c.toml"))
    assert len(first.runs) == 8 * 3
    speeds = [run.scenario["current"]["speed"] for run in first.runs]
    assert all(0.0 <= s <= 0.2 for s in speeds) and len(set(speeds)) == 24
    assert {run.scenario["faults"][0]["onset"] for run in first.runs} <= {5.0, 10.0, 15.0}
    assert [r.scenario for r in again.runs] == [r.scenario for r in first.runs]
    assert speeds != [run.scenario["current"]["speed"] for run in other.runs]
    assert [run.draw for run in first.runs[:4]] == [0, 1, 2, 0]


def test_monte_carlo_draws_the_scenarios_own_seed_when_seed_is_a_distribution(tmp_path):
    """seed = an integer seeds the draws; seed = {integers = ...} draws the scenario's noise seed itself."""
    draws = ('[case.monte_carlo]\nruns = 4\nseed = { integers = [100, 999] }\n'
             '"current.speed" = { uniform = [0.0, 0.2] }\n')
    campaign = load_campaign(_write(tmp_path, GRID + draws))
    seeds = [run.scenario["seed"] for run in campaign.runs]
    assert all(isinstance(s, int) and 100 <= s <= 999 for s in seeds) and len(set(seeds)) > 1
    again = load_campaign(_write(tmp_path, GRID + draws, "again.toml"))
    assert [r.scenario["seed"] for r in again.runs] == seeds            # from the master seed 0: reproducible
    other = load_campaign(_write(tmp_path, GRID + draws + "master_seed = 7\n", "other.toml"))
    assert [r.scenario["seed"] for r in other.runs] != seeds            # master_seed beside it seeds the draws
    with pytest.raises(CampaignError, match="give the master seed as seed or as master_seed, not both"):
        load_campaign(_write(tmp_path, GRID + '[case.monte_carlo]\nruns = 2\nseed = 1\nmaster_seed = 2\n'
                             '"current.speed" = { uniform = [0.0, 0.2] }\n', "both.toml"))


def test_the_example_campaign_is_valid(capsys):
    from pathlib import Path

    example = Path(__file__).resolve().parents[1] / "examples" / "campaign_docking.toml"
    assert main(["campaign", str(example), "--dry-run"]) == 0
    assert "20 runs in 3 cases" in capsys.readouterr().out


# bad input: typed errors naming the field or the address, before anything runs


def test_bad_campaigns_are_refused_naming_the_field(tmp_path):
    with pytest.raises(CampaignError, match="grid axis 'seed' is an empty list"):
        load_campaign(_write(tmp_path, GRID.replace('"seed" = [1, 2]', '"seed" = []')))
    with pytest.raises(CampaignError, match=r"durration: unknown field \(did you mean 'duration'\?\)"):
        load_campaign(_write(tmp_path, GRID + '"durration" = [10.0]\n'))
    with pytest.raises(CampaignError, match=r"current.sped: unknown field \(did you mean 'speed'\?\)"):
        load_campaign(_write(tmp_path, GRID + '"current.sped" = [0.1]\n'))
    with pytest.raises(CampaignError, match=r"case\[0\].gird: unknown field"):
        load_campaign(_write(tmp_path, GRID.replace("[case.grid]", "[case.gird]")))
    with pytest.raises(CampaignError, match="monte_carlo field 'current.speed'.*lo 0.3 > hi 0.1"):
        load_campaign(_write(tmp_path, GRID + '[case.monte_carlo]\nruns = 2\n"current.speed" = '
                                              '{ uniform = [0.3, 0.1] }\n'))
    with pytest.raises(CampaignSizeError, match="8 runs, more than max_runs = 5.*--yes"):
        load_campaign(_write(tmp_path, "max_runs = 5\n" + GRID))
    assert len(load_campaign(tmp_path / "campaign.toml", confirm=True).runs) == 8


def test_a_case_sets_its_own_simulation_options_over_the_campaigns(tmp_path, monkeypatch):
    """[case.simulation] gives the options it names (compiled = true: long healthy runs sharing one compiled
    loop), the others keep [simulation]'s; the worker passes them on; a bad one is named with its case."""
    text = GRID.replace("[case.grid]", "[case.simulation]\ncompiled = true\n[case.grid]")
    campaign = load_campaign(_write(tmp_path, text.replace("[[case]]", "[simulation]\ncompiled = false\n"
                                                                        "method = 'fast'\n[[case]]", 1)))
    assert dict(campaign.settings.simulation) == {"method": "fast", "compiled": False}
    assert all(run.simulation == (("compiled", True),) for run in campaign.runs)
    import uvsym.sim.system_scenario as system_scenario
    from uvsym.campaign.worker import execute

    given = {}

    def record(scenario, **options):
        given.update(options)
        raise RuntimeError("stop after the options")

    monkeypatch.setattr(system_scenario, "simulate_any_scenario", record)
    row = execute(campaign.runs[0], campaign.settings)
    assert given == {"method": "fast", "compiled": True} and row["status"] == "error"
    bad = GRID.replace("[case.grid]", "[case.simulation]\ncompiled = 'yes'\n[case.grid]")
    with pytest.raises(CampaignError, match=r"case\[0\].simulation.compiled: expected true or false"):
        load_campaign(_write(tmp_path, bad))
    with pytest.raises(CampaignError, match=r"case\[0\].simulation.methd: unknown field"):
        load_campaign(_write(tmp_path, GRID.replace("[case.grid]", "[case.simulation]\nmethd = 'fast'\n[case.grid]")))


def test_the_command_reports_bad_input_and_size(tmp_path, capsys):
    path = _write(tmp_path, GRID + '"durration" = [10.0]\n')
    assert main(["campaign", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "did you mean 'duration'" in capsys.readouterr().err
    path = _write(tmp_path, "max_runs = 5\n" + GRID)
    assert main(["campaign", str(path), "--dry-run"]) == 2
    assert "more than max_runs = 5" in capsys.readouterr().err
    assert main(["campaign", str(path), "--dry-run", "--yes"]) == 0
    assert not (tmp_path / "out").exists()


def test_an_unreachable_scheduler_is_named_before_any_run(tmp_path):
    pytest.importorskip("distributed", reason="dask.distributed is not installed (pip install 'uvsym[cluster]')")
    campaign = load_campaign(_write(tmp_path, GRID + "[executor]\ntimeout_s = 0.5\n"))
    started = time.perf_counter()
    with pytest.raises(ExecutorError, match="tcp://127.0.0.1:1"):
        run_campaign(campaign, tmp_path / "out", scheduler="tcp://127.0.0.1:1")
    assert time.perf_counter() - started < 10.0
    assert not (tmp_path / "out").exists()


def test_without_dask_the_error_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed now fails
    campaign = load_campaign(_write(tmp_path, GRID))
    with pytest.raises(ExecutorError, match=r"uvsym\[cluster\]"):
        run_campaign(campaign, tmp_path / "out", executor="dask")


def test_a_folder_of_other_files_is_refused(tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "notes.txt").write_text("mine")
    with pytest.raises(PathError, match="notes.txt"):
        run_campaign(load_campaign(_write(tmp_path, GRID)), tmp_path / "out")


# metrics from hand-written event logs

TRUTH = {"n_faults": 1, "true_actuator": "X", "true_sensor": None, "true_kind": "bias", "true_value": 10.0,
         "onset_s": 5.0, "end_s": None}


def _event(t, event, actuator=None, kind=None, value=None):
    return {"t": t, "event": event, "target": actuator, "kind": kind, "value": value}


def test_metrics_of_a_hand_written_event_log():
    events = [_event(2.0, "detected"),                           # before the onset: a false alarm
              _event(3.0, "cleared"),
              _event(5.8, "detected"),                           # detection delay 0.8 s
              _event(6.5, "isolated", "delta_ru", "bias"),       # wrong, then cleared
              _event(7.0, "cleared", "delta_ru"),
              _event(7.5, "isolated", "X", "bias"),              # isolation delay 2.5 s
              _event(9.0, "identified", "X", "bias", 9.5),
              _event(12.0, "identified", "X", "bias", 10.4) | {"std": 0.2},  # the last: 4 % (2 std) too large
              _event(13.0, "ambiguous", "X|delta_ru")]
    metrics = event_metrics(TRUTH, events[::-1])                # order of the list does not matter
    assert metrics == {"events": 9, "detected": True, "detection_delay_s": pytest.approx(0.8),
                       "isolated_target": "X", "isolated_kind": "bias", "isolated_targets": "X",
                       "isolation_delay_s": pytest.approx(2.5),
                       "identified_value": 10.4, "identified_std": 0.2, "size_error_std": pytest.approx(2.0),
                       "size_error_rel": pytest.approx(0.04), "false_alarms": 1,
                       "ambiguous": True, "unexplained": False, "clear_delay_s": None, "unexcited": False}


def test_alarms_after_a_fault_ends_and_is_cleared_are_false():
    truth_row = TRUTH | {"end_s": 20.0}
    events = [_event(6.0, "detected"), _event(21.0, "identified", "X", None, 3.0),  # before the clearing: its own
              _event(22.0, "cleared"), _event(30.0, "detected"), _event(31.0, "unexcited", "X"),
              _event(32.0, "unexcited", "delta_e")]
    metrics = event_metrics(truth_row, events)
    assert metrics["false_alarms"] == 1 and metrics["detection_delay_s"] == pytest.approx(1.0)
    assert metrics["clear_delay_s"] == pytest.approx(2.0)  # cleared 2 s after the fault's end at 20 s
    assert metrics["identified_value"] == 3.0 and metrics["size_error_rel"] == pytest.approx(0.7)
    assert metrics["identified_std"] is None and metrics["size_error_std"] is None  # no std stated
    assert metrics["isolated_target"] is None and metrics["unexcited"] is True
    assert event_metrics(truth_row, [_event(32.0, "unexcited", "delta_e")])["unexcited"] is False
    healthy = {key: None for key in TRUTH} | {"n_faults": 0}
    metrics = event_metrics(healthy, [_event(3.0, "detected"), _event(4.0, "isolated", "X", "bias")])
    assert metrics["false_alarms"] == 2 and metrics["detected"] is False and metrics["detection_delay_s"] is None
    assert metrics["isolated_target"] == "X"


def test_the_return_to_no_fault_after_a_fault_ends_and_an_unexplained_record():
    """clear_delay_s: from the fault's end until no alarm stands (0 when none stands at the end); none for a
    fault that lasts the run or an alarm that stands to the end; unexplained: any such event."""
    ends = TRUTH | {"end_s": 20.0}
    events = [_event(6.0, "detected"), _event(15.0, "cleared"), _event(16.0, "detected"),
              _event(17.0, "isolated", "X", "bias"), _event(24.5, "cleared", "X")]
    assert event_metrics(ends, events)["clear_delay_s"] == pytest.approx(4.5)
    assert event_metrics(ends, events[:4])["clear_delay_s"] is None  # still alarmed at the run's end
    assert event_metrics(ends, events[:2])["clear_delay_s"] == 0.0  # released before the fault ended
    assert event_metrics(TRUTH, events)["clear_delay_s"] is None  # the fault lasts the run
    two = events[:4] + [_event(18.0, "isolated", "delta_ru", "bias"), _event(24.5, "cleared", "X"),
                        _event(26.0, "cleared", "delta_ru")]
    assert event_metrics(ends, two)["clear_delay_s"] == pytest.approx(6.0)  # the last standing isolation
    metrics = event_metrics(ends, [_event(6.0, "unexplained"), _event(30.0, "cleared")])
    assert metrics["unexplained"] is True and metrics["detected"] is False and metrics["clear_delay_s"] == 0.0


def test_the_final_isolation_is_the_last_one_standing():
    # a diagnosis that watches each actuator holds several isolations; clearing the last leaves the one before
    events = [_event(6.0, "isolated", "X", "bias"), _event(7.0, "isolated", "delta_ru", "proportional"),
              _event(8.0, "isolated", "delta_rd", "proportional"), _event(9.0, "cleared", "delta_rd"),
              _event(10.0, "isolated", "X", "constant")]  # X again: now the latest
    metrics = event_metrics(TRUTH, events)
    assert (metrics["isolated_target"], metrics["isolated_kind"]) == ("X", "constant")
    assert metrics["isolated_targets"] == "delta_ru|X" and metrics["isolation_delay_s"] == pytest.approx(1.0)
    metrics = event_metrics(TRUTH, events[:4])
    assert (metrics["isolated_target"], metrics["isolated_targets"]) == ("delta_ru", "X|delta_ru")
    assert event_metrics(TRUTH, events + [_event(11.0, "cleared")])["isolated_targets"] is None


def test_truth_and_path_error_of_a_run():
    # docking_faults: X bias 13 N, then both rudders at 0.8, all from 0 s: the first listed is the run's fault
    scenario = load_scenario("docking_faults")
    assert truth(scenario) == {"n_faults": 3, "true_actuator": "X", "true_sensor": None, "true_kind": "bias",
                               "true_value": 13.0, "onset_s": 0.0, "end_s": None}
    # sensor noise over the whole run is the sensors' specification: the fault is the later actuator one
    table = read_scenario_file(shipped_scenarios()["docking_faults"])
    noise = {"sensor": "u", "kind": "noise", "value": 0.01}
    table["faults"] = [noise, {"actuator": "delta_e", "kind": "bias", "value": 0.05, "onset": 8.0, "end": 20.0}]
    assert truth(parse_scenario(table)) == {"n_faults": 1, "true_actuator": "delta_e", "true_sensor": None,
                                            "true_kind": "bias", "true_value": 0.05, "onset_s": 8.0, "end_s": 20.0}
    table["faults"] = [noise, noise | {"onset": 3.0}]  # noise that starts later is a fault
    assert truth(parse_scenario(table)) | {"true_value": None} == {
        "n_faults": 1, "true_actuator": None, "true_sensor": "u", "true_kind": "noise", "true_value": None,
        "onset_s": 3.0, "end_s": None}
    table["faults"] = [noise]
    assert truth(parse_scenario(table))["n_faults"] == 0
    result = SimResult(np.array([0.0, 1.0]), {"reference": Signal(np.array([[0.0, 3.0], [0.0, 4.0]]),
                                                                  ("psi_ref", "cross_track"), ("rad", "m"))})
    assert run_metrics(scenario, result, [])["path_error_rms_m"] == pytest.approx(math.sqrt((9 + 16) / 2))


# real campaigns


@pytest.fixture(scope="module")
def local_run(tmp_path_factory):
    """The tiny campaign on the local executor: (folder, campaign, table)."""
    folder = tmp_path_factory.mktemp("local")
    campaign = load_campaign(_tiny(folder))
    return folder, campaign, run_campaign(campaign, folder / "out")


def test_a_tiny_campaign_on_local_processes(local_run):
    folder, campaign, table = local_run
    rows = table.to_pylist()
    assert [r["run_id"] for r in rows] == [r.id for r in campaign.runs] and [r["seed"] for r in rows] == [1, 2]
    assert all(r["status"] == "ok" and r["true_actuator"] == "X" and r["onset_s"] == 1.0 for r in rows)
    assert all(r["final_u_mps"] > 1.0 for r in rows)  # the hook's column: near the 1.5 m/s reference
    # the path error is the RMS cross-track error of the same run made directly
    from uvsym.sim.simulation import simulate_scenario

    direct = simulate_scenario(parse_scenario(campaign.runs[0].scenario), compiled=False)
    cross = direct["reference"]["cross_track"]
    assert rows[0]["path_error_rms_m"] == pytest.approx(float(np.sqrt(np.sum(cross ** 2) / cross.size)), rel=1e-9)
    out = folder / "out"
    assert len(list((out / "chunks").glob("chunk-*.parquet"))) == 2
    assert pq.read_table(out / "results.parquet").to_pylist() == rows
    assert (out / "results.csv").read_text().count("\n") == 3  # header and two rows
    summary = json.loads((out / "summary.json").read_text())
    assert (summary["runs"], summary["ok"], summary["fault_runs"]) == (2, 2, 2)
    assert summary["confusion"] == {"X": {"none": 2}}
    assert (out / "report.html").read_text().count("data:image/svg+xml") == 3
    assert sorted(_executed(folder)) == [1, 2]
    again = run_campaign(campaign, out)  # everything finished: nothing runs again
    assert again.to_pylist() == rows and sorted(_executed(folder)) == [1, 2]


def test_the_results_of_the_chunks_a_run_wrote_equal_its_chunk_files_read_back(local_run):
    """run_campaign keeps the chunks it wrote rather than reading them back: the same table as a new store's."""
    from uvsym.campaign.store import ResultStore

    folder, campaign, table = local_run
    again = ResultStore(folder / "out", campaign.name).results([run.id for run in campaign.runs])
    assert again.num_rows == 2 and again.equals(table)
    assert pq.read_table(folder / "out" / "results.parquet").equals(table)


def test_the_same_campaign_on_a_dask_local_cluster(local_run, tmp_path):
    distributed = pytest.importorskip("distributed", reason="dask.distributed is not installed "
                                                            "(pip install 'uvsym[cluster]')")
    local = local_run[2]
    campaign = load_campaign(_tiny(tmp_path))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                                  dashboard_address=None) as cluster:
        table = run_campaign(campaign, tmp_path / "out", scheduler=cluster.scheduler_address)
    rows, expected = table.to_pylist(), local.to_pylist()
    assert [r["run_id"] for r in rows] == [r["run_id"] for r in expected]
    assert [r["status"] for r in rows] == ["ok", "ok"]
    assert [r["path_error_rms_m"] for r in rows] == pytest.approx([r["path_error_rms_m"] for r in expected])
    assert sorted(_executed(tmp_path)) == [1, 2]


def test_a_killed_driver_resumes_without_redoing_finished_runs(tmp_path):
    path = _tiny(tmp_path, "slow", seeds=(1, 2, 3, 4))
    out = tmp_path / "out"
    driver = subprocess.Popen([sys.executable, "-m", "uvsym.cli", "campaign", str(path), "--out", str(out)],
                              start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while not list(out.glob("chunks/chunk-*.parquet")) and driver.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    os.killpg(driver.pid, signal.SIGKILL)  # the driver and its worker process
    driver.wait()
    finished = {seed for chunk in out.glob("chunks/chunk-*.parquet")
                for seed in pq.read_table(chunk)["seed"].to_pylist()}
    assert 1 <= len(finished) < 4, "the kill should come after the first chunk and before the last"
    assert main(["campaign", str(path), "--out", str(out)]) == 0
    rows = pq.read_table(out / "results.parquet").to_pylist()
    assert sorted(r["seed"] for r in rows) == [1, 2, 3, 4] and all(r["status"] == "ok" for r in rows)
    executed = _executed(tmp_path)
    assert all(executed.count(seed) == 1 for seed in finished)  # finished runs were not redone
    assert len(executed) <= 4 + 1  # at most the run in flight at the kill ran twice


def test_a_campaign_killed_before_its_first_chunk_resumes(tmp_path):
    path = _tiny(tmp_path, "slow", seeds=(1, 2))
    out = tmp_path / "out"
    driver = subprocess.Popen([sys.executable, "-m", "uvsym.cli", "campaign", str(path), "--out", str(out)],
                              start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while not (out / ".build.json").exists() and driver.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    os.killpg(driver.pid, signal.SIGKILL)
    driver.wait()
    assert (out / ".build.json").exists() and not list(out.glob("chunks/chunk-*.parquet"))
    assert main(["campaign", str(path), "--out", str(out)]) == 0
    assert [r["status"] for r in pq.read_table(out / "results.parquet").to_pylist()] == ["ok", "ok"]


def test_a_worker_that_dies_gives_an_error_row_and_the_others_finish(tmp_path):
    from uvsym.campaign.executors import RETRIES

    campaign = load_campaign(_tiny(tmp_path, "killer", seeds=(1, 2, 3)))
    rows = run_campaign(campaign, tmp_path / "out").to_pylist()
    assert [r["status"] for r in rows] == ["ok", "error", "ok"]
    assert rows[1]["error"].startswith("WorkerDied") and "exit code 3" in rows[1]["error"]
    assert f"{RETRIES + 1} times" in rows[1]["error"]  # tried again in new processes first
    assert rows[1]["true_actuator"] == "X"  # truth is known without the run
    assert sorted(_executed(tmp_path)) == [1, 3]


def test_a_campaign_whose_every_run_failed_exits_1_naming_the_commonest_error(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["campaign", str(_tiny(tmp_path, "failing")), "--out", str(out)]) == 1
    assert ("uvsym: error: all 2 runs of tiny failed, 2 with: RuntimeError: no such sensor (each run's "
            f"error: the error column of {out / 'results.csv'})") in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())  # written all the same, saying so
    assert (summary["runs"], summary["ok"], summary["errors"]) == (2, 0, 2)
    assert "2 of 2 runs finished: 0 ok, 2 with an error" in (out / "report.md").read_text()


def test_workers_import_the_drivers_uvsym_not_a_folder_named_uvsym_in_the_working_folder(tmp_path):
    """Run from a folder holding one named uvsym (the parent of a checkout), as the console script runs: its
    own folder first on sys.path, not the working folder. Every run is made by the driver's uvsym."""
    work, launcher = tmp_path / "work", tmp_path / "bin" / "launch.py"
    (work / "uvsym").mkdir(parents=True)
    (work / "uvsym" / "__init__.py").write_text('raise ImportError("the working folder\'s uvsym")\n')
    launcher.parent.mkdir()
    launcher.write_text("import sys\nfrom uvsym.cli import main\nif __name__ == '__main__':\n"
                        "    sys.exit(main(sys.argv[1:]))\n")  # as a console script is
    path = _tiny(work)
    run = subprocess.run([sys.executable, str(launcher), "campaign", path.name, "--out", "out"], cwd=work,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    rows = pq.read_table(work / "out" / "results.parquet").to_pylist()
    assert [r["status"] for r in rows] == ["ok", "ok"], [r["error"] for r in rows]
    assert sorted(_executed(work)) == [1, 2]


def test_local_workers_run_single_threaded_with_a_safe_path_and_malloc_keeping_freed_tables(tmp_path):
    """The workers' environment (uvsym.campaign.executors), in a new driver process (the forkserver keeps the
    environment it started with): one BLAS thread, no working folder on sys.path, glibc's malloc serving the
    output tables from its heap; a value the user set is kept."""
    environment = {key: value for key, value in os.environ.items() if not key.startswith(("MALLOC_", "OPENBLAS"))}
    path = _tiny(tmp_path, "environment", seeds=(1,))
    run = subprocess.run([sys.executable, "-m", "uvsym.cli", "campaign", str(path), "--out", str(tmp_path / "out")],
                         env=environment | {"MALLOC_TRIM_THRESHOLD_": "12345"}, capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    row = pq.read_table(tmp_path / "out" / "results.parquet").to_pylist()[0]
    assert (row["worker_openblas_num_threads"], row["worker_pythonsafepath"]) == ("1", "1")
    assert (row["worker_malloc_mmap_threshold_"], row["worker_malloc_trim_threshold_"]) == (str(32 * 2 ** 20), "12345")


def test_a_run_whose_worker_died_once_is_tried_again_in_a_new_process(tmp_path):
    campaign = load_campaign(_tiny(tmp_path, "flaky", seeds=(1, 2, 3)))
    rows = run_campaign(campaign, tmp_path / "out").to_pylist()
    assert [r["status"] for r in rows] == ["ok", "ok", "ok"]
    assert sorted(_executed(tmp_path)) == [1, 2, 3]


def test_a_rerun_tries_the_runs_whose_worker_was_lost_again(tmp_path):
    path = _tiny(tmp_path, "killer", seeds=(1, 2))
    out = tmp_path / "out"
    assert [r["status"] for r in run_campaign(load_campaign(path), out).to_pylist()] == ["ok", "error"]
    hooks = next(tmp_path.glob("hooks_*.py"))  # the cause fixed: the hook no longer kills its worker
    hooks.write_text(hooks.read_text().replace("os._exit(3)", "pass"))
    rows = run_campaign(load_campaign(path), out).to_pylist()
    assert [r["status"] for r in rows] == ["ok", "ok"]
    assert sorted(_executed(tmp_path)) == [1, 2]  # seed 1 not redone


def test_a_dask_worker_killed_under_a_chunk_has_the_chunk_rerun_run_by_run(tmp_path):
    """The worker process dies under the chunk (its nanny starts another): the chunk is resubmitted run by run, one
    after the other, so the run that kills its worker again gets an error row and takes no other run with it."""
    distributed = pytest.importorskip("distributed", reason="dask.distributed is not installed "
                                                            "(pip install 'uvsym[cluster]')")
    import dask

    campaign = load_campaign(_tiny(tmp_path, "killer", seeds=(2, 3)))
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), \
            distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                                     worker_class=distributed.Nanny) as cluster:
        rows = run_campaign(campaign, tmp_path / "out", scheduler=cluster.scheduler_address, chunk_size=2).to_pylist()
    assert [r["status"] for r in rows] == ["error", "ok"]
    assert rows[0]["error"].startswith("KilledWorker") and rows[0]["seed"] == 2
    assert _executed(tmp_path) == [3]  # once, after the chunk was split (run 2 killed its worker first)


def test_a_shipped_study_scenario_runs_in_a_campaign_by_its_name(tmp_path):
    """abrupt_actuator1 is shipped with the uio-zonotope study, in the format over a plant: a campaign
    finds it by name and sweeps its fields."""
    text = ('name = "s"\n[[case]]\nname = "a"\nscenario = "abrupt_actuator1"\n[case.grid]\n'
            '"faults[0].value" = [2.0, 10.0]\n')
    campaign = load_campaign(_write(tmp_path, text))
    assert [r.scenario["faults"][0]["value"] for r in campaign.runs] == [2.0, 10.0]
    assert all(r.scenario["plant"].endswith(":hover_plant") for r in campaign.runs)


def test_a_study_scenario_is_found_by_name(tmp_path):
    """compass_10deg is shipped with the sensor-fdi-lms study: a campaign names it as it names a vehicle
    scenario; a misspelt name is refused with the shipped ones listed."""
    text = 'name = "s"\n[[case]]\nname = "a"\nscenario = "compass_10deg"\n[case.grid]\nseed = [1, 2]\n'
    campaign = load_campaign(_write(tmp_path, text))
    assert [r.scenario["plant"] for r in campaign.runs] == ["rov_yaw", "rov_yaw"]
    with pytest.raises(CampaignError, match=r"no shipped scenario 'compass_11deg' \(did you mean 'compass_10deg'"
                                            r"\?\); shipped: .*compass_10deg"):
        load_campaign(_write(tmp_path, text.replace("compass_10deg", "compass_11deg")))


def test_values_a_results_table_cannot_hold_are_refused_before_any_run(tmp_path):
    with pytest.raises(CampaignError, match=r"seed = 9223372036854775808 holds an integer beyond 64 bits"):
        load_campaign(_tiny(tmp_path, seeds=(1, 2 ** 63)))
    assert load_campaign(_tiny(tmp_path, seeds=(1, 2 ** 63 - 1))).runs[1].fields["seed"] == 2 ** 63 - 1


@pytest.mark.parametrize("hook, message", [("shadowing", "the column 'seed', which is not a new column name"),
                                           ("huge", "column 'count': expected a number (an integer within 64 bits)")])
def test_a_hook_column_cannot_shadow_a_field_or_overflow_the_table(tmp_path, hook, message):
    rows = run_campaign(load_campaign(_tiny(tmp_path, hook, seeds=(1,))), tmp_path / "out").to_pylist()
    assert rows[0]["status"] == "error" and message in rows[0]["error"]
    assert rows[0]["seed"] == 1  # the field kept
