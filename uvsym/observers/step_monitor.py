"""Calibrated sensor-step monitor: a sensor offset told from motion, glitches and reference changes.

A sensor that measures a physical quantity which moves smoothly (a heading, a depth, a position:
continuous, with a continuous rate) sees a bias fault as a *step* in its measurement. The monitor
tests, on a sliding window of ``W = B + A`` samples (``B`` before a candidate step, ``A`` after
it), the step model against every model of healthy data it knows::

    trend   y_i = c0 + c1 t_i + c2 t_i^2 + n_i                     (smooth motion)
    kink    trend + c3 (t_i - t_p)_+                                (the rate changes at any p: a
                                                                     command or set-point change)
    glitch  trend + c3 [p <= i < p + L],  L = 1..``glitch``         (a short glitch anywhere)
    step    trend + s [i >= B] + c4 (t_i - t_B)_+                   (an offset from sample B on, and
                                                                     the loop's reaction to it)

with n white Gaussian of the stated standard deviation sigma. The statistic is
``g = (min over the healthy models of RSS - RSS_step) / sigma^2``. If the data come from any one
healthy model, ``g <= (RSS_healthy - RSS_(healthy + step)) / sigma^2 ~ chi^2_2`` (nested least
squares), so ``P(g > h) <= exp(-h / 2)``: the threshold ``h = -2 ln(alpha)`` with
``alpha = F dt / 3600`` bounds the false confirmations by F per hour (one test per sample at most,
union bound). A reference change is not a fault by construction: it moves the commands, hence the
measured quantity's curvature (a kink), never its value in one sample.

Sequence: an *alarm* when the newest sample leaves the window's trend by ``alarm_z`` standard
deviations of the one-sample step estimate -- or, on a decision sample, when a second step inside
the last ``A - 1`` samples does (the best-located one) -- the paper-like fast stage: the
substitute drops the provisional step at once. The step is re-estimated each sample (``s_a`` from
the ``a`` samples since) and decided ``A`` samples after it: *confirmed* when ``g > h`` -- the
offset estimate ``b`` gains the step's size (fitted jointly with a second step inside the window,
if there is one) and the window is corrected -- else *released* (a glitch of at most ``glitch``
samples, a noise outlier or the start of a turn). A confirmed offset back to zero (a second step)
*clears*: the fault flag is ``|b| > sqrt(h) sigma_s`` (sigma_s the step estimate's standard
deviation), so it clears when the evidence -- the offset -- is gone. The substitute is ``y - b``
(minus the provisional step while an alarm is pending).

Limits: a glitch longer than ``glitch`` but shorter than ``A`` is a fault whose return is found
inside the same window; both sizes then come from a window holding two steps, and up to about a
quarter of it may stay in the offset. It cannot see a drift (a ramp, which is a kink), a sensor
stuck at a value the quantity holds anyway, nor small steps: a step is told from a fast turn by the
trend around it, so the window sets the smallest step confirmed (:func:`step_power` measures it: at the
defaults half the steps of about 9 noise standard deviations).
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from uvsym.errors import ObserverError
from uvsym.numbers import integer, real
from uvsym.observers.base import Observer, check_name, observer
from uvsym.systems.signals import Signals, signals

__all__ = ["BEFORE", "AFTER", "GLITCH", "sensor_step_monitor", "step_power", "step_threshold", "step_models"]

_TREND_ORDER = 2  # quadratic trend
_LONGEST = 100  # samples in either half of the window: the healthy models grow with its square
# default window: 10 samples before a candidate step, 8 after it, glitches of up to 3 released. A longer
# window confirms smaller steps (the trend is better known; :func:`step_power`, 0.1 per hour at dt = 0.2 s:
# half the steps of about 9 noise standard deviations at (10, 8), 5.5 at (20, 20)) but decides later and
# more often holds two events (a pulse and its return, a turn's start and end), which the one-event
# models below do not fit: a 5-sample pulse is then released, not confirmed
BEFORE, AFTER, GLITCH = 10, 8, 3


def step_threshold(false_alarms_per_hour: float, dt: float) -> float:
    """h of ``g > h`` (module docstring): ``-2 ln(F dt / 3600)``; ObserverError outside (0, 1)."""
    alpha = false_alarms_per_hour * dt / 3600.0
    if not 0.0 < alpha < 1.0:
        raise ObserverError(f"false_alarms_per_hour = {false_alarms_per_hour:g} at dt = {dt:g} s gives a per-test "
                            f"probability of {alpha:g}, outside (0, 1)")
    return -2.0 * math.log(alpha)


def _basis(columns: list[np.ndarray]) -> np.ndarray:
    """(W, r) orthonormal basis of the span of ``columns`` (each (W,))."""
    q, r = np.linalg.qr(np.column_stack(columns))
    return q[:, np.abs(np.diag(r)) > 1e-9 * np.max(np.abs(np.diag(r)))]


def _beyond(trend: np.ndarray, column: np.ndarray) -> np.ndarray:
    """(W,) ``column``'s part orthogonal to the orthonormal ``trend`` (W, r), normalised; 0 inside its span."""
    rest = column - trend @ (trend.T @ column)
    norm = np.linalg.norm(rest)
    return rest / norm if norm > 1e-9 * max(np.linalg.norm(column), 1.0) else np.zeros_like(column)


def step_models(before: int, after: int, glitch: int) -> dict:
    """The window's models (module docstring) for ``before`` + ``after`` samples: ``step`` (W, r)
    basis, ``healthy`` list of bases; the same as the statistic uses them: ``step_beyond`` (W, 2) and
    ``healthy_beyond`` (W, n_h) orthonormal columns of each model past the quadratic trend (a healthy
    model adds one column, so its RSS is the trend's less one squared product:
    ``g sigma^2 = |S^T v|^2 - max_k (c_k^T v)^2``, S = step_beyond);
    ``estimators`` (after, W) rows: the step size from the last ``B + a`` samples (a = 1..A;
    zero-padded in front), ``step_std`` (after,) their standard deviation per unit sigma, ``joint``
    (after, W): row a2 the size of the step at B fitted together with a second step a2 samples ago
    (row 0: alone)."""
    W = before + after
    i = np.arange(W, dtype=float)
    t = (i - before + 0.5) / W  # scaled so that the powers stay well conditioned

    def trend(n: int) -> list[np.ndarray]:
        return [t[-n:] ** p for p in range(_TREND_ORDER + 1)]

    extras = []  # each healthy model's one column beyond the trend
    for p in range(1, W):
        extras.append(np.where(i >= p, i - p + 1.0, 0.0))
        extras += [((i >= p) & (i < p + L)).astype(float) for L in range(1, glitch + 1) if p + L <= W]
    trend_basis = _basis(trend(W))
    healthy = [trend_basis] + [_basis(trend(W) + [column]) for column in extras]
    jump, ramp = (i >= before).astype(float), np.where(i >= before, i - before + 1.0, 0.0)
    step = _basis(trend(W) + [jump, ramp])
    step_beyond = _basis([_beyond(trend_basis, jump), _beyond(trend_basis, ramp)])
    healthy_beyond = np.column_stack([_beyond(trend_basis, column) for column in extras])
    estimators, step_std = np.zeros((after, W)), np.zeros(after)
    for a in range(1, after + 1):  # the step a samples ago, from the last B + a samples
        local = np.arange(before + a, dtype=float)
        columns = trend(before + a) + [(local >= before).astype(float)]
        row = np.linalg.pinv(np.column_stack(columns))[_TREND_ORDER + 1]
        estimators[a - 1, W - before - a:] = row
        step_std[a - 1] = float(np.linalg.norm(row))
    joint = np.zeros((after, W))  # row a2: the step at B fitted jointly with a second one a2 samples ago
    joint[0] = estimators[-1]
    for a2 in range(1, after):
        X = np.column_stack(trend(W) + [jump, (i >= W - a2).astype(float)])
        joint[a2] = np.linalg.pinv(X)[_TREND_ORDER + 1]
    return {"step": step, "healthy": healthy, "step_beyond": step_beyond, "healthy_beyond": healthy_beyond,
            "estimators": estimators, "step_std": step_std, "joint": joint}


def sensor_step_monitor(measured: Signals, *, noise_std: float, dt: float, false_alarms_per_hour: float = 0.1,
                        before: int = BEFORE, after: int = AFTER, glitch: int = GLITCH, alarm_z: float = 3.5,
                        name: str = "step") -> Observer:
    """The step monitor of one sensor (module docstring) as an :class:`Observer`.

    measured: the one sensor (a Signals of size 1); noise_std: its white noise's standard deviation
    (the sensor's unit; the default parameter p = (noise_std,)); dt: sample period (s);
    false_alarms_per_hour: F, the designed bound on false confirmations; before, after (samples):
    B and A; glitch: the longest glitch (samples) to release, ``glitch < after``; alarm_z: the fast
    alarm's level (sigma). Publishes ``<y>_sub`` (the substitute), ``offset_<y>`` (b),
    ``g_<y>`` (the statistic on a decision sample, else 0), ``alarm_<y>`` (a decision pending),
    ``fault_<y>`` (``|b|`` significant), ``confirmed_<y>`` and ``released_<y>`` (1 on the sample).

    Raises ObserverError naming the argument for a bad size, sample count, rate or level.
    """
    check_name(name, "observer")
    if not isinstance(measured, Signals) or measured.size != 1:
        raise ObserverError(f"{name}: measured must be one signal (a Signals of size 1), got {measured!r}")
    sigma = real(noise_std, f"{name}: noise_std", ObserverError, positive=True)
    dt = real(dt, f"{name}: sample period dt", ObserverError, positive=True)
    B = integer(before, f"{name}: before", ObserverError, minimum=_TREND_ORDER + 2)
    A = integer(after, f"{name}: after", ObserverError, minimum=3)
    L = integer(glitch, f"{name}: glitch", ObserverError)
    if B > _LONGEST or A > _LONGEST or L >= A:
        raise ObserverError(f"{name}: before and after must be at most {_LONGEST} samples and glitch < after, got "
                            f"before = {B}, after = {A}, glitch = {L}")
    z_alarm = real(alarm_z, f"{name}: alarm_z", ObserverError, positive=True)
    h = step_threshold(real(false_alarms_per_hour, f"{name}: false_alarms_per_hour", ObserverError, positive=True), dt)
    models = step_models(B, A, L)
    W = B + A
    y_name, unit = measured.names[0], measured.units[0]
    state = Signals(tuple(f"v_{i}" for i in range(1, W + 1)) + ("offset", "age", "count"),
                    (unit,) * W + (unit, "samples", "samples"), group="state")
    publishes = signals((f"{y_name}_sub", unit, "substitute y - offset (- the pending step)"),
                        (f"offset_{y_name}", unit, "confirmed sensor offset b"),
                        (f"g_{y_name}", "-", "step statistic on a decision sample, else 0"),
                        (f"alarm_{y_name}", "-", "a step decision pending"),
                        (f"fault_{y_name}", "-", "|b| significant"),
                        (f"confirmed_{y_name}", "-", "a step confirmed on this sample"),
                        (f"released_{y_name}", "-", "a pending step released on this sample"), group="published")
    params = signals(("noise_std", unit, "white noise standard deviation of the sensor"), group="parameter")
    step_beyond, healthy_beyond = ca.DM(models["step_beyond"].T), ca.DM(models["healthy_beyond"].T)
    estimators = ca.DM(models["estimators"])
    joint = ca.DM(models["joint"])
    s_std = float(models["step_std"][-1])

    def rescan(v, sig):
        """After a decision: the age of the best-located step among the last A - 1 samples of the
        (corrected) window v that leaves the trend by alarm_z (0: none)."""
        estimates = ca.mtimes(estimators, v)
        age, best = 0.0, 0.0
        for a in range(1, A):
            z = ca.fabs(estimates[a - 1]) / (float(models["step_std"][a - 1]) * sig)
            better = ca.logic_and(z > z_alarm, z > best)
            age, best = ca.if_else(better, float(a), age), ca.if_else(better, z, best)
        return age

    def step(s, y, u, p):
        v, offset, age, count = s[:W], s[W], s[W + 1], s[W + 2]
        sig = p[0]
        v_next = ca.vertcat(v[1:], y[0] - offset)
        count_next = ca.fmin(count + 1, W)
        estimates = ca.mtimes(estimators, v_next)  # (A,) step sizes from the last B + a samples
        newest = ca.fabs(estimates[0]) > z_alarm * float(models["step_std"][0]) * sig
        age_next = ca.if_else(age > 0.5, age + 1, ca.if_else(ca.logic_and(count_next >= W, newest), 1.0, 0.0))
        pending = 0.0
        for a in range(1, A + 1):
            pending = ca.if_else(age_next == a, estimates[a - 1], pending)
        beyond = ca.mtimes(healthy_beyond, v_next)  # (n_h,): each healthy model's gain over the trend
        best = 0.0
        for k in range(beyond.numel()):
            best = ca.fmax(best, beyond[k] ** 2)
        deciding = age_next >= A
        g = ca.if_else(deciding, (ca.sumsqr(ca.mtimes(step_beyond, v_next)) - best) / sig ** 2, 0.0)
        confirmed = ca.logic_and(deciding, g > h)
        released = ca.logic_and(deciding, ca.logic_not(confirmed))
        after_step = ca.DM(np.arange(W) >= B)
        second = rescan(v_next - estimates[A - 1] * after_step, sig)  # a second step inside the window?
        size = estimates[A - 1]
        for a2 in range(1, A):
            size = ca.if_else(second == a2, ca.dot(joint[a2, :].T, v_next), size)
        jump = ca.if_else(confirmed, size, 0.0)
        v_kept = v_next - jump * after_step
        offset_next = offset + jump
        age_kept = ca.if_else(deciding, rescan(v_kept, sig), age_next)
        substitute = y[0] - offset_next - ca.if_else(ca.logic_and(age_kept > 0.5, ca.logic_not(deciding)), pending,
                                                     0.0)
        fault = ca.fabs(offset_next) > math.sqrt(h) * s_std * sig
        s_next = ca.vertcat(v_kept, offset_next, age_kept, count_next)
        out = ca.vertcat(substitute, offset_next, g, age_kept > 0.5, fault, confirmed, released)
        return s_next, out

    return observer(name, step=step, state=state, reads_y=measured.renamed(group="measurement"),
                    reads_u=Signals(group="input"), publishes=publishes, params=params, p0=[sigma], dt=dt,
                    description=f"sensor step monitor of {y_name}: {B} samples before, {A} after, glitches up to {L} "
                                f"samples released; confirmations designed for {false_alarms_per_hour:g} per hour "
                                f"(h = {h:.4g}); sampled every {dt:g} s")


def step_power(sizes, *, dt: float, false_alarms_per_hour: float = 0.1, before: int = BEFORE, after: int = AFTER,
               glitch: int = GLITCH, alarm_z: float = 3.5, edges: int = 200, seed: int = 0) -> dict:
    """The monitor's own detection probability of a step of each size (in noise standard deviations), by
    Monte Carlo: per size, a record of unit white noise on a constant level that steps by +size and back
    every ``2 (before + after)`` samples (``edges`` steps), run through :func:`sensor_step_monitor`; a step
    is detected when a confirmation falls within ``after`` samples of it. Numerical evidence (a flat
    record: motion makes it harder), not a bound.

    Returns ``{"sizes": [...], "probability": [...], "edges": edges}`` (probabilities in [0, 1]).
    """
    if isinstance(sizes, (str, bytes)) or not hasattr(sizes, "__iter__"):
        raise ObserverError(f"step_power: sizes must be a sequence of step sizes (noise std), got {sizes!r}")
    sizes = [real(size, "step_power: size", ObserverError, positive=True) for size in sizes]
    edges = integer(edges, "step_power: edges", ObserverError, minimum=1)
    monitor = sensor_step_monitor(signals(("y", "-", "measured")), noise_std=1.0, dt=dt,
                                  false_alarms_per_hour=false_alarms_per_hour, before=before, after=after,
                                  glitch=glitch, alarm_z=alarm_z)
    period = 2 * (before + after)
    n = period * (edges + 2)
    k = np.arange(n)
    onsets = np.arange(1, edges + 1) * period
    level = np.zeros(n)
    for j, onset in enumerate(onsets):
        level[onset:] = 1.0 if j % 2 == 0 else 0.0
    rng = np.random.default_rng(seed)
    confirmed_column = monitor.publishes.names.index("confirmed_y")
    probability = []
    for size in sizes:
        _, out = monitor.run((size * level + rng.standard_normal(n))[:, None], np.zeros((n, 0)), states="final")
        hits = k[out[:, confirmed_column] > 0.5]
        probability.append(float(np.mean([np.any((hits >= onset) & (hits < onset + after + 1)) for onset in onsets])))
    return {"sizes": sizes, "probability": probability, "edges": edges}
