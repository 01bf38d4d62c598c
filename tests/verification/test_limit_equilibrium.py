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


VERTICAL_CUT = np.array([[0, 20], [20, 20], [20, 10], [40, 10]], float)    # H = 10 m on 10 m of clay, base y = 0
TAYLOR = 3.83 * 78.3e3 / (20e3 * 10.0)                                     # Taylor's N = gamma H / (F c) = 3.83


def test_top_surface_keeps_a_vertical_face() -> None:
    """The face of a cut is a vertical segment of the ground surface, crest end first, not a slope to the next
    vertex."""
    poly = shapely.Polygon([(0, 0), (40, 0), (40, 10), (20, 10), (20, 20), (0, 20)])
    assert np.allclose(top_surface(poly), VERTICAL_CUT)


def test_vertical_cut_against_taylor() -> None:
    """The vertical-cut benchmark (undrained, H = 10 m, c = 78.3 kPa, 20 kN/m3): Taylor's 3.83 gives 1.50; the
    critical circle enters behind the crest and exits through the face, its centre in front of the face."""
    from ctmrpim import benchmarks
    from ctmrpim.reference.limit_equilibrium import problem_factor_of_safety

    s = problem_factor_of_safety(benchmarks.load("vertical-cut").problem)
    check("bishop-vertical-cut", abs(s.fs / TAYLOR - 1.0))
    assert 0.0 < s.x_entry < 20.0 - 5.0 and 19.9 <= s.x_exit <= 20.0 < s.xc


def test_circles_must_enter_and_exit_through_the_ground() -> None:
    """The circle the search took before (FS 1.077): tangent to the base, still 10 m below the ground at the
    model's right edge; and a circle whose centre is below the crest, its lower arc ending under the ground."""
    assert bishop(VERTICAL_CUT, 20e3, 78.3e3, 0.0, 41.524, 34.608, 34.608, base=0.0) is None
    assert bishop(VERTICAL_CUT, 20e3, 78.3e3, 0.0, 12.0, 15.0, 6.0, base=0.0) is None
    # one crossing of the face and one of the foundation beyond it: the mass behind the face counts alone
    s = bishop(VERTICAL_CUT, 20e3, 78.3e3, 0.0, 36.0, 34.7, 29.4, base=0.0)
    assert s is not None and s.x_exit <= 20.0 and s.fs == pytest.approx(TAYLOR, rel=0.01)
