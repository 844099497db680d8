"""The quadrotor UIO-bank study: its plant and the paper's failing set-up (scenarios: test_uio_zonotope_scenarios)."""

from __future__ import annotations

import numpy as np
import pytest

from derivations.uio_zonotope.design import ATTITUDE, DT, sampled
from uvsym.errors import UIOConditionError
from uvsym.observers.uio import uio_conditions


def test_sampled_plant_is_the_zero_order_hold_of_the_hover_model():
    """Hand ZOH of the double integrators: G = I + dt A (A^2 = 0), H = dt B + dt^2/2 A B."""
    plant, G, H, _ = sampled()
    from derivations.uio_zonotope.design import linear_plant

    lin = linear_plant().linearize()
    assert plant.dt == DT
    np.testing.assert_allclose(lin.A @ lin.A, 0, atol=1e-15)
    np.testing.assert_allclose(G, np.eye(8) + DT * lin.A, atol=1e-14)
    np.testing.assert_allclose(H, DT * lin.B + DT ** 2 / 2 * lin.A @ lin.B, rtol=1e-12, atol=1e-16)


def test_angle_only_set_up_fails_at_the_sampling_zero():
    _, G, _, D1 = sampled(ATTITUDE)
    with pytest.raises(UIOConditionError) as info:
        uio_conditions(G, np.eye(6)[:3], D1)
    assert any(abs(v + 1) < 1e-6 for v in info.value.eigenvalues)


def test_a_yaw_torque_made_by_the_four_rotors_together_is_invisible_to_every_observer():
    """The limits' "front and back rotors up, right and left down": that input acts along D1, which every
    observer decouples."""
    plant, _, H, D1 = sampled()
    assert plant.u.names == ("Vf", "Vb", "Vr", "Vl")
    torque = H @ np.array([1.0, 1.0, -1.0, -1.0])
    along = D1 @ np.linalg.lstsq(D1, torque, rcond=None)[0]
    assert np.linalg.norm(torque) > 1e-4 and np.linalg.norm(torque - along) < 1e-12 * np.linalg.norm(torque)
