"""Deposit measures of the column collapse (ctmrpim.reference.deposit) on shapes whose answers are known."""
from __future__ import annotations

import numpy as np
import pytest


def test_deposit_measures_of_known_shapes():
    from ctmrpim.reference.deposit import curve_distance, failure_line, run_out, slope_angle, surface_profile
    # a trapezoid deposit: 0.1 high at the wall, falling linearly to 0 at x = 0.4
    pts = np.array([[0.0, 0.0], [0.4, 0.0], [0.0, 0.1]])
    edges = np.array([[0, 1], [1, 2], [2, 0]])
    xs = np.linspace(0.0, 0.5, 501)
    h = surface_profile(pts, edges, xs)
    assert np.allclose(h, np.clip(0.1 * (1 - xs / 0.4), 0, None), atol=1e-12)
    assert run_out(xs, h, 0.01) == pytest.approx(0.36, abs=1e-9)
    assert slope_angle(xs, h, 0.04, 0.36) == pytest.approx(np.degrees(np.arctan(0.25)), abs=1e-9)
    nodes = np.array([[0.0, 0.0], [0.0, 0.05], [0.1, 0.0], [0.1, 0.05], [0.1, 0.09]])
    u = np.array([[0, 0], [0, 0], [0, 0], [0, 0], [0.02, 0.0]])
    assert np.allclose(failure_line(nodes, u, 0.005, np.array([0.0, 0.1, 0.3]), 0.01), [[0.0, 0.05], [0.1, 0.05]])
    assert np.allclose(curve_distance(np.array([[0.5, 1.0], [2.0, 0.0]]), np.array([[0.0, 0.0], [1.0, 0.0]])),
                       [1.0, 1.0])
