"""Unit tests of the Gaussian filters' shared parts (uvsym.observers.kalman): the transition's checks,
the log-likelihood of an empty measurement, covariance units, the filter observer's signal labels,
NaN gating far from the origin and run_filter's positive-margin rule and message."""

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import CovarianceError, ModelError, ObserverError
from uvsym.observers.base import observer
from uvsym.observers.ekf import ekf
from uvsym.observers.kalman import covariance_signals, gaussian_loglik, run_filter, transition
from uvsym.systems.signals import signals
from uvsym.systems.system import system


def held(dt: float, **groups):
    """x+ = x (discrete every dt s), y = x; groups: optional group names of x, u, y."""
    x = signals(("a", "m"), group=groups.get("x", "state"))
    return system("held", "x+ = x", x=x, u=signals(("f", "N"), group=groups.get("u", "input")),
                  rhs=lambda x, u, d, p: x, dt=dt, y=x.renamed(prefix="m_", group=groups.get("y", "output")),
                  output=lambda x, u, p: x)


def decay():
    """x' = -x (continuous), y = x."""
    return system("decay", "x' = -x", x=signals(("a", "m"), group="state"), u=signals(("f", "N"), group="input"),
                  rhs=lambda x, u, d, p: -x)


# --- transition -------------------------------------------------------------------------------------------------


def test_a_sampling_mismatch_of_exactly_the_relative_tolerance_is_accepted():
    """dt = 1e9 2^-30 s and the system's (1e9 + 1) 2^-30 s differ by 2^-30 = 1e-9 dt, all exact in
    binary: the limit itself is accepted, the next double above it is refused."""
    dt = 1e9 * 2.0**-30
    sampled = (1e9 + 1.0) * 2.0**-30
    assert sampled - dt == 2.0**-30 == 1e-9 * dt  # the premise, in exact binary arithmetic
    F = transition(held(sampled), dt)
    assert float(F(ca.DM(2.5), ca.DM(0.0), ca.DM.zeros(0, 1))) == 2.5
    with pytest.raises(ObserverError, match="sampled every"):
        transition(held(np.nextafter(sampled, 2.0)), dt)


@pytest.mark.parametrize("dt, sampled, accepted", [
    (100.0, 100.0 + 1e-8, True),        # relative mismatch 1e-10: rounding, accepted
    (1e-3, 1e-3 * (1 + 1e-5), False),   # relative mismatch 1e-5: a different sample period
])
def test_the_sampling_tolerance_is_relative_to_dt(dt, sampled, accepted):
    if accepted:
        transition(held(sampled), dt)
    else:
        with pytest.raises(ObserverError, match=r"held is sampled every 0\.00100001 s, the filter every 0\.001 s"):
            transition(held(sampled), dt)


@pytest.mark.parametrize("steps", [0, -2, 1.5])
def test_rk4_steps_that_are_not_a_positive_integer_are_refused_with_their_value(steps):
    with pytest.raises(ObserverError, match=rf"^steps must be a positive integer, got {steps!r}$"):
        transition(decay(), 0.1, steps=steps)


# --- gaussian_loglik and covariance_signals --------------------------------------------------------------------


def test_the_log_likelihood_of_an_empty_measurement_is_the_symbolic_zero():
    """n_y = 0: an empty product of densities is 1, its log 0; still an SX scalar (as documented)."""
    value = gaussian_loglik(ca.SX(0, 1), ca.SX(0, 0))
    assert isinstance(value, ca.SX) and value.shape == (1, 1)
    assert float(ca.evalf(value)) == 0.0


def test_covariance_units_treat_an_empty_unit_as_dimensionless():
    P = covariance_signals(signals(("a", ""), ("b", "m"), group="state"))
    assert P.names == ("P.a.a", "P.b.a", "P.b.b") and P.units == ("-", "m", "m m")


# --- filter_observer: names, units, descriptions and groups of its signals --------------------------------------


def test_the_filter_state_and_diagnostics_are_named_and_labelled():
    obs = ekf(held(0.1), dt=0.1, Q=0.01, R=0.2, P0=0.3)
    assert obs.state.names == ("a_hat", "P.a.a") and obs.state.group == "state"
    assert obs.publishes.names == ("a_hat", "r_m_a", "loglik", "pd_margin", "skipped")
    assert obs.publishes.units[2:] == ("-", "-", "-")
    assert obs.publishes.descriptions[2:] == (
        "log-likelihood of y_k", "smallest relative Cholesky pivot of the step (> 0: P.D.)",
        "1 where y_k had a NaN and the update was skipped")


def test_the_signals_a_filter_reads_are_grouped_by_their_role_whatever_the_system_calls_them():
    """A system built without group names (all 'signal'): the filter still reads a measurement, an
    input and a parameter, and says so when a value names an unknown one."""
    x, u = signals(("a", "m")), signals(("f", "N"))
    plant = system("plain", "x+ = k x + f", x=x, u=u, p=signals(("k", "-")), p0=[1.0], dt=0.1,
                   rhs=lambda x, u, d, p: p * x + u)
    obs = ekf(plant, dt=0.1, Q=0.01, R=0.2, P0=0.3)
    assert (obs.reads_y.group, obs.reads_u.group, obs.params.group) == ("measurement", "input", "parameter")
    with pytest.raises(ObserverError, match=r"no parameter named \['c'\]"):
        obs.parameters({"c": 1.0})
    with pytest.raises(ObserverError, match=r"no measurement named \['b'\]"):
        obs.initial_state({"b": 1.0}, [0.0])
    with pytest.raises(ObserverError, match=r"no input named \['g'\]"):
        obs.initial_state([0.0], {"g": 1.0})


@pytest.mark.parametrize("groups", [{"x": "residual"}, {"y": "estimate"}])
def test_an_estimate_named_like_a_residual_is_a_clash_of_published_signals(groups):
    """State r_c publishes r_c_hat, output c_hat publishes r_c_hat too: the clash is between two kinds
    of published signal (estimate and residual), whatever groups the system gave its signals."""
    x = signals(("r_c", "m"), group=groups.get("x", "state"))
    plant = system("clash", "x+ = x", x=x, u=signals(("f", "N"), group="input"), rhs=lambda x, u, d, p: x, dt=0.1,
                   y=signals(("c_hat", "m"), group=groups.get("y", "output")), output=lambda x, u, p: x)
    with pytest.raises(ModelError, match=r"^signal names must be unique; repeated: \['r_c_hat'\]$"):
        ekf(plant, dt=0.1, Q=0.01, R=0.2, P0=0.3)


# --- measurement_gate and run_filter ----------------------------------------------------------------------------


def test_a_skipped_update_far_from_the_origin_publishes_a_zero_residual_and_log_likelihood():
    """x = 1e200 m, y = x: the gated update substitutes the predicted measurement, so its residual is
    exactly 0 (a residual of order 1e200 would square to inf, and 0 * inf is NaN)."""
    obs = ekf(held(0.1), dt=0.1, Q=1.0, R=1.0, P0=1.0, x0=[1e200])
    S, OUT = run_filter(obs, [[np.nan]], [[0.0]])
    assert OUT[0, [0, 1, 2, 4]].tolist() == [1e200, 0.0, 0.0, 1.0]
    assert OUT[0, 3] == pytest.approx(1.0 + 1e-12, abs=1e-15)  # pd_margin: a (1 + jitter) / a for the 1x1 pivot
    assert S[1].tolist() == [1e200, 2.0]  # prior kept, then P = 1 + Q


def test_run_filter_uses_the_parameters_given():
    """x+ = k x + f, y = x with k = 0.5 (p0 says 1): K = P0 / (P0 + R), x^+ = K y, then
    x^- = k x^+ and P^- = k^2 P0 R / (P0 + R) + Q; rtol 1e-10 for the factorisations' jitter."""
    plant = system("gain", "x+ = k x + f", x=signals(("a", "m"), group="state"), u=signals(("f", "m"), group="input"),
                   p=signals(("k", "-"), group="parameter"), p0=[1.0], dt=0.1, rhs=lambda x, u, d, p: p * x + u)
    q, r, p0, y, k = 0.01, 0.2, 0.3, 1.4, 0.5
    S = run_filter(ekf(plant, dt=0.1, Q=q, R=r, P0=p0), [[y]], [[0.0]], p=[k])[0]
    x_post = p0 / (p0 + r) * y
    np.testing.assert_allclose(S[1], [k * x_post, k**2 * p0 * r / (p0 + r) + q], rtol=1e-10)


def margin_echo():
    """An observer (every 0.5 s) publishing its measurement as pd_margin: run_filter's rule alone."""
    return observer("echo", step=lambda s, y, u, p: (s, y), dt=0.5, state=signals(("n", "-")),
                    reads_y=signals(("m", "-")), reads_u=signals(), publishes=signals(("pd_margin", "-")))


@pytest.mark.parametrize("first_bad, margin", [(2, 0.0), (3, -1e-3), (1, np.nan)])
def test_run_filter_names_the_first_sample_whose_margin_is_not_positive(first_bad, margin):
    """A margin of exactly 0 is not positive; t = k dt (dt = 0.5 s)."""
    margins = [1.0, 1e-300, 0.5, 0.2]
    margins[first_bad] = margin
    t, shown = f"{first_bad * 0.5:g}", f"{margin:.3g}"
    message = (f"echo: a covariance is no longer positive definite at sample {first_bad} (t = {t} s; smallest "
               f"relative Cholesky pivot {shown}); Q, R or P0 are ill-scaled, or the model diverged")
    with pytest.raises(CovarianceError) as caught:
        run_filter(margin_echo(), np.array(margins)[:, None], np.zeros((4, 0)), s0=[0.0])
    assert str(caught.value) == message
