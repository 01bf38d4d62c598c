"""Banded LU (LAPACK dgbtrf) of tangents that share one sparsity pattern: the Mohr-Coulomb Newton iteration's, and
the updated-Lagrangian iteration's within one configuration.

Newton on the consistent tangent factorises a new matrix every iteration, always on the elastic stiffness's pattern (the
plastic correction couples the nodes that already share a point). SuperLU orders and analyses each one afresh. Here the
ordering (the narrower band of reverse Cuthill-McKee and, where the dofs' places are known, the sort along the body's
principal axis: :func:`principal_axis_order`), the band and the place of every entry in LAPACK's band storage are found
once from the pattern; each factorisation is one gather into the band and dgbtrf (partial pivoting within the band, so a
non-symmetric tangent of non-associated flow is factorised as it is), on one BLAS thread.

Which wins depends on the rows' density. A meshfree row couples a node with about 140 others (286 entries
per row at r_c = 4 d_c), which leaves a reverse Cuthill-McKee band only a small multiple of the row; a P2 row
has about 22 entries and a band many times that. Measured here, one factorisation, the free block of the
elastic stiffness (band half-width kl, entries per row r):

| system | dofs | kl | r | SuperLU (MMD_AT_PLUS_A) | banded LU |
|---|---|---|---|---|---|
| footing, CTM-RPIM | 1920 | 394 | 286 | 0.147 s | 0.067 s |
| slope, CTM-RPIM | 3613 | 387 | 286 | 0.373 s | 0.217 s |
| slope-gl, CTM-RPIM | 3639 | 431 | 299 | 0.621 s | 0.259 s |
| footing, FE P2 | 7680 | 169 | 22 | 0.074 s | 0.138 s |
| slope, FE P2 | 14444 | 225 | 22 | 0.161 s | 0.422 s |

So the band is taken where kl <= ``MAX_BAND_PER_ROW`` x r (a band's work grows with kl^2 per row, SuperLU's
with its fill, which the row's density sets), else SuperLU; the choice depends on the pattern alone.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg.lapack as lapack
import scipy.sparse as sp
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ctmrpim.blas_threads import one_blas_thread

#: the band is taken where its half-width is at most this many times the free block's entries per row
MAX_BAND_PER_ROW = 2.0


def principal_axis_order(places: np.ndarray) -> np.ndarray:
    """The rows sorted by where their dofs sit (``places`` (n, 2)) along the principal axis of those places, ties
    (a column of a grid) along the second axis, then by row. A meshfree stiffness couples the dofs within twice the
    support radius, so on an elongated body this band is about the dofs of a slab that wide across the body; reverse
    Cuthill-McKee, which follows the pattern's graph, leaves a wider one there (cantilever 257 x 65, default
    scheme: half-bandwidth 917 against 1521, a third of the band factorisation's work; 129 x 33: 469 against 715;
    the footing: 301 against 433), and a narrower one on other bodies (the 1928-node slope: 401 against 417):
    callers take the narrower of the two."""
    centred = places - places.mean(axis=0)
    axes = np.linalg.svd(centred, full_matrices=False)[2] if len(places) > 1 else np.eye(2)
    along, across = centred @ axes[0], centred @ axes[1]
    return np.lexsort((np.arange(len(places)), across, along))


class BandedFactors:
    """dgbtrf's factors of a free block, in the band's order."""

    def __init__(self, lub: np.ndarray, piv: np.ndarray, kl: int, ku: int, perm: np.ndarray) -> None:
        self.lub, self.piv, self.kl, self.ku, self.perm = lub, piv, kl, ku, perm

    def solve(self, b: np.ndarray) -> np.ndarray:
        """A^-1 b (n,)."""
        y, info = lapack.dgbtrs(self.lub, self.kl, self.ku, b[self.perm], self.piv)
        x = np.empty_like(y)
        x[self.perm] = y
        return x


class BandedCholeskyFactors:
    """dpbtrf's factors (upper) of a symmetric positive definite free block, in the band's order."""

    def __init__(self, cb: np.ndarray, perm: np.ndarray) -> None:
        self.cb, self.perm = cb, perm

    def solve(self, b: np.ndarray) -> np.ndarray:
        """A^-1 b (n,)."""
        y, info = lapack.dpbtrs(self.cb, b[self.perm])
        x = np.empty_like(y)
        x[self.perm] = y
        return x


class BandedLU:
    """The band of the free block (rows and columns ``free``) of matrices on ``pattern``'s CSR pattern; ``nodes``
    (n, 2): where the dofs 2i, 2i + 1 sit, for the ordering along the principal axis (None: RCM alone)."""

    def __init__(self, pattern: sp.csr_matrix, free: np.ndarray, nodes: np.ndarray | None = None) -> None:
        self.indptr, self.indices = pattern.indptr, pattern.indices
        new = np.full(pattern.shape[0], -1, np.int64)
        new[free] = np.arange(len(free))
        rows = np.repeat(np.arange(pattern.shape[0]), np.diff(pattern.indptr))
        r, c = new[rows], new[pattern.indices]
        self.take = np.flatnonzero((r >= 0) & (c >= 0))
        r, c = r[self.take], c[self.take]
        n = self.n = len(free)
        orders = [reverse_cuthill_mckee(sp.csr_matrix((np.ones(len(r)), (r, c)), shape=(n, n)), symmetric_mode=True)]
        if nodes is not None:
            orders.append(principal_axis_order(np.asarray(nodes, float)[free // 2]))
        best = None
        for perm in orders:       # the one of least work, n kl (kl + ku) (dgbtrf's)
            rank = np.empty(n, np.int64)
            rank[perm] = np.arange(n)
            pr, pc = rank[r], rank[c]
            kl, ku = int(max((pr - pc).max(initial=0), 0)), int(max((pc - pr).max(initial=0), 0))
            if best is None or kl * (kl + ku) < best[1] * (best[1] + best[2]):
                best = (perm, kl, ku, pr, pc)
        self.perm, self.kl, self.ku, pr, pc = best
        self.rows = 2 * self.kl + self.ku + 1          # dgbtrf's storage: kl more rows for the row interchanges
        self.place = pc * self.rows + (self.kl + self.ku + pr - pc)   # in the (n, rows) C array = F-ordered band
        upper = pr <= pc                               # dpbtrf's storage of a symmetric band: its upper half
        self.upper_take = self.take[upper]
        self.upper_place = pc[upper] * (self.ku + 1) + (self.ku + pr[upper] - pc[upper])
        self.per_row = len(r) / max(n, 1)

    @property
    def worthwhile(self) -> bool:
        """Whether the band is narrow against the rows' density (the module doc)."""
        return self.kl <= MAX_BAND_PER_ROW * self.per_row

    def fits(self, K: sp.csr_matrix) -> bool:
        """Whether K is on the pattern the band was laid out for."""
        return (K.indices is self.indices or (len(K.indices) == len(self.indices)
                                              and np.array_equal(K.indptr, self.indptr)
                                              and np.array_equal(K.indices, self.indices)))

    def factorise(self, K: sp.csr_matrix) -> BandedFactors:
        """The factors of K's free block; RuntimeError where a pivot is exactly zero (as SuperLU's)."""
        band = np.zeros((self.n, self.rows))
        band.ravel()[self.place] = K.data[self.take]
        with one_blas_thread():     # OpenBLAS's threads spin-wait for a busy core (linear_solver's note)
            lub, piv, info = lapack.dgbtrf(band.T, self.kl, self.ku, overwrite_ab=1)
        if info > 0:
            raise RuntimeError("Factor is exactly singular")
        if info < 0:
            raise ValueError(f"dgbtrf: illegal argument {-info}")
        return BandedFactors(lub, piv, self.kl, self.ku, self.perm)

    def cholesky(self, K: sp.csr_matrix) -> BandedCholeskyFactors:
        """The Cholesky factors (dpbtrf) of K's free block, K symmetric positive definite on a symmetric pattern
        (its upper half is read): half the band of the LU, whose row interchanges widen U to kl + ku, and a
        substitution about twice as fast (the 1928-node slope's elastic stiffness, 3613 free dofs, half-width
        387: 0.79 ms against 1.59 ms for dgbtrs and for SuperLU's MMD_AT_PLUS_A factors, one thread).
        RuntimeError where K is not positive definite."""
        band = np.zeros((self.n, self.ku + 1))
        band.ravel()[self.upper_place] = K.data[self.upper_take]
        with one_blas_thread():
            cb, info = lapack.dpbtrf(band.T, lower=0, overwrite_ab=1)
        if info > 0:
            raise RuntimeError("the matrix is not positive definite")
        if info < 0:
            raise ValueError(f"dpbtrf: illegal argument {-info}")
        return BandedCholeskyFactors(cb, self.perm)

