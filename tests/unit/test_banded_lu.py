"""The banded LU of the Mohr-Coulomb tangents: the same solution as SuperLU for a non-symmetric matrix on the
pattern, an exactly singular one refused as SuperLU refuses it, and the choice made by the pattern alone."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ctmrpim.solvers.banded_lu import BandedLU


def _grid_matrix(nx: int, ny: int, reach: int, seed: int = 0) -> sp.csr_matrix:
    """A non-symmetric, diagonally dominant matrix coupling the nodes of an nx x ny grid within ``reach`` (2 dofs
    per node, interleaved), nodes numbered in a shuffled order (the band must come from the ordering)."""
    rng = np.random.default_rng(seed)
    order = rng.permutation(nx * ny)
    ij = np.array([(i, j) for i in range(nx) for j in range(ny)])
    d = np.abs(ij[:, None, :] - ij[None, :, :]).max(axis=2)
    I, J = np.nonzero(d <= reach)
    rows = np.concatenate([2 * order[I] + a for a in (0, 1) for _ in (0, 1)])
    cols = np.concatenate([2 * order[J] + b for _ in (0, 1) for b in (0, 1)])
    A = sp.csr_matrix((rng.normal(size=len(rows)), (rows, cols)), shape=(2 * nx * ny,) * 2)
    return (A + sp.diags(np.full(A.shape[0], 4.0 * (2 * reach + 1) ** 2))).tocsr()


def test_the_band_solves_as_superlu_does() -> None:
    K = _grid_matrix(30, 8, 2)
    free = np.setdiff1d(np.arange(K.shape[0]), [0, 1, 7, 40])
    band = BandedLU(K, free)
    assert band.worthwhile and band.kl < len(free) // 4      # RCM found the grid's narrow band
    K2 = K.copy()
    K2.data *= np.random.default_rng(1).uniform(0.5, 1.5, K.nnz)   # another matrix on the same pattern
    Kff = K2[free][:, free].tocsc()
    b = np.random.default_rng(2).normal(size=len(free))
    x = band.factorise(K2).solve(b)
    assert np.linalg.norm(x - spla.splu(Kff).solve(b)) <= 1e-12 * np.linalg.norm(x)
    assert np.linalg.norm(Kff @ x - b) <= 1e-12 * np.linalg.norm(b)


def test_an_exactly_singular_matrix_is_refused() -> None:
    K = _grid_matrix(10, 4, 1)
    free = np.arange(K.shape[0])
    K.data[K.indptr[5]:K.indptr[6]] = 0.0     # a zero row (a dof whose points all returned to the apex)
    with pytest.raises(RuntimeError, match="singular"):
        BandedLU(K, free).factorise(K)


def test_other_patterns_are_not_taken() -> None:
    K = _grid_matrix(10, 4, 1)
    band = BandedLU(K, np.arange(K.shape[0]))
    other = _grid_matrix(10, 4, 2)
    assert band.fits(K.copy()) and not band.fits(other)
    sparse_rows = sp.random(400, 400, density=0.01, random_state=3, format="csr") + sp.identity(400, format="csr")
    assert not BandedLU(sparse_rows.tocsr(), np.arange(400)).worthwhile   # a wide band against sparse rows


def test_the_cholesky_of_a_symmetric_positive_definite_matrix_solves_as_superlu_does() -> None:
    """The symmetric part of the grid matrix (diagonally dominant: positive definite) through dpbtrf/dpbtrs, its
    upper half read from the CSR pattern, equals SuperLU's solution; an indefinite one is refused."""
    A = _grid_matrix(30, 8, 2, seed=4)
    K = (0.5 * (A + A.T)).tocsr()
    K.sort_indices()
    free = np.setdiff1d(np.arange(K.shape[0]), [0, 1, 7, 40])
    band = BandedLU(K, free)
    Kff = K[free][:, free].tocsc()
    b = np.random.default_rng(5).normal(size=len(free))
    x = band.cholesky(K).solve(b)
    assert np.linalg.norm(x - spla.splu(Kff).solve(b)) <= 1e-12 * np.linalg.norm(x)
    indefinite = K.copy()
    indefinite.setdiag(-indefinite.diagonal())      # the diagonal is on the pattern: the band is the same
    with pytest.raises(RuntimeError, match="not positive definite"):
        band.cholesky(indefinite)
