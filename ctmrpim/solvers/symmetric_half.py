"""A symmetric sparse matrix held by its upper triangle (diagonal included): half the memory of the whole.

A large symmetric solve on the banded path holds the free block beside its band factor only for the products of
the refinement (conjugate gradients on the true residual); PARDISO reads the upper triangle alone. Holding the
half instead of the whole block saves 72 MB of the 257 x 65 cantilever's 143 MB block, at the solve's peak
(docs/design.md, 'What a linear solve holds'). ``A @ x`` is one compiled pass over the half.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ctmrpim.solvers import free_block_kernels


class SymmetricHalf:
    """The symmetric matrix whose upper triangle, diagonal included and stored, is the CSR ``upper``."""

    def __init__(self, upper: sp.csr_matrix) -> None:
        self.upper = upper
        self.shape = upper.shape
        self.dtype = np.dtype(float)
        self.indptr, self.indices, self.data = upper.indptr, upper.indices, upper.data

    @property
    def nnz(self) -> int:
        """The entries of the whole matrix (each stored off-diagonal one twice, the diagonal once)."""
        return 2 * self.upper.nnz - self.shape[0]

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        x = np.ascontiguousarray(x, dtype=float).ravel()
        y = np.zeros(self.shape[0])
        free_block_kernels.symmetric_matvec(self.indptr, self.indices, self.data, x, y)
        return y

    matvec = __matmul__   # what scipy's aslinearoperator takes (the Krylov solvers)

    def full(self) -> sp.csr_matrix:
        """The whole matrix, for the solvers that take it (SuperLU, spsolve, AMG)."""
        return (self.upper + sp.triu(self.upper, k=1, format="csr").T).tocsr()

    def pattern(self) -> sp.csr_matrix:
        """The whole matrix's pattern (ones, one byte each): what reverse Cuthill-McKee orders."""
        ones = sp.csr_matrix((np.ones(len(self.indices), np.int8), self.indices, self.indptr), shape=self.shape)
        return (ones + ones.T).tocsr()
