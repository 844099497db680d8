"""Zonotopes: operations against vertex enumeration, reduction encloses (property tests), propagation
against closed forms, bad inputs."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvsym.errors import SetDivergenceError, SetError
from uvsym.sets import METHODS, Zonotope, box, carry_coefficients, propagate, reduce


def _vertices(Z: Zonotope) -> np.ndarray:
    """Every c + G xi with xi in {-1, 1}^m (small m): the oracle."""
    signs = np.array(list(itertools.product((-1.0, 1.0), repeat=Z.order)))
    return Z.center + signs @ Z.generators.T


def _random_zonotope(seed: int, n: int, m: int) -> Zonotope:
    rng = np.random.default_rng(seed)
    return Zonotope(rng.normal(size=n), rng.normal(size=(n, m)) * rng.uniform(0.01, 2.0, m))


def test_map_sum_hull_and_support_match_vertex_enumeration():
    Z1, Z2 = _random_zonotope(1, 3, 5), _random_zonotope(2, 3, 4)
    M, b = np.random.default_rng(3).normal(size=(2, 3)), np.array([0.5, -1.0])
    mapped = Z1.map(M, b)
    np.testing.assert_allclose(np.sort(_vertices(mapped), axis=0), np.sort(_vertices(Z1) @ M.T + b, axis=0),
                               atol=1e-12)
    total = Z1 + Z2
    sums = (_vertices(Z1)[:, None, :] + _vertices(Z2)[None, :, :]).reshape(-1, 3)
    for a in np.random.default_rng(4).normal(size=(10, 3)):
        assert total.support(a) == pytest.approx(np.max(sums @ a), rel=1e-12)
    lower, upper = total.interval_hull()
    np.testing.assert_allclose(lower, sums.min(axis=0), atol=1e-12)
    np.testing.assert_allclose(upper, sums.max(axis=0), atol=1e-12)


def test_containment_inside_and_just_outside():
    Z = _random_zonotope(5, 3, 7)
    rng = np.random.default_rng(6)
    for xi in rng.uniform(-1, 1, (20, 7)):
        assert Z.contains(Z.center + Z.generators @ xi)
    for a in rng.normal(size=(10, 3)):
        a /= np.linalg.norm(a)
        beyond = Z.center + (Z.support(a) - a @ Z.center + 1e-6) * a  # a^T x exceeds the support
        assert not Z.contains(beyond)


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 5), extra=st.integers(0, 30), seed=st.integers(0, 10_000), method=st.sampled_from(METHODS),
       data=st.data())
def test_reduction_always_encloses(n, extra, seed, method, data):
    Z = _random_zonotope(seed, n, n + extra)
    target = data.draw(st.integers(n, n + extra))
    reduced = reduce(Z, target, method, coefficients=True)
    Zr, R = reduced.zonotope, reduced.coefficients
    assert Zr.order <= target
    np.testing.assert_allclose(Zr.center, Z.center)
    np.testing.assert_allclose(Zr.generators @ R, Z.generators, atol=1e-12)
    assert np.all(np.sum(np.abs(R), axis=1) <= 1 + 1e-12)
    rng = np.random.default_rng(seed)
    for a in rng.normal(size=(20, n)):  # support functions of the two sets (closed form, independent of R)
        assert Zr.support(a) >= Z.support(a) - 1e-9 * (1 + abs(Z.support(a)))
    for xi in rng.choice([-1.0, 1.0], size=(3, Z.order)):  # vertices of the original, by LP
        assert Zr.contains(Z.center + Z.generators @ xi, tolerance=1e-7)


def test_reduction_bad_orders_and_methods():
    Z = _random_zonotope(0, 4, 10)
    with pytest.raises(SetError, match="dimension 4"):
        reduce(Z, 3)
    with pytest.raises(SetError, match="generators must be an integer"):
        reduce(Z, 5.5)
    with pytest.raises(SetError, match="unknown reduction method"):
        reduce(Z, 6, "wobble")
    assert reduce(Z, 12).zonotope.order == 10  # nothing to do


def test_bad_inputs_are_typed_errors_naming_the_argument():
    with pytest.raises(SetError, match="center"):
        Zonotope([0.0, np.nan], np.eye(2))
    with pytest.raises(SetError, match="rows"):
        Zonotope([0.0, 0.0], np.eye(3))
    with pytest.raises(SetError, match="map matrix"):
        Zonotope([0.0, 0.0], np.eye(2)).map(np.eye(3))
    with pytest.raises(SetError, match="Minkowski"):
        Zonotope([0.0], [[1.0]]) + Zonotope([0.0, 0.0], np.eye(2))
    with pytest.raises(SetError, match="upper bound"):
        box([0.0, 0.0], [1.0, np.inf])
    with pytest.raises(SetError, match="lower bound exceeds"):
        box([1.0], [0.0])


def test_scalar_propagation_matches_the_geometric_series():
    """x+ = a x + w, |w| <= 1, |x0| <= 1: the hull radius is a^k + (1 - a^k) / (1 - a), exactly."""
    a = 0.5
    result = propagate([[a]], [[1.0]], box([-1.0], [1.0]), box([-1.0], [1.0]), 30, generators=3)
    k = np.arange(30)
    np.testing.assert_allclose(result.upper[:, 0], a ** k + (1 - a ** k) / (1 - a), rtol=1e-12)
    np.testing.assert_allclose(result.exact_radius[:, 0], result.upper[:, 0], rtol=1e-12)
    assert max(z.order for z in result.outputs) <= 3


def test_carried_coefficients_reproduce_simulated_outputs():
    rng = np.random.default_rng(7)
    A = np.array([[0.6, 0.3, 0.0], [-0.2, 0.5, 0.1], [0.0, 0.2, 0.4]])
    C = rng.normal(size=(2, 3))
    X0, W = box(-0.1 * np.ones(3), 0.1 * np.ones(3)), Zonotope(np.zeros(3), rng.normal(size=(3, 2)) * 0.05)
    result = propagate(A, C, X0, W, 40, generators=6, method="pca")
    runs = 5
    a0, eta = rng.uniform(-1, 1, (3, runs)), rng.uniform(-1, 1, (40, 2, runs))
    coefficients = carry_coefficients(result, a0, eta)
    x = X0.generators @ a0
    for k in range(40):
        if k:
            x = A @ x + W.generators @ eta[k]
        Z = result.outputs[k]
        a = coefficients[k, :Z.order]
        np.testing.assert_allclose(Z.center[:, None] + Z.generators @ a, C @ x, atol=1e-12)
        assert np.all(np.abs(a) <= 1 + 1e-12)
        lower, upper = result.lower[k], result.upper[k]
        assert np.all((C @ x >= lower[:, None] - 1e-12) & (C @ x <= upper[:, None] + 1e-12))


def test_growing_enclosure_is_an_error_not_a_long_run():
    with pytest.raises(SetDivergenceError, match="modulus >= 1"):
        propagate([[1.0, 0.01], [0.0, 1.0]], np.eye(2), box([-1, -1], [1, 1]), box([-1, -1], [1, 1]), 10, 4)
    with pytest.raises(SetDivergenceError, match="reduction wraps"):  # a limit below the exact set itself
        propagate([[0.5]], [[1.0]], box([-1.0], [1.0]), box([-1.0], [1.0]), 5, 2, growth_limit=0.5)
    with pytest.raises(SetError, match="dimension 2"):
        propagate(np.eye(2) * 0.5, np.eye(2), box([-1.0], [1.0]), box([-1, -1], [1, 1]), 5, 4)


@pytest.mark.parametrize("method", ["girard", "combastel"])
def test_compiled_box_reduction_equals_the_numpy_path(method, monkeypatch):
    from uvsym.sets import kernel, reduction

    if kernel.box_reduce(np.eye(2), 2, False) is None:
        pytest.skip("no C compiler: only the numpy path exists")
    Z = _random_zonotope(11, 6, 200)
    compiled = reduce(Z, 30, method, coefficients=True)
    monkeypatch.setattr(reduction, "box_reduce", lambda *args, **kwargs: None)
    reference = reduce(Z, 30, method, coefficients=True)
    np.testing.assert_allclose(compiled.zonotope.generators, reference.zonotope.generators, rtol=1e-14)
    np.testing.assert_allclose(compiled.coefficients, reference.coefficients, rtol=1e-14)
    assert reduce(Z, 30, method, coefficients=False).coefficients is None


@pytest.mark.parametrize("method", ["girard", "combastel"])
@pytest.mark.parametrize("n, m, generators", [(3, 40, 3), (3, 40, 39), (6, 200, 30), (8, 9, 8), (1, 17, 5)])
def test_compiled_box_reduction_breaks_score_ties_as_the_numpy_path(method, n, m, generators, monkeypatch):
    """Integer generators in {-2..2} tie in score again and again (and some are zero): the kernel's selection
    must replace the lower index of a tie, as the numpy path's stable sort does, down to the last column."""
    from uvsym.sets import kernel, reduction

    if kernel.box_reduce(np.eye(2), 2, False) is None:
        pytest.skip("no C compiler: only the numpy path exists")
    G = np.random.default_rng(n * m + generators).integers(-2, 3, size=(n, m)).astype(float)
    Z = Zonotope(np.zeros(n), G)
    compiled = reduce(Z, generators, method, coefficients=True)
    monkeypatch.setattr(reduction, "box_reduce", lambda *args, **kwargs: None)
    reference = reduce(Z, generators, method, coefficients=True)
    np.testing.assert_array_equal(compiled.zonotope.generators, reference.zonotope.generators)
    np.testing.assert_array_equal(compiled.coefficients, reference.coefficients)


def test_untracked_propagation_has_the_same_bands_and_refuses_coefficients():
    args = ([[0.5, 0.1], [0.0, 0.3]], np.eye(2), box([-1, -1], [1, 1]), box([-0.1, -0.1], [0.1, 0.1]), 20, 4)
    tracked, untracked = propagate(*args), propagate(*args, track=False)
    np.testing.assert_array_equal(tracked.upper, untracked.upper)
    with pytest.raises(SetError, match="track=True"):
        carry_coefficients(untracked, np.zeros((2, 1)), np.zeros((20, 2, 1)))


def test_compiled_kernel_builds_and_reports_its_selection_by_default():
    """With a C compiler the kernel exists; by default it returns the replaced mask and the box's row sums.
    G's columns (1, 0), (0, 3), (1, 1), (2, -5): Girard scores 0, 0, 1, 2 replace the first three
    (count 3), leaving (2, -5) then the box of their absolute row sums (2, 4)."""
    from uvsym.codegen.compile import find_compiler
    from uvsym.sets import kernel

    if find_compiler() is None:
        pytest.skip("no C compiler: only the numpy path exists")
    G = np.array([[1.0, 0.0, 1.0, 2.0], [0.0, 3.0, 1.0, -5.0]])
    result = kernel.box_reduce(G, 3, False)
    assert result is not None
    new_G, replaced, sums = result
    np.testing.assert_array_equal(new_G, [[2.0, 2.0, 0.0], [-5.0, 0.0, 4.0]])
    np.testing.assert_array_equal(replaced, [True, True, True, False])
    np.testing.assert_array_equal(sums, [2.0, 4.0])


def test_pca_reduction_aligns_the_box_with_the_group():
    """Generators (1, 1), (2, 2), (0.1, -0.1), all replaced (2 kept of 3 in R^2): their principal axes
    are (1, 1) and (1, -1), so PCA's parallelotope is the set itself, <0, [(3, 3), (0.1, -0.1)]>, with
    support 0.2 along (1, -1); an axis-aligned box would give 6.2 there."""
    Z = Zonotope([1.0, -1.0], [[1.0, 2.0, 0.1], [1.0, 2.0, -0.1]])
    reduced = reduce(Z, 2, "pca").zonotope
    signs = np.sign(reduced.generators[0])  # the singular vectors' signs are arbitrary
    np.testing.assert_allclose(reduced.generators * signs, [[3.0, 0.1], [3.0, -0.1]], atol=1e-12)
    assert reduced.support([1.0, -1.0]) == pytest.approx(2.0 + 0.2, rel=1e-12)


def test_point_zonotope_contains_exactly_its_centre():
    Z = Zonotope([1.0, 2.0], np.zeros((2, 0)))
    assert Z.contains([1.0, 2.0], tolerance=0.0)
    assert Z.contains([1.0, 2.0])
    assert not Z.contains([1.0, 2.0 + 1e-6])


def test_box_centre_and_radii():
    Z = box([0.0, 2.0, 5.0], [2.0, 6.0, 5.0])
    np.testing.assert_array_equal(Z.center, [1.0, 4.0, 5.0])
    np.testing.assert_array_equal(Z.generators, [[1.0, 0.0], [0.0, 2.0], [0.0, 0.0]])


def test_shape_and_name_in_the_messages():
    Z = box([-1.0, -1.0], [1.0, 1.0])
    with pytest.raises(SetError, match=r"^direction must have shape \(2\), got \(3,\)$"):
        Z.support([1.0, 0.0, 0.0])
    with pytest.raises(SetError, match=r"^C must have shape \(any, 2\), got \(3, 3\)$"):
        propagate(np.eye(2) * 0.5, np.eye(3), Z, Z, 5, 4)
    for A in (0.5, [0.5, 0.5]):  # a scalar or a vector is not a matrix
        with pytest.raises(SetError, match=r"^A must have shape \(any, any\), got "):
            propagate(A, np.eye(2), Z, Z, 5, 4)
    with pytest.raises(SetError, match=r"^initial set must be a Zonotope of dimension 2$"):
        propagate(np.eye(2) * 0.5, np.eye(2), box([-1.0], [1.0]), Z, 5, 4)
    with pytest.raises(SetDivergenceError, match=r"eigenvalues of modulus >= 1: \[1\.234568\]$"):
        propagate([[1.2345678]], [[1.0]], box([-1.0], [1.0]), box([-1.0], [1.0]), 5, 2)
    untracked = propagate([[0.5]], [[1.0]], box([-1.0], [1.0]), box([-1.0], [1.0]), 3, 2, track=False)
    with pytest.raises(SetError, match=r"^the propagation kept no coefficient maps: propagate it with track=True$"):
        carry_coefficients(untracked, np.zeros((1, 1)), np.zeros((3, 1, 1)))


def test_growth_guard_measures_the_radius_at_any_offset_and_scale():
    """x+ = x / 2 + w from |x0 - 10| <= 1, |w| <= 1: centre 10 / 2^k, radius 2^-k + 2 (1 - 2^-k), well within
    the default limit; the guard at limit 0.5 still fires when the whole problem is scaled by 1e-9."""
    result = propagate([[0.5]], [[1.0]], box([9.0], [11.0]), box([-1.0], [1.0]), 6, generators=2)
    k = np.arange(6)
    np.testing.assert_allclose(result.upper[:, 0], 10 * 0.5 ** k + 0.5 ** k + 2 * (1 - 0.5 ** k), rtol=1e-12)
    with pytest.raises(SetDivergenceError, match="reduction wraps"):
        propagate([[0.5]], [[1.0]], box([-1e-9], [1e-9]), box([-1e-9], [1e-9]), 3, 2, growth_limit=0.5)


def test_default_growth_limit_stops_a_boxed_rotation():
    """A = 0.99 R(45 deg), boxed every step (2 generators kept of 3; the extra ones are zero): the box's hull
    radius is (0.99 sqrt 2)^k, the exact set's 0.99^k sqrt 2 (k odd) or 0.99^k (k even), a ratio 8 at step 7
    and 16 at step 8, where the default limit of 10 stops it."""
    c = 0.99 * np.sqrt(0.5)
    initial = Zonotope([0.0, 0.0], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    with pytest.raises(SetDivergenceError, match=r"^the enclosure grows: at step 8, output 0's hull radius 14\.8 "
                       r"exceeds 10 times the exact set's 0\.923 \(reduction wraps; raise generators\)$"):
        propagate([[c, -c], [c, c]], np.eye(2), initial, Zonotope([0.0, 0.0], np.zeros((2, 1))), 12, 2)


def test_exact_radius_per_output():
    """x+ = x / 2 + w, |x0_i| <= 1, |w_1| <= 1, |w_2| <= 2: the exact radius of output i is
    2^-k + r_i (1 - 2^-k) / (1 - 1/2)."""
    result = propagate(0.5 * np.eye(2), np.eye(2), box([-1.0, -1.0], [1.0, 1.0]), box([-1.0, -2.0], [1.0, 2.0]), 8, 2)
    decay = 0.5 ** np.arange(8)[:, None]
    np.testing.assert_allclose(result.exact_radius, decay + np.array([1.0, 2.0]) * 2 * (1 - decay), rtol=1e-12)


@pytest.mark.parametrize("compiled", [True, False])
def test_reduction_skips_an_empty_axis(compiled, monkeypatch):
    """Generators (1, 0), (0.1, 0), (0.2, 0) boxed into R^2: one box generator (1.3, 0), none along the empty
    second axis, and R = [1, 0.1, 0.2] / 1.3 (compiled kernel and numpy path)."""
    from uvsym.sets import reduction

    if not compiled:
        monkeypatch.setattr(reduction, "box_reduce", lambda *args, **kwargs: None)
    reduced = reduce(Zonotope([0.0, 0.0], [[1.0, 0.1, 0.2], [0.0, 0.0, 0.0]]), 2, coefficients=True)
    np.testing.assert_allclose(reduced.zonotope.generators, [[1.3], [0.0]], rtol=1e-15)
    np.testing.assert_allclose(reduced.coefficients, [[1 / 1.3, 0.1 / 1.3, 0.2 / 1.3]], rtol=1e-15)


def test_reduction_and_box_messages():
    with pytest.raises(SetError, match=r"^unknown reduction method 'wobble'; known: girard, combastel, pca$"):
        reduce(box([0.0], [1.0]), 1, "wobble")
    with pytest.raises(SetError, match=r"^box lower bound must be finite"):
        box([np.nan], [1.0])


def test_steps_must_be_positive_and_points_conform():
    Z = box([-1.0], [1.0])
    for steps in (0, -1):
        with pytest.raises(SetError, match=rf"^steps must be a positive integer, got {steps}$"):
            propagate([[0.5]], [[1.0]], Z, Z, steps, 2)
    with pytest.raises(SetError, match=r"^point must have shape \(1\), got \(2,\)$"):
        Z.contains([0.0, 0.0])


def test_segment_excludes_a_point_just_off_its_line():
    """<0, [(1, 0)]> and (0.5, 1e-8): 1e-8 off the line, beyond the tolerance 1e-9, though within the LP
    solver's own feasibility tolerance (1e-7): the interval hull decides."""
    segment = Zonotope([0.0, 0.0], [[1.0], [0.0]])
    assert not segment.contains([0.5, 1e-8])
    assert not segment.contains([0.5, -1e-8])
    assert segment.contains([0.5, 0.0])


def test_pca_ties_replace_the_lower_indices():
    """17 generators in R^2, 16 kept: count 3 of the four Girard-score-0 ones (1, 0) .. (4, 0) at indices 2 .. 5
    (the others (1, 1), score 1); ties go to the lower index, so (1, 0), (2, 0), (3, 0) become the box (6, 0)."""
    G = np.ones((2, 17))
    G[:, 2:6] = [[1.0, 2.0, 3.0, 4.0], [0.0, 0.0, 0.0, 0.0]]
    reduced = reduce(Zonotope([0.0, 0.0], G), 16, "pca").zonotope
    expected = np.hstack([np.ones((2, 2)), [[4.0], [0.0]], np.ones((2, 11)), [[6.0], [0.0]]])
    np.testing.assert_allclose(np.abs(reduced.generators), expected, atol=1e-12)


def test_spectral_radius_within_1e_12_of_one_counts_as_one():
    with pytest.raises(SetDivergenceError, match="modulus >= 1"):
        propagate([[1.0 - 1e-12]], [[1.0]], box([-1.0], [1.0]), box([-1.0], [1.0]), 5, 2)


def test_growth_error_names_the_worst_output():
    """Output 0 reads nothing (radius 0 = exact 0), output 1 the state (radius 1, exact 1, over the limit 0.5)."""
    with pytest.raises(SetDivergenceError, match=r"at step 0, output 1's hull radius 1 exceeds 0\.5 times the exact"
                       r" set's 1 "):
        propagate(0.5 * np.eye(2), [[0.0, 0.0], [0.0, 1.0]], box([-1.0, -1.0], [1.0, 1.0]),
                  box([-1.0, -1.0], [1.0, 1.0]), 3, 2, growth_limit=0.5)


def test_carried_coefficients_accept_any_real_numbers():
    from decimal import Decimal

    result = propagate([[0.5]], [[1.0]], box([-1.0], [1.0]), box([-1.0], [1.0]), 3, 2)
    eta = np.full((3, 1, 1), 0.5)
    exact = carry_coefficients(result, [[Decimal("0.25")]], eta)
    np.testing.assert_array_equal(exact, carry_coefficients(result, [[0.25]], eta))


def test_zonotope_map_and_box_shape_messages():
    Z = box([-1.0, -1.0], [1.0, 1.0])
    with pytest.raises(SetError, match=r"^zonotope generators must have shape \(any, any\), got \(2,\)$"):
        Zonotope([0.0, 0.0], [1.0, 2.0])
    with pytest.raises(SetError, match=r"^map matrix must have shape \(any, 2\), got \(3, 3\)$"):
        Z.map(np.eye(3))
    with pytest.raises(SetError, match=r"^map offset must have shape \(2\), got \(3,\)$"):
        Z.map(np.eye(2), [1.0, 2.0, 3.0])
    with pytest.raises(SetError, match=r"^box lower bound must have shape \(any\), got \(1, 1\)$"):
        box([[0.0]], [[1.0]])
    with pytest.raises(SetError, match=r"^box upper bound must have shape \(2\), got \(1,\)$"):
        box([0.0, 0.0], [1.0])


def test_noise_set_of_the_wrong_dimension_is_named_in_lower_case():
    Z = box([-1.0, -1.0], [1.0, 1.0])
    with pytest.raises(SetError, match=r"^noise set must be a Zonotope of dimension 2$"):
        propagate(np.eye(2) * 0.5, np.eye(2), Z, box([-1.0], [1.0]), 5, 4)


def test_reduction_within_the_order_forms_no_map_unless_asked():
    """3 generators under an order bound of 5: nothing is reduced, R = I (3, 3) only when asked for."""
    Z = Zonotope([0.0, 0.0], [[1.0, 0.0, 2.0], [0.0, 1.0, -1.0]])
    assert reduce(Z, 5).coefficients is None
    np.testing.assert_array_equal(reduce(Z, 5, coefficients=True).coefficients, np.eye(3))


def test_centre_must_be_a_vector():
    """A scalar or a column centre is not an (n,) vector, even when its size matches the generators' rows."""
    with pytest.raises(SetError, match=r"^zonotope center must have shape \(any\), got \(\)$"):
        Zonotope(1.0, [[1.0]])
    with pytest.raises(SetError, match=r"^zonotope center must have shape \(any\), got \(2, 1\)$"):
        Zonotope([[1.0], [2.0]], np.eye(2))


def test_point_zonotope_slack_is_the_tolerance_whatever_the_centre():
    """No generators: hull width 0, so a point is in when within tolerance * (1 + 0) of the centre, per
    coordinate, at the origin as at 1e6 (1e6 + 1e-6 is 1e-6 away, 1000 times the default 1e-9)."""
    origin = Zonotope([0.0], np.zeros((1, 0)))
    assert origin.contains([0.5e-9]) and origin.contains([-0.5e-9])
    assert not origin.contains([1.5e-9]) and not origin.contains([-1.5e-9])
    assert origin.contains([1.5e-3], tolerance=2e-3) and not origin.contains([2.5e-3], tolerance=2e-3)
    far = Zonotope([1e6], np.zeros((1, 0)))
    assert far.contains([1e6])
    assert not far.contains([1e6 + 1e-6]) and not far.contains([1e6 - 1e-6])


def test_a_numpy_integer_order_is_accepted_and_exactly_the_order_reduces_nothing():
    """Three generators, none axis-aligned, under an order bound of 3 (given as a numpy integer): nothing is
    reduced (R = I), whereas a bound of 2 boxes them into (1 + 2 + 0.5, 1 + 1 + 0.3) = (3.5, 2.3)."""
    G = np.array([[1.0, 2.0, 0.5], [1.0, -1.0, 0.3]])
    Z = Zonotope([0.0, 0.0], G)
    same = reduce(Z, np.int64(3), coefficients=True)
    np.testing.assert_array_equal(same.zonotope.generators, G)
    np.testing.assert_array_equal(same.coefficients, np.eye(3))
    np.testing.assert_allclose(reduce(Z, np.int64(2), "girard").zonotope.generators, np.diag([3.5, 2.3]),
                               rtol=1e-15)


def test_box_reductions_use_the_compiled_kernel_when_one_is_built(monkeypatch):
    from uvsym.sets import kernel, reduction

    if kernel.box_reduce(np.eye(2), 2, False) is None:
        pytest.skip("no C compiler: only the numpy path exists")
    calls = []

    def spy(*args, **kwargs):
        calls.append((args[2], kwargs.get("details")))
        return kernel.box_reduce(*args, **kwargs)

    monkeypatch.setattr(reduction, "box_reduce", spy)
    Z = _random_zonotope(12, 3, 9)
    for method in ("girard", "combastel", "pca"):
        reduce(Z, 4, method, coefficients=True)
    reduce(Z, 4)  # the default: no map
    # (combastel flag, whether the kernel returns the replaced mask for R); PCA has no compiled path
    assert calls == [(False, True), (True, True), (False, False)]


# --- growth limit and reduction: edge cases (mutation survivors) -----------------------------------------------------


def test_a_hull_radius_exactly_at_the_growth_limit_is_accepted():
    """Step 0 of |x0| <= 1: hull radius 1 = exact radius 1; the guard raises only for MORE than
    growth_limit * exact + 1e-12 max(exact), here (1 - 1e-12) + 1e-12 == 1.0 exactly in floats."""
    limit = 1.0 - 1e-12
    assert limit + 1e-12 == 1.0
    result = propagate([[0.5]], [[1.0]], box([-1.0], [1.0]), box([-1.0], [1.0]), 1, 2, growth_limit=limit)
    assert result.upper[0, 0] == 1.0
    with pytest.raises(SetDivergenceError):
        propagate([[0.5]], [[1.0]], box([-1.0], [1.0]), box([-1.0], [1.0]), 1, 2, growth_limit=limit - 1e-12)


def test_carried_noise_coefficients_accept_any_real_numbers():
    from decimal import Decimal

    result = propagate([[0.5]], [[1.0]], box([-1.0], [1.0]), box([-1.0], [1.0]), 3, 2)
    eta = np.full((3, 1, 1), 0.5)
    decimals = [[[Decimal("0.5")]]] * 3
    np.testing.assert_array_equal(carry_coefficients(result, [[0.25]], decimals),
                                  carry_coefficients(result, [[0.25]], eta))


# --- propagation: edge cases (mutation survivors) --------------------------------------


def test_a_non_square_a_is_named_with_its_shape():
    Z = box([-1.0, -1.0], [1.0, 1.0])
    with pytest.raises(SetError, match=r"^A must be square, got shape \(2, 3\)$"):
        propagate(np.full((2, 3), 0.1), np.eye(2), Z, Z, 5, 4)


@pytest.mark.parametrize("steps", [True, 2.0, "3"])
def test_steps_that_are_not_integers_are_refused(steps):
    """A bool, a float or a string is no step count, even when it compares as >= 1."""
    Z = box([-1.0], [1.0])
    with pytest.raises(SetError, match=rf"^steps must be a positive integer, got {steps!r}$"):
        propagate([[0.5]], [[1.0]], Z, Z, steps, 2)


def test_propagation_reduces_with_the_method_asked_for():
    """x+ = x / 2 + w, generators (2, 0), (0.3, 0.3) and two zero noise generators, at most 3 kept: step 1 has
    (1, 0), (0.15, 0.15), 0, 0 and boxes 3 of them. Girard keeps the largest ||g||_1 - ||g||_inf, (0.15, 0.15),
    and boxes (1, 0): x1 - x2 has radius |0.15 - 0.15| + 1 = 1, the exact one. Combastel keeps the longest,
    (1, 0), and boxes (0.15, 0.15) into (0.15, 0), (0, 0.15): radius 1 + 0.15 + 0.15 = 1.3."""
    initial = Zonotope([0.0, 0.0], [[2.0, 0.3], [0.0, 0.3]])
    noise = Zonotope([0.0, 0.0], np.zeros((2, 2)))
    for method, radius in (("girard", 1.0), ("combastel", 1.3)):
        result = propagate(0.5 * np.eye(2), [[1.0, -1.0]], initial, noise, 2, 3, method=method)
        assert result.exact_radius[1, 0] == pytest.approx(1.0, rel=1e-12)
        assert result.upper[1, 0] == pytest.approx(radius, rel=1e-12)
        assert result.lower[1, 0] == pytest.approx(-radius, rel=1e-12)


def test_untracked_propagation_forms_no_coefficient_maps(monkeypatch):
    """track=False: every reduction is asked for no map R (it would only cost time), boxing 3 generators in R^1."""
    from uvsym.sets import propagation

    maps = []

    def spy(*args, **kwargs):
        result = reduce(*args, **kwargs)
        maps.append(result.coefficients)
        return result

    monkeypatch.setattr(propagation, "reduce", spy)
    propagate([[0.5]], [[1.0]], box([-1.0], [1.0]), box([-1.0], [1.0]), 3, 1, track=False)
    assert maps == [None, None]


def test_propagation_reports_the_noise_generator_count():
    W = Zonotope([0.0], [[0.1, 0.2, 0.3]])
    assert propagate([[0.5]], [[1.0]], box([-1.0], [1.0]), W, 2, 4).noise_generators == 3


def test_growth_tolerance_is_relative_to_a_small_exact_radius():
    """|x0| <= 1e-9 at step 0: hull radius = exact radius = 1e-9. With growth_limit 1 - 1e-6 the excess is
    1e-15, far above the tolerance 1e-12 * 1e-9 = 1e-21 (an absolute 1e-12 would hide it)."""
    tiny = box([-1e-9], [1e-9])
    with pytest.raises(SetDivergenceError, match=r"^the enclosure grows: at step 0, output 0's"):
        propagate([[0.5]], [[1.0]], tiny, tiny, 2, 2, growth_limit=1.0 - 1e-6)


def test_growth_error_names_the_output_with_the_largest_ratio_whatever_its_scale_and_centre():
    """x+ = x / 2, generators 0.01 (1, 1), 0.01 (1, -1), centre (0.02, -0.03), and a zero noise generator; 2 kept,
    so step 1 boxes all three: radii (0.01, 0.01). Output 0 = 100 x1: centre 1, hull radius 1 = exact 1 (ratio 1);
    output 1 = x1 + x2: centre -0.005, hull radius 0.02, exact |0.005 + 0.005| + |0.005 - 0.005| = 0.01
    (ratio 2 > 1.5). Output 1 is named, though output 0's radius, exact radius and upper bound are larger."""
    initial = Zonotope([0.02, -0.03], [[0.01, 0.01], [0.01, -0.01]])
    noise = Zonotope([0.0, 0.0], np.zeros((2, 1)))
    with pytest.raises(SetDivergenceError, match=r"^the enclosure grows: at step 1, output 1's hull radius 0\.02 "
                       r"exceeds 1\.5 times the exact set's 0\.01 \(reduction wraps; raise generators\)$"):
        propagate(0.5 * np.eye(2), [[100.0, 0.0], [1.0, 1.0]], initial, noise, 2, 2, growth_limit=1.5)
