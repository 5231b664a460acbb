"""model.array: the geometry convention the simulator and the angle estimators share."""

import dataclasses

import numpy as np

from model.array import cartesian, direction_cosines, steering, tx_slots
from model.config import get_preset


def test_ula_steering_is_the_reference_convention() -> None:
    cfg = get_preset("full")
    s = steering(cfg.virtual_positions_hw, np.array([0.3, -0.5]))
    v = np.arange(cfg.n_virtual)
    assert s.shape == (2, cfg.n_virtual)
    np.testing.assert_allclose(s[0], np.exp(-1j * np.pi * v * 0.3))
    np.testing.assert_allclose(s[1], np.exp(-1j * np.pi * v * -0.5))


def test_vertical_element_sees_elevation_only() -> None:
    u, w = direction_cosines(np.radians(30.0), np.radians(10.0))
    s = steering(np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]), u, w)
    np.testing.assert_allclose(np.angle(s[1] / s[0]), -np.pi * np.sin(np.radians(10.0)))
    np.testing.assert_allclose(np.angle(s[2] / s[0]),
                               -np.pi * np.sin(np.radians(30.0)) * np.cos(np.radians(10.0)))


def test_cartesian_and_slots() -> None:
    x, y, z = cartesian(10.0, np.radians(90.0), 0.0)
    np.testing.assert_allclose([x, y, z], [0.0, 10.0, 0.0], atol=1e-12)
    x, y, z = cartesian(10.0, 0.0, np.radians(30.0))
    np.testing.assert_allclose([x, y, z], [10 * np.cos(np.radians(30)), 0.0, 5.0])
    cfg = get_preset("full")
    assert list(tx_slots(cfg)) == [0, 1, 2, 3]
    order = (2, 0, 3, 1)
    slots = tx_slots(dataclasses.replace(cfg, tx_order=order))
    assert [order[s] for s in slots] == [0, 1, 2, 3]
