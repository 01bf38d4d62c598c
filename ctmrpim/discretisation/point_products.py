"""The Newton systems' products over the points, compiled, for CTM-RPIM's gradient operator.

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
G (per-dof blocks) keeps the scipy products. The updated-Lagrangian solver takes the full tangent
sum_p w_p G~_p^T A_p G_p (A = dP/dF, 4 x 4 per point) from :meth:`PointProducts.tangent`
(:func:`ctmrpim.discretisation.stiffness_kernels.tangent_rows`), half of it where it is symmetric.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ctmrpim.discretisation import assembly, thread_blocks
from ctmrpim.discretisation import stiffness_kernels as kernels
from ctmrpim.discretisation.gradient_operator import GradientOperator, from_blocks


class PointProducts:
    """The three products for a G (and test operator, where Petrov-Galerkin) in the RPIM layout."""

    def __init__(self, trial: GradientOperator, tested: GradientOperator, w: np.ndarray) -> None:
        self.trial, self.tested = trial, tested
        self.w = np.ascontiguousarray(w, dtype=float)
        self.n = trial.shape[1]
        self._transposed: tuple[np.ndarray, ...] | None = None
        self._pattern: tuple[np.ndarray, np.ndarray] | None = None
        self.blocks = [(a, min(a + assembly.ROW_BLOCK, self.n)) for a in range(0, self.n, assembly.ROW_BLOCK)]
        # the tangent is rebuilt every Newton iteration, also on small clouds: its rows in one block per thread there
        size = min(assembly.ROW_BLOCK, max(1, -(-self.n // thread_blocks.THREADS)))
        self.tangent_blocks = [(a, min(a + size, self.n)) for a in range(0, self.n, size)]
        self.sorted = _sorted_rows(trial.indptr, trial.indices)

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
        self._transpose()       # built once, shared by the test operator
        return self.tested.force(P * self.w[:, None]).ravel()

    def corrected(self, K0: sp.csr_matrix, points: np.ndarray, D: np.ndarray) -> sp.csr_matrix | None:
        """K_0 (2n x 2n) + sum over ``points`` (k,) of w_p B~_p^T D_p B_p with ``D`` (k, 3, 3) in the engineering
        strain and stress (sxx, syy, sxy) of (exx, eyy, gxy); None where a block has no place in K_0's pattern."""
        tr = self.trial
        transposed = self._transpose()
        slot = np.full(len(self.w), -1, np.int64)
        slot[points] = np.arange(len(points))
        Dc = np.ascontiguousarray(D, dtype=float)
        K = K0.copy()
        done = [True]

        def rows(ab: tuple[int, int]) -> None:
            if not kernels.pointwise_rows(tr.indptr, tr.indices, tr.dx, tr.dy, self.tested.dx, self.tested.dy,
                                          self.w, slot, Dc, *transposed, *ab, K.indptr, K.indices, K.data):
                done[0] = False

        thread_blocks.run_blocks(rows, self.blocks, kernel=kernels.pointwise_rows)
        return K if done[0] else None

    def tangent(self, A: np.ndarray) -> sp.csr_matrix:
        """K (2n x 2n) = sum_p w_p G~_p^T A_p G_p for A (m, 4, 4) or (m, 2, 2, 2, 2), dP/dF at the points: the
        product of :func:`ctmrpim.solvers.weak_form.tangent` as a compiled pass node row by node row
        (:func:`ctmrpim.discretisation.stiffness_kernels.tangent_rows`) instead of two sparse products over G's
        half-empty 4 x 2 blocks. Its pattern is every pair of nodes that share a point, column indices sorted."""
        tr, te = self.trial, self.tested
        tptr, trow, tent = self._transpose()
        if self._pattern is None:     # K's node pattern, once: the points and their supports do not change
            self._pattern = assembly.node_pattern(tr.indptr, tr.indices, tptr, trow, self.n, self.blocks)
        node_start, neighbours = self._pattern
        k_indices, k_data, k_indptr = assembly.interleaved_arrays(node_start)
        Ac = np.ascontiguousarray(np.reshape(A, (len(self.w), 16)), dtype=float)
        # symmetric K (Galerkin, every A_p symmetric: a hyperelastic dP/dF) on sorted rows: half the work
        square = Ac.reshape(-1, 4, 4)
        upper = te is tr and self.sorted and bool(np.array_equal(square, square.transpose(0, 2, 1)))
        blocks = self.tangent_blocks
        rows = lambda ab: kernels.tangent_rows(tr.indptr, tr.indices, tr.dx, tr.dy, te.dx, te.dy, self.w, Ac, tptr,
                                               trow, tent, self.n, node_start, neighbours, *ab, k_indices, k_data,
                                               upper)
        thread_blocks.run_blocks(rows, blocks, kernel=kernels.tangent_rows)
        if upper:
            thread_blocks.run_blocks(lambda ab: kernels.mirror_lower(k_indptr, k_indices, k_data, *ab), blocks,
                                     kernel=kernels.mirror_lower)
        K = sp.csr_matrix((k_data, k_indices, k_indptr), shape=(2 * self.n, 2 * self.n), copy=False)
        K.has_sorted_indices = True
        K.has_canonical_format = True
        return K

    def _transpose(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """node -> (point, entry) lists of the points' pattern (:meth:`GradientOperator.transposed`), built once."""
        if self._transposed is None:
            self._transposed = self.trial.transposed()
            self.tested.share_pattern(self.trial)     # the force gathers by it too
        return self._transposed


def _sorted_rows(indptr: np.ndarray, indices: np.ndarray) -> bool:
    """Whether the column indices increase within every row of a CSR pattern."""
    if len(indices) < 2:
        return True
    step = np.diff(indices) > 0
    starts = indptr[1:-1]                      # where a new row begins, the step from the last row does not count
    step[starts[(starts > 0) & (starts < len(indices))] - 1] = True
    return bool(step.all())
