"""External forces of a large-deformation solve: dead and follower tractions, dead point loads.

Dead tractions keep their direction and their total (nominal traction per unit reference length).
Follower tractions turn, t = R(theta) t0 per unit reference length, with cos theta = e0 . e and
sin theta = e0 x e of the reference and current unit directions of a node pair: the segment the
point lies on (a pressure-like load), or the chord of the whole loaded face (``turn = "face"``).
Turning each segment on its own lets a face that does not stay straight turn its tractions by
slightly different angles, and a couple then gets a net force: on the end-moment ring (lever arm up
to L/pi) that made the curvature 1-3.5 % too large; turning with the face keeps the couple exact.
Their load stiffness -dF_ext/dU enters the Newton tangent, which is then non-symmetric.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ctmrpim.discretisation import assembly
from ctmrpim.discretisation.configuration import BoundaryTags, Configuration
from ctmrpim.discretisation.lagrangian_operators import difference_operator, value_operator


@dataclass
class BoundaryLoads:
    """The external loads of a large-deformation solve at m traction points of n nodes: dead and follower
    tractions per unit reference length, and dead point loads."""
    N: sp.csr_matrix            # (m, n) shape functions at the traction points
    weights: np.ndarray         # (m,) reference length x thickness
    tx: np.ndarray              # (m,) nominal traction per unit reference length
    ty: np.ndarray
    turn_ends: np.ndarray       # (m, 2) node pair whose direction each point's follower load turns with
    follower: np.ndarray        # (m,) bool
    d0: np.ndarray              # (m, 2) reference vectors of those node pairs
    F_points: np.ndarray        # (2n,) dead point loads
    _dead: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._dead = assembly.load_vector(self.N, self.weights, self.tx, self.ty) + self.F_points

    def forces(self, x: np.ndarray, factor: float) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """F_ext at load factor ``factor`` with the nodes at ``x`` (n, 2), and its stiffness -dF_ext/dU
        (None when every load is dead)."""
        if not self.follower.any():
            return factor * self._dead, None
        ends, tx, ty = self.turn_ends, self.tx, self.ty
        len0 = np.linalg.norm(self.d0, axis=1)
        e0 = self.d0 / len0[:, None]
        p0 = np.c_[-e0[:, 1], e0[:, 0]]
        d = x[ends[:, 1]] - x[ends[:, 0]]
        length = np.linalg.norm(d, axis=1)
        e = d / length[:, None]
        c, s = (e0 * e).sum(1), (p0 * e).sum(1)
        rx = np.where(self.follower, c * tx - s * ty, tx)
        ry = np.where(self.follower, s * tx + c * ty, ty)
        # d(c, s)/dd = (e0, p0)^T (I - e e^T) / |d|; d(R t0)/dd for each point, zero for dead loads
        proj = (np.eye(2)[None] - e[:, :, None] * e[:, None, :]) / length[:, None, None]
        dc, ds = np.einsum("pi,pij->pj", e0, proj), np.einsum("pi,pij->pj", p0, proj)
        M = np.stack([tx[:, None] * dc - ty[:, None] * ds, tx[:, None] * ds + ty[:, None] * dc], axis=1)
        M *= (self.follower * self.weights * factor)[:, None, None]
        m = len(M)
        MB = sp.bsr_matrix((M, np.arange(m), np.arange(m + 1)), shape=(2 * m, 2 * m))
        K = value_operator(self.N).T @ (MB @ difference_operator(ends, n_nodes=len(x)))
        F = factor * (assembly.load_vector(self.N, self.weights, rx, ry) + self.F_points)
        return F, -K.tocsr()


def reference_loads(conf: Configuration, tags: BoundaryTags, thickness: float, point_forces: np.ndarray
                    ) -> BoundaryLoads:
    """The loads of the reference configuration ``conf``: the tagged tractions (follower ones turning
    with their node pairs) and the point forces (2n,) per unit thickness, all times ``thickness``."""
    q = tags.traction
    turn = q.turn_ends
    N = conf.shape_functions_at(q.points, derivatives=False).N
    return BoundaryLoads(N, q.weights * thickness, tags.tx, tags.ty, turn, q.follower,
                         conf.x[turn[:, 1]] - conf.x[turn[:, 0]], thickness * point_forces)
