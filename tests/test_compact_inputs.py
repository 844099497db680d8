"""A run's inputs held as their varying columns (uvsym.sim.inputs): the dense table they stand for, exactly,
and the same table from the vehicle and the wired loops' builders either way."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from uvsym.errors import SimulationError
from uvsym.sim.inputs import CompactInputs, compact, input_column, input_rows
from uvsym.sim.scenario import load_scenario
from uvsym.sim.simulation import observer_blocks, prepare_run, scenario_arguments
from uvsym.sim.system_scenario import parse_system_scenario, scenario_inputs

ROOT = Path(__file__).resolve().parents[1]


def test_a_table_compacts_to_its_varying_columns_and_back_exactly():
    W = np.zeros((6, 5))
    W[:, 0] = np.arange(6) * 0.1
    W[:, 2] = 3.5
    W[3:, 4] = np.nan  # NaN never equals its first row: the column varies
    W[:, 3] = [1.0, 1.0, 1.0, 1.0, 1.0, 2.0]
    table = compact(W)
    assert table.columns.tolist() == [0, 3, 4] and table.shape == (6, 5) and len(table) == 6
    np.testing.assert_array_equal(table.dense(), W)
    np.testing.assert_array_equal(table[2:4].dense(), W[2:4])
    np.testing.assert_array_equal(input_rows(table, [5, 0]), W[[5, 0]])
    np.testing.assert_array_equal(input_rows(table, 4), W[4])
    np.testing.assert_array_equal(table.column(2), np.full(6, 3.5))
    np.testing.assert_array_equal(table.column(3), W[:, 3])
    assert input_rows(W, 1) is not None and np.array_equal(input_rows(W, 1), W[1])
    np.testing.assert_array_equal(input_column(table, 3), input_column(W, 3))
    np.testing.assert_array_equal(input_column(table, 2), W[:, 2])


def test_compact_inputs_of_the_wrong_shapes_are_refused_naming_them():
    with pytest.raises(SimulationError, match="ascending columns"):
        CompactInputs(np.zeros(3), np.array([2, 1]), np.zeros((4, 2)))
    with pytest.raises(SimulationError, match="ascending columns"):
        CompactInputs(np.zeros(3), np.array([0, 3]), np.zeros((4, 2)))  # column 3 of a 3-column table
    with pytest.raises(SimulationError, match=r"rows \(k, 1\)"):
        CompactInputs(np.zeros(3), np.array([0]), np.zeros((4, 2)))
    with pytest.raises(SimulationError, match="k >= 1"):
        compact(np.zeros((0, 3)))
    with pytest.raises(TypeError, match="sliced by samples"):
        compact(np.zeros((2, 3)))[1]


def test_the_docking_run_builds_the_same_table_compact_or_dense_with_few_columns_varying():
    scenario = load_scenario("docking_faults")
    observers = observer_blocks(scenario.model, scenario.observers, scenario.step)
    arguments = scenario_arguments(scenario, observers)
    dense = prepare_run(scenario.model, scenario.controller, **arguments).W
    kept = prepare_run(scenario.model, scenario.controller, **arguments, compact=True)
    assert isinstance(kept.W, CompactInputs) and isinstance(dense, np.ndarray)
    np.testing.assert_array_equal(kept.W.dense(), dense)
    varying = np.flatnonzero(~np.all(dense == dense[0], axis=0))
    assert set(varying) <= set(kept.W.columns.tolist()) and kept.W.columns.size <= dense.shape[1] // 3


def test_a_wired_scenario_builds_the_same_table_compact_or_dense():
    root = ROOT / "examples" / "dc_motor"
    table = tomllib.loads((root / "speed_sensor_bias.toml").read_text())
    scenario = parse_system_scenario(dict(table, duration=4.0), root=root)
    np.testing.assert_array_equal(scenario_inputs(scenario, compact=True).dense(), scenario_inputs(scenario))
