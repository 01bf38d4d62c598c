"""Stabilised conforming nodal integration (``method.integration = "scni"``; Chen, Wu, Yoon & You 2001,
IJNME 50): a comparator for CTM, not in the paper.

Each node I owns its Voronoi cell Omega_I, clipped to the body's tracked boundary (area A_I). The strain
is smoothed over the cell, and by the divergence theorem the smoothed gradient of shape function J is a
boundary integral of its values only:

    b_kJ(x_I) = 1 / A_I  sum over the cell's boundary of  N_J n_k dGamma        (k = x, y)

evaluated with ``BOUNDARY_GAUSS_POINTS`` Gauss points on every edge of the clipped cell, outward normals n.
The stiffness is then K = sum_I B~_I^T D B~_I A_I: the nodes are the integration points, with weights A_I,
and the smoothed gradients take the place of the RPIM derivatives in the same assembly. The cells tile the
body, so the smoothed gradients of a linear field are exact and the linear patch test passes whatever the
shape functions' derivatives do; no derivative of an RPIM shape function is ever evaluated.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import shapely

from ctmrpim.discretisation.background_cells import body_polygon
from ctmrpim.discretisation.ctm import BoundaryQuadrature, boundary_points
from ctmrpim.errors import ProblemError

#: Gauss points per edge of a smoothing cell: RPIM values are not polynomials; 3 keeps the quadrature
#: error of the boundary integral below the smoothing's own
BOUNDARY_GAUSS_POINTS = 3


def smoothing_cells(nodes: np.ndarray, loops: list[np.ndarray]) -> np.ndarray:
    """The Voronoi cell of every node (n, 2) clipped to the region of ``loops`` (n shapely geometries, in node
    order; a cell may be a MultiPolygon where the body is not convex)."""
    body = body_polygon(loops)
    x0, y0, x1, y1 = body.bounds
    pad = max(x1 - x0, y1 - y0)
    frame = shapely.box(x0 - pad, y0 - pad, x1 + pad, y1 + pad)
    cells = shapely.get_parts(shapely.voronoi_polygons(shapely.multipoints(nodes), extend_to=frame, ordered=True))
    if len(cells) != len(nodes):
        raise ProblemError(f"scni: {len(nodes)} nodes gave {len(cells)} Voronoi cells (coincident nodes?)")
    # a regular grid's Voronoi vertices are co-circular, and GEOS builds some cells with a self-intersecting
    # sliver of round-off size there (invalid: the clip then fails); repaired, they lose only the sliver
    return shapely.intersection(shapely.make_valid(cells), body)


@dataclass
class NodalIntegration:
    """SCNI of n nodes: the smoothing cells' areas (n,), the smoothed gradients b_x, b_y (n, n; row I holds
    b_kJ(x_I), one sparsity pattern), and the Gauss points of the cell edges that lie on the body's boundary
    (``boundary``, with ``ends`` the tracked boundary segment each lies on) with the cell each belongs to
    (``owner``) and the shape functions' values there (``N_boundary``, (b, n))."""

    areas: np.ndarray
    bx: sp.csr_matrix
    by: sp.csr_matrix
    boundary: BoundaryQuadrature
    owner: np.ndarray
    N_boundary: sp.csr_matrix


def smoothed_gradients(nodes: np.ndarray, loops: list[np.ndarray], edges: np.ndarray,
                       values_at: Callable[[np.ndarray], sp.csr_matrix]) -> NodalIntegration:
    """SCNI (module docstring) of the nodes (n, 2) over the region of ``loops``, whose boundary segments are
    ``edges`` (e, 2; node pairs, body on the left); ``values_at(points)`` gives the shape functions' values
    (k, n) at k points."""
    n = len(nodes)
    cells = shapely.orient_polygons(smoothing_cells(nodes, loops))   # exteriors counter-clockwise, holes clockwise
    areas = shapely.area(cells)
    empty = np.flatnonzero(areas <= 0)
    if len(empty):
        i = int(empty[0])
        raise ProblemError(f"scni: node #{i} at ({nodes[i, 0]:g}, {nodes[i, 1]:g}) has no part of the body in its "
                           "Voronoi cell (it lies outside the tracked boundary)")
    segments, owner = _cell_edges(cells)
    # body on the left of each edge: the exterior runs counter-clockwise, so (dy, -dx) points out of the cell
    q = boundary_points(segments, BOUNDARY_GAUSS_POINTS)
    cell = owner[q.segment]
    N = values_at(q.points)
    scale = q.weights / areas[cell]
    # one complex product keeps b_x and b_y on one pattern (a real product drops the entries that sum to 0)
    S = sp.csr_matrix(((q.normals[:, 0] + 1j * q.normals[:, 1]) * scale, (cell, np.arange(len(cell)))),
                      shape=(n, len(cell)))
    B = (S @ N).tocsr()
    B.sort_indices()
    bx = sp.csr_matrix((B.data.real.copy(), B.indices, B.indptr), shape=B.shape)
    by = sp.csr_matrix((B.data.imag.copy(), B.indices, B.indptr), shape=B.shape)
    on, ends = _on_boundary(nodes, edges, segments, owner)
    keep = on[q.segment]
    boundary = BoundaryQuadrature(q.points[keep], q.weights[keep], q.normals[keep], q.segment[keep],
                                  ends[q.segment[keep]])
    return NodalIntegration(areas, bx, by, boundary, cell[keep], N[np.flatnonzero(keep)])


def _cell_edges(cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(s, 2, 2) every edge of every (oriented) cell, and the cell (s,) it bounds."""
    polys, cell_of = shapely.get_parts(cells, return_index=True)
    polygonal = shapely.get_type_id(polys) == 3
    polys, cell_of = polys[polygonal], cell_of[polygonal]
    rings, poly_of = shapely.get_rings(polys, return_index=True)
    coords, ring_of = shapely.get_coordinates(rings, return_index=True)
    # consecutive vertices of one ring are an edge (a ring repeats its first vertex at its end)
    same = ring_of[1:] == ring_of[:-1]
    segments = np.stack([coords[:-1][same], coords[1:][same]], axis=1)
    owner = cell_of[poly_of[ring_of[:-1][same]]]
    keep = np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1) > 0
    return segments[keep], owner[keep]


def _on_boundary(nodes: np.ndarray, edges: np.ndarray, segments: np.ndarray, owner: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Which cell edges (s, 2, 2) lie on the body's boundary, and the boundary segment (node pair of ``edges``)
    each lies on: a boundary node's cell meets the boundary along its two segments (up to their midpoints,
    where the perpendicular bisector of a segment crosses it), so an edge of cell I lies on the boundary when
    its midpoint lies on one of I's two segments."""
    mid = 0.5 * (segments[:, 0] + segments[:, 1])
    length = np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)
    best = np.full(len(segments), np.inf)
    ends = np.zeros((len(segments), 2), int)
    for column in (0, 1):   # the segments that start, then those that end, at the cell's node
        by_node = np.full(len(nodes), -1)
        by_node[edges[:, column]] = np.arange(len(edges))
        k = by_node[owner]
        has = k >= 0
        a, b = nodes[edges[k[has], 0]], nodes[edges[k[has], 1]]
        d = _distance_to_segment(mid[has], a, b)
        closer = d < best[has]
        idx = np.flatnonzero(has)[closer]
        best[idx] = d[closer]
        ends[idx] = edges[k[has][closer]]
    return best <= 1e-9 * np.maximum(length, 1e-300) + 1e-12 * np.abs(nodes).max(), ends


def _distance_to_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k,) distance of points p from segments a-b (all (k, 2))."""
    ab = b - a
    t = np.clip(((p - a) * ab).sum(axis=1) / np.maximum((ab * ab).sum(axis=1), 1e-300), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)
