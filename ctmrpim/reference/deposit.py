"""Measures of a granular deposit (the column collapse, Section 3.4) against measured profiles.

All lengths in the problem's units; the base is y = 0 and the flow goes towards +x.

- :func:`surface_profile`: the height of the free surface over x, from the tracked boundary (the
  highest crossing of each vertical line with the boundary loops; 0 where there is no material).
- :func:`run_out`: the farthest x where the surface is at least ``threshold`` high (linear
  interpolation); the experiment's run-out is defined the same way (its README: scattered rods lie
  further out, so the last rod is no measure).
- :func:`failure_line`: the top of the static region over x, static meaning the final displacement is
  below ``threshold``; the interface between the wedge that stayed and the mass that flowed.
- :func:`curve_distance`: the distance of each measured point from a computed polyline.
- :func:`slope_angle`: the least-squares slope of the surface between two abscissae, in degrees.
"""
from __future__ import annotations

import numpy as np


def surface_profile(points: np.ndarray, edges: np.ndarray, xs: np.ndarray) -> np.ndarray:
    """Height of the free surface at ``xs`` from boundary ``edges`` (e, 2) of node positions (n, 2)."""
    a, b = points[edges[:, 0]], points[edges[:, 1]]
    lo, hi = np.minimum(a[:, 0], b[:, 0]), np.maximum(a[:, 0], b[:, 0])
    x = np.asarray(xs, float)[:, None]
    crosses = (lo[None] <= x) & (x <= hi[None]) & (hi > lo)[None]
    t = np.where(crosses, (x - a[None, :, 0]) / np.where(hi > lo, b[:, 0] - a[:, 0], 1.0)[None], 0.0)
    y = a[None, :, 1] + t * (b[None, :, 1] - a[None, :, 1])
    return np.where(crosses, y, 0.0).max(axis=1, initial=0.0)


def run_out(xs: np.ndarray, heights: np.ndarray, threshold: float) -> float:
    """The farthest x at which ``heights`` reach ``threshold`` (interpolated to the crossing)."""
    above = np.flatnonzero(np.asarray(heights) >= threshold)
    if len(above) == 0:
        return float("nan")
    i = above[-1]
    if i == len(xs) - 1:
        return float(xs[i])
    h0, h1 = heights[i], heights[i + 1]
    return float(xs[i] + (xs[i + 1] - xs[i]) * (h0 - threshold) / (h0 - h1))


def failure_line(points: np.ndarray, displacement: np.ndarray, threshold: float, xs: np.ndarray,
                 width: float) -> np.ndarray:
    """(k, 2) the top of the static region (|u| < threshold) at ``xs``: the highest static node within
    ``width`` / 2 of each abscissa; abscissae without a static node are left out."""
    static = points[np.linalg.norm(displacement, axis=1) < threshold]
    near = np.abs(static[None, :, 0] - np.asarray(xs, float)[:, None]) <= 0.5 * width
    top = np.where(near, static[None, :, 1], -np.inf).max(axis=1, initial=-np.inf)
    keep = np.isfinite(top)
    return np.c_[np.asarray(xs, float)[keep], top[keep]]


def curve_distance(measured: np.ndarray, curve: np.ndarray) -> np.ndarray:
    """(k,) distance of each measured point (k, 2) from the polyline ``curve`` (c, 2)."""
    a, b = curve[:-1], curve[1:]
    ab = b - a
    length2 = np.maximum(np.einsum("sd,sd->s", ab, ab), 1e-300)
    t = np.clip(np.einsum("ksd,sd->ks", measured[:, None, :] - a[None], ab) / length2, 0.0, 1.0)
    nearest = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(measured[:, None, :] - nearest, axis=2).min(axis=1)


def slope_angle(xs: np.ndarray, heights: np.ndarray, x0: float, x1: float) -> float:
    """The surface's mean inclination between x0 and x1 (degrees, positive falling towards +x)."""
    sel = (xs >= x0) & (xs <= x1)
    slope = np.polyfit(xs[sel], heights[sel], 1)[0]
    return float(np.degrees(np.arctan(-slope)))
