"""The Mohr-Coulomb system's products over the points, compiled, for CTM-RPIM's gradient operator.

:class:`~ctmrpim.solvers.plastic_system.PlasticSystem` works on any G (4m x 2n); written with scipy, its three
products run over G's 4 x 2 blocks, half of whose entries are zeros in the RPIM layout (one block
[[dN/dX, 0], [dN/dY, 0], [0, dN/dX], [0, dN/dY]] per point and node, interleaved dofs). :class:`PointProducts`
does them as compiled passes over (dN/dX, dN/dY) (:mod:`ctmrpim.discretisation.gradient_operator`):

- the strain increment's gradient, grad du at the points;
- the internal force, sum_p w_p P_p grad~N (the test gradients where Petrov-Galerkin);
- the consistent tangent K = K_0 + sum over the plastic points of w_p B~_p^T D_p B_p, D_p = D_ep - D: as scipy
  products (G_p^T diag(w dA) G_p of the plastic points' block rows, added to K_0) it took 0.10-0.17 s per
  tangent on the 1029-node footing, whose points have about 43 support nodes each: 45 s of a 99 s run, more than
  the factorisations. Here a compiled pass (:func:`ctmrpim.discretisation.stiffness_kernels.pointwise_rows`)
  adds each plastic point's blocks straight into a copy of K_0's arrays, node row by node row, the rows on a
  thread pool; the points' pattern is transposed once.

The CTM-RPIM solver hands them to the system (:mod:`ctmrpim.solvers.elastoplastic`); the finite-element reference's
G (per-dof blocks) keeps the scipy products.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ctmrpim.discretisation import assembly
from ctmrpim.discretisation import stiffness_kernels as kernels
from ctmrpim.discretisation.gradient_operator import GradientOperator, from_blocks


class PointProducts:
    """The three products for a G (and test operator, where Petrov-Galerkin) in the RPIM layout."""

    def __init__(self, trial: GradientOperator, tested: GradientOperator, w: np.ndarray) -> None:
        self.trial, self.tested = trial, tested
        self.w = np.ascontiguousarray(w, dtype=float)
        self.n = trial.shape[1]
        self._transposed: tuple[np.ndarray, ...] | None = None
        self.blocks = [(a, min(a + assembly.ROW_BLOCK, self.n)) for a in range(0, self.n, assembly.ROW_BLOCK)]

    @classmethod
    def build(cls, G: sp.bsr_matrix, test: sp.bsr_matrix | None, w: np.ndarray) -> PointProducts | None:
        """The products of G (and ``test``), or None where either is not in the RPIM layout."""
        trial = from_blocks(G)
        tested = trial if test is None else from_blocks(test)
        if trial is None or tested is None:
            return None
        if not (np.array_equal(tested.indptr, trial.indptr) and np.array_equal(tested.indices, trial.indices)):
            return None
        return cls(trial, tested, w)

    def gradient(self, dU: np.ndarray) -> np.ndarray:
        """(m, 4) grad du (xX, xY, yX, yY) at the points of the interleaved dofs dU (2n,)."""
        return self.trial.gradient(dU.reshape(-1, 2), identity=0.0)

    def force(self, P: np.ndarray) -> np.ndarray:
        """(2n,) sum_p w_p P_p grad~N of the first Piola stresses P (m, 4: xX, xY, yX, yY), interleaved."""
        return self.tested.force(P * self.w[:, None]).ravel()

    def corrected(self, K0: sp.csr_matrix, points: np.ndarray, D: np.ndarray) -> sp.csr_matrix | None:
        """K_0 (2n x 2n) + sum over ``points`` (k,) of w_p B~_p^T D_p B_p with ``D`` (k, 3, 3) in the engineering
        strain and stress (sxx, syy, sxy) of (exx, eyy, gxy); None where a block has no place in K_0's pattern."""
        tr = self.trial
        if self._transposed is None:     # node -> (point, entry) lists of the points' pattern, once
            etype = np.int32 if len(tr.indices) < 2**31 - 1 else np.int64
            trow, tent = np.empty(len(tr.indices), etype), np.empty(len(tr.indices), etype)
            tptr = kernels.transpose_pattern(tr.indptr, tr.indices, self.n, trow, tent)
            self._transposed = (tptr, trow, tent)
        slot = np.full(len(self.w), -1, np.int64)
        slot[points] = np.arange(len(points))
        Dc = np.ascontiguousarray(D, dtype=float)
        K = K0.copy()
        done = [True]

        def rows(ab: tuple[int, int]) -> None:
            if not kernels.pointwise_rows(tr.indptr, tr.indices, tr.dx, tr.dy, self.tested.dx, self.tested.dy,
                                          self.w, slot, Dc, *self._transposed, *ab, K.indptr, K.indices, K.data):
                done[0] = False

        assembly.run_blocks(rows, self.blocks)
        return K if done[0] else None
