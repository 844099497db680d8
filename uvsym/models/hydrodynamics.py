"""Hydrodynamic and hydrostatic force terms (Fossen 2021, ch. 4, 6, 8).

Each function returns a generalised force vector (N, N m) or matrix about the CO in body
axes, numeric or CasADi as its velocity/attitude arguments are. Velocities are relative
to the water (``nu_r = nu - nu_c``) unless a docstring says otherwise.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from uvsym.symbolic import stack

__all__ = [
    "spheroid_rigid_body",
    "spheroid_added_mass",
    "current_velocity",
    "current_velocity_derivative",
    "hoerner_cd",
    "crossflow_drag",
    "lift_drag",
    "restoring_submerged",
    "speed",
]

# Regularisation of speeds (m/s): sqrt(v.v + eps^2) keeps derivatives finite at rest while
# changing values by less than eps^2 / (2 |v|), i.e. < 1e-15 m/s above 1 mm/s.
SPEED_EPS = 1e-9


def speed(*components):
    """Regularised Euclidean norm sqrt(sum c_i^2 + eps^2) of velocity components (m/s)."""
    return ca.sqrt(sum(c * c for c in components) + SPEED_EPS**2)


def spheroid_rigid_body(rho: float, a: float, b: float) -> tuple[float, float, float]:
    """Mass and principal inertias of a prolate spheroid of water: (m, Ix, Iy) in kg, kg m^2.

    ``m = 4/3 pi rho a b^2``, ``Ix = 2/5 m b^2``, ``Iy = Iz = 1/5 m (a^2 + b^2)``
    (Fossen 2021, sec. 8.4.2), a semi-major (m), b semi-minor (m).
    """
    m = 4.0 / 3.0 * math.pi * rho * a * b**2
    return m, (2.0 / 5.0) * m * b**2, (1.0 / 5.0) * m * (a**2 + b**2)


def spheroid_added_mass(m: float, a: float, b: float, Ix: float, Iy: float, r44: float) -> np.ndarray:
    """Added mass of a prolate spheroid from Lamb's k-factors, 6x6 diagonal (Fossen 2021, sec. 8.4.2).

    ``M_A = diag(k1 m, k2 m, k2 m, r44 Ix, k' Iy, k' Iy)``, with ``r44`` the roll ratio.
    """
    e = math.sqrt(1.0 - (b / a) ** 2)
    log_term = math.log((1.0 + e) / (1.0 - e))
    alpha_0 = (2.0 * (1.0 - e**2) / e**3) * (0.5 * log_term - e)
    beta_0 = 1.0 / e**2 - (1.0 - e**2) / (2.0 * e**3) * log_term
    k1 = alpha_0 / (2.0 - alpha_0)
    k2 = beta_0 / (2.0 - beta_0)
    k_prime = e**4 * (beta_0 - alpha_0) / ((2.0 - e**2) * (2.0 * e**2 - (2.0 - e**2) * (beta_0 - alpha_0)))
    return np.diag([m * k1, m * k2, m * k2, r44 * Ix, k_prime * Iy, k_prime * Iy])


def current_velocity(V_c, beta_c, psi, dof: int = 6):
    """Body-frame current velocity nu_c, (dof,): ``u_c = V_c cos(beta_c - psi)``, ``v_c = V_c sin(beta_c - psi)``.

    V_c (m/s), beta_c (rad, direction the current flows towards, from north), psi (rad).
    """
    u_c = V_c * ca.cos(beta_c - psi)
    v_c = V_c * ca.sin(beta_c - psi)
    return ca.vertcat(u_c, v_c, *([0.0] * (dof - 2)))


def current_velocity_derivative(V_c, beta_c, psi, r, dof: int = 6):
    """Time derivative of nu_c for an irrotational current constant in NED: ``(r v_c, -r u_c, 0, ...)``."""
    nu_c = current_velocity(V_c, beta_c, psi, dof)
    return ca.vertcat(r * nu_c[1], -r * nu_c[0], *([0.0] * (dof - 2)))


# Hoerner's 2-D cross-flow drag coefficient against B / (2 T) (Hoerner 1965, digitised).
_HOERNER_B_2T = (0.0109, 0.1766, 0.3530, 0.4519, 0.4728, 0.4929, 0.4933, 0.5585, 0.6464, 0.8336,
                 0.9880, 1.3081, 1.6392, 1.8600, 2.3129, 2.6000, 3.0088, 3.4508, 3.7379, 4.0031)
_HOERNER_CD = (1.9661, 1.9657, 1.8976, 1.7872, 1.5837, 1.2786, 1.2108, 1.0836, 0.9986, 0.8796,
               0.8284, 0.7599, 0.6914, 0.6571, 0.6307, 0.5962, 0.5868, 0.5859, 0.5599, 0.5593)


def hoerner_cd(B: float, T: float) -> float:
    """2-D cross-flow drag coefficient from Hoerner's curve at B/(2T), linear interpolation."""
    return float(np.interp(B / (2.0 * T), _HOERNER_B_2T, _HOERNER_CD))


def _power_sum(count, power: int):
    """``sum_{k=0}^{count-1} k^power`` in closed form (power 0..3), count an SX or float."""
    return (count, count * (count - 1) / 2, (count - 1) * count * (2 * count - 1) / 6,
            (count * (count - 1) / 2) ** 2)[power]


def crossflow_drag(L: float, B: float, T: float, nu_r, rho: float, strips: int = 20):
    """Cross-flow drag by strip theory, (6,) = (0, Y_h, 0, 0, 0, N_h) (Fossen 2021, eq. 6.131).

    ``Y_h = -1/2 rho T C_d sum |v_r + x r| (v_r + x r) dx`` over the stations
    ``x_k = -L/2 + k L/strips``, k = 0..strips (strips + 1 stations, as the field's reference
    simulator sums them), and ``N_h`` the same with an extra factor x.

    The sum is evaluated exactly in closed form rather than station by station: with
    ``a_k = v_r + x_k r`` and ``s_k = sign(a_k)``, ``sum x_k^j |a_k| a_k`` is
    ``v^2 S_j + 2 v r S_{j+1} + r^2 S_{j+2}`` with the signed moments ``S_i = sum s_k x_k^i``,
    and since a_k is monotone in k the signs change once, at the count c of stations with
    ``x_k < -v_r/r``: ``S_i = +-(T_i - 2 P_i(c))`` with T and P full and partial power sums,
    polynomials in c. Half the operations of the station loop (the fast simulations' largest
    single term), the same value to rounding; the count has derivative 0, so Jacobians are
    those of the station sum.

    L length (m), B beam (m), T draft (m), nu_r (6,) relative velocity, rho (kg/m^3).
    """
    scale = 0.5 * rho * T * hoerner_cd(B, T) * L / strips
    v_r, r = nu_r[1], nu_r[5]
    x0, h, stations = -L / 2.0, L / strips, strips + 1
    # stations with a_k < 0 when r > 0 (those with x_k < -v/r); with r = 0 all or none, by the sign of v
    root_count = ca.fmin(ca.fmax(ca.ceil((-v_r / ca.if_else(r == 0, 1.0, r) - x0) / h), 0), stations)
    below = ca.if_else(r == 0, ca.if_else(v_r < 0, stations, 0.0), root_count)

    def partial(count, power: int):
        """sum_{k<count} x_k^power, x_k = x0 + k h (binomial expansion)."""
        return sum(math.comb(power, i) * x0 ** (power - i) * h**i * _power_sum(count, i) for i in range(power + 1))

    sign = ca.if_else(r < 0, -1.0, 1.0)  # the stations above the root are positive when r >= 0
    moments = [sign * (partial(float(stations), i) - 2 * partial(below, i)) for i in range(4)]
    Y = -scale * (v_r**2 * moments[0] + 2 * v_r * r * moments[1] + r**2 * moments[2])
    N = -scale * (v_r**2 * moments[1] + 2 * v_r * r * moments[2] + r**2 * moments[3])
    return ca.vertcat(0.0, Y, 0.0, 0.0, 0.0, N)


def lift_drag(span: float, area: float, CD_0: float, nu_r, rho: float):
    """Hull lift and drag of a submerged wing profile, (6,) (Beard and McLain 2012; Fossen 2021).

    ``alpha = atan2(w_r, u_r)``, ``CL = CL_alpha alpha`` with
    ``CL_alpha = pi AR / (1 + sqrt(1 + (AR/2)^2))``, ``CD = CD_0 + CL^2 / (pi e AR)``, e = 0.7,
    ``AR = span^2 / area``; forces ``1/2 rho U_r^2 area C`` rotated from flow to body axes.

    span (m), area (m^2), CD_0 (-), nu_r (6,) relative velocity, rho (kg/m^3).
    """
    oswald = 0.7
    aspect = span**2 / area
    cl_alpha = math.pi * aspect / (1.0 + math.sqrt(1.0 + (aspect / 2.0) ** 2))
    u_r, v_r, w_r = nu_r[0], nu_r[1], nu_r[2]
    u_eps = u_r + SPEED_EPS
    alpha = ca.atan2(w_r, u_eps)
    CL = cl_alpha * alpha
    CD = CD_0 + CL**2 / (math.pi * oswald * aspect)
    q_area = 0.5 * rho * (u_r**2 + v_r**2 + w_r**2) * area
    F_drag, F_lift = q_area * CD, q_area * CL
    # cos and sin of alpha without evaluating them: (u, w) / |(u, w)|
    norm = ca.sqrt(u_eps**2 + w_r**2)
    ca_, sa_ = u_eps / norm, w_r / norm
    return ca.vertcat(ca_ * (-F_drag) - sa_ * (-F_lift), 0.0,
                      sa_ * (-F_drag) + ca_ * (-F_lift), 0.0, 0.0, 0.0)


def restoring_submerged(W: float, B: float, phi, theta, r_bg, r_bb):
    """Restoring forces of a submerged body, g(eta), (6,) (Fossen 2021, eq. 4.6).

    W weight (N), B buoyancy (N), phi/theta (rad), r_bg/r_bb CG/CB from the CO (m).
    """
    sth, cth = ca.sin(theta), ca.cos(theta)
    sphi, cphi = ca.sin(phi), ca.cos(phi)
    xg, yg, zg = r_bg
    xb, yb, zb = r_bb
    return stack([
        [(W - B) * sth],
        [-(W - B) * cth * sphi],
        [-(W - B) * cth * cphi],
        [-(yg * W - yb * B) * cth * cphi + (zg * W - zb * B) * cth * sphi],
        [(zg * W - zb * B) * sth + (xg * W - xb * B) * cth * cphi],
        [-(xg * W - xb * B) * cth * sphi - (yg * W - yb * B) * sth],
    ])
