"""Machine-checked claims: identities, LMI certificates re-checked exactly, negative controls refuted."""

from __future__ import annotations

import json
from fractions import Fraction

import casadi as ca
import numpy as np
import pytest

from derivations.actuator_observers.claims import core_paper_claims
from uvsym.cli import main
from uvsym.testing import assert_checked, assert_proved, assert_refuted
from uvsym.verify import Certificate, exact_positive_definite, lyapunov_decrease, prove_identity


@pytest.fixture(scope="module")
def claims():
    return core_paper_claims()


def test_every_core_paper_claim_comes_out_as_expected(claims):
    assert len(claims) >= 8
    check = {"proved": assert_proved, "checked": assert_checked, "refuted": assert_refuted}
    for certificate in claims:
        check[certificate.expected](certificate)
    assert {c.expected for c in claims} == {"proved", "checked", "refuted"}  # negative controls are among them
    for certificate in (c for c in claims if c.status == "checked"):  # sampling is labelled as evidence
        assert "sampled" in certificate.method and "not a proof" in certificate.method


def test_counterexamples_really_violate_their_claims(claims):
    for certificate in (c for c in claims if c.status == "refuted"):
        example = certificate.counterexample
        if "x" in example:  # a velocity of the fault-tolerant loop where V' > -gamma nu'nu
            assert _loop_V_dot(certificate.claim, list(example["x"].values())) > -example["gamma"] * sum(
                v * v for v in example["x"].values())
        elif "A" in example:  # an eigenpair of a vertex: A v = lambda v with Re(lambda) > -gamma
            A, v = np.array(example["A"]), np.array(example["eigenvector_real"])
            assert max(np.linalg.eigvals(A).real) > -example["gamma"]
            assert np.linalg.norm(v) > 0
        else:  # a point where the two sides of the identity differ
            from uvsym import vehicle
            from uvsym.observers import actuator_observer

            observer = actuator_observer(vehicle("otter3dof"), "proportional")
            point = example["point"]

            def vector(name, point=point):
                return np.array([point[f"{name}_{i}"] for i in range(3)])

            e, K, tau_d = vector("e"), vector("K"), vector("tau_d")
            derived = np.asarray(observer.error_dynamics(e, vector("f"), vector("eta"), vector("nu"), tau_d,
                                                         vector("tau_d_dot"), K)).ravel()
            claimed = np.asarray(observer.error_matrix(tau_d, K)).dot(e)
            assert np.max(np.abs(derived - claimed)) > 1e-6 * max(1.0, np.max(np.abs(derived)))


def test_convergence_claims_agree_with_the_closed_form_rates(claims):
    """Not judged by the labels the derivation sets: in the momentum form A = -K T_d^2 (proportional) or -K (bias)
    is diagonal, so V decreases at rate 2 gamma over the box exactly when every k_i tau_min^2 (or k_i) exceeds
    gamma; a proved claim's P must satisfy P > 0 and A^T P + P A + 2 gamma P < 0 at every corner (numpy)."""
    import itertools

    from derivations.actuator_observers.claims import GAINS

    cases = [("docking_auv", "proportional", GAINS, 0.5, 20.0, 0.5), ("remus100", "proportional", GAINS, 0.5, 20.0,
                                                                     0.5),
             ("remus100", "bias", GAINS, 1.0, 1.0, 1.0), ("remus100", "bias", np.r_[GAINS[:5], -1.0], 1.0, 1.0, 0.0)]
    convergence = [c for c in claims if "decreases at rate" in c.claim]
    assert len(convergence) == len(cases)
    for certificate, (vehicle_name, kind, K, tau_min, tau_max, gamma) in zip(convergence, cases):
        assert vehicle_name in certificate.claim and f"rate {2 * gamma:g}" in certificate.claim
        rates = K * tau_min**2 if kind == "proportional" else K
        assert certificate.status == ("proved" if np.all(rates > gamma) else "refuted"), certificate.claim
        if certificate.status == "proved" and "P" in certificate.details:
            P = np.array(certificate.details["P"])
            assert np.linalg.eigvalsh(P).min() > 0
            for tau in itertools.product(*[(tau_min, tau_max)] * len(K)):
                A = -np.diag(K * np.array(tau) ** 2 if kind == "proportional" else K)
                assert np.linalg.eigvalsh(A.T @ P + P @ A + 2 * gamma * P).max() < 0


def _loop_V_dot(claim: str, nu) -> float:
    """V' = 2 nu' M nu_dot of the section 3.2 loop, rebuilt here from the model and the faults' definitions."""
    from uvsym import vehicle

    model = vehicle("otter3dof")
    nu = np.asarray(nu, dtype=float)
    B = np.asarray(model.B(np.zeros(3), np.zeros(3), np.zeros(2), 0.0, 0.0))
    u_d = -50.0 * B.T @ nu
    if "paper's estimates" in claim:
        u_d = np.array([u_d[0] - 13.0043, u_d[1] / 0.8001])
    else:
        assert "no correction" in claim
    u = np.array([u_d[0] + 13.0, 0.8 * u_d[1]])  # thruster T_L bias 13 N, T_R factor 0.8
    nu_dot = np.asarray(model.nu_dot(np.zeros(3), nu, u, 0.0, 0.0)).ravel()
    return float(2.0 * nu @ model.M @ nu_dot)


def test_fault_tolerant_loop_is_proved_only_with_exact_correction(claims):
    loop = {c.claim.split(": ")[0]: c for c in claims if c.claim.startswith("Section 3.2")}
    statuses = {name.split(", ", 1)[1].rstrip(")"): c.status for name, c in loop.items()}
    assert statuses == {"healthy": "proved", "faults corrected with exact estimates": "proved",
                        "faults, no correction": "refuted", "faults corrected with the paper's estimates": "refuted"}
    for certificate in loop.values():
        if certificate.status == "proved":
            assert certificate.margin > 0 and certificate.details["boxes"] > 1


def test_exact_positive_definiteness():
    assert exact_positive_definite([[Fraction(2), Fraction(1)], [Fraction(1), Fraction(2)]]) == (True, Fraction(3, 2))
    ok, pivot = exact_positive_definite([[Fraction(1), Fraction(2)], [Fraction(2), Fraction(1)]])
    assert not ok and pivot == -3


def test_lyapunov_certificate_holds_for_its_P():
    A = np.array([[-1.0, 5.0], [0.0, -2.0]])  # stable but far from normal
    certificate = lyapunov_decrease("V decreases", [A], gamma=0.5, set_description="one matrix")
    assert_proved(certificate)
    P = np.array(certificate.details["P"])
    assert np.all(np.linalg.eigvalsh(P) > 0)
    assert np.all(np.linalg.eigvalsh(A.T @ P + P @ A + 2 * 0.5 * P) <= 1e-9)
    assert_refuted(lyapunov_decrease("too fast", [A], gamma=1.5, set_description="one matrix"))


def test_identity_prover_proves_and_refutes():
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    assert_proved(prove_identity("sin^2 + cos^2 = 1", ca.sin(x) ** 2 + ca.cos(x) ** 2, ca.SX(1), [x], "all x"))
    # sympy.simplify knows this one; the exact rational step alone does not
    assert_proved(prove_identity("cosh^2 - sinh^2 = 1", ca.cosh(x) ** 2 - ca.sinh(x) ** 2, ca.SX(1), [x], "all x"))
    refuted = prove_identity("x y = x", x * y, x, [x, y], "all x, y", expected="refuted")
    assert_refuted(refuted)
    point = refuted.counterexample["point"]
    assert point["x"] * point["y"] != pytest.approx(point["x"])


def test_assertions_explain_what_failed():
    refuted = Certificate("claim", "set", "method", "refuted", counterexample={"x": 1.0})
    with pytest.raises(AssertionError, match="not proved: claim over set by method: refuted"):
        assert_proved(refuted)
    with pytest.raises(AssertionError, match="not refuted"):
        assert_refuted(Certificate("claim", "set", "method", "refuted"))
    with pytest.raises(ValueError, match="status"):
        Certificate("claim", "set", "method", "maybe")


def test_uvsym_verify_prints_json_writes_proofs_and_sets_the_exit_code(claims, tmp_path, capsys, monkeypatch):
    from dataclasses import replace

    import derivations.actuator_observers as study

    # the study's claims are core_paper_claims(): the module's, already decided, stand in for a second run of them
    monkeypatch.setattr(study, "DERIVATION", replace(study.DERIVATION, claims=lambda: claims))
    assert main(["verify", "actuator-observers", "--json", "--out", str(tmp_path)]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [row["claim"] for row in rows] == [c.claim for c in claims]
    for row in rows:
        assert {"claim", "status", "expected", "method", "set", "margin", "seconds", "counterexample"} <= set(row)
    assert json.loads((tmp_path / "actuator-observers" / "proofs.json").read_text())[0]["claim"] == rows[0]["claim"]
    wrong = replace(study.DERIVATION, claims=lambda: [Certificate("wrong", "set", "method", "refuted")])
    monkeypatch.setattr(study, "DERIVATION", wrong)
    assert main(["verify", "actuator-observers", "--out", str(tmp_path)]) == 1


def test_gain_synthesis_places_the_decay_and_is_certified():
    from uvsym.errors import UvsymError
    from uvsym.verify.synthesis import synthesize_observer_gain

    A = np.array([[0.0, 1.0], [-2.0, -0.1]])  # lightly damped oscillator, position measured
    C = np.array([[1.0, 0.0]])
    design = synthesize_observer_gain(A, C, decay=1.0)
    assert_proved(design.certificate)
    assert max(np.linalg.eigvals(A - design.L @ C).real) <= -1.0 + 1e-9
    with pytest.raises(UvsymError, match="no observer gain"):
        synthesize_observer_gain(A, np.zeros((1, 2)), decay=1.0)  # nothing measured: nothing to place


def test_interval_enclosure_holds_at_sampled_points():
    from uvsym.verify.interval import IntervalFunction

    x = ca.SX.sym("x", 3)
    expression = ca.vertcat(x[0] * x[1] - ca.sin(x[2]) * ca.fabs(x[0]), ca.fmax(x[0], 0.3) / (2 + x[1] ** 2),
                            ca.exp(x[2]) * ca.cos(x[0] * x[1]), ca.tanh(x[0]) ** 3,
                            ca.if_else(x[0] < x[1], x[2], -x[0]), ca.sqrt(1 + x[1] ** 2), 1 / (x[0] - 10))
    function = ca.Function("f", [x], [expression])
    rng = np.random.default_rng(3)
    centre, half = rng.normal(size=(500, 3)) * 3, rng.uniform(0, 2, size=(500, 3))
    bounds = IntervalFunction(function)(centre - half, centre + half)
    points = centre + half * rng.uniform(-1, 1, size=(500, 3))
    values = np.asarray(function.map(500)(points.T)).T
    assert np.all(values >= bounds.lo) and np.all(values <= bounds.hi)
    # where |x_0| has its kink inside a box the box is not smooth
    straddles = (centre[:, 0] - half[:, 0] < 0) & (centre[:, 0] + half[:, 0] > 0)
    assert not np.any(bounds.smooth[straddles])
    # a point box of an exact expression encloses the exact value within a few ulps
    exact = IntervalFunction(ca.Function("g", [x], [x[0] * x[1] + x[2]]))([[0.1, 0.2, 0.3]], [[0.1, 0.2, 0.3]])
    assert exact.lo[0, 0] < 0.1 * 0.2 + 0.3 < exact.hi[0, 0] and exact.hi[0, 0] - exact.lo[0, 0] < 1e-15
    # exact float results are not widened: an equilibrium evaluates to exactly 0
    balanced = IntervalFunction(ca.Function("h", [x], [(x[0] - 13.0) + 13.0 + 0.5 * x[1] * x[2]]))
    balanced = balanced([[0.0] * 3], [[0.0] * 3])
    assert balanced.lo[0, 0] == 0.0 == balanced.hi[0, 0]


def test_interval_evaluation_names_what_it_cannot_do():
    from uvsym.errors import VerificationError
    from uvsym.verify.interval import IntervalFunction

    x = ca.SX.sym("x", 2)
    with pytest.raises(VerificationError, match="atan2"):
        IntervalFunction(ca.Function("f", [x], [ca.atan2(x[0], x[1])]))
    with pytest.raises(VerificationError, match="lower bound above"):
        IntervalFunction(ca.Function("f", [x], [x[0]]))([[1.0, 0.0]], [[0.0, 1.0]])


def test_region_decrease_proves_refutes_and_gives_up_honestly():
    from uvsym.verify.region import region_decrease

    x = ca.SX.sym("x", 2)
    V = ca.dot(x, x)
    stable = ca.vertcat(-x[0] + 0.1 * x[1] ** 2, -x[1] - 0.2 * x[0] * x[1])
    proved = region_decrease("toy", V, stable, x, 0.5, [-2, -2], [2, 2], 0.1)
    assert_proved(proved)
    # V' = -2|x|^2 + 0.2 x0 x1^2 - 0.4 x0 x1^2 >= -2|x|^2 - 0.2 |x0| x1^2: the bound has room
    grid = np.linspace(-2, 2, 41)
    worst = max(-2 * (a * a + b * b) - 0.2 * a * b * b + 0.5 * (a * a + b * b) for a in grid for b in grid)
    assert worst <= 0 and proved.margin > 0
    # a quadratic term that wins far from the equilibrium
    unstable = ca.vertcat(-x[0] + x[1] ** 2, -x[1] - 0.2 * x[0] * x[1])
    refuted = region_decrease("toy, big term", V, unstable, x, 0.5, [-2, -2], [2, 2], 0.1, expected="refuted")
    assert_refuted(refuted)
    a, b = refuted.counterexample["x"].values()
    assert 2 * a * (-a + b * b) + 2 * b * (-b - 0.2 * a * b) > -0.5 * (a * a + b * b)
    # a constant push: V' > 0 right next to the equilibrium
    pushed = region_decrease("toy, pushed", V, stable + ca.vertcat(0.1, 0), x, 0.5, [-2, -2], [2, 2], 0.1)
    assert pushed.status == "refuted" and pushed.counterexample["V_dot"] > pushed.counterexample["bound"]
    # a push too small for a rigorous counterexample near 0: not proved
    tiny = region_decrease("toy, tiny push", V, stable + ca.vertcat(1e-300, 0), x, 0.5, [-2, -2], [2, 2], 0.1)
    assert tiny.status in ("refuted", "inconclusive")
    tight = region_decrease("toy, too few boxes", V, stable, x, 0.99, [-2, -2], [2, 2], 0.1, max_boxes=10)
    assert tight.status == "inconclusive" and "boxes" in tight.reason


def test_region_decrease_rejects_a_box_without_the_equilibrium():
    from uvsym.errors import VerificationError
    from uvsym.verify.region import region_decrease

    x = ca.SX.sym("x", 2)
    with pytest.raises(VerificationError, match="equilibrium"):
        region_decrease("toy", ca.dot(x, x), -x, x, 0.5, [0.5, -1], [1, 1], 0.1)


def test_counterexample_summaries_say_what_fails(claims):
    refuted = [c for c in claims if c.status == "refuted"]
    assert refuted and all(c.counterexample_summary() for c in refuted)
    assert all(c.counterexample_summary() == "" for c in claims if c.status == "proved")
    region = next(c for c in refuted if "V_dot" in c.counterexample)
    assert f"V' = {region.counterexample['V_dot']:.3g} >" in region.counterexample_summary()


def test_counterexample_summaries_word_for_word():
    def summary(example):
        return Certificate("c", "s", "m", "refuted", counterexample=example).counterexample_summary()

    assert summary({"eigenvalue_modulus": 1.23456, "rho": 1.0}) == \
        "the sampled map has an eigenvalue of modulus 1.23 >= 1"
    assert summary({"eigenvalue_real": 0.5, "gamma": 0.25}) == \
        "a vertex's eigenvalue has real part 0.5 > -gamma = -0.25"
    assert summary({"V_dot": 0.13066, "bound": -0.30861, "x": {"u (m/s)": 0.0791139, "r (rad/s)": -2.0}}) == \
        "at u (m/s) = 0.0791, r (rad/s) = -2: V' = 0.131 > -0.309"
    assert summary({"relative_difference": 0.99999}) == \
        "the two sides differ by 1 (relative to the size of their terms) at a sampled point"
    assert Certificate("c", "s", "m", "refuted", counterexample={"point": {"x": 1.0}}).counterexample_summary() == ""
    assert Certificate("c", "s", "m", "proved").counterexample_summary() == ""


def test_certificate_to_dict_names_every_field_and_drops_infinite_margins():
    example = {"x": {"a": 1.0}}
    certificate = Certificate("claim", "set", "method", "refuted", "proved", -2.5, 0.25, example, "why", {"boxes": 3})
    assert certificate.to_dict() == {"claim": "claim", "set": "set", "method": "method", "status": "refuted",
                                     "expected": "proved", "margin": -2.5, "seconds": 0.25, "counterexample": example,
                                     "reason": "why", "details": {"boxes": 3}}
    for margin in (float("inf"), float("-inf"), float("nan"), None):
        assert Certificate("c", "s", "m", "proved", margin=margin).to_dict()["margin"] is None
    assert json.loads(json.dumps(Certificate("c", "s", "m", "proved", margin=float("inf")).to_dict()))["margin"] is None


def _still_water_loop_nu_dot(model, gain: float, nu, delivered) -> np.ndarray:
    """nu' of ``u_d = -gain B0' nu`` at eta = 0 in still water (B0 = dtau/du at rest), ``delivered(u_d)`` the
    actuators' output, from the model's own nu_dot: the loop rebuilt by hand."""
    zero = np.zeros(model.dof)
    B0 = np.asarray(model.B(zero, zero, np.zeros(model.n_inputs), 0.0, 0.0))
    u = delivered(-gain * B0.T @ np.asarray(nu, dtype=float))
    return np.asarray(model.nu_dot(zero, nu, u, 0.0, 0.0)).ravel()


def test_damping_injection_loop_matches_the_loop_built_by_hand():
    from uvsym import vehicle
    from uvsym.faults import ActuatorFault
    from uvsym.verify.fault_tolerant import damping_injection_loop

    model = vehicle("otter3dof")
    faults = (ActuatorFault(0, "bias", 13.0), ActuatorFault(1, "proportional", 0.8))
    nu = np.array([0.2, -0.1, 0.05])
    cases = {  # u* = S u_d + o undoes the estimated faults; the thrusters then add 13 N to T_L, scale T_R by 0.8
        None: lambda u_d: np.array([u_d[0] + 13.0, 0.8 * u_d[1]]),
        (13.0, 0.8): lambda u_d: u_d,
        (13.5, 0.5): lambda u_d: np.array([u_d[0] - 13.5 + 13.0, 0.8 * u_d[1] / 0.5])}
    for estimates, delivered in cases.items():
        loop = damping_injection_loop(model, 50.0, faults, estimates, fault_time=1.0)
        nu_dot = np.asarray(ca.Function("loop", [loop.nu], [loop.nu_dot])(nu)).ravel()
        assert nu_dot == pytest.approx(_still_water_loop_nu_dot(model, 50.0, nu, delivered), rel=1e-12, abs=1e-12)
    healthy = damping_injection_loop(model, 50.0)
    assert str(healthy.nu) == "[nu_0, nu_1, nu_2]" and healthy.control == "u_d = -50 B' nu"
    nu_dot = np.asarray(ca.Function("loop", [healthy.nu], [healthy.nu_dot])(nu)).ravel()
    assert nu_dot == pytest.approx(_still_water_loop_nu_dot(model, 50.0, nu, lambda u_d: u_d), rel=1e-12)
    # gamma: smallest eigenvalue of the symmetric part of D = dh/dnu at rest, here by central differences
    step, zero = 1e-6, np.zeros(3)
    D = np.column_stack([(np.asarray(model.h(zero, step * e)) - np.asarray(model.h(zero, -step * e))).ravel()
                         for e in np.eye(3)]) / (2 * step)
    assert healthy.gamma == pytest.approx(np.linalg.eigvalsh(0.5 * (D + D.T)).min(), rel=1e-5)
    # at rest in still water the REMUS 100's fins give no lift and its thrust (n|n|) has no slope at n = 0: u_d = 0,
    # the loop is the vehicle left alone (a current would give the fins lift, and u_d with it)
    remus = vehicle("remus100")
    loop = damping_injection_loop(remus, 50.0)
    point = np.array([0.5, 0.1, -0.1, 0.05, 0.02, 0.1])
    nu_dot = np.asarray(ca.Function("loop", [loop.nu], [loop.nu_dot])(point)).ravel()
    alone = np.asarray(remus.nu_dot(np.zeros(6), point, np.zeros(3), 0.0, 0.0)).ravel()
    assert nu_dot == pytest.approx(alone, rel=1e-12, abs=1e-12)


def test_kinetic_energy_decrease_states_its_claim_and_box_and_is_refuted_without_correction():
    from uvsym import vehicle
    from uvsym.faults import ActuatorFault
    from uvsym.verify.fault_tolerant import damping_injection_loop, kinetic_energy_decrease

    model = vehicle("otter3dof")
    faults = (ActuatorFault(0, "bias", 13.0), ActuatorFault(1, "proportional", 0.8))
    loop = damping_injection_loop(model, 50.0, faults, fault_time=1.0)
    certificate = kinetic_energy_decrease("Otter, uncorrected", loop, [3.0, 1.0, 1.0], 0.05)
    assert certificate.expected == "proved" and certificate.status == "refuted"  # the default expectation, not met
    # gamma = 42.65 1/s: the smallest eigenvalue of D's symmetric part (checked by differences above)
    assert certificate.claim == "Otter, uncorrected: V = nu'M nu, V' <= -42.65 nu'nu with u_d = -50 B' nu"
    assert certificate.set == "|u (m/s)| <= 3, |v (m/s)| <= 1, |r (rad/s)| <= 1"
    example = certificate.counterexample
    assert list(example["x"]) == ["u (m/s)", "v (m/s)", "r (rad/s)"]
    nu = np.array(list(example["x"].values()))
    nu_dot = _still_water_loop_nu_dot(model, 50.0, nu, lambda u_d: np.array([u_d[0] + 13.0, 0.8 * u_d[1]]))
    assert 2.0 * nu @ model.M @ nu_dot > -loop.gamma * nu @ nu  # V' = 2 nu'M nu' re-checked in plain floats
    # the box is a box of numbers whatever their type: exact fractions, or unsigned integers (which numpy would
    # negate modulo 256, -1 -> 255, putting the box's lower corner above 0)
    for box in ([Fraction(3), Fraction(1), Fraction(1)], np.array([3, 1, 1], dtype=np.uint8)):
        same = kinetic_energy_decrease("Otter, uncorrected", loop, box, 0.05, expected="refuted")
        assert (same.status, same.expected, same.set) == (
            "refuted", "refuted", "|u (m/s)| <= 3, |v (m/s)| <= 1, |r (rad/s)| <= 1")


def test_damping_injection_loop_faults_start_at_zero_by_default_and_a_stuck_thruster_hands_over_its_share():
    from uvsym import vehicle
    from uvsym.faults import ActuatorFault, Profile
    from uvsym.verify.fault_tolerant import damping_injection_loop

    model = vehicle("otter3dof")
    nu = np.array([0.2, -0.1, 0.05])

    def nu_dot(loop):
        return np.asarray(ca.Function("loop", [loop.nu], [loop.nu_dot])(nu)).ravel()

    later = (ActuatorFault(0, "bias", 13.0, Profile(onset=0.5)),)  # not yet active at the default t = 0 s
    healthy = _still_water_loop_nu_dot(model, 50.0, nu, lambda u_d: u_d)
    assert nu_dot(damping_injection_loop(model, 50.0, later)) == pytest.approx(healthy, rel=1e-12, abs=1e-12)
    # T_R stuck at 20 N, estimated exactly: T_L takes over t (u_d,R - 20) with t the least-squares fit of
    # B0[:, T_R] by B0[:, T_L] (what T_R no longer adds beyond its 20 N)
    zero = np.zeros(3)
    B0 = np.asarray(model.B(zero, zero, np.zeros(2), 0.0, 0.0))
    t = np.linalg.lstsq(B0[:, :1], B0[:, 1], rcond=None)[0][0]
    stuck = damping_injection_loop(model, 50.0, (ActuatorFault(1, "constant", 20.0),), (20.0,))
    expected = _still_water_loop_nu_dot(model, 50.0, nu, lambda u_d: np.array([u_d[0] + t * (u_d[1] - 20.0), 20.0]))
    assert nu_dot(stuck) == pytest.approx(expected, rel=1e-12, abs=1e-12)


def _toy_observer(kind: str):
    """A duck-typed actuator observer on 2 channels: A = -diag(K tau_d^2) (proportional) or -diag(K), and derived
    error dynamics ``A e + tau_d'``: the closed form holds exactly while tau_d is constant, never while it varies."""
    from types import SimpleNamespace

    e, f, eta, nu, tau_d, tau_d_dot, K = (ca.SX.sym(v, 2) for v in ("e", "f", "eta", "nu", "tau_d", "tau_d_dot", "K"))
    A = -ca.diag(K * tau_d**2) if kind == "proportional" else -ca.diag(K)
    return SimpleNamespace(kind=kind, form="toy", model_name="two channels",
                           error_matrix=ca.Function("A", [tau_d, K], [A]),
                           error_dynamics=ca.Function("e_dot", [e, f, eta, nu, tau_d, tau_d_dot, K],
                                                      [ca.mtimes(A, e) + tau_d_dot]))


def test_error_dynamics_claims_name_their_form_set_and_symbols():
    from uvsym import vehicle
    from uvsym.observers import actuator_observer
    from uvsym.verify.observers import error_dynamics_claim

    proved = error_dynamics_claim("Theorem 1", actuator_observer(vehicle("otter3dof"), "proportional", "momentum"))
    assert_proved(proved)
    assert proved.claim == "Theorem 1 (momentum form, otter3dof): e' = L M^-1 T_d e"
    assert proved.set == "all e, f, eta, nu, K, tau_d constant"
    toy = error_dynamics_claim("Toy", _toy_observer("bias"))
    assert_proved(toy)  # the tau_d' term is gone only because tau_d is held constant
    assert toy.claim == "Toy (toy form, two channels): e' = L M^-1 e"
    varying = error_dynamics_claim("Toy", _toy_observer("bias"), constant_tau_d=False, expected="refuted")
    assert_refuted(varying)
    assert varying.claim == "Toy (toy form, two channels): e' = L M^-1 e also while tau_d varies"
    assert varying.set == "all e, f, eta, nu, K, tau_d varying (tau_d' free)"
    point = varying.counterexample["point"]
    assert sorted(point) == sorted(f"{name}_{i}" for name in ("e", "f", "eta", "nu", "tau_d", "tau_d_dot", "K")
                                   for i in range(2))
    assert max(abs(point["tau_d_dot_0"]), abs(point["tau_d_dot_1"])) > 0  # e' - A e = tau_d' differs from 0 there


def test_convergence_claims_take_the_corners_of_the_desired_actions():
    from uvsym.verify.observers import convergence_claim

    # A = -diag(K tau_d^2): the slowest rate over 0.5 <= |tau_d,i| <= 2 is 3 * 0.5^2 = 0.75, so gamma 0.5 holds
    # and gamma 1 does not (although it would at tau_d = 1)
    proved = convergence_claim("Toy", _toy_observer("proportional"), [3.0, 3.0], 0.5, 2.0, 0.5)
    assert_proved(proved)
    assert proved.claim == "Toy (toy form, two channels): V = e'Pe decreases at rate 1"
    assert proved.set == "0.5 <= |tau_d,i| <= 2 (N, N m), K = [3.0, 3.0]"
    # tau_d,1 and tau_d,2 each at 0.5 or 2: 2 x 2 corners
    assert proved.method == "LMI (cvxpy, Clarabel) at 4 vertices, re-checked by exact rational LDL^T"
    refuted = convergence_claim("Toy", _toy_observer("proportional"), [3.0, 3.0], 0.5, 2.0, 1.0, expected="refuted")
    assert_refuted(refuted)
    assert refuted.counterexample["eigenvalue_real"] == pytest.approx(-0.75) and refuted.counterexample["gamma"] == 1.0
    # the bias observer's A does not depend on tau_d: its set names the gains only
    bias = convergence_claim("Toy", _toy_observer("bias"), [3.0, 1.0 / 3.0], 5.0, 9.0, 0.25)
    assert_proved(bias)
    assert bias.set == "K = [3.0, 0.333333]"
    # A = -diag(K) is one matrix whatever tau_d: one vertex, not the corners of a tau_d box that plays no part
    assert bias.method == "LMI (cvxpy, Clarabel) at 1 vertex, re-checked by exact rational LDL^T"
    P, A = np.array(bias.details["P"]), -np.diag([3.0, 1.0 / 3.0])
    assert np.linalg.eigvalsh(P).min() > 0 and np.linalg.eigvalsh(A.T @ P + P @ A + 0.5 * P).max() < 0
    assert_refuted(convergence_claim("Toy", _toy_observer("bias"), [3.0, 1.0 / 3.0], 5.0, 9.0, 0.5, expected="refuted"))


# --- convergence claims: integer and rational gains (mutation survivors) ---------------------------------------------


def test_convergence_claims_take_integer_and_rational_gains_as_reals():
    """K = (3, 1/3) given as an int and a Fraction: the same claim and set as for the doubles (3.0, 0.333333)."""
    from uvsym.verify.observers import convergence_claim

    bias = convergence_claim("Toy", _toy_observer("bias"), [3, Fraction(1, 3)], 5.0, 9.0, 0.25)
    assert_proved(bias)
    assert bias.set == "K = [3.0, 0.333333]"


# --- convergence claims: the expected status (mutation survivors) ----------------------------------------------


def test_convergence_claims_keep_the_expected_status_they_are_given():
    """A negative control (gamma 1 > the slowest rate 3 * 0.5^2 = 0.75) comes out refuted AS EXPECTED; the same
    claim expected proved is an unexpected refutation."""
    from uvsym.verify.observers import convergence_claim

    control = convergence_claim("Toy", _toy_observer("proportional"), [3.0, 3.0], 0.5, 2.0, 1.0, expected="refuted")
    assert (control.status, control.expected, control.as_expected) == ("refuted", "refuted", True)
    claim = convergence_claim("Toy", _toy_observer("proportional"), [3.0, 3.0], 0.5, 2.0, 1.0)
    assert (claim.status, claim.expected, claim.as_expected) == ("refuted", "proved", False)
    assert claim.counterexample["eigenvalue_real"] == pytest.approx(-0.75)  # the slowest rate, 3 * 0.5^2, < gamma


def test_error_dynamics_claims_keep_the_expected_status_and_the_stated_symbols():
    from types import SimpleNamespace

    from uvsym.verify.observers import error_dynamics_claim

    varying = error_dynamics_claim("Toy", _toy_observer("bias"), constant_tau_d=False, expected="refuted")
    assert (varying.status, varying.expected, varying.as_expected) == ("refuted", "refuted", True)
    # derived e' = -2 K e against the claimed -K e: false for tau_d constant too, and the counterexample names only
    # the symbols of the constant-tau_d set (no tau_d'); the size n = 2 comes from tau_d, K being a 1 x 2 row
    e, f, eta, nu, tau_d, tau_d_dot = (ca.SX.sym(v, 2) for v in ("e", "f", "eta", "nu", "tau_d", "tau_d_dot"))
    K = ca.SX.sym("K", 1, 2)
    wrong = SimpleNamespace(kind="bias", form="toy", model_name="two channels",
                            error_matrix=ca.Function("A", [tau_d, K], [-ca.diag(K)]),
                            error_dynamics=ca.Function("e_dot", [e, f, eta, nu, tau_d, tau_d_dot, K],
                                                       [-2 * ca.mtimes(ca.diag(K), e)]))
    refuted = error_dynamics_claim("Toy", wrong, expected="refuted")
    assert (refuted.status, refuted.expected) == ("refuted", "refuted")
    point = refuted.counterexample["point"]
    assert sorted(point) == sorted(f"{name}_{i}" for name in ("e", "f", "eta", "nu", "tau_d", "K") for i in range(2))
    # the difference of the two sides, -K e, is nonzero at the counterexample
    assert max(abs(point["K_0"] * point["e_0"]), abs(point["K_1"] * point["e_1"])) > 0


@pytest.mark.parametrize("kind", ["bias", "constant", "proportional"])
def test_the_any_plant_derivation_is_the_vehicles_own_with_its_matrices_put_in(kind):
    """The free-symbol derivation behind the any-plant proofs, evaluated at the docking AUV's M^-1 and h,
    gives the vehicle's own error dynamics at random points (so the proof is about the same observer)."""
    from uvsym import vehicle
    from uvsym.observers.actuator import actuator_observer, any_plant_error_dynamics

    model = vehicle("docking_auv")
    own = actuator_observer(model, kind, "paper", require_assumption_1=False)
    d = any_plant_error_dynamics(kind, "paper", 6)
    put_in = ca.substitute([d["e_dot"], d["A"]], [d["M_inv"], d["h"]],
                           [ca.DM(np.linalg.inv(model.M)), model.h(d["eta"], d["nu"])])
    names = ("e", "f", "eta", "nu", "tau_d", "tau_d_dot", "K")
    generic = ca.Function("generic", [d[v] for v in names], put_in)
    rng = np.random.default_rng(3)
    for _ in range(5):
        point = [rng.normal(size=6) for _ in names]
        e_dot, A = generic(*point)
        assert np.allclose(np.asarray(e_dot).ravel(), np.asarray(own.error_dynamics(*point)).ravel(), rtol=1e-9,
                           atol=1e-9)
        assert np.allclose(np.asarray(A), np.asarray(own.error_matrix(point[4], point[6])), rtol=1e-12, atol=1e-12)


def test_the_any_plant_claim_refutes_a_wrong_closed_form_and_the_graph_claims_say_why_they_are_not_proved(claims):
    from uvsym.observers.actuator import any_plant_error_dynamics

    d = any_plant_error_dynamics("bias", "paper", 2)
    inputs = [d[v] for v in ("e", "f", "eta", "nu", "tau_d", "K", "h")] + [ca.vec(d["M_inv"])]
    wrong = prove_identity("missing M^-1", ca.substitute(d["e_dot"], d["tau_d_dot"], ca.DM.zeros(2)),
                           ca.mtimes(ca.jacobian(d["R"], d["nu"]), d["e"]), [ca.vertcat(*inputs)], "all", "refuted")
    assert wrong.status == "refuted"
    graph = [c for c in claims if "docking_auv" in c.claim and c.expected == "checked"]
    assert len(graph) == 2 and all("no exact proof of this graph exists" in c.method for c in graph)
    any_plant = [c for c in claims if "any plant of 6 DOF" in c.claim]
    assert [c.status for c in any_plant] == ["proved"] * 3
