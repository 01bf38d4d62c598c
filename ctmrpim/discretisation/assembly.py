"""Global stiffness and load vectors from CTM points and RPIM shape functions (Eqs. 5-6).

Degrees of freedom are interleaved: node i owns dofs 2i (u_x) and 2i+1 (u_y). The stiffness is
K = sum_p w_p B~_p^T D B_p (the paper's Eq. 7 lacks the transpose on B; Eq. 9's form is used), summed
node row by node row straight into K's CSR arrays by the compiled kernels of
:mod:`ctmrpim.discretisation.stiffness_kernels`, never by scattering a dense block per integration point;
small systems are assembled by scipy's sparse products instead (the two agree to round-off).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ctmrpim.discretisation import rpim_kernels
from ctmrpim.discretisation import stiffness_kernels as kernels
from ctmrpim.discretisation.gradient_correction import GradientCorrection
from ctmrpim.discretisation.thread_blocks import run_blocks
from ctmrpim.problem.model import Problem

ROW_BLOCK = 512        # node rows per kernel call on the threads (:mod:`ctmrpim.discretisation.thread_blocks`)
#: below this many shape-function entries scipy's products are taken (numba's first kernel call in a
#: process costs 0.2-0.45 s; :data:`ctmrpim.discretisation.rpim.COMPILED_MIN_POINTS`)
COMPILED_MIN_ENTRIES = 300_000


def dof(node: np.ndarray, component: int) -> np.ndarray:
    """Global dof numbers (shape of ``node``) of a component (0 = x, 1 = y) at node indices ``node``."""
    return 2 * np.asarray(node) + component


def stiffness(dNdx: sp.csr_matrix, dNdy: sp.csr_matrix, weights: np.ndarray, D: np.ndarray,
              test: tuple[sp.csr_matrix, sp.csr_matrix] | GradientCorrection | None = None) -> sp.csr_matrix:
    """K (2n x 2n) = sum_p B~_p^T D B_p w_p (Eq. 5) from the derivatives ``dNdx``, ``dNdy`` (m, n) at m points
    with ``weights`` (m,), for one constant D (3, 3). B~ is built from the ``test`` gradients (d~N/dx, d~N/dy)
    where given (Petrov-Galerkin, not symmetric: :mod:`ctmrpim.discretisation.consistent_integration`), else
    B~ = B. All matrices must share one sparsity pattern. K's pattern is every pair of nodes that share a
    point (an entry that sums to zero is kept); its column indices are sorted. ``test`` may also be the
    correction's coefficients (:class:`GradientCorrection`), which the compiled kernel adds to the trial gradients
    as it reads them (the corrected arrays are never held)."""
    m, n = dNdx.shape
    compiled = rpim_kernels.use_compiled(dNdx.nnz, COMPILED_MIN_ENTRIES)
    correction = test if isinstance(test, GradientCorrection) else None
    if correction is not None and not compiled:
        test, correction = correction.applied(dNdx, dNdy), None
    tdx, tdy = test if test is not None and correction is None else (dNdx, dNdy)
    axes = D[0, 2] == 0 and D[1, 2] == 0 and D[2, 0] == 0 and D[2, 1] == 0
    if axes and np.array_equal(D, D.T) and not compiled:
        return _stiffness_products(dNdx, dNdy, weights, D, test)
    for M in (dNdy, tdx, tdy):
        same = M.indices is dNdx.indices or (np.array_equal(M.indices, dNdx.indices))
        if M.nnz != dNdx.nnz or not (same and np.array_equal(M.indptr, dNdx.indptr)):
            raise ValueError("the gradients must share one sparsity pattern")
    indptr, indices = dNdx.indptr, dNdx.indices     # int32 or int64: the kernels compile for either
    data = [np.ascontiguousarray(M.data, dtype=float) for M in (dNdx, dNdy, tdx, tdy)]
    w = np.ascontiguousarray(weights, dtype=float)
    Dc = np.ascontiguousarray(D, dtype=float)
    etype = np.int32 if dNdx.nnz < 2**31 - 1 else np.int64
    trow, tent = np.empty(dNdx.nnz, etype), np.empty(dNdx.nnz, etype)
    tptr = kernels.transpose_pattern(indptr, indices, n, trow, tent)
    blocks = [(a, min(a + ROW_BLOCK, n)) for a in range(0, n, ROW_BLOCK)]
    node_start, neighbours = node_pattern(indptr, indices, tptr, trow, n, blocks)
    k_indices, k_data, k_indptr = interleaved_arrays(node_start)
    # symmetric K (Galerkin, symmetric D) on sorted rows: the upper blocks summed, the lower ones copied
    upper = test is None and np.array_equal(D, D.T) and dNdx.has_canonical_format
    corr = (correction.c, correction.points, correction.nodes, correction.d_c, correction.mode) if correction \
        else (np.zeros((1, 3, 2)), np.zeros((1, 2)), np.zeros((1, 2)), 1.0, 0)
    run_blocks(lambda ab: kernels.stiffness_rows(indptr, indices, *data, w, Dc, tptr, trow, tent, n, node_start,
                                                 neighbours, *ab, k_indices, k_data, upper, *corr), blocks,
               kernel=kernels.stiffness_rows)
    if upper:
        run_blocks(lambda ab: kernels.mirror_lower(k_indptr, k_indices, k_data, *ab), blocks,
                   kernel=kernels.mirror_lower)
    K = sp.csr_matrix((k_data, k_indices, k_indptr), shape=(2 * n, 2 * n), copy=False)
    K.has_sorted_indices = True
    K.has_canonical_format = True
    return K


def mass(N: sp.csr_matrix, weights: np.ndarray) -> sp.csr_matrix:
    """M (n x n) = sum_p w_p N_p^T N_p from the shape functions ``N`` (m, n) at m points with ``weights`` (m,): the
    mass matrix of the L2 projection onto the nodes (:mod:`ctmrpim.discretisation.state_transfer`). Its pattern is
    every pair of nodes that share a point; column indices sorted. Large sets by the compiled
    :func:`~ctmrpim.discretisation.stiffness_kernels.mass_rows` on K's node pattern (exactly symmetric; measured
    on the 1071-node column's 9600 points, two threads: about 5 ms against 45 ms for scipy's N^T W N), small ones
    by scipy's products (the two agree to round-off)."""
    n = N.shape[1]
    if not rpim_kernels.use_compiled(N.nnz, COMPILED_MIN_ENTRIES):
        return (N.T @ sp.diags(np.asarray(weights, dtype=float)) @ N).tocsr()
    indptr, indices = N.indptr, N.indices
    etype = np.int32 if N.nnz < 2**31 - 1 else np.int64
    trow, tent = np.empty(N.nnz, etype), np.empty(N.nnz, etype)
    tptr = kernels.transpose_pattern(indptr, indices, n, trow, tent)
    blocks = [(a, min(a + ROW_BLOCK, n)) for a in range(0, n, ROW_BLOCK)]
    node_start, neighbours = node_pattern(indptr, indices, tptr, trow, n, blocks)
    data, w = np.ascontiguousarray(N.data, dtype=float), np.ascontiguousarray(weights, dtype=float)
    m_data = np.empty(int(node_start[-1]))
    run_blocks(lambda ab: kernels.mass_rows(indptr, indices, data, w, tptr, trow, tent, n, node_start, neighbours,
                                            *ab, m_data), blocks, kernel=kernels.mass_rows)
    itype = np.int32 if max(len(m_data), n) < 2**31 - 1 else np.int64
    M = sp.csr_matrix((m_data, neighbours.astype(itype, copy=False), node_start.astype(itype)), shape=(n, n),
                      copy=False)
    M.has_sorted_indices = True
    M.has_canonical_format = True
    return M


def node_pattern(indptr: np.ndarray, indices: np.ndarray, tptr: np.ndarray, trow: np.ndarray, n: int,
                 blocks: list[tuple[int, int]]) -> tuple[np.ndarray, np.ndarray]:
    """K's node pattern from the points' pattern (indptr, indices) over ``n`` nodes and its transpose (tptr,
    trow): (node_start (n + 1), the sorted neighbours of every node row, row after row), node J a neighbour of
    I where they share an integration point; the rows in ``blocks`` on the thread pool."""
    parts: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}

    def rows(ab: tuple[int, int]) -> None:
        parts[ab] = kernels.node_pattern_rows(indptr, indices, tptr, trow, n, *ab)

    run_blocks(rows, blocks, kernel=kernels.node_pattern_rows)
    node_start = np.zeros(n + 1, np.int64)
    if blocks:
        np.cumsum(np.concatenate([parts[ab][0] for ab in blocks]), out=node_start[1:])
        neighbours = np.concatenate([parts[ab][1] for ab in blocks])
    else:
        neighbours = np.zeros(0, indices.dtype)
    return node_start, neighbours


def interleaved_arrays(node_start: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """K's CSR arrays (indices, data: empty; indptr: filled) for the interleaved dofs of a node pattern with
    ``node_start`` (n + 1): node row I owns entries 4 node_start[I] .. 4 node_start[I + 1], row 2I's first."""
    n = len(node_start) - 1
    counts = np.diff(node_start)
    nnz = 4 * int(node_start[-1])
    itype = np.int32 if max(nnz, 2 * n) < 2**31 - 1 else np.int64
    k_indptr = np.empty(2 * n + 1, itype)
    k_indptr[0:-1:2] = 4 * node_start[:-1]
    k_indptr[1::2] = 4 * node_start[:-1] + 2 * counts
    k_indptr[-1] = nnz
    return np.empty(nnz, itype), np.empty(nnz), k_indptr


def subtract(K: sp.csr_matrix, C: sp.csr_matrix) -> sp.csr_matrix:
    """K - C, in place on K's arrays where C's entries all lie in K's pattern (the consistency terms of the
    consistent schemes couple nodes that already share a point), else as a new matrix."""
    if C.shape != K.shape:
        raise ValueError("K and C differ in shape")
    if rpim_kernels.numba_ready() and K.has_sorted_indices and kernels.add_on_pattern(
            K.indptr, K.indices, K.data, C.indptr, C.indices, np.asarray(C.data, float), -1.0):
        return K
    return (K - C).tocsr()


def _stiffness_products(dNdx: sp.csr_matrix, dNdy: sp.csr_matrix, weights: np.ndarray, D: np.ndarray,
              test: tuple[sp.csr_matrix, sp.csr_matrix] | None = None) -> sp.csr_matrix:
    """:func:`stiffness` by scipy's sparse products, for D[0, 2] = D[1, 2] = 0. With z = dN/dx + i dN/dy per
    point and node (z~ likewise from the test gradients), two complex products give every sum the stiffness
    needs: Z~^T W Z = (xx - yy) + i (xy + yx) and Z~^H W Z = (xx + yy) + i (xy - yx), a third less work than
    three real products; the four 2 x 2 block entries of every node pair then share one pattern (BSR)."""
    n = dNdx.shape[1]
    tdx, tdy = test if test is not None else (dNdx, dNdy)
    rows = np.repeat(np.arange(dNdx.shape[0]), np.diff(dNdx.indptr))
    wZ = sp.csr_matrix(((dNdx.data + 1j * dNdy.data) * weights[rows], dNdx.indices, dNdx.indptr), shape=dNdx.shape)
    t = tdx.data + 1j * tdy.data
    ZT = sp.csr_matrix((t, tdx.indices, tdx.indptr), shape=tdx.shape).T.tocsr()
    ZHT = sp.csr_matrix((ZT.data.conj(), ZT.indices, ZT.indptr), shape=ZT.shape)
    p1 = ZT @ wZ
    p2 = ZHT @ wZ
    p1.sort_indices()
    p2.sort_indices()
    pattern, d1, d2 = p1, p1.data, p2.data
    if not (np.array_equal(p1.indptr, p2.indptr) and np.array_equal(p1.indices, p2.indices)):
        # an entry that summed to exactly zero was dropped from one product only: use the union pattern
        pattern = (abs(p1) + abs(p2)).tocsr()
        pattern.sort_indices()
        d1, d2 = _on_pattern(p1, pattern), _on_pattern(p2, pattern)
    xx = 0.5 * (d1.real + d2.real)
    yy = 0.5 * (d2.real - d1.real)
    xy = 0.5 * (d1.imag + d2.imag)
    yx = 0.5 * (d1.imag - d2.imag)
    return _block_stiffness(pattern, xx, xy, yx, yy, D, n)


def _block_stiffness(pattern: sp.csr_matrix, xx: np.ndarray, xy: np.ndarray, yx: np.ndarray, yy: np.ndarray,
                     D: np.ndarray, n: int) -> sp.csr_matrix:
    """K (2n x 2n) from the node-pair sums xx_IJ = sum_p w_p dN_I/dx dN_J/dx (and xy, yx, yy) on ``pattern``:
    the 2 x 2 block of each pair is B_I^T D B_J written out for D[0, 2] = D[1, 2] = 0 (D symmetric)."""
    blocks = np.empty((len(xx), 2, 2))
    blocks[:, 0, 0] = D[0, 0] * xx + D[2, 2] * yy
    blocks[:, 0, 1] = D[0, 1] * xy + D[2, 2] * yx
    blocks[:, 1, 0] = D[0, 1] * yx + D[2, 2] * xy
    blocks[:, 1, 1] = D[1, 1] * yy + D[2, 2] * xx
    return sp.bsr_matrix((blocks, pattern.indices, pattern.indptr), shape=(2 * n, 2 * n)).tocsr()


def _on_pattern(a: sp.csr_matrix, pattern: sp.csr_matrix) -> np.ndarray:
    """The entries of ``a`` laid out on ``pattern``'s (sorted, larger) sparsity, zeros elsewhere."""
    n = a.shape[1]
    key = lambda m: np.repeat(np.arange(m.shape[0], dtype=np.int64), np.diff(m.indptr)) * n + m.indices
    out = np.zeros(pattern.nnz, dtype=a.dtype)
    out[np.searchsorted(key(pattern), key(a))] = a.data
    return out


def load_vector(N: sp.csr_matrix, weights: np.ndarray, tx: np.ndarray, ty: np.ndarray) -> np.ndarray:
    """F (2n,) = sum_j N_j^T t_j w_j J_j (Eq. 6, second term), interleaved dofs, from shape functions ``N`` (k, n)
    at k points with ``weights`` (k,) and load components ``tx``, ``ty`` (k,)."""
    return np.column_stack([N.T @ (tx * weights), N.T @ (ty * weights)]).ravel()


def body_force_vector(N: sp.csr_matrix, weights: np.ndarray, problem: Problem) -> np.ndarray:
    """F (2n,) = sum_p N_p^T b w_p over the integration points, b = density * gravity (Eq. 6, body term), from
    shape functions ``N`` (m, n) and ``weights`` (m,), which include the thickness."""
    bx, by = problem.body_force
    if bx == 0.0 and by == 0.0:
        return np.zeros(2 * N.shape[1])
    return load_vector(N, weights, np.full(N.shape[0], bx), np.full(N.shape[0], by))


def strain(dNdx: sp.csr_matrix, dNdy: sp.csr_matrix, u: np.ndarray) -> np.ndarray:
    """(m, 3) exx, eyy, gxy at the rows' points from nodal displacements u (n, 2)."""
    return np.c_[dNdx @ u[:, 0], dNdy @ u[:, 1], dNdy @ u[:, 0] + dNdx @ u[:, 1]]
