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


def test_uvsym_verify_prints_json_writes_proofs_and_sets_the_exit_code(tmp_path, capsys, monkeypatch):
    assert main(["verify", "actuator-observers", "--json", "--out", str(tmp_path)]) == 0
    rows = json.loads(capsys.readouterr().out)
    for row in rows:
        assert {"claim", "status", "expected", "method", "set", "margin", "seconds", "counterexample"} <= set(row)
    assert json.loads((tmp_path / "actuator-observers" / "proofs.json").read_text())[0]["claim"] == rows[0]["claim"]
    from dataclasses import replace

    import derivations.actuator_observers as study

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
