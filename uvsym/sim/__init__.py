"""Simulation: closed loops of a Model with controllers, observers, faults and supervisors."""

from uvsym.sim.closed_loop import ClosedLoop, ObserverBlock, build_closed_loop
from uvsym.sim.controllers import Autopilot, LineOfSight, Loop
from uvsym.sim.result import Signal, SimResult
from uvsym.sim.run import METHODS, Correction, Supervisor
from uvsym.sim.simulation import simulate

__all__ = [
    "METHODS",
    "Autopilot",
    "ClosedLoop",
    "Correction",
    "LineOfSight",
    "Loop",
    "ObserverBlock",
    "Signal",
    "SimResult",
    "Supervisor",
    "build_closed_loop",
    "simulate",
]
