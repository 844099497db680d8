"""Actuator-fault hypotheses as regressions on the bias observer's estimate.

The bias observer (Liu et al. 2014, Theorem 2, any form) estimates ``d = tau - tau_d``: the
generalised force (N, N m) delivered beyond what healthy actuators would deliver,
``tau_d = tau(y, u_e)``. Its sampled-data form (:mod:`uvsym.observers.discrete`, trapezoidal
rule) is a linear filter of d with the observer's constant error matrix P:

    r_k = Phi r_{k-1} + Gamma (d_{k-1} + d_k) / 2,
    Phi = (I - dt/2 P)^-1 (I + dt/2 P),   Gamma = -(I - dt/2 P)^-1 P dt.

A fault of kind ``deliver(v, f) = (g0 + g1 f) v + s0 + s1 f`` (:class:`uvsym.faults.ActuatorKind`)
on actuator a, commanded to deliver ``v = u_e,a``, changes the delivered force by
``B_a(y, u_e) [((g0 - 1) v + s0) + f (g1 v + s1)]`` to first order (``B_a`` the column of
``d tau / d u``, taken inside the actuator's limits so that a command on its limit does not see the
kink of the saturation). Every hypothesis (a, kind) is therefore linear in its size f:
``r = c + f phi`` with c and phi combinations of the two filtered series ``F[B_a]`` and
``F[B_a v]`` that :class:`RegressorBank` keeps. The filter's state at a window's first sample
carries the history before it; the n columns ``Phi^j`` span that free response and are projected
out of every fit, so a window's verdict depends on its own samples only.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.errors import ObserverError
from uvsym.evaluation import InPlace
from uvsym.models.model import Model

__all__ = ["RegressorBank", "ResidualNoise"]

_INSIDE = 1e-6  # B is taken this fraction of the actuator's range inside its limits


@dataclass(frozen=True)
class ResidualNoise:
    """white: (n,) per-sample noise level of the residual that does not depend on the state (N, N m):
    sensor noise through ``(I - dt/2 P)^-1 L`` and the model-error floor; velocity_std: (n,) the
    velocity sensors' standard deviations (m/s, rad/s), for the part that does (see RegressorBank)."""

    white: np.ndarray
    velocity_std: np.ndarray


class RegressorBank:
    """Filtered per-actuator regressors and the residual over a growing record.

    model: the vehicle; P: (n, n) the bias observer's error matrix (constant, real negative
    eigenvalues); dt: sample period (s); noise: the residual's noise. The observer's
    ``q = P (tau_d - h)`` reads the noisy velocities too, so the residual also carries the filtered
    white noise ``E n`` with ``E = (I - dt/2 P)^-1 dt P d(tau - h)/dnu``, which depends on the state
    (fin angles of attack, propeller loading); its slow part has the density of white noise of
    variance ``(E sigma_n)^2 / (1 - phi)^2``. ``sigma`` (N, n) is the resulting noise level per
    sample and channel, the whitening of every fit. After :meth:`append`, ``r`` is (N, n),
    ``G`` and ``H`` are (N, m, n): ``F[B_a]`` and ``F[B_a u_e,a]`` per actuator a.
    """

    def __init__(self, model: Model, P: np.ndarray, dt: float, noise: ResidualNoise):
        self.model, self.dt = model, float(dt)
        self.n, self.m = model.dof, model.n_inputs
        self.noise = noise
        self.sigma = np.zeros((0, self.n))
        n = self.n
        eta, nu, u = ca.SX.sym("eta", n), ca.SX.sym("nu", n), ca.SX.sym("u", self.m)
        self._slope = ca.Function("slope", [eta, nu, u], [ca.jacobian(model.tau.raw(eta, nu, u, 0.0, 0.0)
                                                                      - model.h.raw(eta, nu), nu)])
        self._E = np.linalg.solve(np.eye(n) - dt / 2 * P, dt * P)  # times d(tau - h)/dnu
        eigenvalues, V = np.linalg.eig(np.asarray(P, dtype=float))
        if np.max(np.abs(eigenvalues.imag)) > 1e-9 * np.max(np.abs(eigenvalues)) or np.any(eigenvalues.real >= 0):
            raise ObserverError(f"diagnosis: the residual observer's error matrix must have real negative "
                                f"eigenvalues, got {np.round(eigenvalues, 6).tolist()}")
        lam = eigenvalues.real
        self.V, self.V_inv = V.real, np.linalg.inv(V.real)
        self.phi = (1 + dt * lam / 2) / (1 - dt * lam / 2)  # per mode
        self.gamma = -lam * dt / (1 - dt * lam / 2)
        self.Phi = self.V @ np.diag(self.phi) @ self.V_inv
        self._powers: dict[int, np.ndarray] = {}
        self._effects: dict[tuple, tuple] = {}  # exact fault effects computed so far (see exact)
        self._maps: dict[tuple, object] = {}  # the model's Functions mapped over so many samples
        self._state = None  # per mode: filter state (lfilter zi); _last: the last raw regressor
        self._last = None
        self.r = np.zeros((0, self.n))
        self.G = np.zeros((0, self.m, self.n))
        self.H = np.zeros((0, self.m, self.n))
        self.u_e = np.zeros((0, self.m))
        self.y = np.zeros((0, 2 * self.n))
        lower, upper = np.asarray(model.u_min, dtype=float), np.asarray(model.u_max, dtype=float)
        margin = _INSIDE * (upper - lower)
        self._inside = (lower + margin, upper - margin)

    def __len__(self) -> int:
        return len(self.r)

    def append(self, y: np.ndarray, u_e: np.ndarray, r: np.ndarray) -> None:
        """Add samples: y (k, 2n) measured [eta; nu], u_e (k, m) expected actuator values, r (k, n) residual."""
        k = len(r)
        if k == 0:
            return
        u_in = np.clip(u_e, *self._inside)
        n, m = self.n, self.m
        B = self._mapped(self.model.B.raw, k)(y[:, :n].T, y[:, n:].T, u_in.T, 0.0, 0.0)[0]  # (n, k m)
        slope = self._mapped(self._slope, k)(y[:, :n].T, y[:, n:].T, u_e.T)[0]
        slope = slope.reshape(n, k, n).transpose(1, 0, 2)
        E = self._E @ slope  # (k, n, n)
        slow = (E**2 @ self.noise.velocity_std**2) / np.maximum(1.0 - np.abs(np.diag(self.Phi)), 1e-12) ** 2
        self.sigma = np.concatenate([self.sigma, np.sqrt(self.noise.white**2 + slow)])
        B = B.reshape(n, k, m).transpose(1, 2, 0)  # (k, m, n): column a of B per sample
        raw = np.concatenate([B, B * u_e[:, :, None]], axis=1)  # (k, 2m, n)
        if self._state is None:
            self._state = np.zeros((1, 2 * m, n))
        filtered, self._state = self._through_filter(raw, raw[0] if self._last is None else self._last, self._state)
        self._last = raw[-1]
        self.G = np.concatenate([self.G, filtered[:, :m]])
        self.H = np.concatenate([self.H, filtered[:, m:]])
        self.r = np.concatenate([self.r, np.asarray(r, dtype=float)])
        self.u_e = np.concatenate([self.u_e, np.asarray(u_e, dtype=float)])
        self.y = np.concatenate([self.y, np.asarray(y, dtype=float)])

    def exact(self, rows: np.ndarray, actuator: int, kind, theta: float, onset: int) -> tuple[np.ndarray, np.ndarray]:
        """(c, phi), each (len(rows), n): the fault's exact effect on the residual linearised at ``theta``.

        ``D(f) = tau(y, u_e with actuator a delivering deliver(u_e,a, f)) - tau(y, u_e)`` on each sample
        from ``onset`` on (zero before), through the vehicle's own force model (saturation, quadratic
        thrust and fin drag included); ``D(f) ~ D(theta) + (f - theta) D'(theta)`` gives
        ``c = F[D(theta) - theta D']`` and ``phi = F[D']``, filtered from a zero state at the window's first
        sample (the free response is projected out of every fit).
        """
        D, slope = self._effect(rows, actuator, kind, theta)
        active = (rows >= onset)[:, None]
        return self._filter(active * (D - theta * slope)), self._filter(active * slope)

    def _effect(self, rows: np.ndarray, actuator: int, kind, theta: float) -> tuple[np.ndarray, np.ndarray]:
        """(D(theta), D'(theta)) on the contiguous ``rows``, each (len(rows), n); kept per (a, kind, theta)
        so that later windows evaluate only their new samples."""
        key = (actuator, kind.name, theta)
        first, D, slope = self._effects.get(key, (rows[0], np.zeros((0, self.n)), np.zeros((0, self.n))))
        if rows[0] < first:
            first, D, slope = rows[0], np.zeros((0, self.n)), np.zeros((0, self.n))
        have = first + len(D)
        if rows[-1] >= have:
            D_new, slope_new = self._evaluate(np.arange(have, rows[-1] + 1), actuator, kind, theta)
            D, slope = np.concatenate([D, D_new]), np.concatenate([slope, slope_new])
            if len(self._effects) > 64:
                self._effects.clear()
            self._effects[key] = (first, D, slope)
        return D[rows - first], slope[rows - first]

    def _evaluate(self, rows: np.ndarray, actuator: int, kind, theta: float) -> tuple[np.ndarray, np.ndarray]:
        """D and its central-difference slope in the size on ``rows`` (the force model evaluated 3 times a row)."""
        n, length = self.n, len(rows)
        y, u_e = self.y[rows], self.u_e[rows]
        step = 1e-6 * max(1.0, abs(theta))
        u = np.repeat(u_e[None], 3, axis=0)  # healthy, theta - step, theta + step
        u[1, :, actuator] = kind.deliver(u_e[:, actuator], theta - step)
        u[2, :, actuator] = kind.deliver(u_e[:, actuator], theta + step)
        eta, nu = np.tile(y[:, :n].T, 3), np.tile(y[:, n:].T, 3)
        tau = self._mapped(self.model.tau.raw, 3 * length)(eta, nu, u.reshape(-1, self.m).T, 0.0, 0.0)[0]
        tau = tau.T.reshape(3, length, n)
        low, high = tau[1] - tau[0], tau[2] - tau[0]
        return (low + high) / 2, (high - low) / (2 * step)

    def _filter(self, series: np.ndarray) -> np.ndarray:
        """``series`` (L, n) through the observer's filter from a zero state (trapezoidal inputs)."""
        return self._through_filter(series, series[0], np.zeros((1, self.n)))[0]

    def _through_filter(self, series: np.ndarray, previous: np.ndarray, state: np.ndarray):
        """(filtered, state): ``series`` (k, ..., n) through the observer's filter, the trapezoid's input
        averaged with ``previous`` (..., n) before the first row, from the per-mode ``state`` (1, ..., n)."""
        from scipy.signal import lfilter  # here: importing scipy.signal takes most of a second

        averaged = (np.concatenate([previous[None], series[:-1]]) + series) / 2
        modal = averaged @ self.V_inv.T
        out, state = np.empty_like(modal), state.copy()
        for j in range(self.n):
            out[..., j], state[..., j] = lfilter([self.gamma[j]], [1.0, -self.phi[j]], modal[..., j], axis=0,
                                               zi=state[..., j])
        return out @ self.V.T, state

    def _mapped(self, function, k: int) -> InPlace:
        """``function`` mapped over k samples, evaluated in place (:class:`~uvsym.evaluation.InPlace`), built once
        per (function, k)."""
        key = (function.name(), k)
        if key not in self._maps:
            self._maps[key] = InPlace(function.map(k))
        return self._maps[key]

    def transient(self, rows: np.ndarray) -> np.ndarray:
        """(len(rows) n, n) whitened free response ``Phi^j e_i`` of the filter over the window ``rows``."""
        length = len(rows)
        if length not in self._powers:
            powers = np.empty((length, self.n, self.n))
            powers[0] = np.eye(self.n)
            for j in range(1, length):
                powers[j] = self.Phi @ powers[j - 1]
            self._powers = {length: powers}  # windows of one length follow each other
        return (self._powers[length] / self.sigma[rows][:, :, None]).reshape(length * self.n, self.n)

    def gated(self, series: np.ndarray, rows: np.ndarray, onset: int) -> np.ndarray:
        """``series`` (N, n) on the contiguous ``rows`` as if its input started at sample ``onset``: zero
        before it, the free response ``Phi^(k - onset + 1)`` of the state at ``onset - 1`` removed after it."""
        out = series[rows].copy()
        if onset <= rows[0]:
            return out  # the difference is a free response from the window's start: projected out anyway
        after = rows >= onset
        out[~after] = 0.0
        if onset >= 1 and np.any(after):
            steps = np.arange(1, int(np.count_nonzero(after)) + 1)
            modal = self.V_inv @ series[onset - 1]
            out[after] -= (self.phi[None, :] ** steps[:, None] * modal[None, :]) @ self.V.T
        return out
