"""Problem geometry (ctmrpim.problem.geometry): circles as polygons, areas, add and subtract, loop orientation."""
from __future__ import annotations

import math

import numpy as np
import pytest

from ctmrpim.problem.geometry import CIRCLE_SAGITTA, Geometry, Shape, circle_segments


def test_circle_polygon_sagitta() -> None:
    cx, cy, r = 1.0, -2.0, 3.0
    poly = Shape("circle", (cx, cy, r)).polygon()
    v = np.asarray(poly.exterior.coords)[:-1]
    assert len(v) == circle_segments()
    np.testing.assert_allclose(np.hypot(v[:, 0] - cx, v[:, 1] - cy), r, rtol=1e-14)   # vertices on the arc
    mid = 0.5 * (v + np.roll(v, -1, axis=0))
    sagitta = r - np.hypot(mid[:, 0] - cx, mid[:, 1] - cy)       # chord midpoint to arc
    assert sagitta.max() <= CIRCLE_SAGITTA * r
    assert sagitta.max() > 0.5 * CIRCLE_SAGITTA * r             # and not needlessly fine


def test_rectangle_minus_circle_area() -> None:
    a, b, r = 10.0, 8.0, 1.0
    g = Geometry(add=[Shape("rectangle", (0.0, 0.0, a, b))], subtract=[Shape("circle", (4.0, 3.0, r))])
    exact = a * b - math.pi * r**2
    # the polygon misses (4/3) pi r^2 CIRCLE_SAGITTA of the hole at most (segments of height <= sagitta)
    assert 0 <= g.area - exact <= 4 / 3 * math.pi * r**2 * CIRCLE_SAGITTA
    assert g.area == pytest.approx(exact, rel=1e-6)
    assert len(g.loops()) == 2 and g.circles == [(4.0, 3.0, r)] and not g.is_rectangle()


def test_add_and_subtract() -> None:
    # an L shape from two overlapping rectangles, a triangle notch cut from it
    g = Geometry(add=[Shape("rectangle", (0, 0, 4, 1)), Shape("rectangle", (0, 0, 1, 3))],
                 subtract=[Shape("polygon", ((3, 0), (4, 0), (4, 1)))])
    assert g.area == pytest.approx(4 + 2 - 0.5, rel=1e-15)
    assert g.bounds == (0.0, 0.0, 4.0, 3.0) and len(g.loops()) == 1
    # two separate parts stay two parts
    two = Geometry(add=[Shape("rectangle", (0, 0, 1, 1)), Shape("rectangle", (2, 0, 3, 1))])
    assert len(two.polygons) == 2 and two.area == 2.0


def test_boundary_loops_keep_the_body_on_the_left() -> None:
    g = Geometry(add=[Shape("rectangle", (0, 0, 4, 4))], subtract=[Shape("circle", (2, 2, 1))])
    outer, hole = g.loops()

    def signed_area(p: np.ndarray) -> float:
        return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
    assert signed_area(outer) == pytest.approx(16.0) and signed_area(hole) < 0
