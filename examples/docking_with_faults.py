"""Docking with actuator faults
============================

The shipped docking scenario with a thruster bias and a rudder fault, varied: a larger rudder fault.

Loads the scenario, changes the proportional factor of both rudders (upper and lower, 0.8 as
shipped) to 0.5, simulates with the compiled fast path, prints the observers' converged estimates
and writes the result (.npz) and a quick-look figure into a folder of your choice (default: a
temporary one).

Run: python examples/docking_with_faults.py [OUTPUT_FOLDER]
"""

import dataclasses
import sys
import tempfile
from pathlib import Path

from uvsym.sim.scenario import load_scenario
from uvsym.sim.simulation import simulate_scenario

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp())
scenario = load_scenario("docking_faults")
faults = tuple(dataclasses.replace(f, value=0.5) if f.kind == "proportional" else f
               for f in scenario.actuator_faults)
scenario = dataclasses.replace(scenario, actuator_faults=faults, duration=40.0)
for f in scenario.actuator_faults:
    print(f"fault: {scenario.model.input_labels[f.actuator]} {f.kind} {f.value:g} from {f.profile.onset:g} s")

result = simulate_scenario(scenario, method="fast")
for name in result.signals:
    if name.startswith("f_hat/"):
        estimate = result[name]
        print(name, ", ".join(f"{label} = {v:.3g}" for label, v in zip(estimate.labels, estimate.values[-1])))
proportional = result["f_hat/proportional"]
print(f"wrote {result.save(out / 'docking.npz')}")
result.plot(out / "docking.svg")
assert abs(proportional.values[-1][proportional.labels.index("N")] - 0.5) < 0.05
