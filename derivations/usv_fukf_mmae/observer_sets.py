"""``uvsym codegen usv-fukf-mmae [--method ekf]``: a bank's step as a C package.

Its example (``main.c``, the float check of ``--float``, the target harness's vectors) is every
``EXAMPLE_EVERY``-th step of the bank in the shipped scenario's run (healthy legs and both thruster
faults): the loop does not log a bank's state, so the states are the bank's initial state stepped
by CasADi through the logged measurements and the guidance's thrust commands (what the bank reads
in the loop), checked against the outputs the loop logged.
"""

from __future__ import annotations

import functools

import numpy as np

from derivations.usv_fukf_mmae.experiment import disturbed_plant, run
from derivations.usv_fukf_mmae.paper import CITATION
from derivations.usv_fukf_mmae.scenario import SCENARIO, block_table, parsed, read
from uvsym.codegen.estimators import exported_observer
from uvsym.codegen.example import Example
from uvsym.codegen.observer_sets import ObserverSet
from uvsym.errors import CodegenError, UnknownNameError
from uvsym.observers.mmae_design import FILTERS, designed_bank
from uvsym.sim.fields import Fields

__all__ = ["EXAMPLE_EVERY", "usv_fukf_mmae", "shipped_bank"]

EXAMPLE_EVERY = 10  # samples: 600 steps of the 6000 of the run
LOGGED_TOLERANCE = 1e-8  # largest |restepped - logged| of a published output (compiled loop vs CasADi's VM)


def shipped_bank(method: str = "ukf"):
    """The shipped scenario's MMAE bank (an Observer) of block ``method`` ('ukf' or 'ekf'), as the
    scenario designs it for the loop (no-fault, left and right models)."""
    if method not in FILTERS:
        raise UnknownNameError(f"unknown method {method!r}; known: {', '.join(FILTERS)}")
    table = read()
    return designed_bank(Fields(block_table(table, method), f"blocks.{method}"), disturbed_plant(), table["step"],
                         method)


@functools.lru_cache(maxsize=2)
def bank_example(method: str = "ukf") -> Example:
    """The bank's steps along the shipped scenario's run (module docstring)."""
    obs, scenario = shipped_bank(method), parsed(read())
    result = run(scenario)
    y = np.column_stack([result["y"][n] for n in obs.reads_y.names])
    u = np.column_stack([result["guidance"][n] for n in obs.reads_u.names])
    logged = result[method].values
    s, p = np.asarray(scenario.z0[scenario.loop.layout[method]], dtype=float), obs.p0
    rows = range(0, len(result.t), EXAMPLE_EVERY)
    states = np.empty((len(rows), obs.state.size))
    for k in range(len(result.t)):
        if k % EXAMPLE_EVERY == 0:
            states[k // EXAMPLE_EVERY] = s
        s_next, out = obs.step(s, y[k], u[k], p)
        if not np.max(np.abs(np.asarray(out).ravel() - logged[k])) <= LOGGED_TOLERANCE:
            raise CodegenError(f"{method} bank example: the restepped bank publishes other values than the loop "
                               f"logged at t = {result.t[k]:g} s")
        s = np.asarray(s_next).ravel()
    return Example(obs.step.name(), (states, y[rows], u[rows], np.tile(p, (len(rows), 1))),
                   f"the shipped scenario {SCENARIO}, every {EXAMPLE_EVERY}th step of the {method} bank "
                   f"({len(rows)} of {len(result.t)}, both thruster faults)")


def usv_fukf_mmae(method: str = "ukf") -> ObserverSet:
    """The MMAE bank (no-fault, left, right models) of the Otter's thrusters, 'ukf' or 'ekf', tuned
    for the shipped scenario."""
    obs = shipped_bank(method)
    return ObserverSet(f"uvsym_otter_{method}_mmae", f"{method.upper()} MMAE bank of the Otter's thrusters "
                       f"(step {obs.dt:g} s)", (exported_observer(obs),), citation=CITATION,
                       example=bank_example(method))
