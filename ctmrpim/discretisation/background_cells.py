"""Background-cell Gauss integration (``method.integration = "cell-gauss"``): a comparator for CTM, not in
the paper.

The scheme the paper sets CTM against: a lattice of rectangular cells, r_x d_c by r_y d_c, over the body's
bounding box; a cell wholly inside the tracked boundary gets the tensor Gauss rule of ``gauss_points``
points each way, a cell the boundary cuts is clipped to the body (so the integration domain is the same
as CTM's), its clipped polygon triangulated (constrained Delaunay) and each triangle given the collapsed
(conical product) Gauss rule of ``gauss_points`` squared points, exact for polynomials of degree
2 gauss_points - 2. RPIM shape functions are not polynomials and their supports do not follow the cells,
so neither rule is exact for them: that inconsistency is what the integration-schemes study measures.
"""
from __future__ import annotations

import math

import numpy as np
import shapely

from ctmrpim.discretisation.ctm import gauss_legendre
from ctmrpim.errors import ProblemError


def body_polygon(loops: list[np.ndarray]) -> shapely.Geometry:
    """The region the closed ``loops`` (each (k, 2); outer loops and holes) enclose, by the even-odd rule
    (the rule CTM pairs its crossings by), as one shapely (multi)polygon."""
    region = shapely.Polygon()
    for loop in loops:
        region = shapely.symmetric_difference(region, shapely.make_valid(shapely.Polygon(loop)))
    return region


def cell_points(loops: list[np.ndarray], hx: float, hy: float, gauss_points: int) -> tuple[np.ndarray, np.ndarray]:
    """Integration points (m, 2) and area weights (m,) of background cells ``hx`` by ``hy`` over the region
    of ``loops``, ``gauss_points`` per direction in a whole cell and squared per triangle of a cut cell."""
    body = body_polygon(loops)
    shapely.prepare(body)
    x0, y0, x1, y1 = body.bounds
    nx, ny = max(1, math.ceil((x1 - x0) / hx)), max(1, math.ceil((y1 - y0) / hy))
    if nx * ny > 5e7:
        raise ProblemError(f"{nx * ny:.3g} background cells: make method.line_spacing larger", key="method.line_spacing")
    ix, iy = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    xa, ya = x0 + ix.ravel() * hx, y0 + iy.ravel() * hy
    boxes = shapely.box(xa, ya, xa + hx, ya + hy)
    whole = shapely.contains_properly(body, boxes)
    cut = ~whole & shapely.intersects(body, boxes)
    g, wg = gauss_legendre(gauss_points)
    # whole cells: the tensor rule mapped from [-1, 1]^2
    cx, cy = xa[whole] + 0.5 * hx, ya[whole] + 0.5 * hy
    gx, gy = np.meshgrid(g, g, indexing="ij")
    wxy = np.outer(wg, wg).ravel() * (0.25 * hx * hy)
    pts_whole = np.stack([cx[:, None] + 0.5 * hx * gx.ravel(), cy[:, None] + 0.5 * hy * gy.ravel()], axis=-1)
    w_whole = np.broadcast_to(wxy, (len(cx), len(wxy)))
    # cut cells: clipped, triangulated, the conical-product rule on each triangle
    tri = _triangles(shapely.intersection(boxes[cut], body))
    pts_cut, w_cut = _triangle_rule(tri, g, wg)
    return np.concatenate([pts_whole.reshape(-1, 2), pts_cut]), np.concatenate([w_whole.ravel(), w_cut])


def _triangles(regions: np.ndarray) -> np.ndarray:
    """(t, 3, 2) the triangles of a constrained Delaunay triangulation of every polygonal part of ``regions``."""
    parts = shapely.get_parts(regions)
    parts = parts[shapely.get_type_id(parts) == 3]              # polygons only: a cell may touch the body along a line
    parts = parts[shapely.area(parts) > 0]
    if len(parts) == 0:
        return np.zeros((0, 3, 2))
    triangles = shapely.get_parts(shapely.constrained_delaunay_triangles(parts))
    coords = shapely.get_coordinates(triangles)
    return coords.reshape(len(triangles), 4, 2)[:, :3]


def _triangle_rule(tri: np.ndarray, g: np.ndarray, wg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points (t k^2, 2) and weights of the conical-product rule (Gauss-Legendre in s and in t / (1 - s))
    on every triangle (t, 3, 2), from the k Gauss points ``g`` and weights ``wg`` on [-1, 1]."""
    a, wa = 0.5 * (g + 1.0), 0.5 * wg                          # the rule on [0, 1]
    s = np.repeat(a, len(a))
    t = (1.0 - s) * np.tile(a, len(a))
    w = np.repeat(wa, len(a)) * np.tile(wa, len(a)) * (1.0 - s)  # sums to 1/2, the reference triangle's area
    p0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    jac = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])    # twice the triangle's area
    pts = p0[:, None, :] + s[None, :, None] * e1[:, None, :] + t[None, :, None] * e2[:, None, :]
    return pts.reshape(-1, 2), (jac[:, None] * w[None, :]).ravel()
