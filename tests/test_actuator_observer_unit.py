"""The observer builders pass their form on: with ``x = 0`` the estimate is ``f_hat = -R``, and R is, by the module's
definitions, ``-K M^-1 T_d nu`` (paper) or ``-K T_d M nu`` (momentum) for the proportional observer and
``-K M^-1 nu`` or ``-K M nu`` for the bias and constant ones; the expected values are those products, by hand."""

from __future__ import annotations

import numpy as np
import pytest

from uvsym import vehicle
from uvsym.observers import bias_observer, constant_observer, proportional_observer

NU = np.array([1.2, 0.1, 0.05])  # m/s, m/s, rad/s
TAU_D = np.array([40.0, 3.0, 8.0])  # N, N, N m
K = np.array([2.0, 3.0, 0.5])


@pytest.mark.parametrize("builder, scales", [(proportional_observer, True), (bias_observer, False),
                                             (constant_observer, False)])
def test_each_builder_passes_its_form_on(builder, scales):
    model = vehicle("otter3dof")  # diagonal M
    M = model.M
    T_d = np.diag(TAU_D) if scales else np.eye(3)
    expected = {"paper": np.diag(K) @ np.linalg.inv(M) @ T_d @ NU, "momentum": np.diag(K) @ T_d @ M @ NU}
    assert not np.allclose(expected["paper"], expected["momentum"])  # the forms differ on this vehicle
    for form, f_hat in expected.items():
        function = builder(model, form)
        np.testing.assert_allclose(np.asarray(function(np.zeros(3), np.zeros(3), NU, TAU_D, K)[1]).ravel(), f_hat,
                                   rtol=1e-12)
