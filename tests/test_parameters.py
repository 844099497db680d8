"""Bad parameters raise ModelError naming the parameter; overrides change the model."""

import math

import numpy as np
import pytest

import uvsym
from uvsym.errors import ModelError, UnknownNameError
from uvsym.models.model import VehicleEquations, assemble
from uvsym.models.parameters import ParameterSet


@pytest.mark.parametrize(("name", "overrides", "message"), [
    ("remus100", {"rho": -1.0}, "'rho' = -1.0 kg/m^3 must be > 0.0"),
    ("remus100", {"L": math.nan}, "'L' must be finite"),
    ("remus100", {"diam": math.inf}, "'diam' must be finite"),
    ("remus100", {"diam": 2.0}, "'diam' = 2.0 m must be smaller than 'L'"),
    ("remus100", {"r_bg": [0.0, 0.02]}, "'r_bg' must have 3 entries"),
    ("remus100", {"rho": [1.0, 2.0]}, "'rho' must have 1 entry"),
    ("remus100", {"rho": "heavy"}, "'rho' must be a number"),
    ("remus100", {"t_prop": 1.5}, "'t_prop' = 1.5 - must be < 1.0"),
    ("remus100", {"densty": 1000.0}, "unknown parameter(s) ['densty']"),
    ("otter", {"Cw_pont": 0.0}, "'Cw_pont' = 0.0 - must be > 0.0"),
    ("otter", {"mp": -5.0}, "'mp' = -5.0 kg must be >= 0.0"),
    ("docking_auv", {"X_min": 10.0}, "'X_min' = 10.0 N must be <= 0.0"),
])
def test_bad_parameter_is_named(name, overrides, message):
    with pytest.raises(ModelError) as info:
        uvsym.vehicle(name, **overrides)
    assert message in str(info.value)
    assert str(info.value).startswith(name)


def test_unknown_vehicle_lists_known_names():
    with pytest.raises(UnknownNameError, match="remus100, torpedo, docking_auv, otter, otter3dof"):
        uvsym.vehicle("remus1000")


def test_override_changes_the_model():
    default = uvsym.vehicle("otter")
    heavier = uvsym.vehicle("otter", mp=40.0)
    assert heavier.M[0, 0] == pytest.approx(default.M[0, 0] + 15.0)
    assert heavier.parameters.v("mp") == 40.0 and default.parameters.v("mp") == 25.0
    assert uvsym.vehicle("otter", mp=40.0) is heavier  # frozen models are shared


def _equations(M, labels=("a",), units=("N",), u_min=(-1.0,), u_max=(1.0,)):
    import casadi as ca
    n = M.shape[0]
    return VehicleEquations(
        M=M, hull_terms=lambda eta, nu, nu_r: {"damping": nu_r},
        actuation=lambda eta, nu, nu_r, u: ca.vertcat(u[0], *([0] * (n - 1))),
        actuator_rate=lambda u, u_cmd: u_cmd - u,
        input_labels=labels, input_units=units, u_min=u_min, u_max=u_max)


@pytest.mark.parametrize(("M", "message"), [
    (np.diag([1.0, 2.0, -3.0]), "not positive definite"),
    (np.array([[1.0, 0.5, 0], [0.0, 1.0, 0], [0, 0, 1.0]]), "not symmetric"),
    (np.diag([1.0, np.nan, 1.0]), "non-finite"),
    (np.eye(4), "must be 3x3"),
])
def test_mass_matrix_is_validated(M, message):
    with pytest.raises(ModelError, match=message):
        assemble("test", "test", 3, ParameterSet("test", {}), _equations(M))


def test_inconsistent_inputs_are_rejected():
    with pytest.raises(ModelError, match="input_units has 2 entries"):
        assemble("test", "", 3, ParameterSet("test", {}), _equations(np.eye(3), units=("N", "N")))
    with pytest.raises(ModelError, match="lower bound 1.0 >= upper bound"):
        assemble("test", "", 3, ParameterSet("test", {}), _equations(np.eye(3), u_min=(1.0,)))


def test_every_parameter_has_a_unit_and_description():
    for name in uvsym.vehicle_names():
        for parameter in uvsym.vehicle(name).parameters.values():
            assert parameter.unit, f"{name}.{parameter.name} has no unit"
            assert parameter.description, f"{name}.{parameter.name} has no description"
