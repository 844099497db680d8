"""InPlace: CasADi Functions evaluated in their buffers give what a DM call gives, bit for bit."""

from concurrent.futures import ThreadPoolExecutor

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import ArgumentError
from uvsym.evaluation import InPlace
from uvsym.models.registry import vehicle


def _as_dm_call(function, *arguments):
    return [np.asarray(v) for v in function.call(list(arguments))]


def test_a_mapped_force_model_with_structural_zeros_matches_the_dm_call_bit_for_bit():
    model = vehicle("docking_auv")
    rng = np.random.default_rng(3)
    k = 257
    eta, nu, u = rng.standard_normal((6, k)), rng.standard_normal((6, k)), rng.uniform(-1, 1, (4, k))
    for function in (model.B.raw.map(k), model.tau.raw.map(k)):
        expected = _as_dm_call(function, eta, nu, u, 0.0, 0.0)
        got = InPlace(function)(eta, nu, u, 0.0, 0.0)
        assert [g.shape for g in got] == [e.shape for e in expected]
        assert all(g.flags.c_contiguous and g.tobytes() == e.tobytes() for g, e in zip(got, expected))
    assert not model.B.raw.map(k).sparsity_out(0).is_dense()  # the case of structural zeros is the one tested


def test_numbers_fill_their_input_and_a_column_takes_a_one_dimensional_array():
    x, a, M = ca.SX.sym("x", 3), ca.SX.sym("a"), ca.SX.sym("M", 2, 3)
    f = ca.Function("f", [x, a, M], [ca.sin(x) * a, M @ x, ca.sum1(x).T])
    arguments = (np.array([0.1, -2.0, 3.5]), 2.5, np.arange(6.0).reshape(2, 3))
    expected = _as_dm_call(f, *arguments)
    got = InPlace(f)(*arguments)
    assert all(g.tobytes() == e.tobytes() and g.shape == e.shape for g, e in zip(got, expected))
    wide = ca.Function("wide", [ca.SX.sym("y", 2, 4)], [ca.SX.sym("y", 2, 4) * 0 + 1])
    assert np.array_equal(InPlace(wide)(7.0)[0], np.ones((2, 4)))


def test_bad_arguments_and_sparse_inputs_are_refused_by_name():
    x = ca.SX.sym("x", 3)
    f = InPlace(ca.Function("f", [x], [2 * x], ["state"], ["out"]))
    with pytest.raises(ArgumentError, match="takes 1 arguments, got 2"):
        f(np.zeros(3), 1.0)
    with pytest.raises(ArgumentError, match=r"argument state must be \(3, 1\), got \(4,\)"):
        f(np.zeros(4))
    with pytest.raises(ArgumentError, match="argument state must be real numbers, got complex128"):
        f(np.array([1 + 5j, 2, 3]))
    with pytest.raises(ArgumentError, match="must be real numbers"):
        f(["a", "b", "c"])
    assert f(np.array([1, 2, 3]))[0].tolist() == [[2.0], [4.0], [6.0]]  # integers are real numbers
    sparse = ca.SX.sym("s", ca.Sparsity.diag(3))
    with pytest.raises(ArgumentError, match="input s is sparse"):
        InPlace(ca.Function("g", [sparse], [ca.sum1(sparse)], ["s"], ["o"]))


def test_threads_sharing_one_in_place_function_each_get_their_own_result():
    x = ca.SX.sym("x", 4)
    f = ca.Function("f", [x], [ca.vertcat(ca.exp(x), ca.cos(x))]).map(5000)
    shared = InPlace(f)
    inputs = [np.random.default_rng(seed).standard_normal((4, 5000)) for seed in range(8)]
    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda X: shared(X)[0], inputs * 3))
    for X, result in zip(inputs * 3, results):
        assert result.tobytes() == np.asarray(f(X)).tobytes()
