"""The actuator-fault campaign (``campaign.toml`` beside this file): which runs count, and its targets.

A run counts towards the correct fraction when its fault is *identifiable* and *excited*, both
judged from the vehicle's geometry and the simulated commands, never from the diagnosis's own
verdicts:

- identifiable: the faulty actuator's column of B (at the initial state, the actuators at their
  mean expected values after the onset) is non-zero and not parallel to any other actuator's
  non-zero one (the smallest singular value of the two unit columns side by side is at least
  ``PARALLEL``): otherwise no measurement can tell the two apart;
- excited: after the onset (over ``EXCITATION_S``) the actuator's expected value varies by at
  least ``VARIATION`` of its range (fault kinds differ only in how they follow the command) and,
  for a fault whose effect is proportional to the command (or to its distance from the stuck
  value), that effect's RMS is at least ``VISIBLE`` of the range.

A run is correct when the decision standing at its end names the right actuator and kind and the
identified size is within ``SIZE_TOLERANCE`` (relative) of the injected one.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from uvsym.faults import actuator_kind
from uvsym.observers.identification import configuration_at

__all__ = ["CAMPAIGN", "metrics", "counts", "size_intervals", "targets"]

CAMPAIGN = Path(__file__).with_name("campaign.toml")
PARALLEL = 1e-3
EXCITATION_S = 10.0
VARIATION = 0.01
VISIBLE = 0.02
SIZE_TOLERANCE = 0.02
TARGETS = {"campaign_correct_fraction": 0.95, "campaign_false_alarms_no_fault": 0,
           "campaign_median_isolation_delay_s": 5.0, "campaign_max_isolation_delay_s": 10.0, "campaign_crashes": 0}


def metrics(scenario, result, events) -> dict:
    """Per-run columns: identifiable, excited and the command's variation and effect (fractions of range)."""
    if not scenario.actuator_faults:
        return {"identifiable": None, "excited": None, "command_variation": None, "effect_rms": None}
    fault = scenario.actuator_faults[-1]
    model, a = scenario.model, fault.actuator
    after = (result.t >= fault.profile.onset) & (result.t <= fault.profile.onset + EXCITATION_S)
    commands = result["u_expected"].values[after]
    B = configuration_at(model, scenario.eta0, scenario.nu0, commands.mean(axis=0)).B
    norms = np.linalg.norm(B, axis=0)
    unit = B / np.maximum(norms, 1e-300)
    identifiable = bool(norms[a] > 0) and all(np.linalg.svd(unit[:, [a, b]], compute_uv=False)[-1] >= PARALLEL
                                              for b in range(model.n_inputs) if b != a and norms[b] > 0)
    span = float(model.u_max[a] - model.u_min[a])
    command = commands[:, a]
    kind = actuator_kind(fault.kind)
    effect = kind.deliver(command, fault.value) - command
    variation = float(np.std(command)) / span
    effect_rms = float(np.sqrt(np.mean(effect**2))) / span
    return {"identifiable": identifiable, "excited": bool(variation >= VARIATION and effect_rms >= VISIBLE),
            "command_variation": variation, "effect_rms": effect_rms}


def correct(row: dict) -> bool:
    """The run's standing decision names the true actuator and kind, and the size is within tolerance."""
    return (row["isolated_target"] == row["true_actuator"] and row["isolated_kind"] == row["true_kind"]
            and row["size_error_rel"] is not None and row["size_error_rel"] <= SIZE_TOLERANCE)


def counts(rows: list[dict]) -> dict:
    """The campaign's figures from its result rows (dicts of :func:`uvsym.campaign.run_campaign`)."""
    ok = [r for r in rows if r["status"] == "ok"]
    faulty = [r for r in ok if r["true_actuator"] is not None]
    counted = [r for r in faulty if r["identifiable"] and r["excited"]]
    delays = np.array([r["isolation_delay_s"] for r in counted if r["isolation_delay_s"] is not None])
    return {
        "campaign_runs": len(rows),
        "campaign_crashes": len(rows) - len(ok),
        "campaign_fault_runs": len(faulty),
        "campaign_counted_runs": len(counted),
        "campaign_correct_fraction": sum(map(correct, counted)) / len(counted) if counted else None,
        "campaign_correct_fraction_all_faults": sum(map(correct, faulty)) / len(faulty) if faulty else None,
        "campaign_false_alarms_no_fault": sum(r["false_alarms"] for r in ok if r["true_actuator"] is None),
        "campaign_false_alarms_before_onset": sum(r["false_alarms"] for r in faulty),
        "campaign_isolated_counted": int(len(delays)),
        "campaign_median_isolation_delay_s": float(np.median(delays)) if len(delays) else None,
        "campaign_max_isolation_delay_s": float(np.max(delays)) if len(delays) else None,
    }


def size_intervals(rows: list[dict]) -> list[dict]:
    """Per case, over the counted runs whose standing decision names the true actuator and kind: how many
    identified sizes lie within ``SIZE_TOLERANCE`` and within 2 of the diagnosis's stated standard
    deviations of the truth, and the largest error in stated deviations (None: no std stated)."""
    table = []
    for case in dict.fromkeys(r["case"] for r in rows):
        right = [r for r in rows if r["case"] == case and r["status"] == "ok" and r["true_actuator"] is not None
                 and r["identifiable"] and r["excited"] and r["isolated_target"] == r["true_actuator"]
                 and r["isolated_kind"] == r["true_kind"] and r["size_error_rel"] is not None]
        in_std = [r["size_error_std"] for r in right if r["size_error_std"] is not None]
        table.append({"case": case, "runs": len(right),
                      "within_tolerance": sum(r["size_error_rel"] <= SIZE_TOLERANCE for r in right),
                      "with_std": len(in_std), "within_2_std": sum(e <= 2.0 for e in in_std),
                      "max_error_std": max(in_std) if in_std else None})
    return table


def targets(figures: dict) -> dict:
    """Target name -> met (bool), each computed from ``figures`` (:func:`counts`); a figure without a value
    (None: no run to compute it from, e.g. every run crashed) meets none."""
    def at_least(key: str, bound: float) -> bool:
        return figures[key] is not None and figures[key] >= bound

    def at_most(key: str, bound: float) -> bool:
        return figures[key] is not None and figures[key] <= bound

    return {
        "correct fraction >= 0.95 (identifiable, excited)":
            at_least("campaign_correct_fraction", TARGETS["campaign_correct_fraction"]),
        "no false alarm without a fault": figures["campaign_false_alarms_no_fault"] == 0,
        "median isolation delay <= 5 s": at_most("campaign_median_isolation_delay_s", 5.0),
        "max isolation delay <= 10 s": at_most("campaign_max_isolation_delay_s", 10.0),
        "no run crashed": figures["campaign_crashes"] == 0,
    }
