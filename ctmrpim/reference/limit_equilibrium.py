"""Limit-equilibrium reference for slopes: Bishop's simplified method on circular slips, searched.

For a circle (centre xc, yc, radius R) the sliding mass between the two points where the lower arc
meets the ground surface (it must enter and exit through the surface, :func:`crosses_ground`) is cut into vertical slices of width b, weight W = gamma b h and base
inclination alpha (positive where the base dips towards the toe, here to the right: the slope faces
+x). Bishop's simplified method (moment equilibrium about the centre, inter-slice shear neglected):

    FS = sum (c b + W tan(phi)) / m_alpha  /  sum W sin(alpha),   m_alpha = cos(alpha) + sin(alpha) tan(phi) / FS,

solved by fixed-point iteration. The critical circle is searched over a grid of centres and radii
(the base of the model, ``base``, limits how deep an arc may go), then refined with Nelder-Mead.
No pore pressure. The slope is given by its ground surface, a polyline y(x) from left to right.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import minimize

if TYPE_CHECKING:
    from shapely.geometry import Polygon

    from ctmrpim.problem.geometry import Geometry
    from ctmrpim.problem.model import Problem

SLICES = 100


@dataclass
class SlipCircle:
    """A slip circle, centre (xc, yc) and radius, with its Bishop factor of safety ``fs`` and the abscissae where
    its arc meets the ground surface (entry left, exit right)."""
    fs: float
    xc: float
    yc: float
    radius: float
    x_entry: float
    x_exit: float


def top_surface(body: Geometry | Polygon) -> np.ndarray:
    """Ground surface (k, 2) of a body (a :class:`ctmrpim.problem.geometry.Geometry` or a shapely polygon):
    the highest boundary point above each vertex abscissa, read just left and just right of it, so that a
    vertical face (a cut, a step) is a vertical segment of the polyline: two points at one abscissa, the
    upper one first on the crest side. Without that, the face would read as a slope from its crest to the
    next vertex."""
    import shapely

    poly = getattr(body, "region", body)
    xs = np.unique(np.asarray(poly.exterior.coords)[:, 0])
    x0, y0, x1, y1 = poly.bounds
    side = 1e-9 * (x1 - x0)           # "just beside" a vertex: far below any node spacing

    def top(x: float) -> float:
        cut = poly.intersection(shapely.LineString([(x, y0 - 1.0), (x, y1 + 1.0)]))
        return cut.bounds[3]

    points = []
    for x in xs:
        left = top(x - side) if x > x0 else None
        right = top(x + side) if x < x1 else None
        ys = [y for y in (left, right) if y is not None]
        if max(ys) - min(ys) > 1e-6 * (y1 - y0):      # a vertical face at x: both of its ends
            points += [(x, left), (x, right)]
        else:                                           # at the end abscissae: the one side there is
            points.append((x, top(x)))
    return np.array(points, float)


def bishop(surface: np.ndarray, gamma: float, c: float, phi: float, xc: float, yc: float, radius: float,
           base: float = -np.inf, slices: int = SLICES) -> SlipCircle | None:
    """Bishop's factor of safety of one circle; None where the circle does not cut a sliding mass that
    enters and exits through the ground surface (:func:`crosses_ground`), or its arc goes below ``base``.

    Each stretch of the arc below the ground between two crossings of the surface bounds a mass of its
    own; the least factor of safety of them is the circle's. A circle can cross the surface four times:
    on a vertical cut, Taylor's critical circle (centre in front of the face) exits through the face just
    above the toe and dips into the foundation beyond it, which is another, separate stretch."""
    xs = np.linspace(surface[0, 0], surface[-1, 0], 4001)
    ground = np.interp(xs, surface[:, 0], surface[:, 1])
    inside = np.abs(xs - xc) < radius
    arc = np.full_like(xs, np.inf)
    arc[inside] = yc - np.sqrt(radius**2 - (xs[inside] - xc) ** 2)
    idx = np.flatnonzero(arc < ground)
    if len(idx) < 3 or yc - radius < base - 1e-9:
        return None
    stretches = np.split(idx, np.flatnonzero(np.diff(idx) != 1) + 1)
    masses = [_slices(surface, gamma, c, phi, xc, yc, radius, xs[run[0]], xs[run[-1]], slices)
              for run in stretches if len(run) >= 3 and crosses_ground(inside, run)]
    masses = [m for m in masses if m is not None]
    return min(masses, key=lambda m: m.fs) if masses else None


def _slices(surface: np.ndarray, gamma: float, c: float, phi: float, xc: float, yc: float, radius: float,
            xa: float, xb: float, slices: int) -> SlipCircle | None:
    """Bishop's factor of safety of the mass above the arc between the abscissae xa < xb; None where the
    weight drives no slide towards the toe or Bishop's m_alpha breaks down."""
    edges = np.linspace(xa, xb, slices + 1)
    xm = 0.5 * (edges[:-1] + edges[1:])
    b = np.diff(edges)
    dx = xm - xc
    root = np.sqrt(np.maximum(radius**2 - dx**2, 1e-300))
    h = np.interp(xm, surface[:, 0], surface[:, 1]) - (yc - root)
    h = np.maximum(h, 0.0)
    W = gamma * b * h
    alpha = np.arctan2(-dx, root)          # base dips to the right (towards the toe) where x < xc
    tphi = np.tan(np.radians(phi))
    driving = np.sum(W * np.sin(alpha))
    if driving <= 0.0:
        return None
    fs = 1.0
    for _ in range(200):
        m = np.cos(alpha) + np.sin(alpha) * tphi / fs
        if np.any(m <= 0.05):              # Bishop's m_alpha breaks down: the circle is unrealistic
            return None
        new = np.sum((c * b + W * tphi) / m) / driving
        if abs(new - fs) <= 1e-10 * new:
            fs = new
            break
        fs = new
    return SlipCircle(float(fs), float(xc), float(yc), float(radius), float(xa), float(xb))


def crosses_ground(inside: np.ndarray, idx: np.ndarray) -> bool:
    """Whether the arc below the ground at the sample indices ``idx`` (contiguous) enters and exits through the
    ground surface: the samples on either side of that stretch lie within the model's abscissae and under the
    circle (``inside``, (k,) bool), where the arc is above the ground.

    A circle whose arc is still below the ground at the first or last abscissa leaves the body through the
    lateral model boundary: the sliding mass would end on a vertical cut through the soil that nothing
    resists (measured on a vertical cut, H = 10 m, c = 78.3 kPa, gamma = 20 kN/m3: FS 1.077 on a circle
    ending 10 m below the ground at the model's edge, against Taylor's 3.83 c / (gamma H) = 1.50). One whose
    arc reaches the end of its lower half below the ground (the centre under the surface) does not bound a
    mass by its lower arc alone. Neither is a mechanism."""
    first, last = idx[0] - 1, idx[-1] + 1
    return first >= 0 and last < len(inside) and bool(inside[first]) and bool(inside[last])


def critical_circle(surface: np.ndarray, gamma: float, c: float, phi: float, base: float = -np.inf,
                    grid: int = 24) -> SlipCircle:
    """The circle of least Bishop factor of safety under the ground ``surface`` (k, 2), left to right: a grid
    over centres above the slope and radii, refined by Nelder-Mead from the best few."""
    x0, x1 = surface[0, 0], surface[-1, 0]
    ytop, ybot = surface[:, 1].max(), surface[:, 1].min()
    height = ytop - min(ybot, base if np.isfinite(base) else ybot)
    best: list[SlipCircle] = []
    for xc in np.linspace(x0, x1, grid):
        for yc in np.linspace(ytop + 0.1 * height, ytop + 3.0 * height, grid):
            deepest = yc - (base if np.isfinite(base) else ybot - height)
            for radius in np.linspace(0.2 * (yc - ybot), deepest, grid):
                s = bishop(surface, gamma, c, phi, xc, yc, radius, base)
                if s is not None:
                    best.append(s)
    if not best:
        raise ValueError("no admissible slip circle found")
    best.sort(key=lambda s: s.fs)

    def objective(v):
        s = bishop(surface, gamma, c, phi, *v, base=base)
        return s.fs if s is not None else 1e9

    result = best[0]
    for start in best[:5]:
        opt = minimize(objective, [start.xc, start.yc, start.radius], method="Nelder-Mead",
                       options={"xatol": 1e-4, "fatol": 1e-7, "maxiter": 2000})
        s = bishop(surface, gamma, c, phi, *opt.x, base=base)
        if s is not None and s.fs < result.fs:
            result = s
    return result


def problem_factor_of_safety(problem: Problem) -> SlipCircle:
    """Bishop's critical circle for a slope Problem: its geometry's ground surface, unit weight
    density x |gravity|, c and phi of its Mohr-Coulomb material, a rigid base at the bottom of the body."""
    gamma = problem.material.density * float(np.hypot(*problem.gravity))
    return critical_circle(top_surface(problem.geometry), gamma, problem.material.c, problem.material.phi,
                           base=problem.geometry.bounds[1])
