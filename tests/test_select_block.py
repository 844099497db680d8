"""The same-sample switch block ``select``: in a loop against a hand-computed sequence, and its errors."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import WiringError
from uvsym.sim import simulate_system
from uvsym.sim.blocks import block, select
from uvsym.sim.feedback import open_loop, state_feedback
from uvsym.sim.wiring import interconnect
from uvsym.systems import signals, system

DT = 0.1


def integrator():
    return system("integrator", "psi' = u", x=signals(("psi", "rad"), group="state"),
                  u=signals(("u", "rad/s"), group="input"), rhs=lambda x, u, d, p: u)


def test_the_controller_acts_on_the_substitute_from_the_sample_the_flag_rises():
    # flag 0 on samples 0-2, 1 from sample 3 (t = 0.3 s); u_k = 1 - psi_sel_k; psi' = u (RK4 is exact)
    blocks = [open_loop("flag_table", [0.0, 0.3], [0.0, 1.0], publishes=["flag"]),
              open_loop("alt_table", [0.0], [1.0], publishes=["alt"]),
              select("sel", flag="flag", on="alt", off="psi", output="psi_sel", unit="rad"),
              state_feedback("ctrl", [[1.0]], reads=["psi_sel"], u_ref=[1.0], publishes=["u"])]
    result = simulate_system(integrator(), blocks, duration=0.5, dt=DT, x0=[0.0])
    # by hand: psi_{k+1} = psi_k + 0.1 u_k; at k = 3 the controller already reads alt = 1, so u_3 = 0
    # (one sample late it would be 1 - 0.271 = 0.729)
    psi = [0.0, 0.1, 0.19, 0.271, 0.271, 0.271]
    np.testing.assert_allclose(result["x"]["psi"], psi, rtol=0, atol=1e-12)
    np.testing.assert_allclose(result["sel"]["psi_sel"], [0.0, 0.1, 0.19, 1.0, 1.0, 1.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(result["u"]["u"], [1.0, 0.9, 0.81, 0.0, 0.0, 0.0], rtol=0, atol=1e-12)
    assert result["sel"].units == ("rad",)


def test_several_channels_switch_together_on_one_flag():
    sel = select("sel", flag="f", on=["a", "b"], off=["c", "d"], output=["x", "y"])
    assert sel.reads.names == ("f", "a", "b", "c", "d") and sel.publishes.names == ("x", "y")
    for flag, expected in ((1.0, [2.0, 3.0]), (0.0, [4.0, 5.0]), (0.4, [4.0, 5.0]), (0.6, [2.0, 3.0])):
        _, out = sel.step(ca.DM(0, 1), [flag, 2.0, 3.0, 4.0, 5.0])
        np.testing.assert_array_equal(np.asarray(out).ravel(), expected)


def test_a_flag_computed_from_the_selected_signal_is_an_algebraic_loop():
    watch = block("watch", step=lambda s, r: (s, ca.if_else(r[0] > 0.5, 1.0, 0.0)), reads="psi_sel", publishes="flag")
    blocks = [watch, open_loop("alt_table", [0.0], [1.0], publishes=["alt"]),
              select("sel", flag="flag", on="alt", off="psi", output="psi_sel"),
              state_feedback("ctrl", [[1.0]], reads=["psi_sel"], publishes=["u"])]
    with pytest.raises(WiringError, match="algebraic loop"):
        interconnect(integrator(), blocks, dt=DT)


def test_a_branch_in_another_unit_is_refused():
    blocks = [open_loop("flag_table", [0.0], [0.0], publishes=["flag"]),
              open_loop("alt_table", [0.0], [1.0], publishes=signals(("alt", "m"), group="published")),
              select("sel", flag="flag", on="alt", off="psi", output="psi_sel", unit="rad"),
              state_feedback("ctrl", [[1.0]], reads=["psi_sel"], publishes=["u"])]
    with pytest.raises(WiringError, match="reads 'alt' in 'rad'"):
        interconnect(integrator(), blocks, dt=DT)


@pytest.mark.parametrize("kwargs, argument", [
    ({"on": ["a", "b"]}, "on must name"),
    ({"off": []}, "off must name"),
    ({"output": ["x", "y"]}, "on must name"),
    ({"flag": ["f"]}, "flag must be one signal"),
    ({"off": "a"}, r"repeated: \['a'\]"),
    ({"output": "f"}, r"repeated: \['f'\]"),
])
def test_bad_arguments_are_wiring_errors_naming_the_argument(kwargs, argument):
    with pytest.raises(WiringError, match=f"select sel: .*{argument}"):
        select("sel", **{"flag": "f", "on": "a", "off": "c", "output": "x", **kwargs})
