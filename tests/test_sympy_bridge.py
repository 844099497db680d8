"""CasADi -> sympy: exact round trips at random points, and LaTeX with the papers' names."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
import sympy as sp

from uvsym import vehicle
from uvsym.errors import UvsymError
from uvsym.observers import actuator_observer
from uvsym.sympy_bridge import latex, to_sympy


def _round_trip_error(inputs: list, expression) -> float:
    converted = to_sympy(expression)
    symbols = [sp.Symbol(s.name(), real=True) for v in inputs for s in ca.vertsplit(v)]
    numeric = sp.lambdify(symbols, converted, "numpy")
    reference = ca.Function("reference", inputs, [expression])
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(40):
        values = [rng.normal(size=v.numel()) for v in inputs]
        ours = np.array(numeric(*np.concatenate(values)), dtype=float).ravel()
        theirs = np.asarray(ca.densify(reference(*values))).ravel(order="F")
        worst = max(worst, float(np.max(np.abs(ours - theirs)) / max(1.0, np.max(np.abs(theirs)))))
    return worst


@pytest.mark.parametrize("name", ["remus100", "docking_auv", "otter", "otter3dof"])
def test_hull_forces_round_trip_exactly(name):
    model = vehicle(name)
    eta, nu = ca.SX.sym("eta", model.dof), ca.SX.sym("nu", model.dof)
    assert _round_trip_error([eta, nu], model.h(eta, nu)) < 1e-14


def test_observer_equations_round_trip_and_keep_parameters_as_symbols():
    model = vehicle("otter3dof")
    observer = actuator_observer(model, "proportional")
    x, eta, nu, tau_d, K = (ca.SX.sym(n, 3) for n in ("x", "eta", "nu", "tau_d", "K"))
    x_dot = observer.function(x, eta, nu, tau_d, K)[0]
    assert _round_trip_error([x, eta, nu, tau_d, K], x_dot) < 1e-14
    L = to_sympy(observer.L(nu, tau_d, K))
    assert {s.name for s in L.free_symbols} == {"K_0", "K_1", "K_2", "tau_d_0", "tau_d_1", "tau_d_2"}
    # L = -K M^-1 T_d: diagonal, each entry a constant times k_i tau_d,i, the constant -1/m_i to the bit
    m = np.diag(model.M)
    for i in range(3):
        k, tau = sp.Symbol(f"K_{i}", real=True), sp.Symbol(f"tau_d_{i}", real=True)
        coefficient = sp.simplify(L[i, i] / (k * tau))
        assert coefficient.is_number and float(coefficient) == -1.0 / float(m[i])
        assert all(L[i, j] == 0 for j in range(3) if j != i)


def test_constants_keep_every_bit():
    value = 0.1 + 1e-17 * 3 + 1 / 3
    assert float(to_sympy(ca.SX(value))) == value


def test_latex_uses_the_papers_symbols():
    nu, tau_d, K = ca.SX.sym("nu", 3), ca.SX.sym("tau_d", 3), ca.SX.sym("K", 3)
    text = latex(actuator_observer(vehicle("otter3dof"), "proportional").L(nu, tau_d, K))
    # CasADi's elements are 0-based, the papers' (and the reports') 1-based
    assert r"\tau_{d,1}" in text and "k_{1}" in text and "k_{0}" not in text and text.startswith(r"\begin{bmatrix}")
    assert r"\nu_{3}" in latex(nu[2] ** 2)


def test_mx_is_refused_with_a_clear_error():
    with pytest.raises(UvsymError, match="SX"):
        to_sympy(ca.MX.sym("x"))


def test_latex_can_hide_rounding_residues_but_only_when_asked():
    k = ca.SX.sym("K", 2)
    expression = ca.vertcat(1e-17 * k[0] - 1.0000000000000002 * k[1], 0.5 * k[0])
    assert "10^{-17}" in latex(expression, 4)
    shown = latex(expression, 4, zero_below=1e-12)
    assert "10^{-17}" not in shown and "1.0" not in shown and "- k_{2}" in shown and "0.5 k_{1}" in shown
