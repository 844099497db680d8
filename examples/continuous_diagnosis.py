"""Continuous actuator diagnosis
=============================

uvsym's continuous actuator diagnosis on faults the shipped experiment does not have.

Starts from the shipped ``docking_diagnosis`` scenario, replaces its faults with a rudder stuck at
0.1 rad from 6 s and an intermittent thruster bias of 8 N (on 4 s of every 10 s from 12 s), adds
surge-speed sensor noise that the diagnosis is told about, runs it without correction and prints
the decision log, then writes it as JSON (the schema of ``uvsym simulate --events``) and a figure of
the run (faults' onsets dashed, alarms dotted) into a folder of your choice (default: a temporary one).

Run: python examples/continuous_diagnosis.py [OUTPUT_FOLDER]
"""

import dataclasses
import sys
import tempfile
from pathlib import Path

from uvsym.diagnosis.events import write_events
from uvsym.faults import ActuatorFault, Profile, SensorFault
from uvsym.sim.scenario import load_scenario
from uvsym.sim.simulation import simulate_scenario

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp())
scenario = load_scenario("docking_diagnosis")
inputs, states = scenario.model.input_labels, scenario.model.state_labels
faults = (ActuatorFault(inputs.index("delta_ru"), "constant", 0.1, Profile(onset=6.0)),
          ActuatorFault(inputs.index("X"), "bias", 8.0, Profile("intermittent", onset=12.0, period=10.0, duty=0.4)))
noise = (SensorFault(states.index("u"), "noise", 0.005),)  # m/s, from the start: the sensor's specification
settings = dataclasses.replace(scenario.diagnosis, correct=False, noise={"u": 0.005})
scenario = dataclasses.replace(scenario, duration=30.0, actuator_faults=faults, sensor_faults=noise,
                               diagnosis=settings)

result = simulate_scenario(scenario)
for e in result.events:
    value = "" if e["value"] is None else f" {e['value']:.4g}"
    print(f"{e['t']:6.2f} s  {e['event']:<10} {e['target'] or ''} {e['kind'] or ''}{value}")
out.mkdir(parents=True, exist_ok=True)
log = write_events(result.events, out / "events.json")
print(f"wrote {log}")
result.plot(out / "diagnosis.svg")
