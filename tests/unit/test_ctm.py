"""CTM integration (Eqs. 12-24): exact polynomial moments over non-convex polygons with holes."""
from __future__ import annotations

import numpy as np
import pytest
import shapely
from clouds import GEOMETRIES
from shapely.geometry import Polygon

from ctmrpim.discretisation.ctm import boundary_points, integration_points
from studies.tolerances import entry

ROUNDOFF = entry("roundoff")["max"]
MONOMIALS = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]


def exact_moment(poly: Polygon, p: int, q: int) -> float:
    """int x^p y^q dA by Green's theorem, oint x^(p+1)/(p+1) y^q dy over the oriented rings
    (exterior counter-clockwise, holes clockwise), Gauss-exact on each straight edge."""
    g, w = np.polynomial.legendre.leggauss(6)
    t, w = 0.5 * (g + 1), 0.5 * w
    poly = shapely.geometry.polygon.orient(poly, 1.0)
    total = 0.0
    for ring in [poly.exterior, *poly.interiors]:
        c = np.asarray(ring.coords)
        a, b = c[:-1], c[1:]
        X = a[:, :1] + t * (b[:, :1] - a[:, :1])
        Y = a[:, 1:] + t * (b[:, 1:] - a[:, 1:])
        total += ((X ** (p + 1) / (p + 1) * Y ** q) * w).sum(axis=1) @ (b[:, 1] - a[:, 1])
    return total


POLYGONS = {
    "l-shape-with-hole": Polygon([(0, 0), (4, 0), (4, 1.3), (1.7, 1.3), (1.7, 3), (0, 3)],
                                 [[(0.5, 0.5), (0.8, 1.9), (1.2, 0.6)]]),
    "comb": Polygon([(0, 0), (5, 0), (5, 2), (4, 2), (4, 0.5), (3, 0.5), (3, 2), (2, 2), (2, 0.5), (1, 0.5),
                     (1, 2), (0, 2)]),
    "two-holes": Polygon([(-1, -1), (3, -1.5), (2.5, 2), (-1.2, 1.5)],
                         [[(0, 0), (0.5, 0), (0.5, 0.5), (0, 0.5)], [(1.5, 0.2), (2.0, 0.9), (1.2, 1.0)]]),
    **{name: g.region for name, g in GEOMETRIES.items()},
}


def loops_of(poly: Polygon) -> list[np.ndarray]:
    poly = shapely.geometry.polygon.orient(poly, 1.0)
    return [np.asarray(poly.exterior.coords)[:-1]] + [np.asarray(r.coords)[:-1] for r in poly.interiors]


@pytest.mark.parametrize("name", sorted(POLYGONS))
@pytest.mark.parametrize("gauss", [2, 3])
def test_exact_mode_integrates_quadratics(name: str, gauss: int) -> None:
    poly = POLYGONS[name]
    size = np.sqrt(poly.area)
    q = integration_points(loops_of(poly), 0.37 * size, 0.29 * size, gauss, mode="exact")
    x, y = q.points[:, 0], q.points[:, 1]
    assert shapely.contains_xy(poly, x, y).all()
    for p, r in MONOMIALS:
        ref = exact_moment(poly, p, r)
        scale = poly.area * max(abs(c) for c in poly.bounds) ** (p + r) + 1e-300
        assert abs(q.weights @ (x ** p * y ** r) - ref) <= ROUNDOFF * scale, (p, r)


def test_orientation_does_not_matter() -> None:
    poly = POLYGONS["two-holes"]
    loops = loops_of(poly)
    a = integration_points(loops, 0.3, 0.3, 2, mode="exact")
    b = integration_points([lp[::-1] for lp in loops], 0.3, 0.3, 2, mode="exact")
    assert a.weights.sum() == pytest.approx(b.weights.sum(), rel=ROUNDOFF)


def test_lines_through_vertices_are_neither_dropped_nor_doubled() -> None:
    """A diamond whose vertices sit exactly on integration lines, and a notch vertex too."""
    diamond = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
    for n_bands in (1, 2, 4):  # with 1 Gauss point the lines sit at band centres: y = 0 is one of them
        q = integration_points([diamond], 2.0 / n_bands, 2.0 / n_bands, 1, mode="uniform")
        # midpoint rule in y on a piecewise linear width: exact on each band when bands break at y = 0
        if n_bands % 2 == 0:
            assert q.weights.sum() == pytest.approx(2.0, rel=ROUNDOFF)
    notch = np.array([[0, 0], [2, 0], [2, 2], [1, 1], [0, 2]], float)  # vertex (1, 1) on the line y = 1
    q = integration_points([notch], 0.1, 2.0 / 3.0, 1, mode="uniform")
    assert np.isclose(q.points[:, 1], 1.0).any()
    on_line = np.isclose(q.points[:, 1], 1.0)
    assert q.weights[on_line].sum() / (2.0 / 3.0) == pytest.approx(2.0, rel=ROUNDOFF)  # width at y = 1 is 2


def test_uniform_mode_on_rectangle_matches_paper_counts() -> None:
    """Cantilever 33 x 9: r_x = r_y = d_c/3, one Gauss point; weights sum to the area."""
    L, W, n = 48.0, 12.0, 33 * 9
    d_c = np.sqrt(L * W / (n - 1))
    rect = np.array([[0, -6], [48, -6], [48, 6], [0, 6]], float)
    q = integration_points([rect], d_c / 3, d_c / 3, 1)
    assert q.weights.sum() == pytest.approx(L * W, rel=ROUNDOFF)
    assert q.n_lines == round(W / (d_c / 3))
    assert len(q.weights) == q.n_lines * round(L / (d_c / 3))


def test_boundary_points_integrate_linear_tractions_and_normals() -> None:
    seg = np.array([[[0.0, 0.0], [2.0, 1.0]], [[2.0, 1.0], [0.0, 3.0]]])
    q = boundary_points(seg, 2)
    length = np.hypot(2, 1) + np.hypot(2, 2)
    assert q.weights.sum() == pytest.approx(length, rel=ROUNDOFF)
    f = 1 + q.points[:, 0] + 2 * q.points[:, 1]
    exact = np.hypot(2, 1) * (1 + 1 + 1) + np.hypot(2, 2) * (1 + 1 + 4)
    assert q.weights @ f == pytest.approx(exact, rel=ROUNDOFF)
    # body on the left of each segment: outward normal on the right
    assert q.normals[0] @ np.array([1.0, -2.0]) / np.sqrt(5) == pytest.approx(1.0)
