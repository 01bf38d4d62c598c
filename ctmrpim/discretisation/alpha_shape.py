"""Alpha-shape boundary tracking of a node cloud (paper Section 2.4), in its Delaunay form.

The paper's test (an empty circle of radius alpha through two nodes) over all node pairs is O(n^3).
The equivalent Delaunay form used here keeps the Delaunay triangles whose circumradius is below alpha;
boundary edges are the edges of exactly one kept triangle. The edges are chained into closed loops
with the body on their left: outer loops counter-clockwise, holes clockwise, islands as further outer
loops. Small spurious holes (a gap in a jittered cloud is not a hole) are filled, pinch vertices
(where two parts of the body touch) are split so that every loop is simple, and the result is
validated before anyone integrates over it.

On a moving cloud the reference triangulation can be carried instead (:func:`carried_boundary`): it keeps
the corners the body had, which the alpha shape of moved nodes cuts, for as long as it stays valid.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import shapely
from scipy.spatial import Delaunay, QhullError

from ctmrpim.errors import ProblemError

#: Holes with an area below this many d_c^2 are gaps in the cloud, not holes, and are filled.
SPURIOUS_HOLE_AREA = 4.0
#: A carried triangle squashed below this share of its reference area ends the carried topology (the alpha
#: shape re-tracks): the body there no longer looks like the reference
MIN_CARRIED_AREA = 0.05


@dataclass
class Boundary:
    """Tracked boundary of a node cloud."""

    points: np.ndarray             # (n, 2) node coordinates the loops index into
    loops: list[np.ndarray]        # node indices of each closed loop (first node not repeated)
    triangles: np.ndarray          # (t, 3) kept alpha triangles, counter-clockwise
    detached: np.ndarray           # nodes in no kept triangle (not part of the body)
    filled_holes: int = 0          # spurious holes closed

    @property
    def edges(self) -> np.ndarray:
        """(e, 2) directed boundary edges, body on the left."""
        return np.concatenate([np.c_[lp, np.roll(lp, -1)] for lp in self.loops])

    def loop_coordinates(self) -> list[np.ndarray]:
        """Each loop's node coordinates, (k, 2) for a loop of k nodes, in loop order."""
        return [self.points[lp] for lp in self.loops]

    @property
    def area(self) -> float:
        """Area enclosed by the loops: outer loops count positive, holes negative."""
        return float(sum(signed_area(self.points[lp]) for lp in self.loops))

    @property
    def n_outer(self) -> int:
        """Number of outer (counter-clockwise) loops: the body's separate parts."""
        return sum(signed_area(self.points[lp]) > 0 for lp in self.loops)

    @property
    def n_holes(self) -> int:
        """Number of holes (clockwise loops)."""
        return len(self.loops) - self.n_outer


def signed_area(xy: np.ndarray) -> float:
    """Shoelace area of a closed polygon of vertices ``xy`` (k, 2), positive when counter-clockwise."""
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def circumradii(points: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(t,) circumradius of each triangle ``tri`` (t, 3) of node indices into ``points`` (n, 2); inf if degenerate."""
    a, b, c = points[tri[:, 0]], points[tri[:, 1]], points[tri[:, 2]]
    la = np.linalg.norm(b - c, axis=1)
    lb = np.linalg.norm(c - a, axis=1)
    lc = np.linalg.norm(a - b, axis=1)
    area2 = np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(area2 > 0, la * lb * lc / (2.0 * area2), np.inf)


def alpha_shape(points: np.ndarray, alpha: float, d_c: float, reference: np.ndarray | None = None,
                max_reference_edge: float | None = None,
                inside: Callable[[np.ndarray], np.ndarray] | None = None) -> Boundary:
    """Tracked boundary of ``points`` (n, 2) for an absolute alpha radius (paper Section 2.4).

    On a deformed cloud, ``reference`` (the nodes' reference positions) and ``max_reference_edge``
    also drop every triangle with an edge longer than that in the reference configuration: nodes
    that were far apart (the two ends of a beam rolled into a ring) are never joined into the body.
    Where the body's geometry is known (the reference configuration), ``inside`` ((k, 2) points ->
    (k,) bool) drops every triangle whose centroid lies outside it: the alpha shape alone spans the
    notch of a re-entrant corner with a triangle as small as any inside (a square grid's corner node
    and its two neighbours), and cuts the corner off; a hole one or two spacings across is kept, not
    filled as a gap.
    """
    points = np.asarray(points, dtype=float)
    if len(points) < 3:
        raise ProblemError(f"alpha shape: {len(points)} node(s) cannot enclose an area")
    try:
        dt = Delaunay(points)
    except QhullError as exc:
        raise ProblemError(_qhull_failure(points, exc)) from None
    except MemoryError:
        raise ProblemError(f"alpha shape: out of memory triangulating {len(points)} nodes") from None
    tri = dt.simplices.copy()
    cw = _doubled_areas(points, tri) < 0
    tri[cw] = tri[cw][:, [0, 2, 1]]
    keep = circumradii(points, tri) < alpha
    body = np.ones(len(tri), bool) if inside is None else np.asarray(inside(points[tri].mean(axis=1)), bool)
    keep &= body
    if reference is not None and max_reference_edge is not None:
        r = np.asarray(reference, float)[tri]
        longest = np.max(np.linalg.norm(r - np.roll(r, 1, axis=1), axis=2), axis=1)
        keep &= longest <= max_reference_edge
    if not keep.any():
        raise ProblemError(f"alpha shape: alpha = {alpha:g} keeps no triangle; increase method.alpha")

    loops = _loops(points, tri[keep])
    filled = 0
    small = [lp for lp in loops if -SPURIOUS_HOLE_AREA * d_c**2 < signed_area(points[lp]) < 0]
    if small:
        centroids = points[tri].mean(axis=1)
        for lp in small:
            keep |= ~keep & body & _inside(centroids, points[lp])
        filled = len(small)
        loops = _loops(points, tri[keep])

    used = np.zeros(len(points), bool)
    used[tri[keep].ravel()] = True
    boundary = Boundary(points=points, loops=loops, triangles=tri[keep], detached=np.flatnonzero(~used),
                        filled_holes=filled)
    validate(boundary)
    return boundary


def carried_boundary(points: np.ndarray, triangles: np.ndarray, reference: np.ndarray,
                     alpha: float) -> Boundary | None:
    """The boundary of the reference triangulation ``triangles`` (t, 3; counter-clockwise on the ``reference``
    positions (n, 2)) carried to the moved nodes ``points`` (n, 2), while it stays valid: every triangle still
    counter-clockwise with at least MIN_CARRIED_AREA of its reference area and a circumradius below ``alpha``
    (what the alpha shape would keep: a node thrown off the body stretches its triangles beyond it), and the
    boundary loops simple and apart. It keeps the corners the body carries (a re-entrant corner node stays a
    boundary vertex), which the alpha shape of the moved nodes cuts with a triangle across the notch; None where
    a triangle folded, flattened or stretched or two parts of the boundary touch (the alpha shape re-tracks)."""
    now, ref = _doubled_areas(points, triangles), _doubled_areas(reference, triangles)
    if not np.all(now > MIN_CARRIED_AREA * ref) or not np.all(circumradii(points, triangles) < alpha):
        return None
    loops = _loops(points, triangles)
    # one geometry per loop first: loops of different lengths make no rectangular coordinate array
    rings = shapely.MultiLineString([points[np.r_[lp, lp[:1]]] for lp in loops])
    if not shapely.is_simple(rings):
        return None
    used = np.zeros(len(points), bool)
    used[triangles.ravel()] = True
    boundary = Boundary(points=points, loops=loops, triangles=triangles, detached=np.flatnonzero(~used),
                        filled_holes=0)
    try:
        validate(boundary)
    except ProblemError:
        return None
    return boundary


def _doubled_areas(points: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(t,) twice the signed area of each triangle (positive counter-clockwise)."""
    a, b, c = points[tri[:, 0]], points[tri[:, 1]], points[tri[:, 2]]
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def _inside(q: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Even-odd point-in-polygon for many points against one polygon."""
    x, y = q[:, 0:1], q[:, 1:2]
    x0, y0 = poly[:, 0], poly[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    crosses = (y0 <= y) != (y1 <= y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
    return (crosses & (x < xc)).sum(axis=1) % 2 == 1


def _loops(points: np.ndarray, tri: np.ndarray) -> list[np.ndarray]:
    """Chain the boundary edges of counter-clockwise triangles into loops, body on the left."""
    directed = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    # an edge's key as one integer (a row-wise np.unique sorts rows as records: ten times slower)
    key = np.minimum(directed[:, 0], directed[:, 1]).astype(np.int64) * len(points) + directed.max(axis=1)
    _, inv, counts = np.unique(key, return_inverse=True, return_counts=True)
    edges = directed[counts[inv.ravel()] == 1]
    if len(edges) == 0:
        return []
    # At a pinch vertex (several outgoing edges) the next edge is the one reached first turning
    # clockwise from the way back: that keeps each loop around one part of the body, so loops are simple.
    order = np.argsort(edges[:, 0], kind="stable")
    starts = np.searchsorted(edges[order, 0], edges[:, 1], side="left")
    ends = np.searchsorted(edges[order, 0], edges[:, 1], side="right")
    if np.any(ends == starts):
        raise ProblemError("alpha shape: an open boundary chain (internal error in the triangulation)")
    nxt = order[starts]
    multi = np.flatnonzero(ends - starts > 1)
    for e in multi:  # only pinch vertices, a handful at most
        cand = order[starts[e]:ends[e]]
        v = edges[e, 1]
        back = points[edges[e, 0]] - points[v]
        out = points[edges[cand, 1]] - points[v]
        ang_back = np.arctan2(back[1], back[0])
        cw_turn = np.mod(ang_back - np.arctan2(out[:, 1], out[:, 0]), 2 * np.pi)
        cw_turn[cw_turn == 0] = 2 * np.pi
        nxt[e] = cand[np.argmin(cw_turn)]
    seen = np.zeros(len(edges), bool)
    loops = []
    for start in range(len(edges)):  # walks boundary edges only, O(perimeter)
        if seen[start]:
            continue
        chain = []
        e = start
        while not seen[e]:
            seen[e] = True
            chain.append(edges[e, 0])
            e = nxt[e]
        if e != start:
            raise ProblemError("alpha shape: boundary edges do not close into loops")
        loops.append(np.asarray(chain))
    return loops


def validate(boundary: Boundary, expected_area: float | None = None, area_tol: float | None = None) -> None:
    """Fail loudly, naming nodes, rather than hand a broken boundary to CTM."""
    pts = boundary.points
    for lp in boundary.loops:
        if len(lp) < 3:
            raise ProblemError(f"alpha shape: a loop of {len(lp)} node(s) ({lp.tolist()})")
        vals, cnt = np.unique(lp, return_counts=True)
        if np.any(cnt > 1):
            raise ProblemError(f"alpha shape: loop is not simple at node(s) {vals[cnt > 1].tolist()[:5]}")
    tri_area = 0.5 * np.abs(_doubled_areas(pts, boundary.triangles)).sum()
    if abs(boundary.area - tri_area) > 1e-9 * max(tri_area, 1e-300):
        raise ProblemError(f"alpha shape: loops enclose {boundary.area:g} but the kept triangles cover {tri_area:g}")
    outer = [lp for lp in boundary.loops if signed_area(pts[lp]) > 0]
    for lp in boundary.loops:
        if signed_area(pts[lp]) < 0:
            probe = pts[lp].mean(axis=0, keepdims=True)
            if not any(_inside(pts[lp][:1] * 0.999999 + probe * 1e-6, pts[o])[0] for o in outer):
                raise ProblemError(f"alpha shape: hole through node {lp[0]} lies in no outer loop")
    if expected_area is not None and area_tol is not None and abs(boundary.area - expected_area) > area_tol:
        raise ProblemError(f"alpha shape encloses {boundary.area:.6g}, expected {expected_area:.6g} "
                           f"(tolerance {area_tol:.3g}); adjust method.alpha")


def _qhull_failure(points: np.ndarray, exc: Exception) -> str:
    """What a Qhull failure means: a degenerate cloud (collinear or coincident nodes) where it is one,
    else Qhull's own first line (a resource limit, a precision problem) with the node count."""
    centred = points - points.mean(axis=0)
    s = np.linalg.svd(centred, compute_uv=False)
    if s[-1] <= 1e-12 * max(s[0], 1e-300):
        return "alpha shape: the nodes are collinear or coincide; they enclose no area"
    first = next((line.strip() for line in str(exc).splitlines() if line.strip()), type(exc).__name__)
    return f"alpha shape: Qhull failed to triangulate {len(points)} nodes ({first})"
