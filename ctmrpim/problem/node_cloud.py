"""Field nodes for a geometry: a tensor grid, a spacing, or a CSV file.

On a single axis-aligned rectangle ``grid = [nx, ny]`` is the exact tensor grid (the paper's
17 x 5 ... 257 x 65 clouds). On any other body nodes are placed along every boundary loop at about
the grid spacing (corners kept, circles snapped onto their true arcs) and a regular grid fills the
inside, keeping clear of the boundary by at least ``CLEARANCE`` spacings.

``jitter`` (a fraction of the spacing, with ``seed``) makes a generated cloud irregular: every node off the
boundary moves by a uniform random offset in [-jitter h, jitter h] along each axis, so a method can be checked
on clouds that are not grids (the tensor order is kept, so a quadrilateral mesh of the grid stays valid). An
offset that would bring a node nearer the boundary than ``JITTER_CLEARANCE`` spacings is not applied.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely

from ctmrpim.errors import ProblemError
from ctmrpim.problem.geometry import Geometry

CLEARANCE = 0.5     # interior grid nodes closer than this (x spacing) to a boundary node are dropped
CORNER_ANGLE = math.radians(20.0)  # a boundary vertex turning more than this is kept as a node
MAX_JITTER = 0.4    # largest nodes.jitter: two neighbours moved towards each other stay 0.2 h apart
JITTER_CLEARANCE = 0.25   # a jittered node keeps this (x spacing) from the boundary, else it stays put


@dataclass(frozen=True)
class NodeSpec:
    """Exactly one of ``grid``, ``spacing`` or ``file``; ``jitter`` and ``seed`` move generated nodes."""

    grid: tuple[int, int] | None = None
    spacing: float | None = None
    file: str | None = None
    jitter: float = 0.0
    seed: int | None = None

    def __post_init__(self) -> None:
        given = [k for k in ("grid", "spacing", "file") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ProblemError("give exactly one of grid = [nx, ny], spacing = h or file = \"nodes.csv\""
                               + (f" (got {', '.join(given)})" if given else ""), key="nodes")
        if self.grid is not None and (len(self.grid) != 2 or min(self.grid) < 2):
            raise ProblemError(f"grid = {list(self.grid)} needs two integers >= 2", key="nodes.grid")
        if self.spacing is not None and not self.spacing > 0:
            raise ProblemError(f"spacing = {self.spacing} must be > 0", key="nodes.spacing")
        if not 0.0 <= self.jitter <= MAX_JITTER:
            raise ProblemError(f"jitter = {self.jitter:g} must lie in [0, {MAX_JITTER:g}] (a fraction of the spacing)",
                               key="nodes.jitter")
        if self.jitter and self.file is not None:
            raise ProblemError("jitter moves generated nodes; the nodes of a file are used as given", key="nodes.jitter")
        if self.seed is not None and not self.jitter:
            raise ProblemError(f"seed = {self.seed} has no effect without nodes.jitter > 0", key="nodes.seed")

    def as_dict(self) -> dict:
        """The given one of ``grid`` (as a list), ``spacing`` or ``file``, and the jitter with its seed, as
        ``summary.json`` reports them."""
        out = {k: (list(v) if isinstance(v, tuple) else v) for k, v in
               (("grid", self.grid), ("spacing", self.spacing), ("file", self.file)) if v is not None}
        if self.jitter:
            out.update(jitter=self.jitter, seed=self.seed or 0)
        return out


def make_nodes(geometry: Geometry, spec: NodeSpec, base_dir: Path | None = None) -> np.ndarray:
    """Field node coordinates (n, 2) for ``geometry``."""
    x0, y0, x1, y1 = geometry.bounds
    if spec.file is not None:
        return _read_nodes(geometry, Path(base_dir or ".") / spec.file)
    if spec.grid is not None:
        nx, ny = spec.grid
        hx, hy = (x1 - x0) / (nx - 1), (y1 - y0) / (ny - 1)
        if geometry.is_rectangle():
            X, Y = np.meshgrid(np.linspace(x0, x1, nx), np.linspace(y0, y1, ny), indexing="xy")
            return _jittered(geometry, np.c_[X.ravel(), Y.ravel()], hx, hy, spec)
    else:
        hx = hy = float(spec.spacing)
    return _jittered(geometry, _fill(geometry, hx, hy), hx, hy, spec)


def _jittered(geometry: Geometry, nodes: np.ndarray, hx: float, hy: float, spec: NodeSpec) -> np.ndarray:
    """``nodes`` (n, 2) with those off the boundary moved by ``spec.jitter`` of the spacings (hx, hy) at random
    (uniform per axis, generator seeded by ``spec.seed``); boundary nodes, and moves that would come nearer the
    boundary than JITTER_CLEARANCE spacings, stay put."""
    if not spec.jitter:
        return nodes
    h = min(hx, hy)
    offset = np.random.default_rng(spec.seed or 0).uniform(-1.0, 1.0, nodes.shape) * spec.jitter * np.array([hx, hy])
    off_boundary = geometry.distance_to_boundary(nodes) > 1e-9 * h
    moved = nodes + offset
    keeps_clear = (geometry.distance_outside(moved) == 0.0) & (geometry.distance_to_boundary(moved)
                                                               > JITTER_CLEARANCE * h)
    out = nodes.copy()
    take = off_boundary & keeps_clear
    out[take] = moved[take]
    return out


def _fill(geometry: Geometry, hx: float, hy: float) -> np.ndarray:
    h = min(hx, hy)
    x0, y0, x1, y1 = geometry.bounds
    boundary = np.concatenate([_resample_loop(loop, h) for loop in geometry.loops()])
    boundary = geometry.snap_to_circles(boundary, tol=1e-3 * h)
    # a circle tangent to another shape leaves two polygon vertices a hair apart, which snapping makes one
    _, first = np.unique(np.round(boundary / (1e-6 * h)), axis=0, return_index=True)
    boundary = boundary[np.sort(first)]
    X, Y = np.meshgrid(np.arange(x0, x1 + 0.5 * hx, hx), np.arange(y0, y1 + 0.5 * hy, hy))
    grid = np.c_[X.ravel(), Y.ravel()]
    inside = shapely.contains_xy(geometry.region, grid[:, 0], grid[:, 1])
    grid = grid[inside]
    from scipy.spatial import cKDTree  # here, not at the top: it is a quarter of the CLI's start-up time

    d, _ = cKDTree(boundary).query(grid)
    clear = (d > CLEARANCE * h) & (geometry.distance_to_boundary(grid) > CLEARANCE * h)
    nodes = np.concatenate([boundary, grid[clear]])
    if len(nodes) < 3:
        raise ProblemError(f"node spacing {h:g} is too coarse for this geometry: only {len(nodes)} nodes",
                           key="nodes")
    return nodes


def _turning_angles(loop: np.ndarray) -> np.ndarray:
    """|turning angle| at each vertex of a closed loop (k, 2), radians."""
    a, b = loop - np.roll(loop, 1, axis=0), np.roll(loop, -1, axis=0) - loop
    return np.abs(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1)))


def geometry_corners(geometry: Geometry) -> np.ndarray:
    """(c, 2) the corners of every loop of ``geometry``: vertices turning by more than ``CORNER_ANGLE`` (the
    chords of a circle turn by far less)."""
    return np.concatenate([loop[_turning_angles(loop) > CORNER_ANGLE] for loop in geometry.loops()])


def _resample_loop(loop: np.ndarray, h: float) -> np.ndarray:
    """Points along a closed loop at spacing about h, keeping its corners."""
    b = np.roll(loop, -1, axis=0) - loop
    corners = np.flatnonzero(_turning_angles(loop) > CORNER_ANGLE)
    if len(corners) == 0:
        corners = np.array([0])
    seg = np.linalg.norm(b, axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])  # arc length at each vertex, closing vertex last
    total = s[-1]
    ring = shapely.LinearRing(loop)
    starts = s[corners]
    ends = np.append(starts[1:], total)
    counts = np.maximum(1, np.round((ends - starts) / h).astype(int))
    # arc-length positions: each stretch between corners divided evenly, corner included once
    pos = np.concatenate([a0 + (a1 - a0) * np.arange(c) / c for a0, a1, c in zip(starts, ends, counts)])
    pts = shapely.get_coordinates(shapely.line_interpolate_point(ring, pos))
    return pts


def _read_nodes(geometry: Geometry, path: Path) -> np.ndarray:
    import pandas as pd

    if not path.is_file():
        raise ProblemError(f"node file {str(path)!r} not found", key="nodes.file")
    try:
        table = pd.read_csv(path)
    except Exception as exc:  # pandas raises many parser error types
        raise ProblemError(f"cannot read node file {str(path)!r}: {exc}", key="nodes.file") from None
    cols = {c.strip().lower(): c for c in table.columns}
    if not {"x", "y"} <= set(cols):
        raise ProblemError(f"node file {str(path)!r} needs columns x and y (has {list(table.columns)})",
                           key="nodes.file")
    # coerce rather than cast: a cell like "a" must end in the message below, not in a ValueError
    xy = table[[cols["x"], cols["y"]]].apply(pd.to_numeric, errors="coerce")
    nodes = xy.to_numpy(dtype=float)
    bad = np.flatnonzero(~np.isfinite(nodes).all(axis=1))
    if len(bad):
        raise ProblemError(f"node file {str(path)!r} holds non-numbers, first in data row {bad[0] + 1}",
                           key="nodes.file")
    if len(nodes) < 3:
        raise ProblemError(f"node file {str(path)!r} holds {len(nodes)} node(s); a body needs at least 3",
                           key="nodes.file")
    return nodes


def check_nodes_inside(geometry: Geometry, nodes: np.ndarray, tol: float) -> None:
    """Every node of ``nodes`` (n, 2) must lie in the body or within ``tol`` of its boundary, no two coincide and
    every corner of the geometry is a node (within ``tol``); a ProblemError naming them otherwise."""
    out = np.flatnonzero(geometry.distance_outside(nodes) > tol)
    if len(out):
        first = ", ".join(f"#{i} ({nodes[i, 0]:g}, {nodes[i, 1]:g})" for i in out[:5])
        raise ProblemError(f"{len(out)} node(s) lie outside the geometry: {first}", key="nodes")
    from scipy.spatial import cKDTree

    d, _ = cKDTree(nodes).query(nodes, k=2)
    same = np.flatnonzero(d[:, 1] <= 1e-9 * math.sqrt(geometry.area))
    if len(same):
        raise ProblemError(f"{len(same)} node(s) coincide with another, e.g. #{same[0]} "
                           f"({nodes[same[0], 0]:g}, {nodes[same[0], 1]:g})", key="nodes")
    corners = geometry_corners(geometry)
    far = np.flatnonzero(cKDTree(nodes).query(corners)[0] > tol)
    if len(far):
        x, y = corners[far[0]]
        raise ProblemError(f"{len(far)} corner(s) of the geometry have no node, e.g. ({x:g}, {y:g}): the boundary "
                           "would cut them off; add them to the nodes", key="nodes")


def mean_node_spacing(area: float, n_nodes: int) -> float:
    """d_c = sqrt(A) / sqrt(n - 1), Eq. (36)."""
    if n_nodes < 2:
        raise ProblemError(f"{n_nodes} node(s): need at least two to define a node spacing", key="nodes")
    return math.sqrt(area) / math.sqrt(n_nodes - 1)
