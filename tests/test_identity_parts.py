"""Unit tests of the identity prover's parts (``uvsym.verify.identity``): the atomisation behind the exact
proof, the symbolic child process and its budget, the term-size scale, input and box validation, and the
interval re-check of a gap. Expected values are worked out by hand in each docstring."""

import multiprocessing
import time

import casadi as ca
import numpy as np
import pytest
import sympy as sp

from uvsym.errors import VerificationError
from uvsym.verify import identity

x, y = sp.symbols("x y", real=True)


# --- _atomised / exact_zero -------------------------------------------------------------------------------------


def test_distinct_transcendental_atoms_are_not_confused():
    """sin(x) - cos(x) and sin(x) - sin(y) are not identically zero: each distinct function call must be its own
    symbol (a single shared symbol would make both differences 'proved')."""
    assert not identity.exact_zero(sp.sin(x) - sp.cos(x))
    assert not identity.exact_zero(sp.sin(x) - sp.sin(y))
    assert identity.exact_zero(sp.sin(x) - sp.sin(x))


def test_atom_arguments_are_expanded_before_comparison():
    """sin(x (x + 1)) and sin(x^2 + x) are the same function of the same value: the arguments are expanded, so
    the difference is zero by rational arithmetic alone (likewise exp of a product against exp of its expansion)."""
    assert sp.sin(x * (x + 1)) != sp.sin(x**2 + x)  # sympy keeps the two forms apart by itself
    assert identity.exact_zero(sp.sin(x * (x + 1)) - sp.sin(x**2 + x))
    assert identity.exact_zero(2 * sp.exp((x + y) ** 2) - sp.exp(x**2 + 2 * x * y + y**2) * 2)


def test_atoms_are_named_in_order_of_first_appearance():
    """Each new atom is a fresh symbol named atom0, atom1, ... (how a difference left nonzero reads)."""
    atomised = identity._atomised(sp.sin(x) + 2 * sp.cos(x) + sp.sin(x) ** 2)
    assert sorted(s.name for s in atomised.free_symbols) == ["atom0", "atom1"]


# --- _symbolic_outcome ------------------------------------------------------------------------------------------


class _Channel:
    def __init__(self):
        self.sent = []

    def send(self, how):
        self.sent.append(how)


@pytest.fixture
def recorded_limits(monkeypatch):
    """The child's CPU limits, recorded rather than set; getrlimit answers only for RLIMIT_CPU; 100.7 s used."""
    limits = []

    def getrlimit(kind):
        assert kind == identity.resource.RLIMIT_CPU
        return identity.resource.RLIM_INFINITY, identity.resource.RLIM_INFINITY

    monkeypatch.setattr(identity.resource, "getrlimit", getrlimit)
    monkeypatch.setattr(identity.resource, "setrlimit", lambda kind, pair: limits.append(pair))
    monkeypatch.setattr(identity.time, "process_time", lambda: 100.7)
    return limits


@pytest.mark.parametrize("seconds, soft", [(0.5, 101), (0.01, 101), (1.0, 101), (1.2, 102)])
def test_cpu_limit_is_at_least_one_second_beyond_the_time_used(recorded_limits, seconds, soft):
    """Soft limit = max(1, ceil(seconds)) + int(100.7): 0.5 s and 0.01 s give 1 + 100, 1.2 s gives 2 + 100."""
    identity._symbolic_outcome([sp.Integer(0)], _Channel(), seconds)
    assert recorded_limits == [(soft, identity.resource.RLIM_INFINITY)]


def test_an_exactly_zero_entry_does_not_end_the_check_of_the_others(recorded_limits):
    """[0, x]: the first entry vanishes, the second does not: the whole difference is not zero ('')."""
    channel = _Channel()
    identity._symbolic_outcome([sp.Integer(0), x], channel, 1.0)
    identity._symbolic_outcome([sp.Integer(0), x - x, sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1, y], channel, 1.0)
    assert channel.sent == ["", ""]


@pytest.mark.parametrize("margin, outcome", [(0, "simplify"), (-1, "")])
def test_simplify_is_tried_up_to_and_including_the_op_count_limit(recorded_limits, monkeypatch, margin, outcome):
    """sin^2 + cos^2 - 1 needs simplification; with the limit equal to its op count it is simplified, with the
    limit one below, it is not tried (and the entry is left 'not zero')."""
    entry = sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1
    ops = sp.count_ops(entry)  # the quantity the limit is stated in
    assert ops > 1
    monkeypatch.setattr(identity, "SIMPLIFY_OPS", ops + margin)
    channel = _Channel()
    identity._symbolic_outcome([entry], channel, 1.0)
    assert channel.sent == [outcome]


# --- _symbolic (the child process) ------------------------------------------------------------------------------


def test_symbolic_child_is_a_forked_daemon_with_a_write_only_channel(monkeypatch):
    """The child is forked even where the platform's default start method is spawn (macOS, newer Pythons: a
    local target could not be pickled there), is a daemon (never outlives the caller) and gets the send end of a
    one-way pipe (not readable)."""

    def report(entries, channel, seconds):
        channel.send(f"daemon={multiprocessing.current_process().daemon} readable={channel.readable}")

    monkeypatch.setattr(identity, "_symbolic_outcome", report)
    default = multiprocessing.get_start_method(allow_none=True)
    multiprocessing.set_start_method("spawn", force=True)
    try:
        outcome = identity._symbolic([sp.Integer(0)], 0.5)
    finally:
        multiprocessing.set_start_method(default, force=True)
    assert outcome == "daemon=True readable=False"


def test_a_child_that_ends_without_an_answer_is_a_timeout(monkeypatch):
    """A child stopped by its CPU limit sends nothing: the closed pipe reads as 'timeout'."""
    monkeypatch.setattr(identity, "_symbolic_outcome", lambda entries, channel, seconds: None)
    assert identity._symbolic([sp.Integer(0)], 0.5) == "timeout"


def test_a_child_too_slow_on_the_wall_clock_is_abandoned(monkeypatch):
    """With a wall allowance of 0.05 s per CPU second (at least 1 s of CPU counted), a child that answers only
    after 3 s of sleep is not waited for: 'timeout', and it is stopped."""

    def late(entries, channel, seconds):
        time.sleep(3)
        channel.send("late")

    monkeypatch.setattr(identity, "_symbolic_outcome", late)
    monkeypatch.setattr(identity, "WALL_FACTOR", 0.05)
    assert identity._symbolic([sp.Integer(0)], 0.5) == "timeout"


@pytest.mark.parametrize("seconds, cpu", [(3.0, 3.0), (0.25, 1.0), (1.5, 1.5)])
def test_wall_clock_allowance_is_wall_factor_times_the_cpu_budget_of_at_least_one_second(monkeypatch, seconds, cpu):
    """The parent waits WALL_FACTOR * max(1, seconds) s for the answer: 3 s -> 3 WALL_FACTOR, 0.25 s -> WALL_FACTOR."""
    waits = []
    poll = multiprocessing.connection.Connection.poll

    def recorded(self, timeout=0.0):
        waits.append(timeout)
        return poll(self, timeout)

    monkeypatch.setattr(multiprocessing.connection.Connection, "poll", recorded)
    monkeypatch.setattr(identity, "_symbolic_outcome", lambda entries, channel, seconds: channel.send("exact"))
    assert identity._symbolic([sp.Integer(0)], seconds) == "exact"
    assert waits == [pytest.approx(identity.WALL_FACTOR * cpu)]


# --- _magnitude -------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("expression, point, expected", [
    ((x - 1) ** 2, {x: 3}, 16),  # (|3| + |-1|)^2
    (x * (y - 2) ** 3, {x: -2, y: 1}, 54),  # |-2| (|1| + |-2|)^3
    (1 / (x - 1), {x: 3}, sp.Rational(1, 2)),  # a negative power is a term as a whole: |1 / (3 - 1)|
    (x**2 - 3 * x * y, {x: -1, y: 2}, 7),  # |-1|^2 + |-3| |-1| |2|
])
def test_magnitude_is_the_sum_of_absolute_terms_through_products_and_powers(expression, point, expected):
    assert identity._magnitude(expression).subs(point) == expected


# --- _symbols ---------------------------------------------------------------------------------------------------

X, P, Q = ca.SX.sym("x"), ca.SX.sym("p"), ca.SX.sym("q")
V = ca.SX.sym("v", 2)


def _message(call) -> str:
    with pytest.raises(VerificationError) as error:
        call()
    return str(error.value)


def test_symbols_are_the_inputs_entries_in_order():
    assert [str(s) for s in identity._symbols([V, X], X * V[1], V[0])] == ["v_0", "v_1", "x"]


@pytest.mark.parametrize("inputs", [[X, 1.0], X, [X, ca.DM(1)]])
def test_inputs_must_be_a_list_of_sx(inputs):
    assert _message(lambda: identity._symbols(inputs, X, X)) == "inputs must be a list of CasADi SX symbol vectors"


def test_inputs_must_be_symbols():
    assert (_message(lambda: identity._symbols([V[0] + 1], V[0], V[0]))
            == "inputs must hold symbols only (no expressions or constants)")


def test_free_symbols_of_either_side_are_all_named():
    """p and q appear only on the right-hand side: both are named, comma-separated, in alphabetical order."""
    assert (_message(lambda: identity._symbols([X], X, Q * X + P))
            == "lhs/rhs use symbols not among the inputs: p, q (list them in inputs)")


# --- _box -------------------------------------------------------------------------------------------------------


def test_box_is_two_flat_float_arrays():
    """Nested lists are flattened, integers (even beyond int64) become floats; a point box (lower == upper) is
    a valid set."""
    lower, upper = identity._box(([[0], [-1]], [2, 10**30]), 2)
    assert lower.dtype == upper.dtype == np.float64
    assert lower.tolist() == [0.0, -1.0] and upper.tolist() == [2.0, 1e30]
    lower, upper = identity._box(([1, 2], [1, 3]), 2)
    assert lower.tolist() == [1.0, 2.0] and upper.tolist() == [1.0, 3.0]
    assert identity._box(None, 3) is None


@pytest.mark.parametrize("box", [(1, 2, 3), 5, ([0], ["a"])])
def test_box_that_is_not_a_pair_of_arrays(box):
    assert (_message(lambda: identity._box(box, 1))
            == "box must be a pair (lower, upper) of arrays, one entry per input symbol")


@pytest.mark.parametrize("box", [([0], [1, 1]), ([0, 0], [1]), ([0, 0, 0], [1, 1, 1]), ([np.nan, 0], [1, 1]),
                                 ([0, 0], [1, np.inf]), ([-np.inf, 0], [1, 1])])
def test_box_with_the_wrong_size_or_non_finite_bounds(box):
    assert (_message(lambda: identity._box(box, 2))
            == "box must be finite lower and upper bounds with 2 entries (one per input symbol)")


def test_box_with_a_lower_bound_above_its_upper_bound():
    assert _message(lambda: identity._box(([0, 2], [1, 1]), 2)) == "box has a lower bound above its upper bound"


# --- _certain_gap -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("lhs, rhs, k, gap", [
    (2 * X, X + 1, 0, 2.0),  # 6 - 4 at x = 3
    (X + 1, 2 * X, 0, 2.0),  # 4 - 6: the gap's size, whatever its sign
    (ca.vertcat(X, 2 * X), ca.vertcat(X, X), 1, 3.0),  # entry 1: 6 - 3
    (ca.vertcat(X, 2 * X), ca.vertcat(X, X), 0, 0.0),  # entry 0: x - x
    (0.1 * X, X / 10, 0, 0.0),  # both round 0.3 differently: an interval around 0, no certain gap
    (ca.sign(ca.sqrt(X - 4)) + 3, ca.SX(0), 0, 0.0),  # sqrt(-1) is undefined: nothing is certain there
])
def test_certain_gap_is_a_rigorous_lower_bound_of_the_difference(lhs, rhs, k, gap):
    bound = identity._certain_gap(ca.SX(lhs), ca.SX(rhs), [X], np.array([3.0]), k)
    assert 0.0 <= bound and gap - 1e-12 <= bound <= gap


def test_certain_gap_of_an_operation_without_intervals_is_unknown_and_a_nan_point_names_the_function():
    assert identity._certain_gap(ca.erf(X), X, [X], np.array([3.0]), 0) is None
    assert _message(lambda: identity._certain_gap(2 * X, X, [X], np.array([np.nan]), 0)).startswith("difference: ")
