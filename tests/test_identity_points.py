"""The sample points of the identity prover (``_points``): where its numerical evidence is taken.

The expected shares below follow from the documented sampling design, computed by hand: over a box,
60 % uniform on [lower, upper], 20 % exactly at an end (either with probability 1/2), 20 % near zero
(random sign, magnitude ``M 10^u`` with ``u`` uniform on [-6, 0) and ``M = max(|lower|, |upper|)``,
clipped to the box); without a box, 50 % N(0, 2^2), 35 % random sign times ``10^u`` with ``u``
uniform on [-3, 8), 15 % integers -10..10. Tolerances are about 5 standard deviations of a share
estimated from the number of values drawn.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvsym.verify.identity import _points

SAMPLES = 20000
# columns: two symmetric boxes (half-widths 1 and 1000), one away from zero, one lopsided around zero
LOWER = np.array([-1.0, -1000.0, 2.0, -8.0])
UPPER = np.array([1.0, 1000.0, 5.0, 2.0])


def _box_points() -> np.ndarray:
    return _points(np.random.default_rng(7), 4, (LOWER, UPPER), SAMPLES)


def _free_points() -> np.ndarray:
    return _points(np.random.default_rng(7), 2, None, SAMPLES).ravel()


def _share(mask) -> float:
    return float(np.mean(mask))


def test_box_points_are_floats_inside_the_box():
    points = _box_points()
    assert points.shape == (SAMPLES, 4)
    assert points.dtype == np.float64
    assert np.all(np.isfinite(points))
    assert np.all(points >= LOWER) and np.all(points <= UPPER)


def test_box_points_hit_each_end_a_tenth_of_the_time():
    """Symmetric boxes: near-zero magnitudes stay below the half-width, so only the ends draw sits on it."""
    ratio = _box_points()[:, :2] / UPPER[:2]  # (SAMPLES, 2), in [-1, 1]
    assert abs(_share(ratio == -1.0) - 0.1) < 0.01
    assert abs(_share(ratio == 1.0) - 0.1) < 0.01
    assert abs(_share(np.abs(ratio) == 1.0) - 0.2) < 0.008


def test_box_points_spread_uniformly_over_the_box():
    """Share in (a/2, a) on each side: uniform 0.6 * 1/4, near zero 0.2 * (log10 2 / 6) / 2."""
    ratio = _box_points()[:, :2] / UPPER[:2]
    expected = 0.6 / 4 + 0.2 * math.log10(2.0) / 12
    assert abs(_share((ratio > 0.5) & (ratio < 1.0)) - expected) < 0.01
    assert abs(_share((ratio < -0.5) & (ratio > -1.0)) - expected) < 0.01
    interior = ratio[np.abs(ratio) < 1.0]
    assert np.unique(interior).size == interior.size  # continuous draws, no repeated value


def test_box_points_near_zero_are_log_uniform_down_to_a_millionth_of_the_box():
    """|x| / a below 1e-3: near zero 0.2 * 3/6, uniform 0.6 * 1e-3; log10 uniform on [-6, -3) there."""
    ratio = _box_points()[:, :2] / UPPER[:2]
    small = ratio[np.abs(ratio) < 1e-3]
    assert abs(small.size / ratio.size - (0.1 + 0.6e-3)) < 0.006
    assert np.count_nonzero(np.abs(ratio) < 1e-6) <= 2  # only uniform draws: expected 0.024 of them
    exponents = np.log10(np.abs(small))
    assert abs(float(np.mean(exponents)) + 4.5) < 0.07  # std of the mean: (3 / sqrt 12) / sqrt(4000)
    assert abs(_share(small < 0) - 0.5) < 0.04
    # each symmetric box on its own reaches down to its own millionth
    for column, half_width in enumerate(UPPER[:2]):
        values = np.abs(_box_points()[:, column])
        assert abs(_share(values < 1e-3 * half_width) - 0.1006) < 0.01
        assert np.count_nonzero(values < 1e-6 * half_width) <= 2


def test_free_points_are_finite_floats_below_1e8():
    points = _points(np.random.default_rng(7), 2, None, SAMPLES)
    assert points.shape == (SAMPLES, 2)
    assert points.dtype == np.float64
    assert np.all(np.isfinite(points))
    assert np.max(np.abs(points)) < 1e8


def test_free_points_include_every_small_integer():
    """Integers -10..10, 15 % of the values; the other draws are continuous (never integer in practice)."""
    values = _free_points()
    integral = values[(values == np.round(values)) & (np.abs(values) <= 10)]
    assert set(integral.tolist()) == set(range(-10, 11))
    assert abs(integral.size / values.size - 0.15) < 0.01


def test_free_points_normal_part_has_standard_deviation_two():
    """Non-integer values in (-1, 1): N(0, 4) gives 0.5 * erf(0.5 / sqrt 2), the scaled part 0.35 * 3/11."""
    values = _free_points()
    fractional = values != np.round(values)
    expected = 0.5 * math.erf(0.5 / math.sqrt(2.0)) + 0.35 * 3 / 11
    assert abs(_share(fractional & (np.abs(values) < 1.0)) - expected) < 0.01


def test_free_points_scaled_part_is_log_uniform_from_1e_minus_3_to_1e8_with_both_signs():
    """Above 10.5 only the scaled part (N(0, 4) beyond 10.5: 1.5e-7): 0.35 * (8 - log10 10.5) / 11.

    Below 1e-2 (nonzero): scaled 0.35 * 1/11, N(0, 4) 0.5 * erf(0.005 / sqrt 2)."""
    values = _free_points()
    large = values[np.abs(values) > 10.5]
    assert abs(large.size / values.size - 0.35 * (8 - math.log10(10.5)) / 11) < 0.008
    assert abs(_share(large < 0) - 0.5) < 0.025
    exponents = np.log10(np.abs(large))
    assert abs(float(np.mean(exponents)) - (8 + math.log10(10.5)) / 2) < 0.1
    small = values[(values != 0) & (np.abs(values) < 1e-2)]
    expected = 0.35 / 11 + 0.5 * math.erf(0.005 / math.sqrt(2.0))
    assert abs(small.size / values.size - expected) < 0.005


class _Draws:
    """A generator stand-in: each uniform draw is the next given fraction of [low, high), in call order."""

    def __init__(self, fractions):
        self.fractions = iter(fractions)

    def uniform(self, low=0.0, high=1.0, size=None):
        return low + (high - low) * np.full(size, next(self.fractions))

    def normal(self, size=None):
        return np.full(size, 0.25)

    def integers(self, low, high, size=None):
        return np.full(size, low + 3)


@pytest.mark.parametrize("choice, expected", [(0.0, 0.0), (0.59, 0.0), (0.6, 3.0), (0.7, 3.0), (0.8, 0.003)])
def test_box_points_put_a_draw_on_a_boundary_in_the_next_share(choice, expected):
    """Draws lie on [0, 1): half-open shares [0, 0.6), [0.6, 0.8), [0.8, 1) and end halves [0, 0.5), [0.5, 1)
    are exactly 60/20/20 % and 1/2 each. Box [-1, 3]: uniform fraction 1/4 -> 0; ends fraction 1/2 -> upper 3;
    sign fraction 3/4 -> +1; exponent fraction 1/2 -> 10^-3 * max(1, 3) = 0.003."""
    draws = _Draws([0.25, 0.5, 0.75, 0.5, choice])
    point = _points(draws, 1, (np.array([-1.0]), np.array([3.0])), 1)
    assert point.shape == (1, 1)
    assert point[0, 0] == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("choice, expected", [(0.49, 0.5), (0.5, 10.0 ** 2.5), (0.84, 10.0 ** 2.5), (0.85, -7.0)])
def test_free_points_put_a_draw_on_a_boundary_in_the_next_share(choice, expected):
    """Shares [0, 0.5) normal, [0.5, 0.85) scaled, [0.85, 1) integers. Normal 0.25 * 2 = 0.5; sign fraction
    3/4 -> +1, exponent fraction 1/2 of [-3, 8) -> 10^2.5; integer -10 + 3 = -7."""
    draws = _Draws([0.75, 0.5, choice])
    point = _points(draws, 1, None, 1)
    assert point.shape == (1, 1)
    assert point[0, 0] == pytest.approx(expected, rel=1e-12)
