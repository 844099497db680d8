"""Seeded runs of the quadrotor with the UIO bank: healthy runs, abrupt and drift actuator faults.

Closed loop (uvsym's choice; the paper's controller is lost): ``u_k = -K y_k`` (discrete LQR
holding hover), the plant ``x_{k+1} = f_d(x_k, u_k + F_i f_k, tau_d,k)`` of the sampled System,
``y_k = x_k + v_k``. Every run draws ``x_0`` in the initial error box (the observers start at
``xhat_0 = 0``, so ``e_0 = x_0``), a yaw disturbance torque ``tau_d`` (a sinusoid of random
phase plus a random walk: unknown and unbounded to the observers) and noise ``v_k``: uniform in
its box, or (every fourth run) on the box's vertices, the worst case for the band. Plant and
observers run as CasADi ``mapaccum`` over the samples and ``map`` over the runs.

Faults (the paper's two kinds, on the commanded voltage of one actuator from sample ``onset``):
abrupt ``f = b`` and drift ``f = eta (t - t_s)``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import casadi as ca
import numpy as np

from derivations.uio_zonotope.design import DT, ERROR_BOUND, SAMPLES, bands, design
from uvsym.observers.uio_bank import isolate, outside_band

__all__ = ["ABRUPT_SIZE", "DRIFT_RATE", "ONSET", "Fault", "Runs", "detection", "simulate_runs"]

ONSET = 50  # sample of the fault (the paper's k = 50)
ABRUPT_SIZE = 10.0  # V, b of f = b (about 17 % of the 58.8 V hover trim)
DRIFT_RATE = 20.0  # V/s, eta of f = eta (t - t_s)
DISTURBANCE = (0.02, 0.5, 0.002)  # yaw torque: amplitude (N m), frequency (Hz), random-walk step (N m)
VERTEX_EVERY = 4  # every fourth run draws noise on the box's vertices
ISOLATION_WINDOW = 50  # samples after the alarm over which the isolating observer must stay inside


@dataclass(frozen=True)
class Fault:
    """actuator: input index; kind: ``abrupt`` (size in V) or ``drift`` (size in V/s); onset: sample."""

    actuator: int
    kind: str
    size: float
    onset: int = ONSET

    def values(self, samples: int) -> np.ndarray:
        """(samples,) f_k in V."""
        k = np.arange(samples)
        active = k >= self.onset
        return np.where(active, self.size if self.kind == "abrupt" else self.size * (k - self.onset) * DT, 0.0)


@dataclass(frozen=True)
class Runs:
    """x, y: (N, n, runs); u: (N, m, runs) commanded; fault: (N,) V; residuals: per observer
    (N, p, runs); noise: (N, p, runs) v; x0: (n, runs)."""

    x: np.ndarray
    y: np.ndarray
    u: np.ndarray
    fault: np.ndarray
    residuals: tuple
    noise: np.ndarray
    x0: np.ndarray


@functools.lru_cache(maxsize=4)
def _loop(samples: int, runs: int) -> ca.Function:
    """(x0 (n, runs), v (p, N runs), d (1, N runs), f (m, N runs)) -> (x, y, u) rolled out and mapped."""
    d = design()
    plant = d.plant
    x, v, tau, f = (ca.SX.sym(a, s) for a, s in (("x", plant.x.size), ("v", plant.x.size), ("d", 1),
                                                  ("f", plant.u.size)))
    y = ca.mtimes(ca.DM(d.C), x) + v
    u = -ca.mtimes(ca.DM(d.K), y)
    x_next = plant.f(x, u + f, tau, plant.p0)
    step = ca.Function("closed_loop", [x, ca.vertcat(v, tau, f)], [x_next, ca.vertcat(x, y, u)],
                       ["x", "w"], ["x_next", "log"])
    return step.mapaccum("run", samples, [0], [0]).map(runs)


@functools.lru_cache(maxsize=8)
def _observer_runs(index: int, samples: int, runs: int) -> ca.Function:
    obs = design().bank.observers[index]
    return obs.step.mapaccum(f"{obs.name}_run", samples, [0], [0]).map(runs)


def _draws(seed: int, runs: int, samples: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(x0 (n, runs), v (N, p, runs), d (N, runs)) of one seed."""
    d = design()
    rng = np.random.default_rng(seed)
    n, vbar = d.plant.x.size, d.noise_bound
    x0 = rng.uniform(-ERROR_BOUND, ERROR_BOUND, (n, runs))
    unit = rng.uniform(-1.0, 1.0, (samples, n, runs))
    unit[..., ::VERTEX_EVERY] = np.sign(unit[..., ::VERTEX_EVERY])
    amplitude, frequency, walk = DISTURBANCE
    t = np.arange(samples)[:, None] * DT
    tau = amplitude * np.sin(2 * np.pi * frequency * t + rng.uniform(0, 2 * np.pi, runs)) \
        + np.cumsum(rng.uniform(-walk, walk, (samples, runs)), axis=0)
    return x0, unit * vbar[None, :, None], tau


def simulate_runs(seed: int, runs: int, fault: Fault | None = None, samples: int = SAMPLES) -> Runs:
    """``runs`` seeded closed-loop runs (module docstring) with the bank's residuals."""
    d = design()
    n, m = d.plant.x.size, d.plant.u.size
    x0, v, tau = _draws(seed, runs, samples)
    f = np.zeros((samples, m))
    fault_values = np.zeros(samples)
    if fault is not None:
        fault_values = fault.values(samples)
        f[:, fault.actuator] = fault_values
    w = np.concatenate([v, tau[:, None, :], np.repeat(f[:, :, None], runs, axis=2)], axis=1)  # (N, q, runs)
    flat = lambda a: a.transpose(1, 0, 2).reshape(a.shape[1], -1, order="F")  # noqa: E731 (N, q, R) -> (q, N R)
    unflat = lambda a, k: np.asarray(a).reshape(k, samples, runs, order="F").transpose(1, 0, 2)  # noqa: E731
    _, log = _loop(samples, runs)(x0, flat(w))
    log = unflat(log, 2 * n + m)
    x, y, u = log[:, :n], log[:, n:2 * n], log[:, 2 * n:]
    residuals = []
    for i, obs in enumerate(d.bank.observers):
        s0 = -d.bank.designs[i].Q @ y[0]  # xhat_0 = 0
        _, out = _observer_runs(i, samples, runs)(s0, flat(y), flat(u), obs.p0)
        residuals.append(unflat(out, 2 * n)[:, n:])
    return Runs(x, y, u, fault_values, tuple(residuals), v, x0)


def detection(runs: Runs, onset: int) -> dict:
    """Per run: first alarm at or after ``onset`` (any observer outside its band), the delay in
    samples, and the observers inside their bands over ISOLATION_WINDOW samples from the alarm."""
    d = design()
    limits = bands(len(runs.fault))
    outside = np.stack([outside_band(r, band) for r, band in zip(runs.residuals, limits)], axis=1)  # (N, obs, R)
    alarms, isolated = [], []
    for j in range(outside.shape[2]):
        hits = np.flatnonzero(outside[onset:, :, j].any(axis=1))
        k = int(onset + hits[0]) if hits.size else None
        alarms.append(k)
        isolated.append(None if k is None else isolate(outside[:, :, j], d.bank.decoupled, k, ISOLATION_WINDOW))
    return {"alarm": alarms, "delay": [None if k is None else k - onset for k in alarms], "isolated": isolated,
            "outside": outside}
