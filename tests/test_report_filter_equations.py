"""Kalman filters' equations in their structured form, and the size guard of every equation."""

import dataclasses
import re

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import UvsymError
from uvsym.observers.ekf import ekf
from uvsym.observers.ukf import ukf
from uvsym.report.equations import equations_markdown, filter_equations, observer_equations, operations
from uvsym.report.html import markdown_to_html
from uvsym.systems import signals, system

P0 = [1.0, 0.5, 0.01, 0.01, 0.1]  # R (ohm), L (H), k (N m/A), J (kg m^2), b (N m s)


def dc_motor(friction: float = 0.0):
    """Armature current i and speed omega driven by the voltage v; the speed is measured; an optional
    Coulomb-like friction ``friction tanh(omega)`` makes the model nonlinear."""
    return system("dc_motor", "DC motor", x=signals(("i", "A"), ("omega", "rad/s")), u=signals(("v", "V")),
                  p=signals(("R", "ohm"), ("L", "H"), ("k", "N m/A"), ("J", "kg m^2"), ("b", "N m s")), p0=P0,
                  y=signals(("omega_meas", "rad/s")), output=lambda x, u, p: x[1],
                  rhs=lambda x, u, d, p: ca.vertcat((u[0] - p[0] * x[0] - p[2] * x[1]) / p[1],
                                                    (p[2] * x[0] - p[4] * x[1] - friction * ca.tanh(x[1])) / p[3]))


def _matrix(line: str) -> np.ndarray:
    """The numbers of the (only) bmatrix of a LaTeX line; sympy's ``a \\cdot 10^{b}`` read back as floats."""
    body = re.search(r"\\begin\{bmatrix\}(.*)\\end\{bmatrix\}", line).group(1)
    def number(cell: str) -> float:
        cell = cell.strip().replace(" ", "")
        mantissa, _, exponent = cell.partition(r"\cdot10^{")
        return float(mantissa) * 10.0 ** int(exponent.rstrip("}") or 0)
    return np.array([[number(c) for c in row.split("&")] for row in body.split(r"\\")])


def test_the_ekf_of_a_dc_motor_renders_prediction_gain_and_update_with_its_jacobians():
    filt = ekf(dc_motor(), dt=0.01, Q=1e-4, R=1e-2, P0=1.0).equations["filter"]
    parts = filter_equations(filt, digits=8)
    assert list(parts) == ["model", "jacobians", "prediction", "gain", "update"]
    assert all(not part.skipped for part in parts.values())
    assert r"P_{k+1|k} = F_k P_{k|k} F_k^{\top} + Q" in parts["prediction"]
    assert r"K_k = P_{k|k-1} H_k^{\top} S_k^{-1}" in parts["gain"]
    assert r"\hat{x}_{k|k} = \hat{x}_{k|k-1} + K_k r_k" in parts["update"]
    assert r"\dot{i} = - 2 i - 0.02 \omega + 2 v" in parts["model"]
    # F: one RK4 step of the linear motor is the 4th-order Taylor polynomial of expm(A dt)
    R, L, k, J, b = P0
    Adt = 0.01 * np.array([[-R / L, -k / L], [k / J, -b / J]])
    taylor = sum(np.linalg.matrix_power(Adt, m) / np.prod(range(1, m + 1)) for m in range(5))
    A_line, F_line, H_line = parts["jacobians"]
    assert A_line.startswith("A = ") and F_line.startswith("F_k = ") and H_line.startswith("H_k = ")
    np.testing.assert_allclose(_matrix(A_line.split(r"\quad")[0]), Adt / 0.01)
    np.testing.assert_allclose(_matrix(F_line), taylor, rtol=1e-7)
    np.testing.assert_array_equal(_matrix(H_line), [[0.0, 1.0]])
    np.testing.assert_allclose(_matrix(parts["prediction"][2]), 1e-4 * np.eye(2))


def test_an_entry_above_the_size_guard_is_named_and_the_note_says_what_was_skipped():
    parts = filter_equations(ekf(dc_motor(friction=0.02), dt=0.01, Q=1e-4, R=1e-2, P0=1.0).equations["filter"],
                             max_operations=12)
    A_line, F_line, H_line = parts["jacobians"]
    assert "F_{2,2}" in F_line and "F_{1,2}" in F_line  # the speed column goes through tanh
    notes = {re.match(r"\$([AFH]_\{\d,\d\})\$", n).group(1): n for n in parts["jacobians"].skipped}
    assert "F_{2,2}" in notes
    size = int(re.search(r": (\d+) operations written out, more than the guard of 12; not shown", notes["F_{2,2}"])
               .group(1))
    assert size > 12
    np.testing.assert_array_equal(_matrix(H_line), [[0.0, 1.0]])  # small entries are still shown
    text = equations_markdown(parts)
    assert "Not written out (size guard):" in text and "- $F_{2,2}$: " in text
    page = markdown_to_html(text, "motor", None)
    assert page.count("<math") >= 10 and "<strong>Prediction</strong>" in page


def test_an_observer_keeping_its_filter_renders_the_structured_form():
    lines = observer_equations(ekf(dc_motor(friction=0.02), dt=0.01, Q=1e-4, R=1e-2, P0=1.0, steps=2))
    assert r"S_k = H_k P_{k|k-1} H_k^{\top} + R" in lines
    assert any(line.startswith(r"F(\mathbf{x}, \mathbf{u}) = \text{2 RK4 steps of }") for line in lines)
    assert lines.skipped and all("more than the guard of 400" in note for note in lines.skipped)


def test_the_ukf_shows_its_weights_and_the_closed_form_of_an_affine_output():
    parts = filter_equations(ukf(dc_motor(), dt=0.01, Q=1e-4, R=1e-2, P0=1.0, alpha=0.5).equations["filter"])
    # n = 2, alpha = 0.5, kappa = 0: lambda = -1.5, w_m0 = lambda / (n + lambda) = -3, w_c0 = -3 + 1 - 0.25 + 2
    weights = parts["prediction"][1]
    assert r"\lambda = \alpha^2 (n + \kappa) - n = -1.5" in weights
    assert r"w^{m}_0 = -3,\ w^{c}_0 = -0.25,\ w_i = 1" in weights
    assert parts["jacobians"][0].startswith(r"H = \frac{\partial h}{\partial \mathbf{x}} = \begin{bmatrix} 0 & 1")
    assert r"K_k = P_{xz} P_{zz}^{-1}" in parts["gain"]


def test_operations_count_a_shared_sub_expression_at_each_use():
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    assert operations(x * y + ca.sin(x)) == 6  # +, *, x, y, sin, x
    shared = x * y
    assert operations(shared * ca.sin(shared)) == 8  # *, (x y) twice (3 each), sin
    assert operations(ca.SX(2.0)) == 1
    deep = x
    for _ in range(1500):  # deeper than Python's recursion limit: sin, +, the constant per level
        deep = ca.sin(deep) + 1.0
    assert operations(deep) == 3 * 1500 + 1


def test_a_filter_of_another_method_is_refused_by_name():
    filt = dataclasses.replace(ekf(dc_motor(), dt=0.01, Q=1e-4, R=1e-2, P0=1.0).equations["filter"], method="pf")
    with pytest.raises(UvsymError, match="no structured form for filter method 'pf'"):
        filter_equations(filt)
