"""Rigid walls of the explicit solver (ctmrpim.solvers.explicit.contact): no slip, frictionless, Coulomb, release."""
from __future__ import annotations

import numpy as np
import pytest

from ctmrpim.errors import ProblemError
from ctmrpim.problem.model import Wall
from ctmrpim.solvers.explicit.contact import contact, wall_table


def enforce_walls(walls: list[Wall], x: np.ndarray, v: np.ndarray, dt: float) -> np.ndarray:
    """The step's contact (:func:`contact`, the walls in turn) at every node: the half-step velocities after it."""
    table = wall_table(tuple(walls))
    return np.array([contact(table, *xi, *vi, dt) for xi, vi in zip(x, v)])


def test_walls_no_slip_frictionless_coulomb_and_release():
    base = Wall("base", (0, 0), (0, 2))                       # normal normalised on construction
    assert base.normal == (0.0, 1.0)
    x = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 1e-3], [0.0, 0.0]])
    v = np.array([[1.0, -2.0], [1.0, -2.0], [1.0, -2.0], [1.0, 3.0]])
    dt = 1e-3
    no_slip = enforce_walls([base], x, v, dt)
    assert np.array_equal(no_slip[0], [0.0, 0.0])            # on the base, pressed: stopped
    assert no_slip[2] == pytest.approx([0.0, -1.0])          # lands exactly on the base this step, no slip
    assert np.array_equal(no_slip[3], v[3])                  # moving away: free
    smooth = enforce_walls([Wall("b", (0, 0), (0, 1), friction=0.0)], x, v, dt)
    assert smooth[0] == pytest.approx([1.0, 0.0])            # tangential velocity kept
    rough = enforce_walls([Wall("b", (0, 0), (0, 1), friction=0.3)], x, v, dt)
    assert rough[0] == pytest.approx([1.0 - 0.3 * 2.0, 0.0])  # Coulomb: |dv_t| = mu |dv_n|
    sticky = enforce_walls([Wall("b", (0, 0), (0, 1), friction=0.6)], x, v, dt)
    assert sticky[0] == pytest.approx([0.0, 0.0])            # mu |dv_n| >= |v_t|: stick
    with pytest.raises(ProblemError):
        Wall("w", (0, 0), (0, 0))
    with pytest.raises(ProblemError):
        Wall("w", (0, 0), (0, 1), friction=-0.1)
