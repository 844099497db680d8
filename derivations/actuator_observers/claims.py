"""Liu et al. 2014's claims, checked by machine (Theorems 1-3, Remark 2, section 3.2), with negative controls.

Theorems 1-3: the derived error dynamics against the paper's closed forms, and convergence over
sets of desired actions by LMI (:mod:`uvsym.verify.observers`). The closed forms are proved in
exact rationals on the models' double constants where the two sides agree exactly; the paper
form on the docking AUV's coupled M holds only up to the rounding of those constants (``M^-1 M``
is the identity to about 1e-16), so Theorems 2 and 3 there are ``checked`` by sampling at 50
digits, not proved, and say why no proof of that graph exists: CasADi folds products of M^-1's
double constants into rounded doubles, so the graph's two sides differ in exact arithmetic by
rounding residues. The same identities with M^-1 and h as free symbols (any plant of 6 DOF) are
proved in exact arithmetic; a wrong closed form is refuted. Section 3.2 argues with a generic
feedback; uvsym makes it concrete (its choice, stated in every claim): the 3-DOF Otter (no
restoring forces) under ``u_d = -k B^T nu`` on its twin thrusters, with the experiment's pair of
faults, a bias of 13 N on one thruster and a factor 0.8 on the other
(:mod:`uvsym.verify.fault_tolerant`):

- healthy: ``V' <= -gamma nu^T nu`` on the box (proved);
- faulty with the correction from exact estimates: the same (proved);
- faulty without correction: V' is positive near the equilibrium along ``B f_a`` (refuted, a
  negative control);
- corrected with the paper's estimates (13.0043, 0.8001): the residual bias of 0.0043 N still
  makes V' positive close to the equilibrium (refuted): the paper's ``V'_FTC = V' < 0`` needs
  exact estimates; otherwise only a neighbourhood of nu = 0 is reached.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from derivations.actuator_observers.paper import PAPER, TRUE
from uvsym.faults import ActuatorFault
from uvsym.models.registry import vehicle
from uvsym.observers.actuator import actuator_observer
from uvsym.verify.certificate import Certificate
from uvsym.verify.fault_tolerant import damping_injection_loop, kinetic_energy_decrease
from uvsym.verify.lyapunov import lyapunov_decrease
from uvsym.verify.observers import any_plant_error_dynamics_claim, convergence_claim, error_dynamics_claim

__all__ = ["core_paper_claims", "coupled_mass_claim", "fault_tolerant_loop_claims"]

THEOREMS = {"proportional": "Theorem 1", "bias": "Theorem 2", "constant": "Theorem 3"}
GAINS = np.full(6, 3.0)  # K of the convergence claims (1/s per (N or N m)^2 or 1/s: momentum form)
LOOP_VEHICLE = "otter3dof"
FEEDBACK_GAIN = 50.0  # k of u_d = -k B^T nu, N s/m
VELOCITY_BOX = np.array([3.0, 1.0, 1.0])  # |u| m/s, |v| m/s, |r| rad/s
CUBE = 0.05  # half-side of the cube around nu = 0 covered by the Hessian argument
FAULTS = (ActuatorFault(0, "bias", TRUE["f_a"]), ActuatorFault(1, "proportional", TRUE["f_p"]))
PAPER_ESTIMATES = (PAPER["f_bar_a"], PAPER["f_bar_p"])  # the paper's f_bar_a and f_bar_p (section 4)


def _dynamics(vehicle_name: str, kind: str, form: str = "paper", **options) -> Certificate:
    return error_dynamics_claim(THEOREMS[kind], actuator_observer(vehicle(vehicle_name), kind, form), **options)


def _graph_checked(vehicle_name: str, kind: str) -> Certificate:
    """The paper form's identity on the vehicle's own graph (``checked``), its method saying why no proof exists."""
    certificate = _dynamics(vehicle_name, kind, expected="checked")
    why = ("; no exact proof of this graph exists: CasADi folds products of M^-1's double constants into rounded "
           "doubles, which exact rational arithmetic leaves as residues (largest sampled relative difference "
           f"{certificate.details.get('largest_relative_difference', float('nan')):.1e}); the identity for any M^-1 "
           "and h is proved in the next row")
    return replace(certificate, method=certificate.method + why) if certificate.status == "checked" else certificate


def _convergence(vehicle_name: str, kind: str, K, tau_min: float, tau_max: float, **options) -> Certificate:
    observer = actuator_observer(vehicle(vehicle_name), kind, "momentum")
    return convergence_claim(THEOREMS[kind], observer, K, tau_min, tau_max, **options)


def coupled_mass_claim(vehicle_name: str = "docking_auv", expected: str = "refuted") -> Certificate:
    """Theorem 1's observer in the paper's form on a coupled M, with the gains the paper's rate suggests.

    ``k_i = M_ii^2`` gives every channel the rate ``k_i tau_d,i^2 / m_i^2 = 1`` when M is diagonal;
    with the docking AUV's sway-roll coupling and ``tau_d = (1, 1, 1, -1, 1, 1)`` the error
    matrix ``-K (M^-1 T_d)^2`` has an eigenvalue in the right half-plane: a negative control.
    """
    model = vehicle(vehicle_name)
    observer = actuator_observer(model, "proportional", "paper", require_assumption_1=False)
    K = np.diag(model.M) ** 2
    tau_d = np.ones(model.dof)
    tau_d[3] = -1.0  # roll against sway
    A = np.asarray(observer.error_matrix(tau_d, K))
    return lyapunov_decrease(f"Theorem 1 (paper form, {vehicle_name}, coupled M): V = e'Pe does not grow", [A], 0.0,
                             f"tau_d = {tau_d.tolist()} (N, N m), K_i = M_ii^2", expected)


def fault_tolerant_loop_claims() -> list[Certificate]:
    """Section 3.2: healthy and corrected loops proved; uncorrected, or corrected with the paper's
    slightly-off estimates, refuted near the equilibrium."""
    model, exact = vehicle(LOOP_VEHICLE), tuple(f.value for f in FAULTS)
    certificates = []
    for faults, estimates, name, expected in (
            ((), None, "healthy", "proved"),
            (FAULTS, exact, "faults corrected with exact estimates", "proved"),
            (FAULTS, None, "faults, no correction", "refuted"),
            (FAULTS, PAPER_ESTIMATES, "faults corrected with the paper's estimates", "refuted")):
        loop = damping_injection_loop(model, FEEDBACK_GAIN, faults, estimates, fault_time=1.0)
        certificates.append(kinetic_energy_decrease(f"Section 3.2 ({LOOP_VEHICLE}, {name})", loop, VELOCITY_BOX,
                                                    CUBE, expected))
    return certificates


def core_paper_claims() -> list[Certificate]:
    """Theorems 1-3 and section 3.2 by machine, the coupled-M variant, and negative controls that must be refuted."""
    return [
        _dynamics("otter3dof", "proportional"),
        _graph_checked("docking_auv", "bias"),
        any_plant_error_dynamics_claim(THEOREMS["bias"], "bias", "paper", 6),
        _graph_checked("docking_auv", "constant"),
        any_plant_error_dynamics_claim(THEOREMS["constant"], "constant", "paper", 6),
        any_plant_error_dynamics_claim(THEOREMS["proportional"], "proportional", "paper", 6),
        _dynamics("docking_auv", "proportional", "momentum"),
        _dynamics("remus100", "proportional", "momentum"),
        _dynamics("otter3dof", "proportional", constant_tau_d=False, expected="refuted"),
        _convergence("docking_auv", "proportional", GAINS, 0.5, 20.0, gamma=0.5),
        _convergence("remus100", "proportional", GAINS, 0.5, 20.0, gamma=0.5),
        _convergence("remus100", "bias", GAINS, 1.0, 1.0, gamma=1.0),
        _convergence("remus100", "bias", np.r_[GAINS[:5], -1.0], 1.0, 1.0, gamma=0.0, expected="refuted"),
        coupled_mass_claim(),
        *fault_tolerant_loop_claims(),
    ]
