"""Cartesian transformation method: domain integrals as sums over integration lines (Section 2.2).

The domain is cut by horizontal integration lines (Gauss points in y, Eq. 22); each line is
intersected with every boundary loop (a vectorised scanline with half-open edge rules, so a line
through a vertex is neither dropped nor doubled), the crossings are paired into inside intervals,
and each interval is split into sub-segments with Gauss points in x (Eq. 23). A point's weight is
w_x J_x w_y J_y (Eq. 24).

Two band layouts:

* ``uniform`` (the paper's, used by the solver): bands of height about r_y over [y_min, y_max],
  sub-segments of length about r_x;
* ``exact`` (for quadrature tests and error norms): bands split at every vertex ordinate, where the
  cross-section width is linear in y, so n Gauss points integrate polynomials of degree 2n - 2 in y
  (the line integral gains one degree) and 2n - 1 in x exactly.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ctmrpim.errors import ProblemError


@dataclass
class Quadrature:
    """CTM integration points (m, 2) and their weights w_x J_x w_y J_y (m,) (Eq. 24), laid on ``n_lines``
    horizontal integration lines."""
    points: np.ndarray     # (m, 2)
    weights: np.ndarray    # (m,)
    n_lines: int


def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points and weights, each (n,), on [-1, 1]."""
    return np.polynomial.legendre.leggauss(n)


def _edges(loops: list[np.ndarray]) -> np.ndarray:
    """(E, 4) edges x0, y0, x1, y1 of closed loops."""
    return np.concatenate([np.c_[lp, np.roll(lp, -1, axis=0)] for lp in loops])


def _bands(y_breaks: np.ndarray, max_height: float | None) -> np.ndarray:
    """Split consecutive break ordinates further so no band is taller than max_height."""
    lo, hi = y_breaks[:-1], y_breaks[1:]
    n = np.ones(len(lo), int) if max_height is None else np.maximum(1, np.ceil((hi - lo) / max_height - 1e-9).astype(int))
    idx = np.repeat(np.arange(len(lo)), n)
    k = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
    h = (hi - lo)[idx] / n[idx]
    a = lo[idx] + k * h
    return np.c_[a, a + h]


def line_intervals(loops: list[np.ndarray], y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Inside intervals of horizontal lines at ordinates ``y``: (line index, x_start, x_end)."""
    e = _edges(loops)
    x0, y0, x1, y1 = (e[:, i][None, :] for i in range(4))
    yy = y[:, None]
    crosses = (y0 <= yy) != (y1 <= yy)          # half-open: a vertex counts for exactly one of its edges
    li, ei = np.nonzero(crosses)
    t = (y[li] - e[ei, 1]) / (e[ei, 3] - e[ei, 1])
    xc = e[ei, 0] + t * (e[ei, 2] - e[ei, 0])
    order = np.lexsort((xc, li))
    li, xc = li[order], xc[order]
    counts = np.bincount(li, minlength=len(y))
    if np.any(counts % 2):
        bad = np.flatnonzero(counts % 2)[0]
        raise ProblemError(f"CTM: integration line y = {y[bad]:.6g} crosses the boundary an odd number of "
                           "times: the boundary loops are not closed")
    return li[0::2], xc[0::2], xc[1::2]


def integration_points(loops: list[np.ndarray], r_x: float, r_y: float, gauss_points: int = 1,
                       mode: str = "uniform", min_band: float = 0.0) -> Quadrature:
    """CTM integration points and weights over the region bounded by ``loops`` (Eqs. 22-24).

    ``loops`` are closed polygons, each (k, 2) (outer counter-clockwise, holes clockwise, or any orientation:
    the even-odd pairing of crossings needs none). In ``uniform`` mode bands have height about
    ``r_y`` and sub-segments length about ``r_x``; in ``exact`` mode bands also break at vertex
    ordinates and r_x, r_y only bound the band height and sub-segment length; vertex ordinates
    closer than ``min_band`` to the previous break are merged (a finely sampled circle would
    otherwise make a band per vertex), which gives up exactness only inside those thin bands.
    """
    ys = np.concatenate([lp[:, 1] for lp in loops])
    y_min, y_max = ys.min(), ys.max()
    if mode == "uniform":
        n_bands = max(1, int(round((y_max - y_min) / r_y)))
        bands = _bands(np.linspace(y_min, y_max, n_bands + 1), None)
        seg_len = r_x
    elif mode == "exact":
        breaks = np.unique(ys)
        if min_band > 0:
            keep = np.concatenate([[True], np.diff(np.floor((breaks - breaks[0]) / min_band)) > 0])
            keep[-1] = True
            breaks = breaks[keep]
        bands = _bands(breaks, r_y)
        seg_len = r_x
    else:
        raise ValueError(f"unknown CTM mode {mode!r}")
    g, wg = gauss_legendre(gauss_points)
    half = 0.5 * (bands[:, 1] - bands[:, 0])
    y_lines = ((bands[:, 0] + bands[:, 1]) * 0.5)[:, None] + half[:, None] * g[None, :]
    w_lines = half[:, None] * wg[None, :]                       # w_y J_y
    y_lines, w_lines = y_lines.ravel(), w_lines.ravel()

    li, xa, xb = line_intervals(loops, y_lines)
    length = xb - xa
    n_sub = np.maximum(1, np.round(length / seg_len).astype(int)) if mode == "uniform" else \
        np.maximum(1, np.ceil(length / seg_len - 1e-9).astype(int))
    seg_owner = np.repeat(np.arange(len(li)), n_sub)
    k = np.arange(n_sub.sum()) - np.repeat(np.cumsum(n_sub) - n_sub, n_sub)
    h = (length / n_sub)[seg_owner]
    mid = xa[seg_owner] + (k + 0.5) * h
    x = (mid[:, None] + 0.5 * h[:, None] * g[None, :]).ravel()
    wx = (0.5 * h[:, None] * wg[None, :]).ravel()               # w_x J_x
    line = np.repeat(li[seg_owner], gauss_points)
    points = np.c_[x, y_lines[line]]
    weights = wx * w_lines[line]                                 # Eq. (24)
    return Quadrature(points=points, weights=weights, n_lines=len(y_lines))


@dataclass
class BoundaryQuadrature:
    """Gauss points on boundary segments, for the traction term of Eq. 6: m points with their length weights,
    outward normals and the segment (and node pair) each lies on."""
    points: np.ndarray     # (m, 2)
    weights: np.ndarray    # (m,) length weights
    normals: np.ndarray    # (m, 2) outward unit normals
    segment: np.ndarray    # (m,) index of the boundary segment each point lies on
    ends: np.ndarray | None = None      # (m, 2) node indices of that segment, where known
    follower: np.ndarray | None = None  # (m,) the load at the point turns (large deformation)
    turn_ends: np.ndarray | None = None  # (m, 2) the node pair whose direction a follower load turns with


def boundary_points(segments: np.ndarray, gauss_points: int = 2) -> BoundaryQuadrature:
    """Gauss points on boundary segments (S, 2, 2), body on the segment's left (Eq. 6, second term)."""
    g, wg = gauss_legendre(gauss_points)
    a, b = segments[:, 0], segments[:, 1]
    d = b - a
    length = np.linalg.norm(d, axis=1)
    pts = (0.5 * (a + b))[:, None, :] + 0.5 * d[:, None, :] * g[None, :, None]
    normals = np.c_[d[:, 1], -d[:, 0]] / length[:, None]
    return BoundaryQuadrature(points=pts.reshape(-1, 2), weights=(0.5 * length[:, None] * wg[None, :]).ravel(),
                              normals=np.repeat(normals, gauss_points, axis=0),
                              segment=np.repeat(np.arange(len(segments)), gauss_points))
