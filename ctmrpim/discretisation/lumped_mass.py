"""Lumped nodal mass of the explicit dynamic solver (Eq. 9, "the lumped matrix is used").

Row-sum lumping of the RPIM consistent mass goes negative (RPIM shape functions are not positive), so the
mass is lumped geometrically (docs/design.md, 'Explicit dynamics'): each node carries density x thickness
x one third of the area of the alpha-shape triangles it is a vertex of, on the initial cloud. Every node
of the body gets a positive mass, the masses sum to density x thickness x the tracked area, and they
never change afterwards (mass is conserved exactly; a node keeps its mass wherever it goes).
"""
from __future__ import annotations

import numpy as np

from ctmrpim.errors import ProblemError


def nodal_areas(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(n,) one third of the area of the triangles (t, 3) around each of the points (n, 2)."""
    a, b, c = (points[triangles[:, k]] for k in range(3))
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    out = np.zeros(len(points))
    np.add.at(out, triangles.ravel(), np.repeat(area / 3.0, 3))
    return out


def lumped_mass(points: np.ndarray, triangles: np.ndarray, density: float, thickness: float) -> np.ndarray:
    """(n,) nodal masses; a node in no triangle (outside the body) or a density <= 0 is an error."""
    if not density > 0:
        raise ProblemError(f"density = {density!r}: explicit dynamics needs a positive density", key="material.density")
    mass = density * thickness * nodal_areas(points, triangles)
    if not (mass > 0).all():
        i = int(np.argmin(mass))
        raise ProblemError(f"node #{i} at ({points[i, 0]:g}, {points[i, 1]:g}) has mass {mass[i]:g} <= 0: it lies in "
                           "no alpha triangle of the initial cloud; increase method.alpha", key="method.alpha")
    return mass
