"""C packages and claims of a scenario's blocks: ``uvsym codegen FILE.toml`` and ``uvsym verify FILE.toml``.

:func:`scenario_package` exports the step of every block a scenario's ``[[blocks]]`` name (or those
selected), ``<block>_step(s, r) -> (s_next, out)``, each argument documented signal by signal with
its unit, as one C package (:class:`~uvsym.codegen.observer_sets.ObserverSet`). Its example
(``main.c``, the float check) is the first block's run in the scenario: its reads as the loop
logged them, and its states from its initial state stepped through them by CasADi.

:func:`scenario_claims` states what can be proved of the scenario's estimators on its plant
(:mod:`uvsym.verify.estimators`): for an observer whose state estimates the plant's, its sampled
step linearised at the plant's operating point contracts; for a Luenberger block designed for a
decay rate, its linearised error decays at that rate (the LMI design's own claim, re-checked). An
estimator of which nothing can be claimed (a UKF's state holds its covariance) is listed as such.
"""

from __future__ import annotations

import difflib

import numpy as np

from uvsym.codegen.arguments import entries_of
from uvsym.codegen.example import Example
from uvsym.codegen.observer_sets import ObserverSet
from uvsym.codegen.package import Exported
from uvsym.errors import ScenarioError

__all__ = ["scenario_blocks", "scenario_package", "scenario_claims"]


def scenario_blocks(scenario, names=None) -> list:
    """The scenario's [[blocks]] (not its set-point schedules), or those ``names`` (ScenarioError naming
    an unknown one, with the known)."""
    blocks = [b for b in scenario.loop.blocks if not b.name.startswith("setpoint_")]
    if names is None:
        return blocks
    known = {b.name: b for b in blocks}
    unknown = [n for n in names if n not in known]
    if unknown:
        near = difflib.get_close_matches(unknown[0], list(known), n=1)
        raise ScenarioError(f"blocks: {scenario.name} has no block {unknown[0]!r}"
                            + (f" (did you mean {near[0]!r}?)" if near else "") + f"; its blocks: {', '.join(known)}")
    return [known[n] for n in names]


def _exported(block) -> Exported:
    return Exported(block.step, (entries_of("block state", block.state), entries_of("reads", block.reads)),
                    (entries_of("next block state", block.state), entries_of("published", block.publishes)),
                    block.description or f"{block.name}: one step of {block.dt:g} s" if block.dt else block.name)


def _logged(result, name: str) -> np.ndarray:
    """(N,) the loop signal ``name`` as the result logged it: ``B.n`` from group B, a bare name from the
    one group that logs it (the plant's outputs y first, then its inputs u, then the blocks)."""
    group, _, label = name.rpartition(".")
    if group:
        return np.asarray(result[group][label], dtype=float)
    if name == "t":
        return np.asarray(result.t, dtype=float)
    for g in ("y", "u", *result.signals):
        if name in result.signals[g].labels:
            return np.asarray(result[g][name], dtype=float)
    raise ScenarioError(f"codegen example: the run logged no signal {name!r}")


def block_example(scenario, block, result, steps: int = 200) -> Example:
    """``steps`` samples of the block's step in the scenario's run ``result``: its reads as logged and
    its states from the scenario's initial block state, stepped through them by CasADi."""
    steps = min(steps, len(result.t))
    R = np.column_stack([_logged(result, n) for n in block.reads.names])[:steps] if block.reads.size else \
        np.zeros((steps, 0))
    s0 = scenario.z0[scenario.loop.layout[block.name]]
    states = np.empty((steps, block.state.size))
    s = np.asarray(s0, dtype=float)
    for k in range(steps):
        states[k] = s
        s = np.asarray(block.step(s, R[k])[0]).ravel()
    return Example(block.step.name(), (states, R),
                   f"{scenario.name}: the first {steps} samples of block {block.name} in the scenario's run")


def scenario_package(scenario, names=None, result=None) -> ObserverSet:
    """The C package of the scenario's blocks (module docstring); ``result``: its run (simulated when None)."""
    blocks = [b for b in scenario_blocks(scenario, names) if b.state.size]
    if not blocks:
        raise ScenarioError(f"blocks: {scenario.name} has no block with a state to export (set-point tables and "
                            "static gains are not exported)")
    if result is None:
        from uvsym.sim.system_scenario import simulate_system_scenario

        result = simulate_system_scenario(scenario)
    name = "".join(c if c.isalnum() else "_" for c in scenario.name).strip("_") or "scenario"
    return ObserverSet(name, f"{scenario.description or scenario.name}: the steps of "
                             f"{', '.join(b.name for b in blocks)}", tuple(_exported(b) for b in blocks),
                       example=block_example(scenario, blocks[0], result))


def scenario_claims(scenario, table: dict) -> tuple[list, list[str]]:
    """(certificates, notes): the claims of the module docstring for the scenario's estimators (``table``:
    its parsed TOML, for the design parameters); notes name the blocks nothing is claimed of, and why."""
    from uvsym.verify.estimators import linear_decay_claim, sampled_decay_claim

    plant = scenario.plant
    tables = {t.get("name", t.get("type")): t for t in table.get("blocks", []) if isinstance(t, dict)}
    certificates, notes = [], []
    for block in scenario_blocks(scenario):
        observer = block.source
        if observer is None:
            notes.append(f"{block.name}: runs no observer of the plant's state (a controller, a schedule or a "
                         "bank of its own): nothing claimed")
            continue
        if observer.state.size != plant.x.size:
            notes.append(f"{block.name}: its state ({observer.state.size} entries) is not an estimate of "
                         f"{plant.name}'s {plant.x.size} states alone: no contraction claimed")
            continue
        certificates.append(sampled_decay_claim(observer, plant))
        decay = tables.get(block.name, {}).get("decay")
        if decay is not None:
            certificates.append(linear_decay_claim(observer, plant, float(decay)))
    return certificates, notes
