"""Under load, the rotor-resistance change and a speed-sensor offset look the same in steady state.

At the loaded operating point (load torque ``LOAD`` N m, slip) the motor is solved for its
equilibrium with the rotor resistance raised by ``RR_RISE`` on the same supply voltages: the
currents and fluxes of the new equilibrium equal the old ones (the rotor branch sees only Rr / slip,
so the slip scales with Rr and the torque stays at the load) while the speed drops by
``alpha Rr_rise i_sq / (I0 n_p)``. A speed sensor reading ``omega_m + F2 f_s`` then reads the same
as a healthy motor with an offset ``f_s = -d omega_m / F2``: no estimator that uses the measured
currents, voltages and the speed reading in steady state tells the two apart, so every such
design's steady fault estimate is biased by at least that offset (the corrected design's measured
-0.25 rad/s per +20 % is this offset, -d omega_m / 2).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import fsolve

import uvsym
from derivations.motor_hybrid_observer.design import F

__all__ = ["LOAD", "RR_RISES", "indistinguishable_offsets"]

LOAD = 20.0  # N m, the loaded operating point (the case)
RR_RISES = (0.2, 1.0)  # relative rotor-resistance rises tried
SOLVE_TOLERANCE = 1e-14


def indistinguishable_offsets(load: float = LOAD, rises=RR_RISES) -> dict:
    """Per rise: the equilibrium's change of the measured currents (A, max abs), of the fluxes (Wb),
    of the speed (rad/s), the residual |f| of the solve, and the sensor offset that mimics it (rad/s)."""
    motor = uvsym.plant("induction_motor", T_L=load)
    Rr, F2 = float(motor.constants.v("Rr")), float(F[2, 0])
    out = {"load_N_m": load, "operating_point": motor.x_op.tolist(), "slip_rad_per_s":
           float(motor.constants.v("omega_s") - motor.constants.v("n_p") * motor.x_op[4])}
    for rise in rises:
        def f(x, rise=rise):
            return np.array(motor.f(x, motor.u_op, rise * Rr * x, motor.p0)).ravel()
        x = fsolve(f, motor.x_op, xtol=SOLVE_TOLERANCE)
        dx = x - motor.x_op
        out[f"{rise:g}"] = {"currents_change_A": float(np.max(np.abs(dx[:2]))),
                            "fluxes_change_Wb": float(np.max(np.abs(dx[2:4]))),
                            "speed_change_rad_per_s": float(dx[4]), "solve_residual": float(np.max(np.abs(f(x)))),
                            "mimicking_offset_rad_per_s": float(-dx[4] / F2)}
    return out
