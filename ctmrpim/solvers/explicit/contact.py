"""Contact of the nodes with rigid walls in the explicit dynamic solver (Section 3.4).

A wall (:class:`ctmrpim.problem.model.Wall`) is a fixed line through ``point`` with unit ``normal``
pointing into the body's side. Contact is enforced on the half-step velocity of the central-difference
scheme, node by node: a node whose predicted gap g + dt v.n would be negative gets the normal velocity
that brings it exactly onto the wall (v.n = -g / dt: it stops in the normal direction), and its
tangential velocity follows the wall's rule:

- ``friction = "no-slip"`` (the paper's rough base): the tangential velocity is removed;
- ``friction = mu`` (Coulomb): the tangential velocity drops by at most mu times the normal velocity
  change (the impulse ratio of Coulomb friction), and to zero when that is enough (stick);
- ``friction = 0``: a frictionless roller (the paper's left wall, and the gate).

A node may leave a wall whenever its forces pull it away (no adhesion). The energy the walls take out
is the work of their velocity corrections, booked by the explicit solver.

A ``gate`` wall holds the column during the initial gravity stage only and is removed at t = 0.
"""
from __future__ import annotations

import numpy as np

from ctmrpim.problem.model import Wall


def enforce_walls(walls: list[Wall], x: np.ndarray, v: np.ndarray, dt: float) -> np.ndarray:
    """The half-step velocities (n, 2) after contact with ``walls`` (applied in turn), for nodes at ``x``."""
    v = v.copy()
    for wall in walls:
        n = np.asarray(wall.normal)
        g = wall.gap(x)
        vn = v @ n
        hit = g + dt * vn < 0.0
        if not hit.any():
            continue
        vn_new = -g[hit] / dt
        dvn = vn_new - vn[hit]                       # > 0: the normal impulse per unit mass
        v[hit] = wall.slip(v[hit] - vn[hit, None] * n, dvn) + vn_new[:, None] * n
    return v
