"""Fault isolation by predicted converged values and their variance (Liu et al. 2014, sec. 2.2, eqs. 18-24).

A matched observer's error obeys ``e' = A e`` (A known from tau_d), so the fault is
``f = f_hat - A^-1 f_hat'`` at any instant (eq. 21) -- before the estimate has converged. The
paper fits ``f_hat`` over the last ``window_s`` seconds by least squares, differentiates the fit
and applies eqs. 22-24 (``fit = "line"`` or ``"quadratic"`` here). By default uvsym instead fits
the closed form the paper derives that prediction from, eq. 19, ``f_hat(t) = f - C exp(int A_ii dt)``
with the rate known from tau_d: linear least squares in (f, C), exact for a matched observer
whose error matrix is diagonal (``fit = "exponential"``; for a coupled A its diagonal is used).

A matched observer's ``f_bar`` is steady; a mismatched one's wanders with ``tau_d``. Per channel,
the observer whose ``f_bar`` has the smallest variance over the window names the fault type once
that variance is below ``threshold`` (paper: 1e-4) and at most ``margin`` times every other
observer's -- unless that observer settled at its no-fault value, which names no fault. A
channel is also healthy when every observer that can see it has settled at its no-fault value,
i.e. its fault kind's :meth:`~uvsym.faults.ActuatorKind.severity` is small (bias: within
``healthy_tolerance`` of 0; constant: of tau_d; proportional, a kind that scales: within
``healthy_tolerance_p`` of 1). A channel is not observable to an observer while its convergence
rate (-A_ii) is below ``1 / window_s`` -- for the proportional observer that is Remark 2's
``tau_d,i = 0`` made quantitative; such predictions are NaN, never a division by (almost) zero.
An observer that has never been able to see a channel (no desired action so far, e.g. roll of a
vehicle without roll actuation) does not vote on it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from uvsym.errors import ObserverError
from uvsym.faults import actuator_kind
from uvsym.observers.actuator import ActuatorObserver

FITS = ("exponential", "line", "quadratic")

__all__ = ["IsolationSettings", "ChannelDecision", "IsolationResult", "Isolator", "predicted_faults"]


@dataclass(frozen=True)
class IsolationSettings:
    """window_s: fit and variance window (s); fit: exponential (eq. 19), line or quadratic (the
    polynomial whose value and slope at the window's end go into eqs. 22-24); threshold: variance
    bound (units of f squared);
    margin: the winner's variance must be <= margin * every other's; healthy_tolerance: ``|f_bar|`` of
    the bias observer (N, N m) below which a settled channel is healthy; healthy_tolerance_p:
    ``|f_bar - 1|`` of the proportional observer likewise (-)."""

    window_s: float = 1.0
    fit: str = "exponential"
    threshold: float = 1e-4
    margin: float = 0.1
    healthy_tolerance: float = 0.05
    healthy_tolerance_p: float = 0.01

    def __post_init__(self):
        for name in ("window_s", "threshold", "margin", "healthy_tolerance", "healthy_tolerance_p"):
            value = getattr(self, name)
            if not (value > 0 and math.isfinite(value)):
                raise ObserverError(f"isolation setting {name} must be positive and finite, got {value}")
        if self.fit not in FITS:
            raise ObserverError(f"unknown isolation fit {self.fit!r}; known: {', '.join(FITS)}")


@dataclass(frozen=True)
class ChannelDecision:
    """kind: proportional, bias, constant or healthy; time_s the decision time; f_bar the mean
    predicted fault over the window ending then; variance its variance."""

    channel: str
    kind: str
    time_s: float
    f_bar: float
    variance: float


@dataclass(frozen=True)
class IsolationResult:
    """t: (N,) s; f_bar and variance: observer kind -> (N, n) (NaN where not yet available or
    not observable); decisions: channel label -> ChannelDecision, for the channels decided."""

    t: np.ndarray
    labels: tuple[str, ...]
    f_bar: dict[str, np.ndarray]
    variance: dict[str, np.ndarray]
    decisions: dict[str, ChannelDecision] = field(default_factory=dict)

    @property
    def faulty(self) -> dict[str, ChannelDecision]:
        """The decided channels whose kind is a fault (not healthy)."""
        return {c: d for c, d in self.decisions.items() if d.kind != "healthy"}


def _window(t: np.ndarray, window_s: float) -> int:
    """Samples per window (at least 3) for uniformly spaced, increasing times t (ObserverError otherwise)."""
    if len(t) < 2:
        return 3
    dt = float(np.median(np.diff(t)))
    if not dt > 0 or np.max(np.abs(np.diff(t) - dt)) > 1e-6 * dt:
        raise ObserverError("isolation needs uniformly sampled estimates at increasing times")
    return max(3, int(round(window_s / dt)))


def _fit_weights(n: int, dt: float, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Weights giving a least-squares polynomial's value and slope at the last of n samples dt apart."""
    tau = dt * (np.arange(n) - (n - 1))
    pinv = np.linalg.pinv(np.vander(tau, order + 1, increasing=True))
    return pinv[0], pinv[1]


def predicted_faults(observer: ActuatorObserver, K, t: np.ndarray, f_hat: np.ndarray, tau_d: np.ndarray,
                     settings: IsolationSettings = IsolationSettings()) -> tuple[np.ndarray, np.ndarray]:
    """(f_bar (N, n) of eqs. 22-24, visible (N, n)) from estimates f_hat (N, n) and tau_d (N, n).

    ``visible`` is False where a channel's convergence rate (-A_ii) is below ``1 / window_s``;
    f_bar is NaN there and in the rows before the first full window.
    """
    t = np.asarray(t, dtype=float)
    N, n = f_hat.shape
    if tau_d.shape != (N, n) or t.shape != (N,):
        raise ObserverError(f"t, f_hat and tau_d must have matching rows; got {t.shape}, {f_hat.shape}, {tau_d.shape}")
    W = _window(t, settings.window_s)
    A = np.asarray(observer.error_matrix.map(N)(tau_d.T, np.asarray(K, dtype=float)))
    A = np.transpose(A.reshape(n, N, n), (1, 0, 2))  # [A_0 A_1 ...] -> (N, n, n)
    visible = -np.diagonal(A, axis1=1, axis2=2) >= 1.0 / settings.window_s
    f_bar = np.full((N, n), np.nan)
    if N < W:
        return f_bar, visible
    hidden = ~visible[W - 1:]
    windows = sliding_window_view(f_hat, W, axis=0)  # (N - W + 1, n, W)
    if settings.fit == "exponential":
        rate = np.diagonal(A, axis1=1, axis2=2)  # (N, n), negative where visible
        dt = float(t[1] - t[0])
        integral = np.vstack([np.zeros((1, n)), np.cumsum(dt / 2 * (rate[1:] + rate[:-1]), axis=0)])
        span = sliding_window_view(integral, W, axis=0)
        g = np.exp(np.minimum(span - span[..., -1:], 300.0))  # exp(int_{t_end}^{t_j} A_ii dt) >= 1
        Sg, Sgg, Sf, Sgf = g.sum(-1), (g * g).sum(-1), windows.sum(-1), (g * windows).sum(-1)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            f_bar[W - 1:] = (Sgg * Sf - Sg * Sgf) / (W * Sgg - Sg**2)
    else:
        value_w, slope_w = _fit_weights(W, float(t[1] - t[0]), 1 if settings.fit == "line" else 2)
        value, slope = windows @ value_w, windows @ slope_w
        A = np.where(hidden[:, :, None] | hidden[:, None, :], 0.0, A[W - 1:]) + hidden[:, :, None] * np.eye(n)
        f_bar[W - 1:] = value - np.linalg.solve(A, slope[..., None])[..., 0]
    f_bar[W - 1:][hidden | ~np.isfinite(f_bar[W - 1:])] = np.nan
    return f_bar, visible


class Isolator:
    """Isolation over a growing record: feed chunks with :meth:`update`, read :attr:`result`.

    observers: kind -> (ActuatorObserver, K). Each update recomputes only the new samples (and
    the three windows before them); decisions, once made, are kept.
    """

    def __init__(self, observers: dict[str, tuple[ActuatorObserver, np.ndarray]], labels: tuple[str, ...],
                 settings: IsolationSettings = IsolationSettings()):
        if not observers:
            raise ObserverError("isolation needs at least one observer")
        self.observers, self.labels, self.settings = observers, tuple(labels), settings
        n = len(self.labels)
        self.t, self.tau_d = np.zeros(0), np.zeros((0, n))
        self.f_hat = {kind: np.zeros((0, n)) for kind in observers}
        self.f_bar = {kind: np.zeros((0, n)) for kind in observers}
        self.mean = {kind: np.zeros((0, n)) for kind in observers}
        self.variance = {kind: np.zeros((0, n)) for kind in observers}
        self.visible = {kind: np.zeros((0, n), dtype=bool) for kind in observers}
        self.decisions: dict[str, ChannelDecision] = {}

    @property
    def result(self) -> IsolationResult:
        return IsolationResult(self.t, self.labels, dict(self.f_bar), dict(self.variance), dict(self.decisions))

    def update(self, t: np.ndarray, f_hat: dict[str, np.ndarray], tau_d: np.ndarray) -> IsolationResult:
        """Add samples t (k,), f_hat kind -> (k, n), tau_d (k, n); returns the result so far."""
        old = len(self.t)
        self.t = np.concatenate([self.t, np.asarray(t, dtype=float)])
        self.tau_d = np.vstack([self.tau_d, np.asarray(tau_d, dtype=float)])
        W = _window(self.t, self.settings.window_s)
        # Recompute a tail long enough that its first incomplete windows cover only rows that
        # earlier updates already computed from a longer history (f_bar: W - 1 rows, mean and
        # variance of f_bar: 2 W - 2 rows).
        start = max(0, old - 3 * W)
        keep_f, keep_v = (0, 0) if start == 0 else (start + W - 1, start + 2 * W - 2)
        for kind, (observer, K) in self.observers.items():
            self.f_hat[kind] = np.vstack([self.f_hat[kind], np.asarray(f_hat[kind], dtype=float)])
            tail, visible = predicted_faults(observer, K, self.t[start:], self.f_hat[kind][start:],
                                             self.tau_d[start:], self.settings)
            self.visible[kind] = np.vstack([self.visible[kind][:start], visible])
            self.f_bar[kind] = np.vstack([self.f_bar[kind][:keep_f], tail[keep_f - start:]])
            mean, variance = np.full_like(tail, np.nan), np.full_like(tail, np.nan)
            if len(tail) >= W:
                mean[W - 1:] = sliding_window_view(self.f_bar[kind][start:], W, axis=0).mean(axis=-1)
                variance[W - 1:] = sliding_window_view(self.f_bar[kind][start:], W, axis=0).var(axis=-1)
            self.mean[kind] = np.vstack([self.mean[kind][:keep_v], mean[keep_v - start:]])
            self.variance[kind] = np.vstack([self.variance[kind][:keep_v], variance[keep_v - start:]])
        self._decide(old)
        return self.result

    def _decide(self, first: int) -> None:
        """Decide undecided channels from row ``first`` on (see the module docstring)."""
        s, kinds = self.settings, list(self.observers)
        rows = np.arange(first, len(self.t))
        if rows.size == 0:
            return
        for i, label in enumerate(self.labels):
            if label in self.decisions:
                continue
            var = np.column_stack([self.variance[kind][rows, i] for kind in kinds])
            mean = np.column_stack([self.mean[kind][rows, i] for kind in kinds])
            finite = np.isfinite(var)
            # an observer that has never been able to see this channel does not vote
            seen = np.column_stack([np.cumsum(self.visible[kind][:, i])[rows] > 0 for kind in kinds])
            voting = finite | ~seen
            ranked = np.where(finite, var, np.inf)
            best = np.argmin(ranked, axis=1)
            best_var = ranked[np.arange(len(rows)), best]
            ranked[np.arange(len(rows)), best] = np.inf
            fault = voting.all(axis=1) & (best_var < s.threshold) & (best_var <= s.margin * np.min(ranked, axis=1))
            settled_neutral = np.zeros_like(finite)
            for j, kind in enumerate(map(actuator_kind, kinds)):
                tolerance = s.healthy_tolerance_p if kind.scales else s.healthy_tolerance
                near = kind.severity(mean[:, j], self.tau_d[rows, i]) <= tolerance
                settled_neutral[:, j] = finite[:, j] & (var[:, j] < s.threshold) & near
            healthy = (settled_neutral | ~seen).all(axis=1) & settled_neutral.any(axis=1)
            hits = np.flatnonzero(fault | healthy)
            if hits.size:
                h = hits[0]
                j = int(np.argmin(np.where(finite[h], var[h], np.inf)))
                # a matched observer settled at its no-fault value names no fault
                kind = "healthy" if healthy[h] or settled_neutral[h, j] else kinds[j]
                self.decisions[label] = ChannelDecision(label, kind, float(self.t[rows[h]]), float(mean[h, j]),
                                                        float(var[h, j]))
