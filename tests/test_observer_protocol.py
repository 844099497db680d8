"""The estimator contract: Observer validation; the actuator and Luenberger observers implement it."""

import casadi as ca
import numpy as np
import pytest
from scipy.linalg import expm

import uvsym
from uvsym.errors import ArgumentError, ModelError, ObserverError
from uvsym.observers.actuator import actuator_observer
from uvsym.observers.base import Observer, observer
from uvsym.observers.discrete import actuator_fault_observer, gain_units, sampled_observer
from uvsym.observers.luenberger import luenberger_observer
from uvsym.systems import Signals, signals, system

X = signals(("pos", "m", "position"), ("vel", "m/s", "velocity"), group="state")


def _oscillator():
    """x'' = -4 x - 0.4 x' + u, position measured: a linear plant with a known solution."""
    return system("oscillator", "damped oscillator", x=X, u=signals(("force", "m/s^2"), group="input"),
                  y=signals(("pos_meas", "m"), group="output"),
                  rhs=lambda x, u, d, p: ca.vertcat(x[1], -4 * x[0] - 0.4 * x[1] + u[0]),
                  output=lambda x, u, p: x[0])


def test_observer_rejects_mismatched_sizes():
    step = ca.Function("bad_step", [ca.SX.sym("s", 2), ca.SX.sym("y"), ca.SX.sym("u", 0), ca.SX.sym("p", 0)],
                       [ca.SX.zeros(2), ca.SX.zeros(1)], ["s", "y", "u", "p"], ["s_next", "out"])
    with pytest.raises(ObserverError, match="step input s has 2 entries but 3"):
        Observer("bad", step, Signals(("a", "b", "c"), ("-",) * 3), Signals(("y",), ("-",)), Signals(), Signals(),
                 Signals(("o",), ("-",)), np.zeros(0), 0.1)
    with pytest.raises(ObserverError, match="must map"):
        a = ca.SX.sym("a")
        Observer("bad", ca.Function("g", [a], [a]), Signals(), Signals(), Signals(),
                 Signals(), Signals(), np.zeros(0), 0.1)


def test_observer_builder_errors_name_the_problem():
    common = dict(state=signals(("a", "-")), reads_y=signals(("b", "-")), reads_u=signals(),
                  publishes=signals(("a_hat", "-")), dt=0.1)
    with pytest.raises(ObserverError, match="symbols other than s, y, u, p: \\['k'\\]"):
        observer("luen", step=lambda s, y, u, p: (s + ca.SX.sym("k") * y, s), **common)
    with pytest.raises(ObserverError, match="out with 2 entries, expected 1"):
        observer("luen", step=lambda s, y, u, p: (s, ca.vertcat(s, s)), **common)
    with pytest.raises(ObserverError, match="name 'my-observer'"):
        observer("my-observer", step=lambda s, y, u, p: (s, s), **common)
    with pytest.raises(ObserverError, match="dt must be positive"):
        observer("luen", step=lambda s, y, u, p: (s, s), **{**common, "dt": float("nan")})
    obs = observer("luen", step=lambda s, y, u, p: (0.5 * s + 0.5 * y, s), **common)
    with pytest.raises(ObserverError, match=r"Y must be \(N, 1\)"):
        obs.run(np.zeros((4, 2)), np.zeros((4, 0)))
    with pytest.raises(ObserverError, match="non-finite"):
        obs.initial_state([float("nan")], [])


def test_observer_run_matches_hand_recursion():
    obs = observer("avg", step=lambda s, y, u, p: (p[0] * s + (1 - p[0]) * y, s), state=signals(("a", "-")),
                   reads_y=signals(("b", "-")), reads_u=signals(), params=signals(("lam", "-")), p0=[0.5],
                   publishes=signals(("a_hat", "-")), dt=0.1)
    S, out = obs.run(np.ones((4, 1)), np.zeros((4, 0)), p=[0.25])
    expected = [0.0]
    for _ in range(4):
        expected.append(0.25 * expected[-1] + 0.75)
    np.testing.assert_allclose(S.ravel(), expected, rtol=1e-15)
    np.testing.assert_allclose(out.ravel(), expected[:4], rtol=1e-15)
    with pytest.raises(ObserverError, match="no signal named \\['lambda'\\]; known: lam"):
        obs.parameters({"lambda": 0.2})


@pytest.mark.parametrize("kind", ["proportional", "bias", "constant"])
def test_actuator_observer_is_an_observer_with_the_same_numbers(kind):
    """The Observer form runs the same sampled-data step as the closed loop's observers."""
    model = uvsym.vehicle("otter3dof")
    K, dt = np.array([2.0, 1.5, 3.0]), 0.05
    obs = actuator_fault_observer(model, kind, dt, K, form="momentum")
    sampled = sampled_observer(actuator_observer(model, kind, "momentum").function, dt)
    assert obs.reads_y.names == model.state_labels
    assert obs.publishes.names == ("f_hat.X", "f_hat.Y", "f_hat.N")
    assert obs.publishes.units == (("-",) * 3 if kind == "proportional" else ("N", "N", "N m"))
    rng = np.random.default_rng(1)
    Y, U = rng.normal(size=(30, 6)), rng.uniform(5, 20, size=(30, 3))
    S, out = obs.run(Y, U)
    s = sampled.initial_state(Y[0, :3], Y[0, 3:], U[0], K)
    np.testing.assert_allclose(S[0], s, rtol=0, atol=0)
    for k in range(30):
        s, f_hat = (np.asarray(v).ravel() for v in sampled.step(s, Y[k, :3], Y[k, 3:], U[k], K))
        np.testing.assert_allclose(out[k], f_hat, rtol=1e-12, atol=1e-12)
    assert obs.error_dynamics.name_in() == ["e", "f", "eta", "nu", "tau_d", "tau_d_dot", "K"]


def test_luenberger_estimates_a_linear_plant_and_its_error_dynamics_are_A_minus_LC():
    plant = _oscillator()
    L = np.array([[3.0], [2.0]])
    dt = 0.01
    obs = luenberger_observer(plant, L, dt, steps=2)
    assert obs.publishes.names == ("pos_hat", "vel_hat", "r_pos_meas")
    # true trajectory of the free oscillator from x(0) = (1, 0), exactly
    A = np.array([[0.0, 1.0], [-4.0, -0.4]])
    N = 1500
    X_true = np.array([expm(A * dt * k) @ [1.0, 0.0] for k in range(N)])
    S, out = obs.run(X_true[:, :1], np.zeros((N, 1)))
    assert np.abs(out[-1, :2] - X_true[-1]).max() < 1e-8  # |e| ~ exp(-1.7 t) from |e(0)| = 1
    assert abs(out[0, 2] - 1.0) < 1e-15  # residual y - C xhat at xhat = x_op = 0
    # the derived error dynamics of a linear plant are exactly (A - L C) e
    rng = np.random.default_rng(0)
    e, x = rng.normal(size=2), rng.normal(size=2)
    e_dot = np.asarray(obs.error_dynamics(e, x, [0.3], np.zeros(0), np.zeros(0))).ravel()
    np.testing.assert_allclose(e_dot, (A - L @ np.array([[1.0, 0.0]])) @ e, rtol=1e-13, atol=1e-13)


def test_luenberger_rejects_bad_gains_and_discrete_plants():
    plant = _oscillator()
    with pytest.raises(ObserverError, match=r"\(2, 1\) matrix"):
        luenberger_observer(plant, np.ones((1, 2)), 0.01)
    with pytest.raises(ObserverError, match="finite"):
        luenberger_observer(plant, [[np.nan], [1.0]], 0.01)
    with pytest.raises(ObserverError, match="is discrete"):
        luenberger_observer(plant.discretize(0.01, "zoh"), np.ones((2, 1)), 0.01)
    with pytest.raises(ModelError):
        signals(("a", "m"), ("a", "m"))


def test_initial_state_and_run_name_the_bad_sample():
    obs = observer("avg", step=lambda s, y, u, p: (0.5 * s + 0.5 * y, s + u), state=signals(("a", "-")),
                   reads_y=signals(("b", "-")), reads_u=signals(("c", "-")), publishes=signals(("a_hat", "-")),
                   dt=0.1)
    with pytest.raises(ObserverError, match=r"^avg: u0 must have 1 entries \(c\), got 2$"):
        obs.initial_state([0.0], [1.0, 2.0])
    finite_u = np.zeros((3, 1))
    # an infinite measurement is refused even where NaN (a missing sample) is allowed
    with pytest.raises(ObserverError, match="measurements Y finite or NaN"):
        obs.run([[0.0], [np.inf], [1.0]], finite_u, missing_y=True)
    # a NaN measurement is refused when none may be missing, though every input is finite
    with pytest.raises(ObserverError, match="measurements Y finite$"):
        obs.run([[0.0], [np.nan], [1.0]], finite_u)
    with pytest.raises(ObserverError, match="inputs U must be finite"):
        obs.run(np.zeros((3, 1)), [[0.0], [np.nan], [0.0]])


def test_gain_units_per_form_and_fault_kind():
    # by hand: momentum form k_i (1/s), times tau_d,i^2 when the fault scales the command; the paper's form
    # divides by m_i^2 (kg^2 for N, kg^2 m^4 for N m); a two-word unit is bracketed before squaring
    assert gain_units("proportional", "momentum", ("N", "N m")) == ("1/(s N^2)", "1/(s (N m)^2)")
    assert gain_units("bias", "momentum", ("N", "N m")) == ("1/s", "1/s")
    assert gain_units("proportional", "paper", ("N", "N m")) == ("kg^2/(s N^2)", "kg^2 m^4/(s (N m)^2)")
    assert gain_units("bias", "paper", ("N", "N m")) == ("kg^2/s", "kg^2 m^4/s")


def test_actuator_fault_observer_defaults_to_the_paper_form_and_names_its_gains():
    obs = actuator_fault_observer(uvsym.vehicle("otter3dof"), "bias", 0.05, [1.0, 2.0, 3.0])
    assert obs.description.endswith("(paper form), sampled every 0.05 s")
    assert obs.params.units == ("kg^2/s", "kg^2/s", "kg^2 m^4/s")
    with pytest.raises(ObserverError, match=r"no gain named \['K.Z'\]; known: K.X, K.Y, K.N"):
        obs.parameters({"K.Z": 1.0})
    # the step's symbols carry its inputs' names (as observer() names them), so printed expressions read s, y, u, p
    assert [str(v) for v in ca.symvar(obs.step.raw.sx_in(3))] == ["p_0", "p_1", "p_2"]


def test_sampled_observer_keeps_a_coupling_that_vanishes_for_equal_gains():
    """x' = P (x - nu) + tau_d, f_hat = x - nu with P = [[-K1, K1 - K2], [0, -K2]]: R = nu, L = I, q = tau_d."""
    x, eta, nu, tau_d, K = (ca.SX.sym(a, 2) for a in ("x", "eta", "nu", "tau_d", "K"))
    P_sym = ca.vertcat(ca.horzcat(-K[0], K[0] - K[1]), ca.horzcat(0, -K[1]))
    function = ca.Function("coupled", [x, eta, nu, tau_d, K], [ca.mtimes(P_sym, x - nu) + tau_d, x - nu],
                           ["x", "eta", "nu", "tau_d", "K"], ["x_dot", "f_hat"])
    dt, gains = 0.1, np.array([1.0, 3.0])
    sampled = sampled_observer(function, dt)
    P_exact = np.array([[-1.0, -2.0], [0.0, -3.0]])
    np.testing.assert_array_equal(np.asarray(sampled.pieces([0, 0], [1, 1], [0, 0], gains)[0]), P_exact)
    # one Crank-Nicolson step (module docstring) from f_hat = 0 with nu from (1, 2) to (1.5, 1), tau_d (1, -1)
    nu0, nu1, tau = np.array([1.0, 2.0]), np.array([1.5, 1.0]), np.array([1.0, -1.0])
    s0 = sampled.initial_state([0, 0], nu0, tau, gains)
    _, f_hat = sampled.step(s0, [0, 0], nu1, tau, gains)
    expected = np.linalg.solve(np.eye(2) - dt / 2 * P_exact, dt * tau - (nu1 - nu0))
    np.testing.assert_allclose(np.asarray(f_hat).ravel(), expected, rtol=1e-14)


def test_actuator_fault_observer_refuses_gains_that_are_not_numbers_and_reads_desired_forces():
    model = uvsym.vehicle("otter3dof")
    with pytest.raises(ObserverError, match=r"^bias observer: the gains K must be 3 positive finite numbers "
                                            r".*got 'fast'$"):
        actuator_fault_observer(model, "bias", 0.05, "fast")
    with pytest.raises(ObserverError, match=r"got \[1\.0, None, 3\.0\]$"):
        actuator_fault_observer(model, "bias", 0.05, [1.0, None, 3.0])
    obs = actuator_fault_observer(model, "bias", 0.05, [1.0, 2.0, 3.0])
    assert obs.reads_u.names == ("tau_d.X", "tau_d.Y", "tau_d.N")
    assert obs.reads_u.group == "desired force"


def _held_sum_observer(init=lambda y0, u0, p: [y0[0] + p[0], y0[1] + u0[0]]):
    """s_next = g s + u, out = s (y unread, so a missing sample cannot spoil it); init = (y1 + g, y2 + c)."""
    return observer("avg2", step=lambda s, y, u, p: (p[0] * s + u[0], s), state=signals(("a", "-"), ("b", "-")),
                    reads_y=signals(("y1", "-"), ("y2", "-")), reads_u=signals(("c", "-")),
                    params=signals(("g", "-")), p0=[1.0], publishes=signals(("a_out", "-"), ("b_out", "-")), dt=0.1,
                    init=init)


def test_run_starts_from_the_first_complete_measurement_with_the_given_parameters():
    obs = _held_sum_observer()
    # sample 0 misses y1 (None reads as NaN), sample 1 is complete: s0 = (2 + g, 3 + U[0]) with g = 2 -> (4, 13);
    # then s_{k+1} = 2 s_k + u_k by hand
    S, out = obs.run([[None, 1.0], [2.0, 3.0], [None, None]], [[10.0], [0.0], [0.0]], p=[2.0], missing_y=True)
    np.testing.assert_array_equal(S, [[4.0, 13.0], [18.0, 36.0], [36.0, 72.0], [72.0, 144.0]])
    np.testing.assert_array_equal(out, S[:3])
    # no complete sample: the first one, its NaN as zero, with p0: s0 = (0 + 1, 5 + 0), held (g = 1, u = 0)
    S, _ = obs.run([[np.nan, 5.0], [np.nan, 7.0]], np.zeros((2, 1)), missing_y=True)
    np.testing.assert_array_equal(S, [[1.0, 5.0]] * 3)
    S, _ = obs.run([[np.nan, np.nan]], [[2.0]], missing_y=True)
    np.testing.assert_array_equal(S, [[1.0, 2.0], [3.0, 4.0]])
    # None where a number is due is refused like NaN, not passed on as an object
    with pytest.raises(ObserverError, match="measurements Y finite$"):
        obs.run([[None, 1.0], [2.0, 3.0]], np.zeros((2, 1)))
    with pytest.raises(ObserverError, match="inputs U must be finite"):
        obs.run(np.zeros((2, 2)), [[0.0], [None]])


def test_run_refuses_mismatched_samples_and_takes_a_single_one():
    obs = _held_sum_observer()
    message = r"^avg2: measurements Y must be \(N, 2\) \(y1, y2\) and inputs U \(N, 1\), at least one sample; got "
    with pytest.raises(ObserverError, match=message + r"\(3, 2\) and \(2, 1\)$"):
        obs.run(np.zeros((3, 2)), np.zeros((2, 1)))
    with pytest.raises(ObserverError, match=message + r"\(3, 2\) and \(3, 2\)$"):
        obs.run(np.zeros((3, 2)), np.zeros((3, 2)))
    with pytest.raises(ObserverError, match=message + r"\(0, 2\) and \(0, 1\)$"):
        obs.run(np.zeros((0, 2)), np.zeros((0, 1)))
    # one sample: s0 = (1 + 1, 2 + 3), s1 = s0 + 3
    S, out = obs.run([[1.0, 2.0]], [[3.0]])
    np.testing.assert_array_equal(S, [[2.0, 5.0], [5.0, 8.0]])
    np.testing.assert_array_equal(out, [[2.0, 5.0]])


def test_run_takes_a_given_initial_state_of_any_shape_and_refuses_a_bad_one():
    obs = _held_sum_observer()
    S, _ = obs.run(np.zeros((2, 2)), [[1.0], [-1.0]], s0=[[1.0], [2.0]])  # a column is read as the state vector
    np.testing.assert_array_equal(S, [[1.0, 2.0], [2.0, 3.0], [1.0, 2.0]])
    with pytest.raises(ObserverError, match=r"^avg2: s0 must be 2 finite values, got 3$"):
        obs.run(np.zeros((2, 2)), np.zeros((2, 1)), s0=[1.0, 2.0, 3.0])
    with pytest.raises(ObserverError, match=r"^avg2: s0 must be 2 finite values, got 2$"):
        obs.run(np.zeros((2, 2)), np.zeros((2, 1)), s0=[None, 1.0])


def test_initial_state_names_the_observer_and_takes_any_shape_of_init_as_floats():
    obs = _held_sum_observer()
    with pytest.raises(ObserverError) as refused:
        obs.initial_state([1.0], [0.0])
    assert str(refused.value) == "avg2: y0 must have 2 entries (y1, y2), got 1"
    # init's (2, 1) column of integers is the state vector of floats: (y1 + g, y2 + c) = (1 + 1, 2 + 3)
    column = _held_sum_observer(lambda y0, u0, p: [[int(y0[0] + p[0])], [int(y0[1] + u0[0])]])
    s0 = column.initial_state([1.0, 2.0], [3.0])
    assert s0.shape == (2,) and s0.dtype == np.float64 and s0.tolist() == [2.0, 5.0]


@pytest.mark.parametrize("init, size, finite", [(lambda y0, u0, p: [1.0, 2.0, 3.0], 3, True),
                                                 (lambda y0, u0, p: [1.0, np.nan], 2, False),
                                                 (lambda y0, u0, p: [np.inf], 1, False)])
def test_initial_state_refuses_an_init_of_the_wrong_size_or_not_finite(init, size, finite):
    with pytest.raises(ObserverError) as refused:
        _held_sum_observer(init).initial_state([1.0, 2.0], [3.0])
    assert str(refused.value) == f"avg2: init gave {size} entries (finite: {finite}), expected 2 finite"


def _builder_common():
    return dict(state=signals(("a", "-")), reads_y=signals(("b", "-")), reads_u=signals(),
                publishes=signals(("a_hat", "-")), dt=0.1)


@pytest.mark.parametrize("step, message", [
    (lambda s, y, u, p: [s, s], "luen: step must return (s_next, out)"),  # a list, not a tuple
    (lambda s, y, u, p: (s,), "luen: step must return (s_next, out)"),
    (lambda s, y, u, p: (s, s, s), "luen: step must return (s_next, out)"),
    (lambda s, y, u, p: (s, "a"), "luen: step: expected a CasADi expression or a list of them, got str"),
    (lambda s, y, u, p: (ca.vertcat(s, s), s), "luen: step gives s_next with 2 entries, expected 1"),
    (lambda s, y, u, p: (s, s + ca.SX.sym("k")), "luen: step uses symbols other than s, y, u, p: ['k']")])
def test_the_observer_builder_names_what_its_step_returned_wrong(step, message):
    with pytest.raises(ObserverError) as caught:
        observer("luen", step=step, **_builder_common())
    assert str(caught.value) == message


def test_the_observer_builder_names_a_bad_observer_name_and_defaults_to_no_parameters():
    with pytest.raises(ObserverError) as caught:
        observer("my-observer", step=lambda s, y, u, p: (s, s), **_builder_common())
    assert str(caught.value) == ("observer name 'my-observer' must start with a letter and hold only letters, digits "
                                 "and single underscores (it names C functions)")
    built = observer("luen", step=lambda s, y, u, p: (s, s), **_builder_common())
    assert built.params.size == 0 and built.params.group == "parameter" and built.p0.shape == (0,)


def test_the_observer_builder_names_a_nan_constant_and_the_cure():
    # math.nan in the step (what float(symbol) arithmetic through numpy or math would leave behind)
    with pytest.raises(ObserverError) as caught:
        observer("luen", step=lambda s, y, u, p: (s + float("nan"), s), **_builder_common())
    assert str(caught.value) == ("luen: the step holds a NaN constant: a math or numpy function applied to a CasADi "
                                 "symbol gives NaN; use casadi's own (ca.sin, ca.exp, ...)")


def _step_function(inputs=("s", "y", "u", "p"), outputs=("s_next", "out")):
    """A step of one state, one measurement, no input or parameter: (s, y) -> (s, s), with the given names."""
    s, y, u, p = ca.SX.sym("s"), ca.SX.sym("y"), ca.SX.sym("u", 0), ca.SX.sym("p", 0)
    return ca.Function("step", [s, y, u, p], [s, s], list(inputs), list(outputs))


def _direct(name="luen", step=None, state=("a",), reads_y=("b",)):
    return Observer(name, _step_function() if step is None else step, Signals(state, ("-",) * len(state)),
                    Signals(reads_y, ("-",) * len(reads_y)), Signals(), Signals(), Signals(("o",), ("-",)),
                    np.zeros(0), 0.1)


@pytest.mark.parametrize("arguments, message", [
    (dict(name="bad-name"), "observer name 'bad-name' must start with a letter and hold only letters, digits and "
                            "single underscores (it names C functions)"),
    (dict(reads_y=("a",)), "luen: names ['a'] stand in more than one of state, reads_y, reads_u, params; each signal "
                           "needs its own name"),
    (dict(step="not a function"), "luen: step must be a casadi.Function, got str"),
    (dict(step=_step_function(outputs=("s_next", "y_out"))),
     "luen: step must map (s, y, u, p) -> (s_next, out), got (s, y, u, p) -> (s_next, y_out)"),
    (dict(step=_step_function(inputs=("s", "y", "u", "q"))),
     "luen: step must map (s, y, u, p) -> (s_next, out), got (s, y, u, q) -> (s_next, out)")])
def test_an_observer_built_directly_names_what_is_wrong(arguments, message):
    with pytest.raises(ObserverError) as caught:
        _direct(**arguments)
    assert str(caught.value) == message


def test_an_observer_built_directly_with_distinct_names_is_accepted():
    assert _direct().name == "luen"


def _full_observer(name="luen", dt=0.1, p0=(2,), publishes=("o",)):
    """s' = s + k y + c / y, out = log(s): state a, measurement b, input c, parameter k, output o."""
    s, y, u, p = ca.SX.sym("s"), ca.SX.sym("y"), ca.SX.sym("u"), ca.SX.sym("p")
    step = ca.Function("step", [s, y, u, p], [s + p * y + u / y, ca.log(s)], ["s", "y", "u", "p"], ["s_next", "out"])
    return Observer(name, step, Signals(("a",), ("m",)), Signals(("b",), ("m",)), Signals(("c",), ("N",)),
                    Signals(("k",), ("-",)), Signals(publishes, ("-",) * len(publishes)), p0, dt)


@pytest.mark.parametrize("arguments, message", [
    ((float("nan"), 1.0, 0.0, 2.0), "luen.step: argument s entry a is nan; every entry must be finite"),
    ((1.0, float("nan"), 0.0, 2.0), "luen.step: argument y entry b is nan; every entry must be finite"),
    ((1.0, 1.0, float("inf"), 2.0), "luen.step: argument u entry c is inf; every entry must be finite"),
    ((1.0, 1.0, 0.0, float("-inf")), "luen.step: argument p entry k is -inf; every entry must be finite"),
    ((1.0, 0.0, 1.0, 2.0), "luen.step: output s_next entry a is inf at finite arguments"),
    ((0.0, 1.0, 0.0, 2.0), "luen.step: output out entry o is -inf at finite arguments")])
def test_an_observers_step_names_each_non_finite_entry_by_its_signal(arguments, message):
    with pytest.raises(ArgumentError) as caught:
        _full_observer().step(*arguments)
    assert str(caught.value).startswith(message)


@pytest.mark.parametrize("arguments, message", [
    (dict(dt=float("inf")), "luen: sample period dt must be positive and finite (s), got inf"),
    (dict(dt=0.0), "luen: sample period dt must be positive and finite (s), got 0.0"),
    (dict(publishes=("o", "q")), "luen: step output out has 1 entries but 2 signals are named (o, q)"),
    (dict(p0=(1.0, 2.0)), "luen: parameters p0")])
def test_an_observer_names_a_bad_period_output_count_or_parameter_vector(arguments, message):
    with pytest.raises(ObserverError) as caught:
        _full_observer(**arguments)
    assert str(caught.value).startswith(message)


def test_an_observer_stores_its_parameters_as_floats_and_takes_capitals_in_its_name():
    built = _full_observer(name="Luen_2")
    assert isinstance(built.p0, np.ndarray) and built.p0.dtype == float and built.p0.tolist() == [2.0]


def test_an_input_count_mismatch_lists_the_named_signals():
    with pytest.raises(ObserverError) as caught:
        _direct(state=("a", "z"))
    assert str(caught.value) == "luen: step input s has 1 entries but 2 signal signals are named (a, z)"


def test_run_goes_in_fixed_chunks_with_the_numbers_of_one_step_after_another(monkeypatch):
    """Linear in N: the steps are rolled in chunks of RUN_CHUNK (one mapaccum per chunk size, built once),
    never one mapaccum(N); the result is that of calling the step sample after sample."""
    import numpy as np
    from problems import double_integrator

    from uvsym.observers import base
    from uvsym.observers.ukf import ukf

    obs = ukf(double_integrator(outputs=("pos",)), dt=0.1, Q=np.diag([1e-6, 1e-4]), R=1e-4, P0=np.eye(2))
    monkeypatch.setattr(base, "RUN_CHUNK", 64)
    sizes = []
    rolled = base._rolled
    monkeypatch.setattr(base, "_rolled", lambda step, k: sizes.append(k) or rolled(step, k))
    N = 64 * 3 + 7
    Y, U = np.random.default_rng(1).normal(scale=0.01, size=(N, 1)), np.zeros((N, 1))
    S, OUT = obs.run(Y, U)
    assert sizes == [64, 64, 64, 7]
    s, p = S[0], obs.parameters(None)
    for k in range(N):  # one step after another, from the same initial state
        s_next, out = (np.asarray(v).ravel() for v in obs.step(s, Y[k], U[k], p))
        np.testing.assert_array_equal(S[k + 1], s_next)
        np.testing.assert_array_equal(OUT[k], out)
        s = s_next


def test_run_compiled_gives_the_steps_numbers_and_is_the_default_for_long_records(monkeypatch):
    """compiled=True rolls the step in C (IEEE flags): the states and outputs of one step after another to
    rounding, S's first row the initial state; from COMPILE_FROM samples it is the default, unless Y has NaN to
    skip (missing_y: the virtual machine keeps NaN's semantics); without a compiler compiled=True raises."""
    import numpy as np
    from problems import double_integrator

    from uvsym.codegen.compile import find_compiler
    from uvsym.errors import CodegenError
    from uvsym.observers import base
    from uvsym.observers.ukf import ukf

    if find_compiler() is None:
        pytest.skip("no C compiler")
    obs = ukf(double_integrator(outputs=("pos",)), dt=0.1, Q=np.diag([1e-6, 1e-4]), R=1e-4, P0=np.eye(2))
    N = 300
    Y, U = np.random.default_rng(2).normal(scale=0.01, size=(N, 1)), np.zeros((N, 1))
    S_vm, OUT_vm = obs.run(Y, U, compiled=False)
    S_c, OUT_c = obs.run(Y, U, compiled=True)
    assert S_c.shape == S_vm.shape and OUT_c.shape == OUT_vm.shape
    np.testing.assert_array_equal(S_c[0], S_vm[0])
    np.testing.assert_allclose(S_c, S_vm, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(OUT_c, OUT_vm, rtol=1e-12, atol=1e-15)
    chosen = []
    compiled_roll = base._compiled_roll
    monkeypatch.setattr(base, "_compiled_roll", lambda step, required, history: chosen.append(required)
                        or compiled_roll(step, required, history))
    monkeypatch.setattr(base, "COMPILE_FROM", 200)
    obs.run(Y, U)                      # 300 >= 200: compiled by default
    obs.run(Y[:100], U[:100])          # shorter: the virtual machine
    gaps = Y.copy()
    gaps[5] = np.nan
    obs.run(gaps, U, missing_y=True)   # NaN to skip: the virtual machine
    assert chosen == [False]
    monkeypatch.setattr(base, "_compiled_roll", compiled_roll)
    monkeypatch.setattr("uvsym.codegen.compile.find_compiler", lambda: None)
    fresh = ukf(double_integrator(outputs=("pos",)), dt=0.2, Q=np.diag([1e-6, 1e-4]), R=1e-4, P0=np.eye(2))
    with pytest.raises(CodegenError, match="no C compiler"):
        fresh.run(Y, U, compiled=True)
    assert fresh.run(Y, U)[0].shape == (N + 1, fresh.state.size)  # the default falls back to the virtual machine


@pytest.mark.parametrize("compiled", [False, True])
def test_run_keeping_only_the_final_state_gives_the_same_outputs_and_last_state(compiled):
    """states="final": the outputs of the full run and its last state, S (1, n_s), on both paths (the C loop
    writes no state history); an unknown choice is named."""
    import numpy as np
    from problems import double_integrator

    from uvsym.codegen.compile import find_compiler
    from uvsym.errors import ObserverError
    from uvsym.observers.ukf import ukf

    if compiled and find_compiler() is None:
        pytest.skip("no C compiler")
    obs = ukf(double_integrator(outputs=("pos",)), dt=0.1, Q=np.diag([1e-6, 1e-4]), R=1e-4, P0=np.eye(2))
    N = 2500  # more than one of the virtual machine's chunks
    Y, U = np.random.default_rng(3).normal(scale=0.01, size=(N, 1)), np.zeros((N, 1))
    S, OUT = obs.run(Y, U, compiled=compiled)
    last, outputs = obs.run(Y, U, compiled=compiled, states="final")
    assert last.shape == (1, obs.state.size) and outputs.shape == OUT.shape
    np.testing.assert_array_equal(outputs, OUT)
    np.testing.assert_array_equal(last[0], S[-1])
    with pytest.raises(ObserverError, match="states must be 'all', 'final' or a sequence of state names"):
        obs.run(Y, U, states="last")


@pytest.mark.parametrize("compiled", [False, True])
def test_run_keeping_named_state_entries_gives_those_columns_of_the_full_history(compiled):
    """states=[names]: S (N + 1, k), the named columns of the full run's S in the order given, from s0, and the
    same outputs, on both paths (the C loop writes only those entries); an unknown name, an empty selection and
    a number are refused, the unknown one named."""
    import numpy as np
    from problems import double_integrator

    from uvsym.codegen.compile import find_compiler
    from uvsym.errors import ObserverError
    from uvsym.observers.ukf import ukf

    if compiled and find_compiler() is None:
        pytest.skip("no C compiler")
    obs = ukf(double_integrator(outputs=("pos",)), dt=0.1, Q=np.diag([1e-6, 1e-4]), R=1e-4, P0=np.eye(2))
    N = 2500
    Y, U = np.random.default_rng(4).normal(scale=0.01, size=(N, 1)), np.zeros((N, 1))
    S, OUT = obs.run(Y, U, compiled=compiled)
    names = [obs.state.names[-1], obs.state.names[0]]
    kept, outputs = obs.run(Y, U, compiled=compiled, states=names)
    assert kept.shape == (N + 1, 2)
    np.testing.assert_array_equal(kept, S[:, [obs.state.size - 1, 0]])
    np.testing.assert_array_equal(outputs, OUT)
    with pytest.raises(ObserverError, match="no state named 'nosuch'"):
        obs.run(Y, U, states=[names[0], "nosuch"])
    with pytest.raises(ObserverError, match="at least one state entry"):
        obs.run(Y, U, states=[])
    with pytest.raises(ObserverError, match="a sequence of state names"):
        obs.run(Y, U, states=3)


@pytest.mark.parametrize("compiled", [False, True])
def test_a_stateless_observer_keeps_one_empty_state_row_per_sample(compiled):
    """An observer without state entries (a static map of its measurement): states="all" gives S (N + 1, 0)
    and "final" S (1, 0), on both paths, with the same outputs."""
    import numpy as np

    from uvsym.codegen.compile import find_compiler
    from uvsym.observers.base import observer
    from uvsym.systems import signals

    if compiled and find_compiler() is None:
        pytest.skip("no C compiler")
    doubler = observer("doubler", step=lambda s, y, u, p: (s, [2 * y[0]]), state=signals(group="state"),
                       reads_y=signals(("x", "m", ""), group="output"), reads_u=signals(group="input"),
                       publishes=signals(("x2", "m", "twice x")), dt=0.1)
    Y = np.arange(30.0)[:, None]
    S, OUT = doubler.run(Y, np.zeros((30, 0)), compiled=compiled)
    last, published = doubler.run(Y, np.zeros((30, 0)), compiled=compiled, states="final")
    assert S.shape == (31, 0) and last.shape == (1, 0)
    np.testing.assert_array_equal(OUT[:, 0], 2 * Y[:, 0])
    np.testing.assert_array_equal(published, OUT)
