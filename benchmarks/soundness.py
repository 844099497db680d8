"""Soundness of uvsym verify on generated claims with known truth: no proved-false, no refuted-true.

Run ``python benchmarks/soundness.py [count]`` (default 1000 of each kind; on demand, not in CI);
writes ``benchmarks/results/soundness.json`` with ``cases`` (claims checked), ``unsound`` (a
``proved`` for a false claim, a ``refuted`` for a true one, or an interval bound that misses the
exact value at a sampled point) and ``inconclusive_rate`` (region, linear and identity claims
that were neither decided nor checked), per kind as well:

- ``interval``: one operation of uvsym's interval kernel on random boxes of every kind
  (straddling 0, subnormal, huge, zero width, anything), sampled points against mpmath;
- ``region``: :func:`uvsym.verify.borderline.region_cases` through ``region_decrease``;
- ``linear``: :func:`uvsym.verify.borderline.linear_cases`, each as a continuous
  (``lyapunov_decrease``) and a discrete (``discrete_lyapunov_decrease``) claim;
- ``identity``: :func:`uvsym.verify.borderline.identity_cases` through ``prove_identity``;
- ``c_semantics``: :func:`uvsym.verify.borderline.c_semantics_cases` (fmod, copysign, floor, ceil,
  sign, fmin/fmax, atan2 at their kinks) through ``prove_identity``, each verdict re-checked by
  CasADi's own evaluation (:func:`~uvsym.verify.borderline.c_semantics_unsound`).

``python benchmarks/soundness.py COUNT KIND`` runs one kind only, into ``soundness_<kind>.json``;
the C-semantics kind also counts the cases using each operation (``fewest_per_operation``: at least
1,000 of each is the target; ``python benchmarks/soundness.py 6000 c_semantics`` reaches it).
"""

from __future__ import annotations

import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import finish  # noqa: E402

from uvsym.verify.borderline import (
    C_OPERATIONS,
    c_semantics_cases,
    c_semantics_unsound,
    identity_cases,
    linear_cases,
    operations,
    region_cases,
)
from uvsym.verify.enclosure_check import BINARY, BOX_KINDS, OPERATIONS, enclosure_violations, random_box
from uvsym.verify.identity import prove_identity
from uvsym.verify.lyapunov import discrete_lyapunov_decrease, lyapunov_decrease
from uvsym.verify.region import region_decrease

RESULTS = Path(__file__).resolve().parent / "results" / "soundness.json"


def _tally(outcomes: list[tuple[str, bool]], seconds: float, examples: list[str]) -> dict:
    """Counts of one kind: cases, unsound (a proved-false, a refuted-true or a missed enclosure),
    statuses, inconclusive rate."""
    statuses = [s for s, _ in outcomes]
    unsound = [(s, holds) for s, holds in outcomes
               if (s == "proved" and not holds) or (s == "refuted" and holds) or s == "missed"]
    return {"cases": len(outcomes), "unsound": len(unsound), "seconds": round(seconds, 1),
            "statuses": {s: statuses.count(s) for s in sorted(set(statuses))},
            "inconclusive_rate": statuses.count("inconclusive") / max(1, len(statuses)), "unsound_examples": examples}


def interval_kind(count: int, rng) -> dict:
    started, outcomes, examples = time.perf_counter(), [], []
    names = sorted(OPERATIONS)
    for k in range(count):
        name = names[k % len(names)]
        boxes = [random_box(rng, str(rng.choice(BOX_KINDS))) for _ in range(2 if name in BINARY else 1)]
        violations = enclosure_violations(name, boxes, rng)
        examples += violations[:1]
        outcomes.append(("missed" if violations else "enclosed", True))  # a box with a missed point counts once
    return _tally(outcomes, time.perf_counter() - started, examples[:5])


def region_kind(count: int) -> dict:
    started, outcomes, examples = time.perf_counter(), [], []
    for case in region_cases(count, seed=101):
        certificate = region_decrease(case.name, *case.arguments(), max_boxes=20_000)
        holds = case.holds
        if certificate.status == "refuted" and not case.W(list(certificate.counterexample["x"].values())) > 0:
            holds = True  # a counterexample that does not violate the claim is unsound whatever the truth
        outcomes.append((certificate.status, holds))
        if (certificate.status == "proved") != holds and certificate.status in ("proved", "refuted"):
            examples.append(f"{case.name}: {certificate.status}, holds {case.holds}")
    return _tally(outcomes, time.perf_counter() - started, examples[:5])


def linear_kind(count: int) -> dict:
    started, outcomes, examples = time.perf_counter(), [], []
    for case in linear_cases(count, seed=102):
        for status, holds in ((lyapunov_decrease(case.name, [case.A], case.gamma, "generated").status, case.holds),
                              (discrete_lyapunov_decrease(case.name, case.A, case.rho, "generated").status,
                               case.holds_discrete)):
            outcomes.append((status, holds))
            if (status == "proved" and not holds) or (status == "refuted" and holds):
                examples.append(f"{case.name}: {status}, holds {holds}")
    return _tally(outcomes, time.perf_counter() - started, examples[:5])


def identity_kind(count: int) -> dict:
    started, outcomes, examples = time.perf_counter(), [], []
    for case in identity_cases(count, seed=103):
        status = prove_identity(case.kind, case.lhs, case.rhs, case.inputs, "all x", symbolic_seconds=1.0).status
        outcomes.append((status, case.holds))
        if (status == "proved" and not case.holds) or (status == "refuted" and case.holds):
            examples.append(f"{case.kind}: {status}")
    result = _tally(outcomes, time.perf_counter() - started, examples[:5])
    result["by_class"] = {kind: {s: sum(1 for c, (st, _) in zip(identity_cases(count, seed=103), outcomes)
                                        if c.kind == kind and st == s) for s in result["statuses"]}
                          for kind in ("relative", "far", "spot", "masked", "cancelling")}
    return result


def _shard(count: int, shard: int, shards: int) -> list[int]:
    """The case indices of one processor: pairs of cases (a true and a false one, of unlike cost) dealt in turn."""
    return [k for k in range(count) if (k // 2) % shards == shard]


def _c_semantics_verdicts(count: int, shard: int, shards: int) -> list[tuple[str, str | None]]:
    """Status (or "missed") and the C check's objection for every ``shards``-th case from ``shard``."""
    verdicts = []
    cases = c_semantics_cases(count, seed=104)
    for case in (cases[k] for k in _shard(count, shard, shards)):
        try:
            certificate = prove_identity(case.kind, case.lhs, case.rhs, case.inputs, "the reals",
                                         symbolic_seconds=1.0)
        except Exception as exc:  # a raw exception is a finding too (counted as crashed), not the end of the run
            verdicts.append(("crashed", f"{case.kind}: {type(exc).__name__}: {str(exc)[:200]}"))
            continue
        why = c_semantics_unsound(case, certificate)
        # a verdict the C check rejects is unsound whatever the generator's truth
        verdicts.append(("missed" if why else certificate.status, why))
    return verdicts


def c_semantics_kind(count: int) -> dict:
    """The C-semantics identities, on every processor (each case is independent); counts by the
    generator's class and by the operations (``C_OPERATIONS``) each case uses."""
    started, shards = time.perf_counter(), os.cpu_count() or 1
    with ProcessPoolExecutor(shards) as pool:
        parts = list(pool.map(_c_semantics_verdicts, [count] * shards, range(shards), [shards] * shards))
    cases = c_semantics_cases(count, seed=104)
    verdicts = [None] * count
    for shard, part in enumerate(parts):
        for k, verdict in zip(_shard(count, shard, shards), part):
            verdicts[k] = verdict
    outcomes = [(status, case.holds) for case, (status, _) in zip(cases, verdicts)]
    result = _tally(outcomes, time.perf_counter() - started, [why for _, why in verdicts if why][:5])
    result["by_class"] = {kind: {s: sum(1 for c, (st, _) in zip(cases, outcomes) if c.kind == kind and st == s)
                                 for s in result["statuses"]} for kind in dict.fromkeys(c.kind for c in cases)}
    used = [operations(case) for case in cases]
    result["by_operation"] = {op: {"cases": sum(op in u for u in used),
                                   "unsound": sum(op in u and st == "missed" for u, (st, _) in zip(used, verdicts)),
                                   "crashed": sum(op in u and st == "crashed" for u, (st, _) in zip(used, verdicts))}
                              for op in C_OPERATIONS.values()}
    result["fewest_per_operation"] = min(v["cases"] for v in result["by_operation"].values())
    result["crashed"] = sum(status == "crashed" for status, _ in verdicts)
    return result


KINDS = {"region": region_kind, "linear": linear_kind, "identity": identity_kind, "c_semantics": c_semantics_kind}


def main(count: int = 1000, only: str | None = None) -> dict:
    kinds = {"interval": interval_kind(count, np.random.default_rng(100))} if only in (None, "interval") else {}
    if kinds:
        print(f"interval: {kinds['interval']['cases']} cases, {kinds['interval']['unsound']} unsound", flush=True)
    for name, run in KINDS.items():
        if only and name != only:
            continue
        kinds[name] = run(count)
        print(f"{name}: {kinds[name]['cases']} cases, {kinds[name]['unsound']} unsound, inconclusive rate "
              f"{kinds[name]['inconclusive_rate']:.3f}, {kinds[name]['seconds']} s", flush=True)
    claims = [kinds[k] for k in KINDS if k in kinds]
    results = {"cases": sum(k["cases"] for k in kinds.values()), "unsound": sum(k["unsound"] for k in kinds.values()),
               "inconclusive_rate": sum(k["statuses"].get("inconclusive", 0) for k in claims)
               / max(1, sum(k["cases"] for k in claims)),
               "generated_per_kind": count, "kinds": kinds}
    path = RESULTS if only is None else RESULTS.with_name(f"soundness_{only}.json")
    targets = {"unsound_max": 0, "generated_per_kind_min": 1000}
    if "c_semantics" in kinds:
        results["fewest_per_operation"] = kinds["c_semantics"]["fewest_per_operation"]
        results["crashed"] = kinds["c_semantics"]["crashed"]
        targets |= {"fewest_per_operation_min": 1000, "crashed_max": 0}
    return finish(results, targets, path)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1000, sys.argv[2] if len(sys.argv) > 2 else None)
