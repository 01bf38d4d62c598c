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

import math
from functools import lru_cache

import numpy as np
from numba import njit

from ctmrpim.problem.model import NO_SLIP, Wall

#: The friction column of :func:`wall_table` for a no-slip wall.
TABLE_NO_SLIP = -1.0


@lru_cache(maxsize=16)
def wall_table(walls: tuple[Wall, ...]) -> np.ndarray:
    """(k, 5) the walls as the compiled contact reads them: point x, y, unit normal x, y, friction coefficient
    (:data:`TABLE_NO_SLIP` for no slip); made once per set of walls (read-only: the explicit step asks every step)."""
    table = np.array([[*w.point, *w.normal, TABLE_NO_SLIP if w.friction == NO_SLIP else float(w.friction)]
                      for w in walls], float).reshape(-1, 5)
    table.flags.writeable = False
    return table


@njit(cache=True, nogil=True)
def contact(table, x0, x1, v0, v1, dt):
    """The half-step velocity (v0, v1) of a node at (x0, x1) after contact with the walls of ``table``
    (:func:`wall_table`), applied in turn; the tangential rule is :meth:`ctmrpim.problem.model.Wall.slip`'s, compiled
    for one node (the gravity stage's out-of-balance force applies the numpy form to forces)."""
    for k in range(table.shape[0]):
        n0, n1, mu = table[k, 2], table[k, 3], table[k, 4]
        g = (x0 - table[k, 0]) * n0 + (x1 - table[k, 1]) * n1
        vn = v0 * n0 + v1 * n1
        if not g + dt * vn < 0.0:
            continue
        vn_new = -g / dt
        dvn = vn_new - vn                          # > 0: the normal impulse per unit mass
        t0, t1 = v0 - vn * n0, v1 - vn * n1
        if mu == TABLE_NO_SLIP:
            t0 = t1 = 0.0
        elif mu != 0.0:                            # Coulomb: |dv_t| <= mu |dv_n|, stick where that is enough
            size = math.hypot(t0, t1)
            keep = max(size - mu * abs(dvn), 0.0) / (size if size > 0.0 else 1.0)
            t0, t1 = t0 * keep, t1 * keep
        v0, v1 = t0 + vn_new * n0, t1 + vn_new * n1
    return v0, v1
