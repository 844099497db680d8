"""Adaptive LMS-FIR sensor monitor (Zhu Daqi et al., LMS-FIR compass-fault paper, eqs. 3-12).

An FIR filter of order M predicts a sensor from the past inputs, trained by LMS (Widrow)::

    U_k   = [u_{k-1}, ..., u_{k-M}]                         regression vector (M,)
    d_k   = C_k . U_k                                       prediction (eq. 3)
    e_k   = d_k - (y_k - r_k)                               error (eq. 4; r the reference, 0 if none)
    C_{k+1} = C_k - 2 mu e_k U_k                            update (eq. 5, descending the gradient)
    eps2_k = e_k^2                                          error criterion (eq. 7), alarm eps2_k > eps0
    S_k   = sum_i C_{i,k},  over the window W_k = (S_{k-n+1}, ..., S_k):
    R_k   = (S_k - mean W_k)^2 / var W_k                    weight-drift criterion (eqs. 9-11), alarm when
                                                            R > r0 on the last ``hold`` samples

Choices where the paper is silent or garbled (each stated in the report that uses it): the
paper prints ``C + 2 mu e u`` with ``e = d - y``, which climbs the squared error; the step here
descends it. The paper's ``u(k + 1 - i)`` starts at ``u(k)``; in a sampled loop u_k is computed
from y_k, so a substitute built from u_k would feed back on itself within the sample: the
regression vector starts at ``u_{k-1}``. R as printed, ``(V - mean V)^2 / std(V)^2`` with V
already standardised, is the squared z-score of the newest weight-sum drift ``d_j = sum_i
(C_ij - C_i0)`` within its window; the offset ``C_0`` cancels, so the window holds the sums
``S`` themselves, and ``var`` is the population variance (R = 0 until n sums are in). As in the
paper's eq. 5, ``C_k`` is the filter in use at sample k (trained on the samples before it), so
R_k sees e_k one sample later than eps2_k. A single large error (a one-sample disturbance)
moves the weight sum once, and the newest sum's squared z-score is then ``n - 1`` whatever the
error's size, so R alone cannot tell it from a fault; a fault keeps the weights drifting, so the
R alarm asks for ``R > r0`` on ``hold`` consecutive samples (``hold = 1``: the paper's rule as
printed).

On the first ``eps2`` alarm the weights are stored; the double criterion
(:mod:`uvsym.observers.lms_supervisor`) decides fault or disturbance. The monitor publishes the
live prediction ``<y>_fir = r + d``, the substitute ``<y>_sub`` (the frozen filter's ``r + C_f .
U_k`` while frozen, else the live prediction), ``e_<y>``, ``eps2_<y>``, ``R_<y>`` and the flags
``alarm_eps2_<y>``, ``alarm_R_<y>``, ``frozen_<y>``, ``fault_<y>``, ``disturbance_<y>`` (0/1).
None of them depends on the input u_k it reads (u_k only enters the next regression vector), so a
loop may switch a controller to ``<y>_sub`` by ``fault_<y>`` within the same sample
(:func:`uvsym.sim.blocks.select`) without an algebraic loop.

Mean-square stability (independence theory, Widrow & Stearns 1985): with input power
``P_u = E[u^2]`` the trace of the regression covariance is ``M P_u`` and the update above is
stable in mean square for ``0 < mu < 1 / (M P_u)`` (:func:`mu_bound`).
"""

from __future__ import annotations

import numbers
import warnings

import casadi as ca
import numpy as np

from uvsym.errors import ObserverError, StepSizeWarning
from uvsym.observers.base import Observer, check_name, observer
from uvsym.observers.lms_supervisor import DECISION_STATE, double_criterion
from uvsym.symbolic import balanced_sum
from uvsym.systems.signals import Signals, signals

__all__ = ["lms_step", "lms_monitor", "mu_bound", "check_mu"]


MAX_ORDER = 4096  # taps (and window samples): a step of this size is already thousands of operations


def _positive_int(value, what: str, name: str, largest: int = MAX_ORDER) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not 1 <= value <= largest:
        raise ObserverError(f"{name}: {what} must be an integer in [1, {largest}], got {value!r:.40}")
    return int(value)


def _positive(value, what: str, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not (np.isfinite(value) and value > 0):
        raise ObserverError(f"{name}: {what} must be a positive, finite number, got {value!r}")
    return float(value)


def mu_bound(order: int, input_power: float) -> float:
    """The mean-square stability bound ``1 / (M P_u)`` on mu (module docstring); P_u in u's unit squared."""
    _positive_int(order, "order M", "mu_bound")
    return 1.0 / (order * _positive(input_power, "input power P_u", "mu_bound"))


def check_mu(mu: float, order: int, input_power: float, what: str = "mu") -> float:
    """Warn (:class:`uvsym.errors.StepSizeWarning`, naming ``what`` and the bound) when mu is at
    or beyond :func:`mu_bound`; returns the bound."""
    bound = mu_bound(order, input_power)
    if mu >= bound:
        warnings.warn(f"{what} = {mu:g} is at or beyond the mean-square stability bound 1 / (M P_u) = {bound:.4g} "
                      f"(M = {order}, input power P_u = {input_power:.4g}): the LMS weights may diverge",
                      StepSizeWarning, stacklevel=2)
    return bound


def lms_step(order: int, balanced: bool = False) -> ca.Function:
    """The bare LMS-FIR step (paper eqs. 3-5), ``lms_step(C, U, target, u, mu) -> (C_next, U_next, d, e)``.

    C (M,) weights, U (M,) the regression vector ``[u_{k-1}, ..., u_{k-M}]``, target the sample
    the filter predicts (``y - r``), u the new input u_k, mu the step; ``d = C . U``, ``e = d -
    target``, ``C_next = C - 2 mu e U``, ``U_next = [u_k, u_{k-1}, ..., u_{k-M+1}]``. Built on MX, so its
    generated C runs vector loops; called on SX (inside the monitor's step) it expands. balanced: d as a
    balanced tree of additions (:func:`uvsym.symbolic.balanced_sum`), for straight-line code.
    """
    M = _positive_int(order, "order M", "lms_step")
    C, U, target, u, mu = ca.MX.sym("C", M), ca.MX.sym("U", M), ca.MX.sym("target"), ca.MX.sym("u"), ca.MX.sym("mu")
    d = balanced_sum(C * U) if balanced else ca.dot(C, U)
    e = d - target
    return ca.Function("lms_fir_step", [C, U, target, u, mu], [C - (2 * mu * e) * U, ca.vertcat(u, U)[:M], d, e],
                       ["C", "U", "target", "u", "mu"], ["C_next", "U_next", "d", "e"])


def lms_monitor(measured: Signals, regressor: Signals, *, order: int, mu: float, eps0: float, r0: float,
                dt: float, window: int = 20, hold: int = 3, confirm: int = 10, reference: Signals | None = None,
                name: str = "lms") -> Observer:
    """The LMS-FIR monitor of one sensor (module docstring) as an :class:`Observer`.

    measured: the one sensor (its name and unit: the loop signal read); regressor: the one input
    u the filter is driven by; reference: the one signal r subtracted from y before regression
    (a set-point), or None. order M >= 1, window n >= 2, hold >= 1, confirm >= 1 (samples); mu > 0 (per unit
    of u squared), eps0 > 0 (y's unit squared), r0 > 0 (-): the default parameters p = (mu, eps0,
    r0). State: weights C (M), inputs U (M), weight sums W (n), frozen weights C_f (M), the
    decision ``(frozen, age, fault)``, the sample count and the run of samples with R > r0.

    Raises
    ------
    ObserverError
        Naming the argument: an order, window, hold or confirm that is not a positive integer (window
        at least 2), a mu, eps0, r0 or dt that is not positive and finite, not one signal.
    """
    check_name(name, "observer")
    M = _positive_int(order, "order M", name)
    n = _positive_int(window, "window n", name)
    if n < 2:
        raise ObserverError(f"{name}: window n must be at least 2 samples (R needs a spread), got {n}")
    decide = double_criterion(_positive_int(confirm, "confirm", name))
    lms = lms_step(M, balanced=True)  # the step expands to straight-line code: its sums as trees
    hold = _positive_int(hold, "hold", name)
    p0 = [_positive(mu, "mu", name), _positive(eps0, "eps0", name), _positive(r0, "r0", name)]
    _positive(dt, "sample period dt", name)
    for what, group in (("measured", measured), ("regressor", regressor), ("reference", reference)):
        if group is not None and (not isinstance(group, Signals) or group.size != 1):
            raise ObserverError(f"{name}: {what} must be one signal (a Signals of size 1), got {group!r}")
    y_name, y_unit = measured.names[0], measured.units[0]
    u_unit = regressor.units[0]
    weight_unit = f"{y_unit}/{u_unit}" if u_unit not in ("", "-") else y_unit
    state = Signals(tuple(f"C_{i}" for i in range(1, M + 1)) + tuple(f"U_{i}" for i in range(1, M + 1))
                    + tuple(f"S_{j}" for j in range(1, n + 1)) + tuple(f"Cf_{i}" for i in range(1, M + 1))
                    + DECISION_STATE + ("count", "above"),
                    (weight_unit,) * M + (u_unit,) * M + (weight_unit,) * n + (weight_unit,) * M
                    + ("-", "samples", "-", "samples", "samples"), group="state")
    params = signals(("mu", f"1/({u_unit})^2" if u_unit not in ("", "-") else "-", "LMS step"),
                     ("eps0", f"({y_unit})^2", "threshold of eps^2"), ("r0", "-", "threshold of R"),
                     group="parameter")
    publishes = signals((f"{y_name}_fir", y_unit, "live FIR prediction r + d"),
                        (f"{y_name}_sub", y_unit, "substitute: the frozen filter's prediction while frozen"),
                        (f"e_{y_name}", y_unit, "prediction error d - (y - r)"),
                        (f"eps2_{y_name}", f"({y_unit})^2", "error criterion e^2"),
                        (f"R_{y_name}", "-", "weight-drift criterion"),
                        (f"alarm_eps2_{y_name}", "-", "eps^2 > eps0"), (f"alarm_R_{y_name}", "-", "R > r0"),
                        (f"frozen_{y_name}", "-", "filter frozen"), (f"fault_{y_name}", "-", "fault confirmed"),
                        (f"disturbance_{y_name}", "-", "freeze released: a disturbance"), group="published")
    reads_u = (regressor + reference if reference else regressor).renamed(group="input")

    def step(s, y, u, p):
        C, U, W, Cf = s[:M], s[M:2 * M], s[2 * M:2 * M + n], s[2 * M + n:3 * M + n]
        decision, count, above = s[3 * M + n:3 * M + n + 3], s[-2], s[-1]
        mu_, eps0_, r0_ = p[0], p[1], p[2]
        offset = u[1] if reference is not None else 0.0
        C_next, U_next, d, e = lms(C, U, y[0] - offset, u[0], mu_)
        W_next = ca.vertcat(W[1:], balanced_sum(C))
        count_next = ca.fmin(count + 1, n)
        mean = balanced_sum(W_next) / n
        var = balanced_sum((W_next - mean) ** 2) / n
        full = ca.logic_and(count_next >= n, var > 0)
        R = ca.if_else(full, (W_next[-1] - mean) ** 2 / ca.if_else(var > 0, var, 1.0), 0.0)
        above_next = ca.if_else(R > r0_, ca.fmin(above + 1, hold), 0.0)
        alarm_e, alarm_r = e ** 2 > eps0_, above_next >= hold
        decision_next, snapshot, released = decide(decision, alarm_e, alarm_r)
        Cf_next = ca.if_else(snapshot, C, Cf)
        frozen_now = ca.logic_and(decision_next[0], ca.logic_not(snapshot))
        substitute = offset + ca.if_else(frozen_now, balanced_sum(Cf * U), d)
        s_next = ca.vertcat(C_next, U_next, W_next, Cf_next, decision_next, count_next, above_next)
        out = ca.vertcat(offset + d, substitute, e, e ** 2, R, alarm_e, alarm_r, decision_next[0],
                         decision_next[2], released)
        return s_next, out

    return observer(name, step=step, state=state, reads_y=measured.renamed(group="measurement"),
                    reads_u=reads_u, publishes=publishes, params=params, p0=p0, dt=float(dt),
                    description=f"LMS-FIR monitor of {y_name}: order {M}, R window {n}, hold {hold}, confirm {confirm} "
                                "samples; "
                                f"p = (mu, eps0, r0); sampled every {dt:g} s")
