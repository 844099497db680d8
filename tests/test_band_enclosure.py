"""Zonotope bands proved by interval arithmetic on the exact set's hull: proved, refuted with a vertex that
really goes beyond (re-simulated in plain floats), and typed errors."""

from __future__ import annotations

import numpy as np
import pytest

from uvsym.errors import VerificationError
from uvsym.sets import Zonotope, propagate
from uvsym.verify.band_enclosure import band_enclosure_claim, reachable_hull


def _scalar(center0=0.0, center_w=0.0):
    return np.array([[0.5]]), np.array([[1.0]]), Zonotope([center0], [[1.0]]), Zonotope([center_w], [[1.0]])


def test_the_hull_of_a_halving_recursion_is_its_closed_form():
    """xi+ = xi / 2 + w, |xi_0|, |w| <= 1: the reachable hull at step k is +-(2 - 2^-k), every bound exact in floats."""
    hull = reachable_hull(*_scalar(), 12)
    exact = 2.0 - 0.5 ** np.arange(12)
    assert np.array_equal(hull["outer_hi"][:, 0], exact) and np.array_equal(hull["inner_lo"][:, 0], -exact)
    shifted = reachable_hull(*_scalar(1.0, 0.5), 4)  # centers: c_k = c_{k-1} / 2 + 1/2 from 1: 1 at every k
    assert np.array_equal(shifted["outer_hi"][:, 0], 1.0 + exact[:4])


def test_a_band_on_the_hull_is_proved_and_one_a_hair_inside_is_refuted_by_a_vertex():
    A, C, X0, W = _scalar()
    exact = (2.0 - 0.5 ** np.arange(10))[:, None]
    assert band_enclosure_claim("on the hull", A, C, X0, W, -exact, exact, "box").status == "proved"
    inside = exact.copy()
    inside[6] -= 1e-12
    refuted = band_enclosure_claim("a hair inside", A, C, X0, W, -exact, inside, "box", expected="refuted")
    assert refuted.status == "refuted" and refuted.counterexample["step"] == 6
    xi = 1.0  # the vertex a = 1, every b = 1, re-simulated without the verifier
    for _ in range(6):
        xi = 0.5 * xi + 1.0
    assert xi == refuted.counterexample["reached"] > refuted.counterexample["limit"]
    assert "a vertex reaches" in refuted.counterexample_summary()


@pytest.mark.parametrize("seed", range(4))
def test_reduced_bands_of_random_stable_recursions_are_proved_and_shrunken_ones_refuted(seed):
    rng = np.random.default_rng(seed)
    n = 5
    Q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    A = Q @ np.diag(rng.uniform(-0.8, 0.8, n)) @ Q.T  # stable and normal: the reduction does not wrap
    C = rng.normal(size=(2, n))
    X0, W = Zonotope(np.zeros(n), np.diag(rng.uniform(0.1, 1, n))), Zonotope(np.zeros(n), rng.normal(size=(n, 3)))
    band = propagate(A, C, X0, W, 40, generators=8)
    slack = 1e-12 * (1 + band.upper - band.lower)
    assert band_enclosure_claim("reduced", A, C, X0, W, band.lower - slack, band.upper + slack, "box").status \
        == "proved"
    shrunk = band.exact_radius * (1 - 1e-6)  # inside the exact hull: some vertex leaves it
    refuted = band_enclosure_claim("shrunk", A, C, X0, W, -shrunk, shrunk, "box", expected="refuted")
    k, i = refuted.counterexample["step"], refuted.counterexample["output"]
    power = np.linalg.matrix_power
    row = lambda j, G: C[i] @ power(A, j) @ G  # noqa: E731
    sign = 1.0 if refuted.counterexample["reached"] > 0 else -1.0
    xi = X0.generators @ np.sign(sign * row(k, X0.generators))  # the vertex, simulated forward in floats
    for step in range(1, k + 1):
        xi = A @ xi + W.generators @ np.sign(sign * row(k - step, W.generators))
    assert sign * (C[i] @ xi) > sign * refuted.counterexample["limit"]


def test_bad_inputs_are_named():
    A, C, X0, W = _scalar()
    with pytest.raises(VerificationError, match="do not conform"):
        reachable_hull(A, np.ones((1, 2)), X0, W, 3)
    with pytest.raises(VerificationError, match="finite"):
        band_enclosure_claim("nan", A, C, X0, W, np.array([[np.nan]]), np.array([[1.0]]), "box")
    with pytest.raises(VerificationError, match="one shape"):
        band_enclosure_claim("shapes", A, C, X0, W, np.zeros((2, 1)), np.zeros((3, 1)), "box")
