"""A stiffness changed at some points: K = K_0 + sum over those points of w_p B~_p^T D_p B_p, on K_0's pattern.

The consistent tangent of a Mohr-Coulomb body (:mod:`ctmrpim.solvers.plastic_system`) is the elastic stiffness
plus a correction summed over the plastic points, with a different D_p = D_ep - D at each; Newton rebuilds it
every iteration. As scipy products (G_p^T diag(w dA) G_p of the plastic points' block rows, added to K_0) it
took 0.10-0.17 s per tangent on the 1029-node footing, whose points have about 43 support nodes each: 45 s of
a 99 s run, more than the factorisations. Here a compiled pass (:func:`ctmrpim.discretisation.stiffness_kernels.
pointwise_rows`) adds each plastic point's blocks straight into a copy of K_0's arrays, node row by node row,
the rows on a thread pool; the points' pattern is transposed once.

Where G is not the RPIM layout (one 4 x 2 block [[dN/dX, 0], [dN/dY, 0], [0, dN/dX], [0, dN/dY]] per point and
node, interleaved dofs), e.g. the finite-element reference's per-dof blocks, :meth:`PointwiseStiffness.build`
says so and the caller keeps the scipy products.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ctmrpim.discretisation import assembly
from ctmrpim.discretisation import stiffness_kernels as kernels
from ctmrpim.discretisation.gradient_operator import GradientOperator, from_blocks


class PointwiseStiffness:
    """K_0 plus point-wise corrections for a fixed gradient operator G (and test operator, where Petrov-Galerkin)."""

    def __init__(self, G: GradientOperator, test: GradientOperator, w: np.ndarray) -> None:
        self.indptr, self.indices = G.indptr, G.indices
        self.dx, self.dy, self.tdx, self.tdy = G.dx, G.dy, test.dx, test.dy
        self.w = np.ascontiguousarray(w, dtype=float)
        self.n = G.shape[1]
        etype = np.int32 if len(self.indices) < 2**31 - 1 else np.int64
        self.trow, self.tent = np.empty(len(self.indices), etype), np.empty(len(self.indices), etype)
        self.tptr = kernels.transpose_pattern(self.indptr, self.indices, self.n, self.trow, self.tent)
        self.blocks = [(a, min(a + assembly.ROW_BLOCK, self.n)) for a in range(0, self.n, assembly.ROW_BLOCK)]

    @classmethod
    def build(cls, G: sp.bsr_matrix, test: sp.bsr_matrix | None, w: np.ndarray) -> PointwiseStiffness | None:
        """The corrector for G (and ``test``), or None where either is not in the RPIM layout."""
        trial = from_blocks(G)
        tested = trial if test is None else from_blocks(test)
        if trial is None or tested is None:
            return None
        if not (np.array_equal(tested.indptr, trial.indptr) and np.array_equal(tested.indices, trial.indices)):
            return None
        return cls(trial, tested, w)

    def corrected(self, K0: sp.csr_matrix, points: np.ndarray, D: np.ndarray) -> sp.csr_matrix | None:
        """K_0 (2n x 2n) + sum over ``points`` (k,) of w_p B~_p^T D_p B_p with ``D`` (k, 3, 3) in the engineering
        strain and stress (sxx, syy, sxy) of (exx, eyy, gxy); None where a block has no place in K_0's pattern."""
        slot = np.full(len(self.w), -1, np.int64)
        slot[points] = np.arange(len(points))
        Dc = np.ascontiguousarray(D, dtype=float)
        K = K0.copy()
        done = [True]

        def rows(ab: tuple[int, int]) -> None:
            if not kernels.pointwise_rows(self.indptr, self.indices, self.dx, self.dy, self.tdx, self.tdy, self.w,
                                          slot, Dc, self.tptr, self.trow, self.tent, *ab, K.indptr, K.indices,
                                          K.data):
                done[0] = False

        assembly.run_blocks(rows, self.blocks)
        return K if done[0] else None

