"""Predicted faults (Liu et al. 2014, eqs. 19-24) from estimates with a closed form, for an observer whose error
matrix is chosen by hand: A = -diag(K), so channel i converges at rate K_i (1/s).

- exponential fit (eq. 19): f_hat(t) = f - C exp(-a t) is fitted exactly, f_bar = f;
- line and quadratic fits (eqs. 22-24): f_bar = f_hat(t_end) - A^-1 f_hat'(t_end) = f_hat(t_end) + f_hat'(t_end) / a,
  exact for an f_hat that is a polynomial of the fit's order.
"""

from __future__ import annotations

import math
import warnings
from decimal import Decimal
from fractions import Fraction
from types import SimpleNamespace

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import ObserverError
from uvsym.observers import isolation
from uvsym.observers.isolation import IsolationSettings, Isolator, _window, predicted_faults

DT = 0.01  # s
T = np.arange(0.0, 2.0, DT)  # s
W = 100  # samples per window of the default 1 s


def _rates() -> SimpleNamespace:
    """An observer whose error matrix is -diag(K) whatever tau_d: A_ii = -K_i."""
    K = ca.SX.sym("K", 2)
    return SimpleNamespace(error_matrix=ca.Function("A", [ca.SX.sym("tau_d", 2), K], [-ca.diag(K)]))


RATES = _rates()


def predict(f_hat, K=(5.0, 4.0), **settings):
    tau_d = np.ones((len(T), 2))
    return predicted_faults(RATES, np.array(K), T, f_hat, tau_d, IsolationSettings(**settings))


def test_the_exponential_fit_recovers_the_fault_before_the_estimate_converges():
    f, C, a = np.array([13.0, -2.0]), np.array([13.0, 5.0]), np.array([5.0, 4.0])
    f_hat = f - C * np.exp(-np.outer(T, a))
    f_bar, visible = predict(f_hat)
    assert visible.all()
    assert np.isnan(f_bar[:W - 1]).all()  # no full window yet
    np.testing.assert_allclose(f_bar[W - 1:], np.tile(f, (len(T) - W + 1, 1)), rtol=0, atol=1e-9)
    assert abs(f_hat[W - 1, 0] - 13.0) > 0.08  # the estimate itself is still off by C exp(-5 t)


@pytest.mark.parametrize("fit, order", [("line", 1), ("quadratic", 2)])
def test_polynomial_fits_apply_eq_21_at_the_window_end(fit, order):
    a = np.array([5.0, 4.0])
    coefficients = np.array([[1.0, -3.0], [0.5, 2.0], [0.25, -0.75]])[:order + 1]  # f_hat = sum c_j t^j
    f_hat = sum(np.outer(T**j, c) for j, c in enumerate(coefficients))
    slope = sum(j * np.outer(T ** (j - 1), c) for j, c in enumerate(coefficients) if j)
    f_bar, _ = predict(f_hat, fit=fit)
    np.testing.assert_allclose(f_bar[W - 1:], (f_hat + slope / a)[W - 1:], rtol=1e-9, atol=1e-9)


def test_a_line_fit_misses_a_curved_estimate_that_the_quadratic_fit_follows():
    f_hat = np.column_stack([T**2, T**2])
    exact = f_hat + 2 * T[:, None] / np.array([5.0, 4.0])
    line, _ = predict(f_hat, fit="line")
    quadratic, _ = predict(f_hat, fit="quadratic")
    np.testing.assert_allclose(quadratic[W - 1:], exact[W - 1:], rtol=1e-9, atol=1e-9)
    assert np.abs(line[W - 1:] - exact[W - 1:]).min() > 1e-3


@pytest.mark.parametrize("fit", ["exponential", "line", "quadratic"])
def test_a_channel_converging_slower_than_one_per_window_is_hidden(fit):
    """K_2 = 0.5 / s < 1 / window_s: channel 2 is not observable, its f_bar NaN; channel 1 unaffected."""
    f_hat = np.column_stack([3.0 - np.exp(-5.0 * T), 1.0 + 0 * T])
    f_bar, visible = predict(f_hat, K=(5.0, 0.5), fit=fit)
    assert visible[:, 0].all() and not visible[:, 1].any()
    assert np.isnan(f_bar[:, 1]).all()
    assert np.isfinite(f_bar[W - 1:, 0]).all()
    f_bar, visible = predict(f_hat, K=(5.0, 1.0), fit=fit)  # exactly one per window: observable
    assert visible[:, 1].all() and np.isfinite(f_bar[W - 1:, 1]).all()


def test_a_window_longer_than_the_record_gives_no_prediction():
    f_bar, visible = predicted_faults(RATES, np.array([5.0, 4.0]), T[:50], np.ones((50, 2)), np.ones((50, 2)),
                                      IsolationSettings())
    assert f_bar.shape == (50, 2) and np.isnan(f_bar).all() and visible.all()


def test_shorter_windows_predict_earlier():
    f_hat = 2.0 - np.exp(-np.outer(T, [5.0, 4.0]))
    f_bar, _ = predict(f_hat, window_s=0.25)
    assert np.isnan(f_bar[:24]).all() and np.isfinite(f_bar[24:]).all()  # 0.25 s = 25 samples


def test_uneven_sampling_and_mismatched_shapes_are_refused():
    uneven = T.copy()
    uneven[10] += DT / 3
    with pytest.raises(ObserverError, match="uniformly sampled estimates at increasing times"):
        predicted_faults(RATES, np.array([5.0, 4.0]), uneven, np.ones((len(T), 2)), np.ones((len(T), 2)))
    with pytest.raises(ObserverError, match="matching rows"):
        predicted_faults(RATES, np.array([5.0, 4.0]), T, np.ones((len(T), 2)), np.ones((len(T) - 1, 2)))


@pytest.mark.parametrize("name", ["window_s", "threshold", "margin", "healthy_tolerance", "healthy_tolerance_p"])
@pytest.mark.parametrize("value", [0.0, -1.0, math.inf, math.nan])
def test_isolation_settings_must_be_positive_and_finite(name, value):
    with pytest.raises(ObserverError, match=f"isolation setting {name} must be positive and finite"):
        IsolationSettings(**{name: value})


def test_an_unknown_fit_is_refused_with_the_known_ones():
    with pytest.raises(ObserverError, match="unknown isolation fit 'cubic'; known: exponential, line, quadratic"):
        IsolationSettings(fit="cubic")
    assert IsolationSettings() == IsolationSettings(1.0, "exponential", 1e-4, 0.1, 0.05, 0.01)  # the paper's


def test_a_record_of_exactly_one_window_predicts_its_last_sample():
    f_hat = 2.0 - np.exp(-np.outer(T[:W], [5.0, 4.0]))
    f_bar, _ = predicted_faults(RATES, np.array([5.0, 4.0]), T[:W], f_hat, np.ones((W, 2)), IsolationSettings())
    assert np.isnan(f_bar[:W - 1]).all() and np.allclose(f_bar[W - 1], 2.0, atol=1e-9)


@pytest.mark.parametrize("fit", ["line", "quadratic"])
def test_a_hidden_channel_is_cut_out_of_a_coupled_error_matrix(fit):
    """A = [[-5, 1], [2, -0.5]]: channel 2 (rate 0.5 / s) is hidden, so eq. 21 on channel 1 uses A_11 alone:
    f_bar_1 = f_hat_1 + f_hat_1' / 5 for a linear f_hat_1 = 1 + 2 t."""
    coupled = SimpleNamespace(error_matrix=ca.Function("A", [ca.SX.sym("tau_d", 2), ca.SX.sym("K", 2)],
                                                       [ca.DM([[-5.0, 1.0], [2.0, -0.5]])]))
    f_hat = np.column_stack([1.0 + 2.0 * T, np.cos(T)])
    f_bar, visible = predicted_faults(coupled, np.zeros(2), T, f_hat, np.ones((len(T), 2)), IsolationSettings(fit=fit))
    assert visible[:, 0].all() and not visible[:, 1].any() and np.isnan(f_bar[:, 1]).all()
    np.testing.assert_allclose(f_bar[W - 1:, 0], (1.0 + 2.0 * T + 2.0 / 5.0)[W - 1:], rtol=1e-9)


def test_a_channel_too_slow_to_see_is_hidden_without_a_numerical_warning():
    """At a rate of 1e-9 /s the exponential's weights are all 1 to double precision: the fit's denominator
    W sum g^2 - (sum g)^2 is 0 and the channel is hidden (NaN), quietly, whatever numpy's error settings."""
    f_hat = np.column_stack([np.sin(3 * T), np.cos(T)])
    with warnings.catch_warnings(), np.errstate(all="warn"):
        warnings.simplefilter("error")
        f_bar, visible = predict(f_hat, K=(5.0, 1e-9))
    assert not visible[:, 1].any() and np.isnan(f_bar[:, 1]).all()


def test_an_isolator_fed_in_chunks_keeps_the_windowed_means_of_the_whole_record(monkeypatch):
    """Chunks of 50 samples with a 10-sample window (so later updates recompute only a tail, 3 windows before the new
    samples): the record's mean of f_bar is, row by row, the mean of the last 10 predicted faults of the whole record
    (NaN in the first 18 rows); rates of 50 and 40 /s keep both channels visible (>= 1 / window_s); times given as
    exact fractions are kept as float seconds."""
    settings, K, window = IsolationSettings(window_s=0.1), np.array([50.0, 40.0]), 10
    tails = []

    def spy(observer, K, t, f_hat, tau_d, settings):
        tails.append(len(t))
        return predicted_faults(observer, K, t, f_hat, tau_d, settings)

    monkeypatch.setattr(isolation, "predicted_faults", spy)
    f_hat, tau_d = np.column_stack([np.sin(3 * T), np.cos(T)]), np.ones((len(T), 2))
    isolator = Isolator({"bias": (RATES, K)}, ("X", "Y"), settings)
    for start in range(0, len(T), 50):
        times = [Fraction(k, 100) for k in range(start, start + 50)]
        isolator.update(times, {"bias": f_hat[start:start + 50]}, tau_d[start:start + 50])
    assert isolator.t.dtype == np.float64
    f_bar, _ = predicted_faults(RATES, K, T, f_hat, tau_d, settings)
    expected, spread = np.full_like(f_bar, np.nan), np.full_like(f_bar, np.nan)
    for row in range(2 * window - 2, len(T)):
        expected[row] = f_bar[row - window + 1:row + 1].mean(axis=0)
        spread[row] = f_bar[row - window + 1:row + 1].var(axis=0)
    assert np.isfinite(expected[2 * window - 2:]).all()
    np.testing.assert_allclose(isolator.f_bar["bias"], f_bar, rtol=0, atol=1e-12)
    np.testing.assert_allclose(isolator.mean["bias"], expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(isolator.variance["bias"], spread, rtol=0, atol=1e-12)
    assert tails == [50, 80, 80, 80]  # 50 new samples, then 3 windows before them


def test_gains_given_as_exact_fractions_predict_the_fault_like_floats():
    """K = (5, 4) as Fractions is read as float gains: the exponential fit still recovers f = (13, -2) exactly."""
    f, C, a = np.array([13.0, -2.0]), np.array([13.0, 5.0]), np.array([5.0, 4.0])
    f_hat = f - C * np.exp(-np.outer(T, a))
    tau_d = np.ones((len(T), 2))
    f_bar, visible = predicted_faults(RATES, (Fraction(5), Fraction(4)), T, f_hat, tau_d, IsolationSettings())
    assert visible.all()
    np.testing.assert_allclose(f_bar[W - 1:], np.tile(f, (len(T) - W + 1, 1)), rtol=0, atol=1e-9)


def test_the_window_is_the_samples_per_window_s_and_at_least_three():
    """Two samples 0.01 s apart set the spacing (1 s = 100 samples); samples 10 s apart give the floor of 3, as does a
    single sample (no spacing yet)."""
    assert _window(np.array([0.0, 0.01]), 1.0) == 100
    assert _window(np.array([5.0, 15.0]), 1.0) == 3
    assert _window(np.array([0.0]), 1.0) == 3


def test_sampling_is_uniform_within_one_millionth_of_the_step():
    """Steps dt = 15625 2^-14 s (so 1e-6 dt = 2^-20 s exactly) with the last one 2^-20 s longer: at the bound, accepted;
    a deviation of 1e-6 s on a step of 0.01 s (1e-4 of it) is refused, as are repeated times."""
    dt = 15625 * 2.0**-14
    assert 1e-6 * dt == 2.0**-20
    edge = np.array([0.0, dt, 2 * dt, 3 * dt, 4 * dt + 2.0**-20])
    assert edge[-1] - edge[-2] - dt == 2.0**-20  # the deviation is exact
    assert _window(edge, 10 * dt) == 10
    jitter = T.copy()
    jitter[10] += 1e-6
    message = "^isolation needs uniformly sampled estimates at increasing times$"
    with pytest.raises(ObserverError, match=message):
        _window(jitter, 1.0)
    with pytest.raises(ObserverError, match=message):
        predicted_faults(RATES, np.array([5.0, 4.0]), np.zeros(5), np.ones((5, 2)), np.ones((5, 2)))


def test_a_window_of_two_samples_is_widened_to_three():
    """window_s = 0.02 s is 2 samples of 0.01 s: the window holds 3, so the first prediction is at row 2; rates of
    100 and 200 /s (>= 1 / window_s) keep both channels visible and the exponential fit recovers f exactly."""
    f, C, a = np.array([1.5, -0.5]), np.array([1.0, 2.0]), np.array([100.0, 200.0])
    f_hat = f - C * np.exp(-np.outer(T, a))
    f_bar, visible = predict(f_hat, K=a, window_s=0.02)
    assert visible.all() and np.isnan(f_bar[:2]).all()
    np.testing.assert_allclose(f_bar[2:], np.tile(f, (len(T) - 2, 1)), rtol=0, atol=1e-12)


def test_visibility_is_a_rate_of_one_per_window():
    """window_s = 0.5 s: a channel is visible from a rate of 2 /s; 1.5 /s is hidden."""
    f_hat = np.column_stack([3.0 - np.exp(-5.0 * T), 1.0 + 0 * T])
    for rate, seen in ((1.5, False), (2.0, True)):
        _, visible = predict(f_hat, K=(5.0, rate), window_s=0.5)
        assert visible[:, 0].all() and (visible[:, 1] == seen).all()


def test_a_long_record_still_predicts_the_fault_at_its_end():
    """100 s at 0.1 s (window 10 samples), rates 5 and 4 /s: exp(-a t) falls below the smallest double long before
    the end, and the exponential fit, weighted relative to each window's end, still gives f = (13, -2)."""
    t = np.arange(1000) * 0.1
    f, C, a = np.array([13.0, -2.0]), np.array([13.0, 5.0]), np.array([5.0, 4.0])
    f_hat = f - C * np.exp(-np.outer(t, a))
    f_bar, _ = predicted_faults(RATES, a, t, f_hat, np.ones((len(t), 2)), IsolationSettings())
    np.testing.assert_allclose(f_bar[9:], np.tile(f, (len(t) - 9, 1)), rtol=0, atol=1e-9)


@pytest.mark.parametrize("fit", ["line", "quadratic"])
def test_polynomial_fits_use_the_time_step_not_the_clock(fit):
    """The same line f_hat = 1 + 2 t sampled from t = 5 s: f_bar = f_hat + f_hat' / a = 1 + 2 t + 2 / a."""
    t = 5.0 + T
    a = np.array([5.0, 4.0])
    f_hat = np.tile(1.0 + 2.0 * t[:, None], (1, 2))
    f_bar, _ = predicted_faults(RATES, a, t, f_hat, np.ones((len(t), 2)), IsolationSettings(fit=fit))
    np.testing.assert_allclose(f_bar[W - 1:], (f_hat + 2.0 / a)[W - 1:], rtol=1e-9)


def test_the_quadratic_fit_is_the_least_squares_parabola_of_a_cubic_estimate():
    """f_hat = t^3 is not a parabola: f_bar is the value plus slope / a at the window's end of numpy's own
    least-squares parabola through the window (np.polyfit), a cubic fit would be exact instead."""
    a = np.array([5.0, 4.0])
    f_hat = np.tile((T**3)[:, None], (1, 2))
    f_bar, _ = predict(f_hat, fit="quadratic")
    for end in (W - 1, 150, len(T) - 1):
        p = np.polyfit(T[end - W + 1:end + 1] - T[end], f_hat[end - W + 1:end + 1, 0], 2)
        np.testing.assert_allclose(f_bar[end], p[2] + p[1] / a, rtol=1e-9)
        assert abs(f_bar[end, 0] - (T[end] ** 3 + 3 * T[end] ** 2 / 5.0)) > 1e-6


def test_decimal_inputs_are_read_as_floats():
    """Times, estimates and desired actions given as Decimals predict, and are stored, like the same floats."""
    f_hat = 2.0 - np.exp(-np.outer(T, [5.0, 4.0]))
    tau_d = np.ones((len(T), 2))
    expected, _ = predict(f_hat)
    as_decimal = [Decimal(float(x)) for x in T]  # exact binary values
    f_bar, _ = predicted_faults(RATES, np.array([5.0, 4.0]), as_decimal, f_hat, tau_d, IsolationSettings())
    np.testing.assert_array_equal(f_bar, expected)
    isolator = Isolator({"bias": (RATES, np.array([5.0, 4.0]))}, ("X", "Y"))
    decimals = np.vectorize(lambda x: Decimal(float(x)), otypes=[object])
    isolator.update(as_decimal, {"bias": decimals(f_hat)}, decimals(tau_d))
    assert isolator.tau_d.dtype == isolator.f_hat["bias"].dtype == np.float64
    np.testing.assert_array_equal(isolator.f_bar["bias"], expected)


def test_a_fit_that_divides_zero_by_zero_or_overflows_is_nan_quietly():
    """Rate 0 (channel 2): every weight exp(0) = 1, so the fit is 0 / 0 and the channel hidden. Rate 400 /s over a 1 s
    window with a constant estimate of 1e50 (channel 1): the weights reach their cap e^300, so sum g^2 sum f_hat is
    about 70 e^600 100 1e50 > 1e308 and overflows: no prediction. Both without a warning, whatever numpy's settings."""
    f_hat = np.column_stack([np.full(len(T), 1e50), np.cos(T)])
    with warnings.catch_warnings(), np.errstate(all="raise"):
        warnings.simplefilter("error")
        f_bar, visible = predict(f_hat, K=(400.0, 0.0))
    assert visible[:, 0].all() and not visible[:, 1].any()
    assert np.isnan(f_bar).all()


def test_the_weights_cap_at_e300_keeps_a_large_constant_estimate_predictable():
    """Rate 400 /s over a 1 s window: the 25 samples 0.75 s or more before the window's end weigh e^300 (the cap),
    so sum g^2 sum f_hat ~ 25 e^600 100 f = 5.6e307 for a constant f = 6e43, below the largest double (1.8e308): the
    fit still returns f exactly (with a cap of e^301 the sum would overflow)."""
    f_hat = np.full((len(T), 2), 6e43)
    f_bar, visible = predict(f_hat, K=(400.0, 400.0))
    assert visible.all()
    np.testing.assert_allclose(f_bar[W - 1:], 6e43, rtol=1e-12)
