"""Simulation: closed loops of a Model with controllers, observers, faults and supervisors, and
closed loops of any System with blocks wired by signal name."""

from uvsym.sim.blocks import Block, block, observer_block, renamed
from uvsym.sim.closed_loop import ClosedLoop, build_closed_loop
from uvsym.sim.controllers import Autopilot, LineOfSight, Loop
from uvsym.sim.feedback import lqr, lqr_gain, open_loop, pid, state_feedback
from uvsym.sim.loop import SampledLoop
from uvsym.sim.result import Signal, SimResult
from uvsym.sim.run import METHODS, Correction, Substitution, Supervisor
from uvsym.sim.simulation import simulate
from uvsym.sim.system_simulation import simulate_system
from uvsym.sim.wiring import WiredLoop, interconnect

__all__ = [
    "METHODS",
    "Autopilot",
    "Block",
    "ClosedLoop",
    "Correction",
    "LineOfSight",
    "Loop",
    "SampledLoop",
    "Signal",
    "SimResult",
    "Substitution",
    "Supervisor",
    "WiredLoop",
    "block",
    "build_closed_loop",
    "interconnect",
    "lqr",
    "lqr_gain",
    "observer_block",
    "open_loop",
    "pid",
    "renamed",
    "simulate",
    "simulate_system",
    "state_feedback",
]
