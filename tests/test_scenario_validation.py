"""Scenarios that used to be accepted and run to garbage (or to a raw traceback) are refused with a
ScenarioError naming the field; a run that reaches the pitch singularity stops there."""

import copy
import math
import re

import pytest

from uvsym.errors import ScenarioError, SimulationError
from uvsym.sim.run import available_memory
from uvsym.sim.scenario import parse_scenario, read_scenario_file, shipped_scenarios
from uvsym.sim.simulation import simulate_scenario


@pytest.fixture(scope="module")
def docking_table():
    return read_scenario_file(shipped_scenarios()["docking_faults"])


def _with(table, **changes):
    """A deep copy of ``table`` with dotted-path changes (``faults.0.onset``)."""
    table = copy.deepcopy(table)
    for path, value in changes.items():
        *parents, last = path.split("__")
        node = table
        for key in parents:
            node = node[int(key)] if isinstance(node, list) else node[key]
        if isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
    return table


@pytest.mark.parametrize("changes, field", [
    ({"controller__path__waypoints__1__0": math.nan}, r"controller\.path\.waypoints\[1\]\[0\]: expected a finite"),
    ({"controller__path__waypoints__2__1": "east"}, r"controller\.path\.waypoints\[2\]\[1\]: .*'east'"),
    ({"faults__0__onset": 120.0}, r"faults\[0\]\.onset: 120 s is outside the run \[0, 90\) s"),
    ({"faults__0__onset": -1.0}, r"faults\[0\]\.onset: must be >= 0.0, got -1.0"),
    ({"faults__1__value": -5.0}, r"faults\[1\]\.value: a proportional factor .* -5 would reverse it"),
    ({"faults__1__value": 1.0}, r"faults\[1\]\.value: a proportional actuator fault of 1.0 changes nothing"),
    ({"faults__0__value": 0.0}, r"faults\[0\]\.value: a bias actuator fault of 0.0 changes nothing"),
    ({"duration": 1e12}, r"duration: 1e\+12 s at step 0.01 s \(1e\+14 samples\)"),
    ({"step": 1e-300}, r"step: 90 s at step 1e-300 s .* more than 1e\+12 samples"),
    ({"initial__eta__4": math.pi / 2}, r"initial\.eta: theta \(entry 5\): .*singular at theta = 90 deg"),
])
def test_accepted_but_wrong_scenarios_are_refused_naming_the_field(docking_table, changes, field):
    parse_scenario(docking_table)  # the shipped scenario itself is valid
    with pytest.raises(ScenarioError, match=field):
        parse_scenario(_with(docking_table, **changes))


def test_a_run_that_does_not_fit_in_memory_gives_the_figures(docking_table):
    available = available_memory()
    if available is None:
        pytest.skip("this system does not say how much memory it has")
    samples = 10 ** math.ceil(math.log10(available / 80))  # 8 bytes x 74 logged entries a sample: > 7x available
    duration = 0.01 * samples
    figures = r"needs at least [\d.]+ [KMGTPE]iB of memory, [\d.]+ [KMGTPE]iB are available"
    with pytest.raises(ScenarioError, match=r"duration: .* " + figures):
        parse_scenario(_with(docking_table, duration=duration))


def test_duplicate_observers_and_a_blind_tau_d_are_refused(docking_table):
    twice = _with(docking_table)
    twice["observers"].append(dict(twice["observers"][0]))
    with pytest.raises(ScenarioError, match=r"observers\[2\]\.kind: a proportional observer is already listed "
                                            r"\(observers\[0\]\)"):
        parse_scenario(twice)
    blind = _with(docking_table)
    blind["observers"][0]["tau_d"] = [0.0] * 6
    with pytest.raises(ScenarioError, match=r"observers\[0\]\.tau_d: .*zero in every channel"):
        parse_scenario(blind)


def test_a_run_through_the_pitch_singularity_stops_there_naming_time_and_state(docking_table):
    table = _with(docking_table, duration=2.0, initial__eta__4=math.radians(70.0), initial__nu__4=3.0)
    table["faults"], table["observers"] = [], []
    with pytest.raises(SimulationError, match=r"kinematic singularity at t = 0\.\d+ s: the state x.theta = 9\d\.\d+ "
                                              r"deg reached pitch \+-90 deg"):
        simulate_scenario(parse_scenario(table))


@pytest.mark.parametrize("patch, field", [({"kind": "stuck"}, "faults[0].kind"),
                                          ({"profile": "intermittent", "duty": 2.0}, "faults[0].duty"),
                                          ({"profile": "wobble"}, "faults[0].profile"),
                                          ({"end": -1.0}, "faults[0].end")])
def test_a_bad_fault_entry_names_its_field(patch, field):
    table = read_scenario_file(shipped_scenarios()["docking_faults"])
    table["faults"] = [dict(table["faults"][0], **patch)]
    with pytest.raises(ScenarioError, match=re.escape(field) + ":"):
        parse_scenario(table)
