"""Machine-checked claims: identities, LMI certificates re-checked exactly, negative controls refuted."""

from __future__ import annotations

import json
from fractions import Fraction

import casadi as ca
import numpy as np
import pytest

from uvsym.cli import main
from uvsym.testing import assert_proved, assert_refuted
from uvsym.verify import Certificate, exact_positive_definite, lyapunov_decrease, prove_identity
from uvsym.verify.observers import core_paper_claims


@pytest.fixture(scope="module")
def claims():
    return core_paper_claims()


def test_every_core_paper_claim_comes_out_as_expected(claims):
    assert len(claims) >= 8
    for certificate in claims:
        (assert_proved if certificate.expected == "proved" else assert_refuted)(certificate)
    assert {c.expected for c in claims} == {"proved", "refuted"}  # negative controls are among them


def test_counterexamples_really_violate_their_claims(claims):
    for certificate in (c for c in claims if c.status == "refuted"):
        example = certificate.counterexample
        if "A" in example:  # an eigenpair of a vertex: A v = lambda v with Re(lambda) > -gamma
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
    import derivations.actuator_observers as study

    monkeypatch.setattr(study, "claims", lambda: [Certificate("wrong", "set", "method", "refuted")])
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
