"""The Mohr-Coulomb system's compiled products over the points equal the sparse products they replace: the gradient,
the internal force and the consistent tangent's point-wise correction, for any per-point D (non-symmetric:
non-associated flow), with and without Petrov-Galerkin test gradients; what they cannot do is refused (a G not in
the RPIM layout, a block outside K_0's pattern)."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from ctmrpim.discretisation.lagrangian_operators import gradient_operator
from ctmrpim.discretisation.point_products import PointProducts
from ctmrpim.solvers.plastic_system import FROM_GRAD, TO_P, block_rows
from ctmrpim.solvers.weak_form import internal_force, tangent


def _gradients(seed: int, m: int = 300, n: int = 80, support: int = 12):
    """(dN/dx, dN/dy) at m points with ``support`` random nodes each (one pattern, sorted columns)."""
    rng = np.random.default_rng(seed)
    cols = np.sort(np.array([rng.choice(n, support, replace=False) for _ in range(m)]), axis=1)
    indptr = np.arange(0, m * support + 1, support)
    return tuple(sp.csr_matrix((rng.normal(size=m * support), cols.ravel(), indptr), shape=(m, n)) for _ in "xy")


@pytest.mark.parametrize("petrov", [False, True])
def test_the_compiled_products_equal_the_sparse_products(petrov: bool) -> None:
    dx, dy = _gradients(1)
    G = gradient_operator(dx, dy)
    test = None
    if petrov:   # test gradients on the same pattern, other values
        rng = np.random.default_rng(7)
        test = gradient_operator(sp.csr_matrix((rng.normal(size=dx.nnz), dx.indices, dx.indptr), shape=dx.shape),
                                 sp.csr_matrix((rng.normal(size=dx.nnz), dx.indices, dx.indptr), shape=dx.shape))
    m = dx.shape[0]
    rng = np.random.default_rng(3)
    w = rng.uniform(0.5, 1.5, m)
    GT = G.T if test is None else test.T
    K0 = tangent(G, np.broadcast_to(TO_P @ np.eye(3) @ FROM_GRAD, (m, 4, 4)), w, GT)
    points = np.sort(rng.choice(m, m // 3, replace=False))
    D = rng.normal(size=(len(points), 3, 3))      # non-symmetric
    products = PointProducts.build(G, test, w)
    K = products.corrected(K0, points, D)
    Gp = block_rows(G, points)
    GTp = Gp.T if test is None else block_rows(test, points).T
    expected = K0 + tangent(Gp, TO_P[None] @ D @ FROM_GRAD[None], w[points], GTp)
    assert abs(K - expected).max() <= 1e-12 * abs(expected).max()
    assert K.nnz == K0.nnz        # on K_0's pattern; K_0 itself unchanged
    assert abs(K0 - tangent(G, np.broadcast_to(TO_P @ FROM_GRAD, (m, 4, 4)), w, GT)).max() == 0
    dU, P = rng.normal(size=G.shape[1]), rng.normal(size=(m, 4))
    assert np.allclose(products.gradient(dU), (G @ dU).reshape(-1, 4), rtol=0, atol=1e-12 * abs(G @ dU).max())
    f = internal_force(G, P, w, GT)
    assert np.allclose(products.force(P), f, rtol=0, atol=1e-12 * abs(f).max())


@pytest.mark.parametrize("petrov, symmetric", [(False, False), (True, False), (False, True), (True, True)])
def test_the_compiled_tangent_equals_the_sparse_product(petrov: bool, symmetric: bool) -> None:
    """G~^T diag(w A) G with a full 4 x 4 A per point (the large-deformation tangents; a symmetric one, as
    hyperelasticity gives, takes the half-work path where the test gradients are the trial ones), every entry to
    round-off, on the pattern of the node pairs that share a point (sorted columns)."""
    dx, dy = _gradients(4)
    G = gradient_operator(dx, dy)
    test = None
    if petrov:
        rng = np.random.default_rng(8)
        test = gradient_operator(sp.csr_matrix((rng.normal(size=dx.nnz), dx.indices, dx.indptr), shape=dx.shape),
                                 sp.csr_matrix((rng.normal(size=dx.nnz), dx.indices, dx.indptr), shape=dx.shape))
    m = dx.shape[0]
    rng = np.random.default_rng(5)
    w = rng.uniform(0.5, 1.5, m)
    A = rng.normal(size=(m, 4, 4))
    if symmetric:
        A = A + A.transpose(0, 2, 1)
    products = PointProducts.build(G, test, w)
    expected = tangent(G, A, w, G.T if test is None else test.T)
    for _ in range(2):        # the second call re-uses the pattern built by the first
        K = products.tangent(A)
        assert K.has_sorted_indices and np.all(np.diff(K.indices[K.indptr[0]:K.indptr[1]]) > 0)
        assert abs(K - expected).max() <= 1e-12 * abs(expected).max()
    if symmetric and not petrov:
        assert abs(K - K.T).max() <= 1e-14 * abs(K).max()     # the mirrored half (a node's own block summed)
    pairs = (abs(dx.T) @ abs(dx)).tocsr()          # the node pairs that share a point
    assert K.nnz == 4 * pairs.nnz


def test_what_it_cannot_do_is_refused() -> None:
    dx, dy = _gradients(2)
    G = gradient_operator(dx, dy)
    w = np.ones(dx.shape[0])
    assert PointProducts.build(G.tocsr().tobsr(blocksize=(4, 1)), None, w) is None     # the FE layout
    products = PointProducts.build(G, None, w)
    empty = sp.identity(G.shape[1], format="csr")        # a K_0 whose pattern lacks the coupling blocks
    assert products.corrected(empty, np.array([0, 5]), np.ones((2, 3, 3))) is None
