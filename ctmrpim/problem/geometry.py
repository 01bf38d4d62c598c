"""Problem geometry: shapes added and subtracted, as polygons with holes (shapely).

Boolean operations, validity (self-intersection) and point-in-polygon tests are shapely's: a
well-kept library is more trustworthy here than hand-written clipping. Circles are polygons whose
chords stay within ``CIRCLE_SAGITTA`` of the true arc (relative to the radius), and every circle is
remembered so that nodes placed on its boundary can be snapped onto the exact arc.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon, box
from shapely.validation import explain_validity

from ctmrpim.errors import ProblemError

#: Largest chord-to-arc distance of a circle's polygon, as a fraction of its radius.
CIRCLE_SAGITTA = 1e-5


@dataclass(frozen=True)
class Shape:
    """One entry of ``geometry.add`` or ``geometry.subtract``: rectangle, polygon or circle."""

    kind: str
    data: tuple

    def polygon(self) -> Polygon:
        """The shape as a shapely polygon (a circle by ``circle_segments()`` chords); a ProblemError if it is empty or
        not simple."""
        if self.kind == "rectangle":
            x0, y0, x1, y1 = self.data
            if not (x1 > x0 and y1 > y0):
                raise ProblemError(f"rectangle {list(self.data)} is empty (need x1 > x0 and y1 > y0)")
            return box(x0, y0, x1, y1)
        if self.kind == "circle":
            cx, cy, r = self.data
            if not r > 0:
                raise ProblemError(f"circle {list(self.data)} has radius <= 0")
            n = circle_segments()
            t = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
            return Polygon(np.c_[cx + r * np.cos(t), cy + r * np.sin(t)])
        if self.kind == "polygon":
            pts = np.asarray(self.data, dtype=float)
            if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
                raise ProblemError("a polygon needs at least three [x, y] vertices")
            poly = Polygon(pts)
            # collinear vertices first: a bow tie's lobes cancel to zero signed area too, but what is
            # wrong with a bow tie is that it crosses itself, and the message should say so
            if not poly.convex_hull.area > 0:
                raise ProblemError(f"polygon {pts.tolist()} encloses no area")
            if not poly.is_valid:
                raise ProblemError(f"polygon {pts.tolist()} is not simple, it crosses or touches itself: "
                                   f"{explain_validity(poly)}")
            return poly
        raise ProblemError(f"unknown shape {self.kind!r}; use rectangle, polygon or circle")


def circle_segments() -> int:
    """Segments of a circle's polygon so that the sagitta is at most CIRCLE_SAGITTA * r."""
    return int(math.ceil(math.pi / math.acos(1.0 - CIRCLE_SAGITTA)))


@dataclass
class Geometry:
    """The body: union of ``add`` minus union of ``subtract``; possibly several parts with holes."""

    add: list[Shape]
    subtract: list[Shape] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.add:
            raise ProblemError("geometry.add is empty: the body has no shape")
        region = shapely.union_all([s.polygon() for s in self.add])
        if self.subtract:
            region = region.difference(shapely.union_all([s.polygon() for s in self.subtract]))
        region = shapely.make_valid(region) if not region.is_valid else region
        polys = [g for g in getattr(region, "geoms", [region]) if isinstance(g, Polygon) and g.area > 0]
        if not polys:
            raise ProblemError("the geometry is empty after subtracting the cut-outs")
        self.region = MultiPolygon(polys) if len(polys) > 1 else polys[0]
        self.circles = [s.data for s in (*self.add, *self.subtract) if s.kind == "circle"]

    @property
    def area(self) -> float:
        """Area of the body."""
        return float(self.region.area)

    @property
    def perimeter(self) -> float:
        """Length of the body's boundary, holes included."""
        return float(self.region.length)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(x_min, y_min, x_max, y_max) of the body."""
        return tuple(float(b) for b in self.region.bounds)

    @property
    def polygons(self) -> list[Polygon]:
        """The body's parts, each a polygon with its holes."""
        return list(getattr(self.region, "geoms", [self.region]))

    def loops(self) -> list[np.ndarray]:
        """Boundary loops as (k, 2) arrays without the repeated end point: outer counter-clockwise,
        holes clockwise, so that the body always lies to the left."""
        out = []
        for poly in self.polygons:
            poly = shapely.geometry.polygon.orient(poly, sign=1.0)
            out.append(np.asarray(poly.exterior.coords)[:-1])
            out.extend(np.asarray(r.coords)[:-1] for r in poly.interiors)
        return out

    def is_rectangle(self) -> bool:
        """True when the body is one axis-aligned rectangle (a tensor grid then fits it exactly)."""
        env = self.region.envelope
        return isinstance(self.region, Polygon) and abs(env.area - self.region.area) <= 1e-12 * env.area

    def distance_outside(self, points: np.ndarray) -> np.ndarray:
        """Distance of each point from the body (0 inside or on the boundary)."""
        return shapely.distance(self.region, shapely.points(points))

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(k,) bool: which of the points (k, 2) lie strictly inside the body."""
        points = np.asarray(points, float).reshape(-1, 2)
        return shapely.contains_xy(self.region, points[:, 0], points[:, 1])

    def distance_to_boundary(self, points: np.ndarray) -> np.ndarray:
        """(k,) distance of each of the points (k, 2) from the body's boundary, inside or outside."""
        return shapely.distance(self.region.boundary, shapely.points(points))

    def snap_to_circles(self, points: np.ndarray, tol: float) -> np.ndarray:
        """Move points lying within ``tol`` of a circle's arc exactly onto it (honours true arcs).

        Points on the circle's polygon lie up to its sagitta inside the arc, so the tolerance is at
        least twice that whatever ``tol`` is: with a node spacing below 1 % of the radius a tolerance
        proportional to the spacing alone would leave them on the chords, inside a hole."""
        pts = np.array(points, dtype=float)
        for cx, cy, r in self.circles:
            d = np.hypot(pts[:, 0] - cx, pts[:, 1] - cy)
            near = np.abs(d - r) <= max(tol, 2.0 * CIRCLE_SAGITTA * r)
            pts[near, 0] = cx + (pts[near, 0] - cx) * r / d[near]
            pts[near, 1] = cy + (pts[near, 1] - cy) * r / d[near]
        return pts
