"""Induction (traction) motor in the synchronous d-q frame, as printed by Yu, Jiang & Zhang (2018).

``x' = A x + F_a(x) + B u + E d``, ``y = C x`` (Yu et al. 2018, eq. 23, without
the sensor fault), x = (i_sq, i_sd, lambda_rq, lambda_rd, omega_m), u = (u_sq, u_sd), y = (i_sq,
i_sd, omega_m)::

    A = [[-gamma, -omega_s, alpha beta, 0, 0], [omega_s, -gamma, 0, alpha beta, 0],
         [alpha Lm, 0, -alpha, -omega_s, 0], [0, alpha Lm, omega_s, -alpha, 0], [0, 0, 0, 0, 0]]
    F_a(x) = (-n_p beta omega_m lambda_rd, n_p beta omega_m lambda_rq, n_p omega_m lambda_rd,
              -n_p omega_m lambda_rq, mu (lambda_rd i_sq - lambda_rq i_sd) - T_L / J)
    B = [I_2; 0] / (delta Ls)
    E = [[-beta Lm/Lr, 0, beta/Lr, 0, 0], [0, -beta Lm/Lr, 0, beta/Lr, 0],
         [Lm/Lr, 0, -1/Lr, 0, 0], [0, Lm/Lr, 0, -1/Lr, 0], [0, 0, 0, 0, 0]]

with ``delta = 1 - Lm^2/(Ls Lr)``, ``alpha = Rr/Lr``, ``beta = Lm/(delta Ls Lr)``,
``gamma = Lm^2 Rr/(delta Ls Lr^2) + Rs/(delta Ls)``, ``mu = n_p Lm/(J Lr)``. Rows 3-4 of F_a are
printed with ``n_p beta``; the rotor-flux equation ``lambda_rq' = alpha Lm i_sq - alpha lambda_rq
- (omega_s - n_p omega_m) lambda_rd`` (slip frequency) and the units (beta is in 1/H) need ``n_p``,
the default here; ``build(printed_typo=True)`` gives the printed form.

Disturbance: f is affine in Rr with ``df/dRr = E x``, so ``d = dRr * x`` (5 entries, dRr the
rotor-resistance change in Ohm) makes ``E d`` the exact effect of ``Rr -> Rr + dRr``.

The load torque T_L (N m, a known parameter; the paper has none, default 0) brakes the speed.
Operating point (rotor-flux oriented): ``lambda_rq = 0``, ``i_sd = I0``, ``lambda_rd = Lm I0``,
``i_sq = T_L / (J mu Lm I0)`` (torque balance), slip ``omega_sl = alpha i_sq / I0`` (rotor q-flux
balance), ``omega_m = (omega_s - omega_sl) / n_p``, ``u_sq = delta Ls (omega_s I0 (1 + beta Lm) +
gamma i_sq - omega_sl beta Lm I0)``, ``u_sd = Rs I0 - delta Ls omega_s i_sq``. With T_L = 0 this is
the zero-slip point ``omega_m = omega_s / n_p``, ``i_sq = 0``, ``u_sq = omega_s Ls I0``,
``u_sd = Rs I0``. An equilibrium of the consistent form, not of the printed one (rows 3-4 then
leave ``+-n_p (beta - 1) omega_m lambda``).

Numbers: the paper's are in a reference it does not reproduce; these are the Modelica Standard
Library IM_SquirrelCageData defaults at full precision (Lm = 3 sqrt(1 - 0.0667) / (2 pi 50 Hz),
Ls = Lr = 3 / (2 pi 50 Hz); rounded to 9.225 and 9.549 mH they would give beta = 1516.6, not
1516.7). omega_s = 500 rad/s puts omega_m at 250 rad/s, where the paper's 1 rad/s fault is 0.4 %;
I0 = 30 A is uvsym's choice: the stator voltage omega_s Ls I0 = 143 V is then close to the data's
nominal peak phase voltage (sqrt(2) 100 V), field-weakened at this 80 Hz supply. mu is as
printed, without the 3/2 of an amplitude-invariant d-q transform, so the torque, and with it the
speed's response to the currents, follows the paper rather than the Modelica machine.
"""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np

from uvsym.errors import ModelError
from uvsym.models.parameters import ParameterSet, load_parameters
from uvsym.systems.signals import signals
from uvsym.systems.system import System, system

NAME = "induction_motor"
DESCRIPTION = "Induction motor, d-q frame (Yu, Jiang & Zhang 2018), rotor-resistance change as disturbance"
PARAMETER_FILES = [Path(__file__).with_suffix(".toml")]

STATES = signals(("i_sq", "A", "q-axis stator current"), ("i_sd", "A", "d-axis stator current"),
                 ("lambda_rq", "Wb", "q-axis rotor flux linkage"), ("lambda_rd", "Wb", "d-axis rotor flux linkage"),
                 ("omega_m", "rad/s", "mechanical rotor speed"), group="state")
INPUTS = signals(("u_sq", "V", "q-axis stator voltage"), ("u_sd", "V", "d-axis stator voltage"), group="input")
DISTURBANCES = signals(("dRr_i_sq", "V", "rotor-resistance change times i_sq"),
                       ("dRr_i_sd", "V", "rotor-resistance change times i_sd"),
                       ("dRr_lambda_rq", "Ohm Wb", "rotor-resistance change times lambda_rq"),
                       ("dRr_lambda_rd", "Ohm Wb", "rotor-resistance change times lambda_rd"),
                       ("dRr_omega_m", "Ohm rad/s", "rotor-resistance change times omega_m (E's column is 0)"),
                       group="disturbance")
OUTPUTS = STATES.select(["i_sq", "i_sd", "omega_m"]).renamed(group="output")


def coefficients(p: ParameterSet) -> dict[str, float]:
    """delta (-), alpha (1/s), beta (1/H), gamma (1/s), mu (1/(kg m^2)) of the module docstring;
    ModelError unless delta = 1 - Lm^2/(Ls Lr) > 0."""
    Rs, Rr, Lm, Ls, Lr = (p.v(k) for k in ("Rs", "Rr", "Lm", "Ls", "Lr"))
    delta = 1.0 - Lm**2 / (Ls * Lr)
    if delta <= 0:
        raise ModelError(f"{NAME}: leakage coefficient delta = 1 - Lm^2/(Ls Lr) = {delta:.6g} must be > 0; "
                         f"parameters Lm = {Lm:g} H, Ls = {Ls:g} H, Lr = {Lr:g} H")
    return {"delta": delta, "alpha": Rr / Lr, "beta": Lm / (delta * Ls * Lr),
            "gamma": Lm**2 * Rr / (delta * Ls * Lr**2) + Rs / (delta * Ls), "mu": p.v("n_p") * Lm / (p.v("J") * Lr)}


def matrices(p: ParameterSet) -> dict[str, np.ndarray]:
    """The paper's A (5x5), B (5x2, 1/H), C (3x5) and E (5x5) from the parameters (SI units)."""
    k, Lm, Lr, w = coefficients(p), p.v("Lm"), p.v("Lr"), p.v("omega_s")
    a, b, g = k["alpha"], k["beta"], k["gamma"]
    A = np.array([[-g, -w, a * b, 0, 0], [w, -g, 0, a * b, 0], [a * Lm, 0, -a, -w, 0],
                  [0, a * Lm, w, -a, 0], [0, 0, 0, 0, 0]], dtype=float)
    B = np.vstack([np.eye(2) / (k["delta"] * p.v("Ls")), np.zeros((3, 2))])
    C = np.eye(5)[[0, 1, 4]]
    E = np.array([[-b * Lm / Lr, 0, b / Lr, 0, 0], [0, -b * Lm / Lr, 0, b / Lr, 0], [Lm / Lr, 0, -1 / Lr, 0, 0],
                  [0, Lm / Lr, 0, -1 / Lr, 0], [0, 0, 0, 0, 0]], dtype=float)
    return {"A": A, "B": B, "C": C, "E": E}


def build(printed_typo: bool = False, **overrides) -> System:
    """The motor as a System; ``printed_typo=True`` uses the printed ``n_p beta`` in F_a rows 3-4.

    Raises
    ------
    ModelError
        For an unknown, non-finite or out-of-bounds override, or Lm^2 >= Ls Lr.
    """
    p = load_parameters(NAME, PARAMETER_FILES, overrides)
    k, m = coefficients(p), matrices(p)
    n_p, beta, mu = p.v("n_p"), k["beta"], k["mu"]
    flux_gain = n_p * beta if printed_typo else n_p
    load = p.v("T_L") / p.v("J")  # rad/s^2

    def rhs(x, u, d, _p):
        i_sq, i_sd, l_rq, l_rd, w_m = (x[i] for i in range(5))
        F_a = ca.vertcat(-n_p * beta * w_m * l_rd, n_p * beta * w_m * l_rq, flux_gain * w_m * l_rd,
                         -flux_gain * w_m * l_rq, mu * (l_rd * i_sq - l_rq * i_sd) - load)
        return ca.mtimes(ca.DM(m["A"]), x) + F_a + ca.mtimes(ca.DM(m["B"]), u) + ca.mtimes(ca.DM(m["E"]), d)

    I0, w_s, Ls, Lm = p.v("I0"), p.v("omega_s"), p.v("Ls"), p.v("Lm")
    if p.v("T_L") and not I0 > 0:
        raise ModelError(f"{NAME}: a load torque T_L = {p.v('T_L'):g} N m needs a magnetising current I0 > 0")
    i_sq = p.v("T_L") / (p.v("J") * mu * Lm * I0) if p.v("T_L") else 0.0  # A: torque balance (module docstring)
    slip = k["alpha"] * i_sq / I0  # rad/s, electrical
    form = "printed F_a (n_p beta in rows 3-4)" if printed_typo else "F_a rows 3-4 with n_p"
    return system(NAME, f"{DESCRIPTION}; {form}", x=STATES, u=INPUTS, d=DISTURBANCES, y=OUTPUTS, rhs=rhs,
                  output=lambda x, u, _p: ca.mtimes(ca.DM(m["C"]), x),
                  x_op=[i_sq, I0, 0.0, Lm * I0, (w_s - slip) / n_p],
                  u_op=[k["delta"] * Ls * w_s * I0 * (1 + beta * Lm) + k["delta"] * Ls * (k["gamma"] * i_sq
                                                                                       - slip * beta * Lm * I0),
                        p.v("Rs") * I0 - k["delta"] * Ls * w_s * i_sq],
                  constants=p, extras={"coefficients": k, "printed_typo": printed_typo},
                  source="Yu, Jiang & Zhang (2018) eq. 23 and its A, F_a, B, C, E; parameters: Modelica Standard "
                         "Library IM_SquirrelCageData defaults; omega_s = 500 rad/s and I0 are uvsym's choices")
