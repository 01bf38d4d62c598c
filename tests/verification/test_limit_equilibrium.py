"""Bishop's simplified method (the limit-equilibrium reference of the slope benchmarks): the two
geometries of issue 5 against their quoted factors of safety, and properties of one circle."""
from __future__ import annotations

import numpy as np
import pytest
import shapely
from verify import check

from ctmrpim.reference.limit_equilibrium import bishop, critical_circle, top_surface

EMBANKMENT = np.array([[0, 15], [20, 15], [40, 5], [60, 5]], float)    # Smith & Griffiths 6.4, base y = 0
GRIFFITHS_LANE = np.array([[0, 10], [12, 10], [32, 0]], float)         # Griffiths & Lane (1999) Ex. 1
SOIL = dict(gamma=20e3, c=10e3, phi=20.0)


@pytest.mark.parametrize("surface, key, quoted", [(EMBANKMENT, "bishop-slope", 1.368),
                                                  (GRIFFITHS_LANE, "bishop-slope-gl", 1.378)])
def test_critical_circle_matches_the_quoted_factor_of_safety(surface, key: str, quoted: float) -> None:
    s = critical_circle(surface, **SOIL, base=0.0)
    check(key, abs(s.fs / quoted - 1.0))
    assert s.yc - s.radius >= -1e-9                       # never below the rigid base
    assert surface[0, 0] <= s.x_entry < s.x_exit <= surface[-1, 0]


def test_one_circle_scales_as_the_method_says() -> None:
    """Purely cohesive soil: FS = c * arc length * R / (moment of the weight), so FS ~ c and ~ 1/gamma."""
    s1 = bishop(EMBANKMENT, 20e3, 10e3, 0.0, 36.0, 28.0, 23.0)
    s2 = bishop(EMBANKMENT, 20e3, 20e3, 0.0, 36.0, 28.0, 23.0)
    s3 = bishop(EMBANKMENT, 40e3, 10e3, 0.0, 36.0, 28.0, 23.0)
    assert s2.fs == pytest.approx(2 * s1.fs, rel=1e-12)
    assert s3.fs == pytest.approx(0.5 * s1.fs, rel=1e-12)
    assert bishop(EMBANKMENT, **SOIL, xc=36.0, yc=28.0, radius=5.0) is None   # misses the slope


def test_top_surface_of_a_polygon() -> None:
    poly = shapely.Polygon([(0, 0), (60, 0), (60, 5), (40, 5), (20, 15), (0, 15)])
    assert np.allclose(top_surface(poly), EMBANKMENT)


def test_top_surface_of_a_problem_geometry() -> None:
    from ctmrpim.problem.geometry import Geometry, Shape

    g = Geometry(add=[Shape("polygon", [(0, 0), (32, 0), (12, 10), (0, 10)])])
    assert np.allclose(top_surface(g), GRIFFITHS_LANE)
