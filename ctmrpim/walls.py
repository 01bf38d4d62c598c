"""Rigid walls and base for the explicit dynamic solver (issue 7; Section 3.4).

A wall is a fixed line through ``point`` with unit ``normal`` pointing into the body's side. Contact is
enforced on the half-step velocity of the central-difference scheme, node by node: a node whose
predicted gap g + dt v.n would be negative gets the normal velocity that brings it exactly onto the
wall (v.n = -g / dt: it stops in the normal direction), and its tangential velocity follows the wall's
rule:

- ``friction = "no-slip"`` (the paper's rough base): the tangential velocity is removed;
- ``friction = mu`` (Coulomb): the tangential velocity drops by at most mu times the normal velocity
  change (the impulse ratio of Coulomb friction), and to zero when that is enough (stick);
- ``friction = 0``: a frictionless roller (the paper's left wall, and the gate).

A node may leave a wall whenever its forces pull it away (no adhesion). The energy the walls take out
is the work of their velocity corrections, booked by the explicit solver.

A ``gate`` wall holds the column during the initial gravity stage only and is removed at t = 0.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ProblemError

NO_SLIP = "no-slip"


@dataclass(frozen=True)
class Wall:
    name: str
    point: tuple[float, float]
    normal: tuple[float, float]       # unit, into the body's side
    friction: float | str = NO_SLIP   # "no-slip", or a Coulomb coefficient >= 0 (0: frictionless)
    gate: bool = False                # only in the gravity stage; removed at t = 0

    def __post_init__(self) -> None:
        n = np.asarray(self.normal, float)
        if n.shape != (2,) or not np.linalg.norm(n) > 0:
            raise ProblemError(f"normal = {self.normal!r} must be a non-zero [nx, ny]", key=f"wall.{self.name}.normal")
        object.__setattr__(self, "normal", tuple(float(v) for v in n / np.linalg.norm(n)))
        object.__setattr__(self, "point", tuple(float(v) for v in self.point))
        if self.friction != NO_SLIP and not (isinstance(self.friction, (int, float))
                                            and not isinstance(self.friction, bool) and self.friction >= 0):
            raise ProblemError(f"friction = {self.friction!r} must be \"no-slip\" or a coefficient >= 0",
                               key=f"wall.{self.name}.friction")

    def slip(self, tangential: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """What the wall's friction leaves of tangential vectors (k, 2) against normal magnitudes (k,)
        (velocity changes or forces): nothing (no-slip), all (frictionless), or each shortened by
        mu x normal, to zero where that is enough (Coulomb: stick)."""
        if self.friction == NO_SLIP:
            return np.zeros_like(tangential)
        if self.friction == 0:
            return tangential
        size = np.linalg.norm(tangential, axis=1)
        keep = np.maximum(size - self.friction * np.abs(normal), 0.0) / np.where(size > 0, size, 1.0)
        return tangential * keep[:, None]

    def gap(self, x: np.ndarray) -> np.ndarray:
        """Signed distance of positions (n, 2) from the wall, positive on the body's side."""
        return (x - np.asarray(self.point)) @ np.asarray(self.normal)


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
