"""A positive-weight average of integration-point values at the nodes, for fields that must keep their range.

The L2 projection onto the nodal RPIM space (:class:`ctmrpim.discretisation.state_transfer.NodalProjection`)
is exact for linear fields but overshoots where a field changes sharply: projected onto the nodes, the
equivalent plastic strain of a shear band went down to -0.023 in the footing (49 x 21) and to -1.30 in the
column collapse (16 x 9, 1 s; 3.92 at a node where the points hold at most 2.88), values the material can
never hold. The average here cannot leave the range of the values it averages: at each node x it is

    sum_p k_p v_p / sum_p k_p,      k_p = w_p phi(|x_p - x| / rho) >= 0,

over the points x_p (area weights w_p) within the radius rho, phi the quartic spline 1 - 6 s^2 + 8 s^3 - 3 s^4
of the stress recovery (:mod:`ctmrpim.discretisation.stress_recovery`), rho = RADIUS d_c, or 1.5 times the
distance of the nearest point where none lies within it. A non-negative field stays non-negative and never
exceeds its largest point value. It is first-order only (a linear field is smoothed at a boundary): stresses
keep the projection or the recovery; this serves the plastic strain.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ctmrpim.errors import ProblemError

#: averaging radius rho / d_c: the stress recovery's fitting radius
RADIUS = 2.0


class KernelAverage:
    """The average above from the points ``points`` (m, 2) with weights ``weights`` (m,) (those of weight 0 take
    no part) at ``at`` (k, 2), radius ``radius`` (a length): built once as a sparse (k, m) matrix whose rows are
    non-negative and sum to 1, each call one product."""

    def __init__(self, at: np.ndarray, points: np.ndarray, weights: np.ndarray, radius: float) -> None:
        at, points, weights = (np.asarray(a, float) for a in (at, points, weights))
        used = np.flatnonzero(weights > 0)
        if len(used) == 0:
            raise ProblemError("nodal average: no integration point has a positive weight")
        tree = cKDTree(points[used])
        nearest = tree.query(at, k=1)[0]
        rho = np.maximum(radius, 1.5 * nearest)
        pairs = cKDTree(at).sparse_distance_matrix(tree, rho.max(), output_type="ndarray")
        pairs = pairs[pairs["v"] < rho[pairs["i"]]]
        i, j = pairs["i"], pairs["j"]
        s = pairs["v"] / rho[i]
        kernel = weights[used[j]] * (1 - 6 * s ** 2 + 8 * s ** 3 - 3 * s ** 4)
        total = np.bincount(i, kernel, len(at))
        self.matrix = sp.csr_matrix((kernel / total[i], (i, used[j])), shape=(len(at), len(points)))

    def __call__(self, values: np.ndarray) -> np.ndarray:
        """(k, c) averages of ``values`` (m, c) given at the points."""
        return np.asarray(self.matrix @ values)
