"""Qualified signal names: several blocks publishing one name in a loop, read as ``block.name`` or ``y.name``."""

from __future__ import annotations

import numpy as np
import pytest
from problems import DT, integrator

from uvsym.errors import WiringError
from uvsym.observers.luenberger import luenberger_observer
from uvsym.sim import (
    Substitution,
    block,
    interconnect,
    observer_block,
    open_loop,
    renamed,
    simulate_system,
    state_feedback,
)
from uvsym.systems import signals, system

MASS, SPRING, DAMPING = 2.0, 8.0, 1.5  # kg, N/m, N s/m: A = [[0, 1], [-4, -0.75]], C = [1, 0]
PLANT = system("mass_spring", "mass on a spring with viscous damping",
               x=signals(("pos", "m"), ("vel", "m/s"), group="state"), u=signals(("force", "N"), group="input"),
               y=signals(("pos_meas", "m"), group="output"),
               rhs=lambda x, u, d, p: [x[1], (u[0] - SPRING * x[0] - DAMPING * x[1]) / MASS],
               output=lambda x, u, p: x[0])
K = [[6.0, 4.0]]  # u = -K x


def gain(pole: float) -> np.ndarray:
    """L placing both poles of A - L C at -pole: det(sI - A + LC) = s^2 + (l1 + 0.75) s + 0.75 l1 + 4 + l2."""
    l1 = 2 * pole - 0.75
    return np.array([[l1], [pole ** 2 - 4 - 0.75 * l1]])


SLOW = observer_block(luenberger_observer(PLANT, gain(3.0), dt=DT))  # named luenberger
FAST = observer_block(luenberger_observer(PLANT, gain(10.0), dt=DT, name="fast"))
X0 = [0.3, -0.2]


def run(blocks, **options):
    return simulate_system(PLANT, blocks, duration=2.0, dt=DT, x0=X0, **options)


def test_the_gains_place_the_poles_asked_for():
    A, C = np.array([[0.0, 1.0], [-SPRING / MASS, -DAMPING / MASS]]), np.array([[1.0, 0.0]])
    for pole in (3.0, 10.0):
        np.testing.assert_allclose(np.linalg.eigvals(A - gain(pole) @ C), [-pole, -pole], atol=1e-6)


def test_two_observers_publishing_the_same_names_each_run_as_they_do_alone():
    drive = open_loop("drive", [0.0, 0.5], [0.0, 2.0], publishes=["force"])
    both = run([drive, SLOW, FAST])
    alone = {b.name: run([drive, b]) for b in (SLOW, FAST)}
    for name in ("luenberger", "fast"):
        assert both[name].labels == ("pos_hat", "vel_hat", "r_pos_meas")
        np.testing.assert_allclose(both[name].values, alone[name][name].values, rtol=0, atol=1e-12)
    np.testing.assert_allclose(both["x"].values, alone["fast"]["x"].values, rtol=0, atol=1e-12)
    assert np.abs(both["fast"]["pos_hat"][5] - both["luenberger"]["pos_hat"][5]) > 1e-3  # they differ
    loop = interconnect(PLANT, [drive, SLOW, FAST], dt=DT)
    assert loop.names == ("t", "pos_meas", "force", "luenberger.pos_hat", "luenberger.vel_hat",
                          "luenberger.r_pos_meas", "fast.pos_hat", "fast.vel_hat", "fast.r_pos_meas")
    assert loop.units["fast.vel_hat"] == "m/s" and "pos_hat" not in loop.units
    alone_loop = interconnect(PLANT, [drive, FAST], dt=DT)  # one publisher: bare names, as before
    assert alone_loop.names == ("t", "pos_meas", "force", "pos_hat", "vel_hat", "r_pos_meas")


def test_feedback_of_one_observer_read_qualified_is_that_observer_read_bare_alone():
    qualified = state_feedback("ctrl", K, reads=["fast.pos_hat", "fast.vel_hat"], publishes=["force"])
    bare = state_feedback("ctrl", K, reads=["pos_hat", "vel_hat"], publishes=["force"])
    both, alone = run([SLOW, FAST, qualified]), run([FAST, bare])
    for group in ("x", "fast", "ctrl"):
        np.testing.assert_allclose(both[group].values, alone[group].values, rtol=0, atol=1e-12)
    np.testing.assert_allclose(both["ctrl"]["force"], -both["fast"].values[:, :2] @ K[0], rtol=0, atol=1e-12)
    assert abs(both["x"]["pos"][-1]) < 0.05 * X0[0]  # the loop is closed through the estimates
    order = both.meta["order"]
    assert order.index("fast.pos_hat") < order.index("force")
    lone = run([FAST, state_feedback("ctrl", K, reads=["fast.pos_hat", "fast.vel_hat"], publishes=["force"])])
    np.testing.assert_array_equal(lone["x"].values, alone["x"].values)  # qualified reads work with one publisher too


def test_a_bare_read_of_a_name_several_publish_names_the_reader_and_the_qualified_choices():
    ctrl = state_feedback("ctrl", K, reads=["pos_hat", "vel_hat"], publishes=["force"])
    with pytest.raises(WiringError) as caught:
        interconnect(PLANT, [SLOW, FAST, ctrl], dt=DT)
    assert str(caught.value) == ("block ctrl reads 'pos_hat', which blocks luenberger and fast both publish; "
                                 "read 'luenberger.pos_hat' or 'fast.pos_hat'")
    third = observer_block(luenberger_observer(PLANT, gain(5.0), dt=DT, name="mid"))
    with pytest.raises(WiringError, match=r"which blocks luenberger, fast and mid all publish; read "
                                          r"'luenberger.pos_hat', 'fast.pos_hat' or 'mid.pos_hat'$"):
        interconnect(PLANT, [SLOW, FAST, third, ctrl], dt=DT)
    drive = open_loop("drive", [0.0], [1.0], publishes=["force"])
    with pytest.raises(WiringError, match=r"^plant mass_spring input 'force' is driven by blocks drive and ctrl; "
                                          r"rename all but one \(uvsym.sim.renamed\)$"):
        interconnect(PLANT, [drive, renamed(ctrl, reads={"pos_hat": "pos_meas", "vel_hat": "t"})], dt=DT)


def test_y_reads_the_measured_output_when_a_block_publishes_its_name_too():
    drive = open_loop("drive", [0.0], [1.0], publishes=["force"])
    scale = block("scale", step=lambda s, r: (s, 3 * r), reads="y.pos_meas", publishes="pos_meas")
    sensor = state_feedback("sensor", [[-1.0]], reads=["y.pos_meas"], publishes=["seen"])
    scaled = state_feedback("scaled", [[-1.0]], reads=["scale.pos_meas"], publishes=["seen"])
    result = run([drive, scale, sensor, scaled])
    measured = result["y"]["pos_meas"]
    assert np.ptp(measured) > 0.1
    np.testing.assert_array_equal(result["sensor"]["seen"], measured)
    np.testing.assert_allclose(result["scaled"]["seen"], 3 * measured, rtol=1e-15, atol=0)
    np.testing.assert_allclose(result["scale"]["pos_meas"], 3 * measured, rtol=1e-15, atol=0)
    loop = interconnect(PLANT, [drive, scale, sensor, scaled], dt=DT)
    assert loop.names == ("t", "y.pos_meas", "force", "scale.pos_meas", "sensor.seen", "scaled.seen")
    assert loop.units["y.pos_meas"] == "m" and loop.units["scale.pos_meas"] == ""  # nobody declares a unit for it
    for read, choices in (("pos_meas", "'y.pos_meas' or 'scale.pos_meas'"),
                          ("pos_meas.raw", "'y.pos_meas.raw' or 'scale.pos_meas.raw'")):
        with pytest.raises(WiringError, match=rf"block bare reads '{read}', which plant mass_spring and block "
                                              rf"scale both publish; read {choices}$"):
            interconnect(PLANT, [drive, scale, state_feedback("bare", [[1.0]], reads=[read], publishes=["b"])],
                         dt=DT)


class SwitchAt:
    """Switches substitution channel psi on at the first check whose samples reach 0.5 s."""

    period = 0.25

    def update(self, t, signals):
        return Substitution({"psi"}) if t[-1] >= 0.5 - 1e-9 else None


def test_a_qualified_substitute_replaces_the_channel_for_all_but_its_publisher():
    heading = system("heading", "psi' = r", x=signals(("psi", "rad"), group="state"),
                     u=signals(("r", "rad/s"), group="input"), rhs=lambda x, u, d, p: u)
    est = state_feedback("est", [[-1.0]], reads=["psi"], u_ref=[1.0], publishes=["psi_hat"])  # what it reads + 1
    alt = state_feedback("alt", [[-1.0]], reads=["psi"], u_ref=[2.0], publishes=["psi_hat"])  # what it reads + 2
    ctrl = state_feedback("ctrl", [[1.0]], reads=["psi"], x_ref=[0.5], publishes=["r"])  # r = -(psi - 0.5)
    watch = [state_feedback(f"watch{i}", [[-1.0]], reads=[read], publishes=["seen"])
             for i, read in enumerate(("psi.raw", "y.psi.raw", "y.psi"))]
    result = simulate_system(heading, [est, alt, ctrl, *watch], duration=1.5, dt=DT, x0=[0.1],
                             substitutions={"psi": "alt.psi_hat"}, supervisor=SwitchAt())
    on = result["substitution"]["psi"] == 1.0
    np.testing.assert_array_equal(on, result.t >= 0.75 - 1e-9)  # switched by the check at the end of [0.5, 0.75)
    psi = result["y"]["psi"]
    np.testing.assert_allclose(result["alt"]["psi_hat"], psi + 2.0, rtol=0, atol=1e-15)  # its sensor, always
    np.testing.assert_allclose(result["est"]["psi_hat"], psi + np.where(on, 3.0, 1.0), rtol=0, atol=1e-15)
    np.testing.assert_allclose(result["ctrl"]["r"], -(psi + np.where(on, 2.0, 0.0) - 0.5), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(result["watch0"]["seen"], psi)  # psi.raw and y.psi.raw: never substituted
    np.testing.assert_array_equal(result["watch1"]["seen"], psi)
    np.testing.assert_allclose(result["watch2"]["seen"], psi + np.where(on, 2.0, 0.0), rtol=0, atol=1e-15)
    assert result["alt"].units == ("rad",) and result["est"].units == ("",)  # the substitute's: the channel's
    with pytest.raises(WiringError, match=r"substitutions \['psi', 'y.psi'\] name one channel twice"):
        interconnect(heading, [est, alt, ctrl], dt=DT, substitutions={"psi": "alt.psi_hat", "y.psi": "est.psi_hat"})
    with pytest.raises(WiringError, match=r"substitution 'psi' -> 'psi_hat' reads 'psi_hat', which blocks est and "
                                          r"alt both publish; read 'est.psi_hat' or 'alt.psi_hat'"):
        interconnect(heading, [est, alt, ctrl], dt=DT, substitutions={"psi": "psi_hat"})


def test_an_algebraic_loop_through_a_qualified_substitution_hints_at_the_qualified_raw_read():
    echo = block("echo", step=lambda s, r: (s, r), reads="y.q", publishes="q")  # q: now ambiguous
    pre = block("pre", step=lambda s, r: (s, 2 * r), reads="y.q", publishes="a")
    est = block("est", step=lambda s, r: (s, r), reads="a", publishes="q_hat")
    other = block("other", step=lambda s, r: (s, r), reads="y.q", publishes="q_hat")
    ctrl = state_feedback("ctrl", [[1.0]], reads=["y.q"], publishes=["u"])
    substitutions = {"y.q": "est.q_hat"}
    with pytest.raises(WiringError, match=r"algebraic loop: .*substitution of y.q: a block that must see the sensor "
                                          r"reads 'y.q.raw'") as caught:
        interconnect(integrator(), [echo, pre, est, other, ctrl], dt=DT, substitutions=substitutions)
    assert "a (block pre)" in str(caught.value) and "est.q_hat (block est)" in str(caught.value)
    loop = interconnect(integrator(), [echo, renamed(pre, reads={"y.q": "y.q.raw"}), est, other, ctrl], dt=DT,
                        substitutions=substitutions)
    assert loop.order.index("a") < loop.order.index("est.q_hat") < loop.order.index("u")
    assert loop.substitution_columns == {"y.q": loop.n_w - 1}


def test_units_resolve_through_qualified_reads():
    tables = [open_loop(name, [0.0], [value], publishes=["ref"]) for name, value in (("a", 1.0), ("b", 2.0))]
    follow = state_feedback("follow", [[-1.0]], reads=signals(("a.ref", "rad")), publishes=["u"])
    loop = interconnect(integrator(), [*tables, follow], dt=DT)
    assert loop.units["a.ref"] == "rad" and loop.units["b.ref"] == ""
    wrong = state_feedback("wrong", [[-1.0]], reads=signals(("a.ref", "m")), publishes=["v"])
    with pytest.raises(WiringError, match=r"block wrong reads 'a.ref' in 'm' but block a publishes it in 'rad'"):
        interconnect(integrator(), [*tables, follow, wrong], dt=DT)


def test_an_unknown_name_is_refused_with_the_close_matches():
    misspelt = state_feedback("ctrl", K, reads=["fast.pos_hta", "fast.vel_hat"], publishes=["force"])
    with pytest.raises(WiringError, match=r"block ctrl reads 'fast.pos_hta', which nothing publishes; published: "
                                          r"fast.pos_hat, .*; did you mean 'fast.pos_hat'"):
        interconnect(PLANT, [SLOW, FAST, misspelt], dt=DT)
    with pytest.raises(WiringError, match=r"plant mass_spring input 'force' is driven by no block; published: .*"
                                          r"; did you mean 'forc'\?$"):
        interconnect(PLANT, [open_loop("drive", [0.0], [1.0], publishes=["forc"])], dt=DT)
    with pytest.raises(WiringError, match=r"reads 'zzz', which nothing publishes; published: force, pos_meas, t$"):
        interconnect(PLANT, [state_feedback("c", [[1.0]], reads=["zzz"], publishes=["force"])], dt=DT)
    bare = state_feedback("ctrl", K, reads=["fast.pos_hat", "vel_ht"], publishes=["force"])
    with pytest.raises(WiringError, match=r"reads 'vel_ht', which nothing publishes; .*; did you mean 'vel_hat'"):
        interconnect(PLANT, [SLOW, FAST, bare], dt=DT)  # the bare name two publish is a close match too


def test_a_published_name_ending_in_raw_is_read_as_published():
    drive = open_loop("drive", [0.0], [1.0], publishes=["u"])
    copies = [block(name, step=lambda s, r, k=k: (s, k * r), reads="q", publishes="q.raw")
              for name, k in (("a", 2.0), ("b", 3.0))]
    watch = state_feedback("watch", [[-1.0]], reads=["q.raw"], publishes=["seen"])
    result = simulate_system(integrator(), [drive, copies[0], watch], duration=0.5, dt=DT, x0=[1.0])
    np.testing.assert_allclose(result["watch"]["seen"], 2 * result["y"]["q"], rtol=1e-15, atol=0)
    with pytest.raises(WiringError, match=r"block watch reads 'q.raw', which blocks a and b both publish; "
                                          r"read 'a.q.raw' or 'b.q.raw'$"):
        interconnect(integrator(), [drive, *copies, watch], dt=DT)


def test_names_that_would_make_a_qualified_read_ambiguous_are_refused():
    drive = open_loop("drive", [0.0], [1.0], publishes=["force"])
    with pytest.raises(WiringError, match=r"block clock publishes 't', the name of the loop's time"):
        interconnect(PLANT, [drive, open_loop("clock", [0.0], [0.0], publishes=["t"])], dt=DT)
    impostor = open_loop("impostor", [0.0], [0.0], publishes=["drive.force"])
    with pytest.raises(WiringError, match=r"block drive publishes 'force', read as 'drive.force', a name block "
                                          r"impostor also publishes"):
        interconnect(PLANT, [drive, impostor], dt=DT)
