"""Simulation: closed loops of a Model with controllers, observers, faults and supervisors, and
closed loops of any System with blocks wired by signal name.

The names below are imported on first use (:mod:`uvsym.lazy`): importing one submodule (the scenario
lookup of ``uvsym simulate``, the integration methods) does not import the simulator.
"""

from uvsym.lazy import lazy_exports

_EXPORTS = {  # name -> the submodule that defines it
    **dict.fromkeys(["Block", "block", "observer_block", "renamed"], "blocks"),
    **dict.fromkeys(["ClosedLoop", "build_closed_loop"], "closed_loop"),
    **dict.fromkeys(["Autopilot", "LineOfSight", "Loop"], "controllers"),
    **dict.fromkeys(["lqr", "lqr_gain", "open_loop", "pid", "state_feedback"], "feedback"),
    "SampledLoop": "loop",
    **dict.fromkeys(["Signal", "SimResult"], "result"),
    "METHODS": "integrator_options",
    **dict.fromkeys(["Correction", "Substitution", "Supervisor"], "run"),
    "simulate": "simulation",
    "simulate_system": "system_simulation",
    **dict.fromkeys(["WiredLoop", "interconnect"], "wiring"),
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
