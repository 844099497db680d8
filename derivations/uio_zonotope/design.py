"""The quadrotor, its two measurement set-ups and the UIO bank with its zonotope bands (uvsym's choices).

Plant: ``uvsym.plant("quadrotor")`` linearised at hover by CasADi (``A, B, E`` by
``casadi.jacobian``), as a linear System discretised by zero-order hold at ``DT`` (the paper's
0.01 s): ``x_{k+1} = G x_k + H u_k + D1 tau_d``. The unknown input is the yaw disturbance
torque (D1, one column), never bounded or measured. Two set-ups:

- the paper's: the six attitude states, ``y = (phi, theta, psi)`` (the paper's angles);
- uvsym's: all eight states measured (angles from the attitude estimate, body rates from gyros,
  z from an altimeter, w from a vertical-speed sensor), ``y = x + v`` with ``|v| <= NOISE_BOUND``.

Paper-silent numbers (all uvsym's): the noise bounds, the initial error box, F's eigenvalues
``POLES``, the order bound ``GENERATORS`` of the joint error-noise zonotope, the LQR weights.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import casadi as ca
import numpy as np

import uvsym
from uvsym.observers.uio_bank import UIOBank, residual_bands, uio_bank
from uvsym.sets import Propagation
from uvsym.sim.feedback import lqr_gain
from uvsym.systems import System, system

__all__ = ["ATTITUDE", "DT", "ERROR_BOUND", "GENERATORS", "NOISE_BOUND", "POLES", "REDUCTION", "SAMPLES", "Design",
           "bands", "design", "hover_plant", "linear_plant"]

DT = 0.01  # s, the paper's sample period
SAMPLES = 300  # samples per run (3 s)
ATTITUDE = ("phi", "theta", "psi", "p", "q", "r")  # the paper's six states
NOISE_BOUND = {"phi": 3.83e-4, "theta": 3.83e-4, "psi": 3.83e-4,  # rad: half an encoder count (Quanser, 4096/rev)
               "p": 0.01, "q": 0.01, "r": 0.01,  # rad/s, gyro
               "z": 0.01, "w": 0.02}  # m altimeter, m/s vertical speed
ERROR_BOUND = 1e-3  # |e_0| per state, in each state's unit
POLES = tuple(np.linspace(0.5, 0.7, 8))  # eigenvalues of F = T G - K1 C (the notes' 0.5-0.7)
GENERATORS = 64  # order bound of the joint (e, v) zonotope: 16 dimensions, order 4
REDUCTION = "girard"
LQR_WEIGHTS = (np.diag([100.0, 100.0, 100.0, 1.0, 1.0, 1.0, 10.0, 1.0]), np.eye(4))  # Q (x), R (u): hover hold


def linear_plant(states=None) -> System:
    """The quadrotor linearised at hover (casadi.jacobian) as a continuous linear System, over
    ``states`` (names; default all eight), sampled later by exact zero-order hold."""
    quad = uvsym.plant("quadrotor")
    lin = quad.linearize()
    keep = list(range(quad.x.size)) if states is None else quad.x.indices(states)
    A, B, E = lin.A[np.ix_(keep, keep)], lin.B[keep], lin.E[keep]
    x = quad.x.select([quad.x.names[i] for i in keep])
    return system(f"{quad.name}_hover", f"{quad.description}, linearised at hover", x=x, u=quad.u, d=quad.d,
                  rhs=lambda xs, us, ds, _p: ca.mtimes(ca.DM(A), xs) + ca.mtimes(ca.DM(B), us)
                  + ca.mtimes(ca.DM(E), ds), source=quad.source)


@dataclass(frozen=True)
class Design:
    """plant (discrete), G, H, D1, C (8 x 8), the LQR gain K (u = -K y), the bank and one band
    (a Propagation) per observer."""

    plant: System
    G: np.ndarray
    H: np.ndarray
    D1: np.ndarray
    C: np.ndarray
    K: np.ndarray
    bank: UIOBank
    bands: tuple[Propagation, ...]

    @property
    def noise_bound(self) -> np.ndarray:
        return np.array([NOISE_BOUND[name] for name in self.plant.x.names])


def sampled(states=None) -> tuple[System, np.ndarray, np.ndarray, np.ndarray]:
    """(discrete plant, G, H, D1) of :func:`linear_plant` at DT."""
    plant = linear_plant(states).discretize(DT, "zoh")
    lin = plant.linearize()
    return plant, lin.A, lin.B, lin.E


@functools.lru_cache(maxsize=1)
def design() -> Design:
    """uvsym's set-up: all states measured, one UIO per actuator, its bands over SAMPLES samples."""
    plant, G, H, D1 = sampled()
    C = np.eye(plant.x.size)
    bank = uio_bank(G, H, C, D1, POLES, states=plant.x, outputs=plant.x, inputs=plant.u, dt=DT)
    K = lqr_gain(G, H, *LQR_WEIGHTS, DT)
    return Design(plant, G, H, D1, C, K, bank, _bands(bank, SAMPLES))


def hover_plant() -> System:
    """The discrete plant of :func:`design` (all eight states measured, ``y = x``), for scenario files:
    ``plant = "derivations.uio_zonotope.design:hover_plant"``."""
    return design().plant


@functools.lru_cache(maxsize=4)
def bands(samples: int) -> tuple[Propagation, ...]:
    """Each bank observer's healthy-residual zonotopes over ``samples`` samples."""
    return design().bands if samples == SAMPLES else _bands(design().bank, samples)


def _bands(bank: UIOBank, samples: int) -> tuple[Propagation, ...]:
    vbar = np.array([NOISE_BOUND[name] for name in bank.observers[0].reads_y.names])
    return tuple(residual_bands(d, vbar, np.full(len(d.F), ERROR_BOUND), samples, GENERATORS, REDUCTION)
                 for d in bank.designs)
