"""The hybrid unknown-input / adaptive observer (uvsym.observers.hybrid) on small linear plants
with known answers: data from scipy's integrator, closed forms derived by hand."""

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from uvsym.errors import ObserverError
from uvsym.observers.hybrid import (
    FaultEstimator,
    decouple,
    hybrid_observer,
    linear_error_model,
    observer_state,
    with_sensor_fault_states,
)
from uvsym.systems import signals, system

DT = 1e-3


def plant(restoring: float = 1.0):
    """x1' = -x1 + x2 + d, x2' = x1 - 2 x2 + d + u, x3' = x1 - restoring x3; y = (x1, x3) (a fault adds to y2)."""
    A = np.array([[-1.0, 1.0, 0.0], [1.0, -2.0, 0.0], [1.0, 0.0, -restoring]])
    return A, system("three", "test plant", x=signals(("x1", "m"), ("x2", "m"), ("x3", "m"), group="state"),
                     u=signals(("u", "m/s"), group="input"), d=signals(("d", "m/s"), group="disturbance"),
                     y=signals(("y1", "m"), ("y3", "m"), group="output"),
                     rhs=lambda x, u, d, p: ca.mtimes(ca.DM(A), x) + ca.vertcat(d, d + u, 0),
                     output=lambda x, u, p: ca.vertcat(x[0], x[2]))


F = np.array([[0.0], [2.0]])


def data(A, fault_onset=None, duration=8.0):
    """Samples of the plant under d = 5 sin(3 t), u = 1, from x(0) = (1, -1, 0.5); the fault, a unit
    step on f_s from ``fault_onset``, adds 2 f_s to y3."""
    t = np.arange(0.0, duration, DT)
    E, B = np.array([1.0, 1.0, 0.0]), np.array([0.0, 1.0, 0.0])
    sol = solve_ivp(lambda s, x: A @ x + E * 5 * np.sin(3 * s) + B, (0, t[-1]), [1.0, -1.0, 0.5], t_eval=t,
                    rtol=1e-10, atol=1e-12)
    X = sol.y.T
    fault = np.zeros_like(t) if fault_onset is None else (t >= fault_onset).astype(float)
    Y = np.column_stack([X[:, 0], X[:, 2] + 2 * fault])
    return t, X, Y, np.ones((t.size, 1))


def split(sys3):
    return decouple(sys3, sys3.linearize(), z1=["x1", "x2"], w1=["y1"], F=F)


def test_decoupling_removes_the_disturbance_direction():
    A, sys3 = plant()
    dec = split(sys3)
    assert np.allclose(dec.Tu @ dec.E1, 0) and np.allclose(dec.H, [[1.0], [1.0]])  # by hand: H = E1 / (C1 E1)
    assert np.allclose(dec.omega["Omega1"], [[0.0, 0.0], [2.0, -3.0]])  # (I - H C1) A11
    assert dec.ranks == {"B": 1, "E": 1, "C[B E]": 1, "m + r": 2}  # C B = 0: Assumption 1 fails here too
    assert dec.undetectable == ()  # (C1, Tu A11) = ([1, 0], [[0, 0], [2, -3]]): the mode -3 is stable


def test_unknown_input_observer_estimates_through_a_large_disturbance():
    A, sys3 = plant()
    t, X, Y, U = data(A)
    dec = split(sys3)
    obs = hybrid_observer(sys3, dec, [[20.0], [0.0]], [[5.0]], DT, name="uio")
    _, out = obs.run(Y, U)
    late = t > 4.0
    assert np.max(np.abs(out[late, :3] - X[late])) < 1e-3  # the disturbance (amplitude 5) does not reach it
    # without the decoupling (H = 0) the same model is off by the disturbance's effect
    blind = decouple(sys3, sys3.linearize(), z1=["x1", "x2"], w1=["y1"], E=np.zeros((3, 1)), F=F)
    _, out_blind = hybrid_observer(sys3, blind, [[20.0], [0.0]], [[5.0]], DT, name="blind").run(Y, U)
    assert np.max(np.abs(out_blind[late, :3] - X[late])) > 0.1


def test_detection_residual_rises_by_the_fault_and_decays_at_L1():
    A, sys3 = plant()
    t, X, Y, U = data(A, fault_onset=2.0)
    obs = hybrid_observer(sys3, split(sys3), [[20.0], [0.0]], [[5.0]], DT, name="detection")
    _, out = obs.run(Y, U)
    r = out[:, obs.publishes.index("r_y3")]
    # by hand: r = e2 + 2 f, e2' = -e2 - L1 r, so r' = -6 r + 2: r jumps by F2 = 2 and settles at 1/3
    for s in (2.1, 2.3, 3.5):
        k = np.searchsorted(t, s)
        assert r[k] == pytest.approx(1 / 3 + 5 / 3 * np.exp(-6.0 * (t[k] - 2.0)), abs=3e-3)


@pytest.mark.parametrize("restoring", [1.0, 0.0])
def test_fault_estimate_converges_or_keeps_the_zero_mode_bias(restoring):
    A, sys3 = plant(restoring)
    t, X, Y, U = data(A, fault_onset=1.0, duration=6.0)
    dec = split(sys3)
    est = FaultEstimator(Gamma=[[1.0]], M1=[[20.0]], M2=[[0.5]])
    obs = hybrid_observer(sys3, dec, [[20.0], [0.0]], [[2.0]], DT, estimator=est, name="estimator")
    _, out = obs.run(Y, U, s0=observer_state(dec, X[0], sys3.linearize().C, 1))
    final = out[-1, obs.publishes.index("f_1_hat")]
    # by hand: with a restoring term (x3' = ... - x3) the fault is observable and the estimate exact; without,
    # (e2, e_q) has a zero mode and a step settles at 1 - L2 / (L2 + 2 Gamma M1)
    expected = 1.0 if restoring else 1.0 - 2.0 / (2.0 + 2 * 20.0)
    assert final == pytest.approx(expected, abs=2e-3)
    model = linear_error_model(dec, [[20.0], [0.0]], [[2.0]], est)
    eigenvalues = np.linalg.eigvals(model.A)
    assert (np.abs(eigenvalues).min() < 1e-9) == (restoring == 0.0)


def test_sensor_fault_states_add_F_f_to_the_outputs_and_stay_constant():
    A, sys3 = plant()
    aug = with_sensor_fault_states(sys3, F, signals(("f_s", "m", "fault"), group="fault"))
    x = np.array([0.1, 0.2, 0.3, 0.7])
    assert np.allclose(np.asarray(aug.h(x, [0.0], [])).ravel(), [0.1, 0.3 + 1.4])
    assert float(np.asarray(aug.f(x, [0.0], [0.0], [])).ravel()[-1]) == 0.0


def test_bad_decouplings_and_gains_are_typed_errors():
    A, sys3 = plant()
    lin = sys3.linearize()
    with pytest.raises(ObserverError, match="unknown"):
        decouple(sys3, lin, z1=["x1", "x9"], w1=["y1"])
    with pytest.raises(ObserverError, match="faults F on outputs of subsystem 2"):
        decouple(sys3, lin, z1=["x1", "x2"], w1=["y1"], F=[[1.0], [0.0]])
    with pytest.raises(ObserverError, match="disturbance E must act on subsystem 1"):
        decouple(sys3, lin, z1=["x1", "x2"], w1=["y1"], E=[[0.0], [0.0], [1.0]])
    with pytest.raises(ObserverError, match="rank\\(C D\\) = 0 but rank\\(D\\) = 1"):
        decouple(sys3, lin, z1=["x1", "x2"], w1=["y1"], E=[[0.0], [1.0], [0.0]])
    with pytest.raises(ObserverError, match="^decoupling: outputs w1 read subsystem-2 states; the split must follow "
                                            "C's blocks$"):
        decouple(sys3, lin, z1=["x1", "x2"], w1=["y3"])
    dec = split(sys3)
    with pytest.raises(ObserverError, match="K1 must be a finite \\(2, 1\\)"):
        hybrid_observer(sys3, dec, [[1.0, 2.0]], [[1.0]], DT)
    with pytest.raises(ObserverError, match="singular"):
        hybrid_observer(sys3, dec, [[1.0], [0.0]], [[1.0]], DT,
                        estimator=FaultEstimator(Gamma=[[1.0]], M1=[[1.0]], M2=[[-0.5]]))


def test_estimator_with_two_measured_outputs_in_subsystem_2_integrates_each_residual():
    A = np.array([[-1.0, 0.0, 0.0], [1.0, -2.0, 0.0], [0.0, 1.0, -1.0]])
    sys3 = system("chain", "x1 -> x2 -> x3", x=signals(("x1", "m"), ("x2", "m"), ("x3", "m"), group="state"),
                  u=signals(("u", "m/s"), group="input"), d=signals(("d", "m/s"), group="disturbance"),
                  y=signals(("y1", "m"), ("y2", "m"), ("y3", "m"), group="output"),
                  rhs=lambda x, u, d, p: ca.mtimes(ca.DM(A), x) + ca.vertcat(d + u, 0, 0),
                  output=lambda x, u, p: x)
    F2 = np.array([[0.0], [1.0], [1.0]])  # one fault seen by both subsystem-2 sensors
    dec = decouple(sys3, sys3.linearize(), z1=["x1"], w1=["y1"], F=F2)
    est = FaultEstimator(Gamma=[[1.0]], M1=[[2.0, 2.0]], M2=[[0.0, 0.0]])
    obs = hybrid_observer(sys3, dec, [[5.0]], 3.0 * np.eye(2), DT, estimator=est, name="two")
    assert obs.state.names[-2:] == ("int_r_y2", "int_r_y3")
    t = np.arange(0.0, 15.0, DT)
    Y = np.outer(t >= 1.0, F2.ravel())  # the plant at rest; a unit fault from t = 1 s
    _, out = obs.run(Y, np.zeros((t.size, 1)), s0=np.zeros(obs.state.size))
    # by hand: x2, x3 have restoring terms, so the fault is observable and its estimate converges to 1
    # (the slowest error mode, about -0.54 1/s, leaves under 1e-3 after 14 s)
    assert out[-1, obs.publishes.index("f_1_hat")] == pytest.approx(1.0, abs=2e-3)
    model = linear_error_model(dec, [[5.0]], 3.0 * np.eye(2), est)
    assert np.linalg.eigvals(model.A).real.max() < 0


def test_fault_directions_of_the_wrong_size_are_typed_errors_naming_F():
    A, sys3 = plant()
    fault = signals(("f_s", "m", "fault"), group="fault")
    with pytest.raises(ObserverError, match=r"^three: F must be a finite \(2, 1\) matrix, got \(1, 3\)$"):
        with_sensor_fault_states(sys3, [1.0, 2.0, 3.0], fault)  # 3 entries fill no (2, q) matrix
    with pytest.raises(ObserverError, match=r"F must be a finite \(2, 1\) matrix, got \(2, 2\)"):
        with_sensor_fault_states(sys3, np.eye(2), fault)  # two fault columns for one named fault
    with pytest.raises(ObserverError, match=r"F \(2, q\); got \(3, 1\), \(1, 3\)$"):
        decouple(sys3, sys3.linearize(), z1=["x1", "x2"], w1=["y1"], F=[0.0, 2.0, 1.0])
    # a flat F of a whole number of rows is read row by row: (0, 2) is F = [[0], [2]]
    flat = decouple(sys3, sys3.linearize(), z1=["x1", "x2"], w1=["y1"], F=[0.0, 2.0])
    np.testing.assert_array_equal(flat.F2, [[2.0]])


def test_sensor_fault_states_keep_the_plant_parameters():
    scaled = system("scaled", "x' = -a x + u, y = x", x=signals(("x", "m"), group="state"),
                    u=signals(("u", "m/s"), group="input"), p=signals(("a", "1/s"), group="parameter"),
                    rhs=lambda x, u, d, p: -p[0] * x + u, p0=[2.5])
    aug = with_sensor_fault_states(scaled, [[1.0]], signals(("f_s", "m"), group="fault"))
    np.testing.assert_array_equal(aug.p0, [2.5])
    # at x = 1, f = 0.5, u = 0 with the default a = 2.5: x' = -2.5, f' = 0, y = 1.5
    np.testing.assert_array_equal(np.asarray(aug.f([1.0, 0.5], [0.0], [], aug.p0)).ravel(), [-2.5, 0.0])
    np.testing.assert_array_equal(np.asarray(aug.h([1.0, 0.5], [0.0], aug.p0)).ravel(), [1.5])


def test_observer_groups_and_the_error_model_gain_message():
    A, sys3 = plant()
    dec = split(sys3)
    obs = hybrid_observer(sys3, dec, [[20.0], [0.0]], [[5.0]], DT, name="groups")
    assert obs.state.group == "state" and obs.state.names == ("v_x1", "v_x2", "x3_hat")
    # the observer has no parameters: one value is one too many, and the message names the observer
    with pytest.raises(ObserverError, match=r"^groups: parameters must have 0 entries \(\), got 1$"):
        obs.parameters([1.0])
    with pytest.raises(ObserverError, match=r"^error model: K1 must be a finite \(2, 1\) matrix, got shape \(1, 2\)$"):
        linear_error_model(dec, [[1.0, 2.0]], [[1.0]])
    with pytest.raises(ObserverError, match=r"^error model: L must be a finite \(1, 1\) matrix, got shape \(2,\)$"):
        linear_error_model(dec, [[1.0], [2.0]], [1.0, 2.0])


def test_defaults_one_rk4_step_the_plant_name_and_the_observer_name_message():
    A, sys3 = plant()
    dec = split(sys3)
    assert dec.plant == "three"
    obs = hybrid_observer(sys3, dec, [[20.0], [0.0]], [[5.0]], 0.1)
    assert obs.name == "hybrid" and obs.description.endswith("sampled every 0.1 s (1 RK4 step(s))")
    # one classical RK4 step of the linear observer s' = M s + c (y, u held) is the 4th-order Taylor polynomial
    s0, y, u = np.array([0.3, -0.2, 0.5]), np.array([1.0, 2.0]), np.array([1.0])
    # by hand from the module docstring: H = (1, 1), Tu = [[0, 0], [-1, 1]], K1 = (20, 0), L = 5, x_hat = (v1 + y1,
    # v2 + y1, z2); v' = Tu (A11 zhat1 + B1 u) + K1 (y1 - zhat1_1), z2' = x_hat1 - z2 + 5 (y3 - z2)
    M = np.array([[-20.0, 0.0, 0.0], [2.0, -3.0, 0.0], [1.0, 0.0, -6.0]])
    c = np.array([0.0, 2 * y[0] - 3 * y[0] + u[0], y[0] + 5 * y[1]])
    h = 0.1
    # s(h) for s' = M s + c: s0 + sum_k h^k M^(k-1) (M s0 + c) / k! to 4th order (RK4 on a linear system)
    expected, term = s0.copy(), M @ s0 + c
    for k in range(1, 5):
        expected = expected + h ** k * term / np.prod(range(1, k + 1))
        term = M @ term
    s1, _ = obs.step(s0, y, u, obs.p0)
    np.testing.assert_allclose(np.asarray(s1).ravel(), expected, rtol=1e-13, atol=1e-13)
    with pytest.raises(ObserverError, match="^observer name 'bad-name' must start with a letter"):
        hybrid_observer(sys3, dec, [[20.0], [0.0]], [[5.0]], 0.1, name="bad-name")


# --- decoupling: edge cases (mutation survivors) ---------------------------------------------------------------------


def test_no_disturbance_columns_give_rank_zero_and_no_decoupling():
    A, sys3 = plant()
    dec = decouple(sys3, sys3.linearize(), z1=["x1", "x2"], w1=["y1"], E=np.zeros((3, 0)), F=F)
    # by hand: no disturbance to remove, so H = 0 (2, 1), Tu = I and rank E = 0; B = (0, 1, 0) has rank 1, C B = 0
    np.testing.assert_array_equal(dec.H, np.zeros((2, 1)))
    np.testing.assert_array_equal(dec.Tu, np.eye(2))
    assert dec.ranks == {"B": 1, "E": 0, "C[B E]": 0, "m + r": 1}


def test_an_undetectable_subsystem_1_is_kept_as_evidence_not_raised():
    # x1' = -x1 + d, x2' = x1 + x2 + u, x3' = -x3; y = (x1, x3); z1 = (x1, x2), w1 = y1, E1 = (1, 0)
    A = np.array([[-1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, -1.0]])
    sys3 = system("unstable", "x2 unseen", x=signals(("x1", "m"), ("x2", "m"), ("x3", "m"), group="state"),
                  u=signals(("u", "m/s"), group="input"), d=signals(("d", "m/s"), group="disturbance"),
                  y=signals(("y1", "m"), ("y3", "m"), group="output"),
                  rhs=lambda x, u, d, p: ca.mtimes(ca.DM(A), x) + ca.vertcat(d, u, 0),
                  output=lambda x, u, p: ca.vertcat(x[0], x[2]))
    dec = decouple(sys3, sys3.linearize(), z1=["x1", "x2"], w1=["y1"])
    # by hand: H = (1, 0), Tu = diag(0, 1), Tu A11 = [[0, 0], [1, 1]]; C1 = (1, 0) sees no x2 (C1 Tu A11 = 0),
    # so the mode +1 of x2 is unobservable and unstable
    np.testing.assert_allclose(dec.omega["Omega1"], [[0.0, 0.0], [1.0, 1.0]])
    assert len(dec.undetectable) == 1 and dec.undetectable[0] == pytest.approx(1.0)


def test_estimator_gain_errors_name_gamma_and_the_description_names_the_kind():
    A, sys3 = plant()
    dec = split(sys3)
    with pytest.raises(ObserverError, match=r"^est: Gamma must be a finite \(1, 1\) matrix, got shape \(2, 2\)$"):
        hybrid_observer(sys3, dec, [[1.0], [0.0]], [[1.0]], DT, name="est",
                        estimator=FaultEstimator(Gamma=np.eye(2), M1=[[1.0]], M2=[[0.0]]))
    est = hybrid_observer(sys3, dec, [[1.0], [0.0]], [[1.0]], 0.5,
                          estimator=FaultEstimator(Gamma=[[1.0]], M1=[[1.0]], M2=[[0.0]]))
    assert est.description == ("hybrid unknown-input observer of three, fault estimator (eq. 18), sampled every "
                               "0.5 s (1 RK4 step(s))")
    detect = hybrid_observer(sys3, dec, [[1.0], [0.0]], [[1.0]], 0.5)
    assert ", detection observer (eq. 6), " in detect.description
