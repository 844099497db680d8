"""Zonotopes of uvsym.sets.zonotope, operation by operation: sums, images, interval hulls, containment and their
errors, with expected values worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvsym.errors import SetError
from uvsym.sets import Zonotope, box
from uvsym.sets.zonotope import finite_matrix


def test_finite_matrix_converts_integers_to_floats():
    array = finite_matrix([1, 2], "weights", (2,))
    assert array.dtype == np.float64
    np.testing.assert_array_equal(array, [1.0, 2.0])
    Z = Zonotope([1, 2], [[1, 0], [0, 3]])
    assert Z.center.dtype == np.float64 and Z.generators.dtype == np.float64


def test_finite_matrix_names_a_value_that_is_not_numbers_and_its_type():
    with pytest.raises(SetError, match=r"^weights must be a numeric array, got str$"):
        finite_matrix("abc", "weights")
    with pytest.raises(SetError, match=r"^zonotope center must be a numeric array, got list$"):
        Zonotope([1.0, "two"], np.eye(2))


def test_empty_generators_give_a_point_of_order_zero():
    Z = Zonotope([1.0, -2.0], [])
    assert Z.order == 0 and Z.generators.shape == (2, 0)
    assert Z.contains([1.0, -2.0], tolerance=0.0)
    assert not Z.contains([1.0, -1.9])


def test_generator_rows_against_center_size_message():
    with pytest.raises(SetError, match=r"^zonotope generators have 3 rows but the center has 2 entries$"):
        Zonotope([0.0, 0.0], np.ones((3, 5)))


def test_zonotope_arrays_are_read_only_copies():
    center, generators = np.array([1.0, 2.0]), np.eye(2)
    Z = Zonotope(center, generators)
    center[0], generators[0, 0] = 9.0, 9.0  # the caller's arrays change, the zonotope does not
    np.testing.assert_array_equal(Z.center, [1.0, 2.0])
    np.testing.assert_array_equal(Z.generators, np.eye(2))
    assert not Z.center.flags.writeable and not Z.generators.flags.writeable
    with pytest.raises(ValueError):
        Z.center[0] = 5.0


def test_tolerance_scales_the_generators_beyond_the_interval_hull():
    # box [-10, 10]: generator 10, so tolerance 1e-3 admits |x| <= 10 (1 + 1e-3) = 10.01
    Z = box([-10.0], [10.0])
    assert Z.contains([10.005], tolerance=1e-3)  # xi = 1.0005
    assert Z.contains([-10.009], tolerance=1e-3)  # xi = -1.0009
    assert not Z.contains([10.011], tolerance=1e-3)  # xi = 1.0011
    assert not Z.contains([10.005], tolerance=0.0)


def test_points_on_the_boundary_are_contained_with_zero_tolerance():
    # diamond with generators (1, 1) and (1, -1): (2, 0) = g1 + g2 and (1, 1) = g1 need ||xi||_inf = 1 exactly
    D = Zonotope([0.0, 0.0], [[1.0, 1.0], [1.0, -1.0]])
    assert D.contains([2.0, 0.0], tolerance=0.0)
    assert D.contains([1.0, 1.0], tolerance=0.0)
    assert D.contains([0.5, 0.5], tolerance=0.0)
    assert not D.contains([1.5, 1.5], tolerance=0.0)  # xi = (1.5, 0), inside the interval hull [-2, 2]^2
    assert box([-1.0], [1.0]).contains([1.0], tolerance=0.0)
    # generator 2, point 3: xi = 1.5 = 1 + tolerance exactly
    assert Zonotope([0.0], [[2.0]]).contains([3.0], tolerance=0.5)
    assert not Zonotope([0.0], [[2.0]]).contains([3.0], tolerance=0.25)


@pytest.mark.parametrize("tolerance", [-0.1, math.nan, math.inf])
def test_contains_refuses_a_negative_or_non_finite_tolerance(tolerance):
    with pytest.raises(SetError, match=rf"^containment tolerance must be finite and >= 0, got {tolerance}$"):
        box([-1.0], [1.0]).contains([0.0], tolerance=tolerance)


def test_box_names_every_entry_whose_lower_bound_exceeds_the_upper():
    # entry 1 has equal bounds (a degenerate axis, allowed); entries 2 and 3 are reversed
    with pytest.raises(SetError, match=r"^box lower bound exceeds the upper bound at entries \[2, 3\]$"):
        box([0.0, 1.0, 3.0, 5.0], [1.0, 1.0, 2.0, 4.0])
    Z = box([0.0, 1.0], [1.0, 1.0])
    np.testing.assert_array_equal(Z.center, [0.5, 1.0])
    np.testing.assert_array_equal(Z.generators, [[0.5], [0.0]])
