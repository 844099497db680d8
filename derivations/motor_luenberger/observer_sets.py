"""``uvsym codegen motor-luenberger``: the motor observer's step as a C package.

The observer is uvsym's Luenberger design (:mod:`.design`) on the induction-motor model; it does
not implement Yu et al. 2018's unknown-input observer, so the package cites no paper.
Its example (``main.c``, the float check of ``--float``) is ``EXAMPLE_STEPS`` steps of the
fault-free experiment run (:func:`.experiment.run`) from ``EXAMPLE_START``: the observer's state,
the noisy measurements and the supply voltages.
"""

from __future__ import annotations

import functools

from derivations.motor_luenberger.design import DECAY, DT, design
from derivations.motor_luenberger.experiment import run
from uvsym.codegen.estimators import exported_observer, observer_example
from uvsym.codegen.observer_sets import ObserverSet

__all__ = ["EXAMPLE_START", "EXAMPLE_STEPS", "motor_luenberger"]

EXAMPLE_START = 0.5  # s: the observer has converged from its start at the operating point
EXAMPLE_STEPS = 1000


@functools.lru_cache(maxsize=1)
def _healthy_run():
    return run(None)


def motor_luenberger(decay: float = DECAY, dt: float = DT) -> ObserverSet:
    """The Luenberger observer of the induction motor, gain for ``decay`` (1/s), step of ``dt`` (s)."""
    obs = design(float(decay), float(dt)).observer
    result = _healthy_run()
    steps = min(EXAMPLE_STEPS, int((result.t[-1] - EXAMPLE_START) / obs.dt))
    example = observer_example(obs, result, EXAMPLE_START, steps,
                               f"the fault-free motor experiment, {steps} steps of {obs.dt:g} s from "
                               f"t = {EXAMPLE_START:g} s")
    return ObserverSet("uvsym_induction_motor", f"Luenberger observer of the induction motor (decay {decay:g} 1/s, "
                       f"step {dt:g} s)", (exported_observer(obs),), example=example)
