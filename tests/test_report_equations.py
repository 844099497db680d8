"""Equations of any observer in its signals' own names."""

import casadi as ca
import numpy as np
import pytest
import sympy as sp
from sympy.parsing.sympy_parser import implicit_multiplication, parse_expr, standard_transformations

from uvsym.errors import UvsymError
from uvsym.observers.luenberger import luenberger_observer
from uvsym.report.equations import function_equations, observer_equations, signal_latex
from uvsym.systems import signals, system
from uvsym.verify.interval import IntervalFunction


def test_signal_names_typeset():
    assert signal_latex("omega_m_hat") == r"\hat{\omega}_{m}"
    assert signal_latex("lambda_rq") == r"\lambda_{rq}"
    assert signal_latex("f_hat.X") == r"\hat{f}_{X}"
    assert signal_latex("x") == "x"
    assert signal_latex("pos") == r"\mathrm{pos}"


def test_luenberger_equations_read_in_signal_names():
    plant = system("osc", "oscillator", x=signals(("pos", "m"), ("omega_m", "rad/s")), u=signals(("u_sq", "V")),
                   y=signals(("pos_meas", "m")), output=lambda x, u, p: x[0],
                   rhs=lambda x, u, d, p: ca.vertcat(x[1], -4 * x[0] - 0.4 * x[1] + u[0]))
    lines = observer_equations(luenberger_observer(plant, [[3.0], [2.0]], 0.01))
    assert len(lines) == 2
    lhs, rhs = lines[1].split(" = ")
    assert lhs == r"\dot{\hat{\omega}_{m}}"
    # the right-hand side, parsed back by sympy, is -4 x - 0.4 w + u + 2 (y - x) with the hat names
    x, w, y, u = sp.symbols("x w y u")
    text = (rhs.replace(r"\hat{\omega}_{m}", "w").replace(r"\hat{\mathrm{pos}}", "x")
            .replace(r"\mathrm{pos}_{meas}", "y").replace("u_{sq}", "u"))
    parsed = parse_expr(text, transformations=standard_transformations + (implicit_multiplication,))
    assert sp.expand(parsed - (-4 * x - 0.4 * w + u + 2 * (y - x))) == 0


def test_function_equations_check_sizes():
    f = ca.Function("f", [ca.SX.sym("a", 2)], [ca.SX.sym("a", 2) * 0])
    with pytest.raises(UvsymError, match="one Signals per input"):
        function_equations(f, [], [])
    with pytest.raises(UvsymError, match="has 2 entries, 1 names"):
        function_equations(f, [signals(("a", "-"))], [(signals(("b", "-")), "")])


def test_interval_sine_of_exact_zero_is_exact_zero():
    """Odd library functions keep an exact zero (so an equilibrium through sin stays exactly 0)."""
    a = ca.SX.sym("a")
    for op in (ca.sin, ca.tanh, ca.atan, ca.sinh, ca.expm1):
        bounds = IntervalFunction(ca.Function("g", [a], [op(a)]))(np.array([[0.0], [0.0]]), np.array([[0.0], [1e-3]]))
        assert bounds.lo[0, 0] == 0.0 and bounds.hi[0, 0] == 0.0
        assert bounds.hi[1, 0] > 0.0  # a box that is not a point still gets its width


def test_golden_text_comparison_tolerates_rounding_but_not_changes():
    from uvsym.testing import assert_same_text

    assert_same_text("K 1.11e-14, t = 3.1788 s, w12[3]", "K 1.39e-14, t = 3.1788 s, w12[3]")
    with pytest.raises(AssertionError, match="number 3.1789 differs"):
        assert_same_text("t = 3.1789 s", "t = 3.1788 s")
    with pytest.raises(AssertionError, match="text differs"):
        assert_same_text("t = 3 s", "t = 3 ms")
    with pytest.raises(AssertionError, match="text differs"):
        assert_same_text("casadi_f1(w)", "casadi_f2(w)")  # digits inside names are text
