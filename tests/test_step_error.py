"""The fast path's RK4 step error, estimated by step doubling on sampled steps, against the exact one."""

from __future__ import annotations

import copy
import math
import tomllib
import warnings
from importlib import resources

import numpy as np
import pytest
from problems import first_order

from uvsym.errors import IntegrationAccuracyWarning, ScenarioError, SimulationError
from uvsym.faults import ActuatorFault, Profile
from uvsym.sim import open_loop, simulate_system
from uvsym.sim.step_error import CHECKS, EARLY, JUMPS, check_indices
from uvsym.sim.system_scenario import parse_system_scenario, simulate_system_scenario

A, B, DT = 40.0, 2.0, 0.05  # v' = -a v + b F: a stiff step for RK4 at a dt of 0.05 s (a dt = 2)


def _run(substeps: int, **options):
    drive = open_loop("drive", [0.0, 0.5], [[1.0], [-1.0]], publishes="F")
    return simulate_system(first_order(a=A, b=B), [drive], duration=1.0, dt=DT, x0=[0.0], substeps=substeps,
                           **options)


def _rk4_factor(substeps: int) -> float:
    """The factor RK4 with ``substeps`` steps over DT multiplies v by (for v' = -a v), and the exact one."""
    h = DT / substeps
    z = -A * h
    return (1 + z + z ** 2 / 2 + z ** 3 / 6 + z ** 4 / 24) ** substeps, math.exp(-A * DT)


def test_too_few_substeps_warn_and_the_substeps_named_meet_the_tolerance():
    with pytest.warns(IntegrationAccuracyWarning, match=r"RK4 with 2 substep\(s\) per 0.05 s sample misses the "
                                                        r"tolerance 0.0001 .* in x.v .*substeps = (\d+) would meet it"):
        coarse = _run(2)
    needed = coarse.meta["rk4_error"]["substeps_needed"]
    assert needed > 2 and coarse.meta["rk4_error"]["state"] == "x.v"
    with warnings.catch_warnings():
        warnings.simplefilter("error", IntegrationAccuracyWarning)
        fine = _run(needed)
    assert fine.meta["rk4_error"]["largest_error_ratio"] <= 1.0


@pytest.mark.filterwarnings("ignore::uvsym.errors.IntegrationAccuracyWarning")
def test_the_estimate_follows_the_true_error_of_a_step():
    """For v' = -a v + b F the exact map over a sample is known: the doubling estimate of the checked
    steps' largest error is within a few tens of percent of the true error there (Richardson)."""
    for substeps in (2, 3, 6):
        result = _run(substeps, rk4_tolerance=1e-4)
        rk4, exact = _rk4_factor(substeps)
        v, F = result["x"]["v"], result["u"]["F"]
        true = np.abs((rk4 - exact) * (v[:-1] - B * F[:-1] / A))  # the error of each step from its own start
        scale = 1e-4 * np.max(np.abs(v)) + 1e-12
        estimate = result.meta["rk4_error"]["largest_error_ratio"] * scale
        k = round(result.meta["rk4_error"]["at_s"] / DT)
        assert estimate == pytest.approx(true[k], rel=0.3)
        assert true[k] >= 0.5 * np.max(true)  # the largest checked step is near the worst of the run


def test_no_check_without_a_tolerance_and_a_bad_tolerance_is_named():
    with warnings.catch_warnings():
        warnings.simplefilter("error", IntegrationAccuracyWarning)
        assert "rk4_error" not in _run(2, rk4_tolerance=None).meta
    for bad in (0.0, -1.0, float("nan"), True, "1e-4"):
        with pytest.raises(SimulationError, match="rk4_tolerance must be a positive number"):
            _run(2, rk4_tolerance=bad)


def test_a_step_where_an_actuator_fault_switches_is_not_checked():
    """A bias at 0.5 s switches inside RK4's last stage of the step before (a smear no substeps remove: its
    doubling estimate would be ~30 times the tolerance): excluded, and the smooth steps pass."""
    drive = open_loop("drive", [0.0], [[1.0]], publishes="F")
    fault = ActuatorFault(0, "bias", 5.0, Profile(onset=0.5))
    with warnings.catch_warnings():
        warnings.simplefilter("error", IntegrationAccuracyWarning)
        result = simulate_system(first_order(a=1.0), [drive], duration=1.0, dt=DT, x0=[0.0], substeps=1,
                                 actuator_faults=(fault,))
    assert result.meta["rk4_error"]["at_s"] != pytest.approx(0.45)
    assert result.meta["rk4_error"]["largest_error_ratio"] < 1.0


def test_a_scenario_sets_its_tolerance_or_turns_the_check_off():
    text = resources.files("uvsym.sim").joinpath("scenarios/plants/rov_yaw_compass_offset.toml").read_text()
    table = tomllib.loads(text)
    table["substeps"] = 2  # too few for the ROV's yaw rate
    with pytest.warns(IntegrationAccuracyWarning, match="substeps = "):
        simulate_system_scenario(parse_system_scenario(copy.deepcopy(table)))
    table["rk4_tolerance"] = False
    with warnings.catch_warnings():
        warnings.simplefilter("error", IntegrationAccuracyWarning)
        assert "rk4_error" not in simulate_system_scenario(parse_system_scenario(copy.deepcopy(table))).meta
    table["rk4_tolerance"] = -1
    with pytest.raises(ScenarioError, match="rk4_tolerance: expected a positive number or false, got -1"):
        parse_system_scenario(table)


def test_the_jumps_checked_are_the_largest_changes_ties_to_the_earlier_sample():
    """Held inputs stepping by 3 at three samples and by 2 at twenty (integers: exact, equal changes), by 1
    elsewhere: the JUMPS checked jumps are the three largest and the earliest nine of the tied twenty, beside
    the first EARLY samples and the evenly spread ones."""
    N = 400
    steps = np.ones(N + 1)
    big, tied = [350, 127, 390], list(range(30, 330, 15))
    steps[big], steps[tied] = 3.0, 2.0
    U = np.cumsum(steps)[:, None]  # U[k] - U[k - 1] = steps[k]
    spread = {round(k) for k in np.linspace(0, N - 1, CHECKS - EARLY - JUMPS)}
    expected = set(range(EARLY)) | set(big) | set(tied[:JUMPS - len(big)]) | spread
    assert check_indices(U) == sorted(expected)
    switching = np.zeros(N, bool)
    switching[tied[0]] = True  # a step where a fault switches is left out, not replaced
    assert check_indices(U, switching) == sorted(expected - {tied[0]})
