"""Compiled (numba) passes of the linear solve over a sparse matrix's arrays: the free-free block of the
constrained system (whole, as CSR, or its upper triangle), products with a CSR matrix (by blocks of rows) and
with a matrix held by its upper triangle, and the band of a symmetrically permuted matrix in LAPACK's storage
(its width and its fill).

Why compiled: scipy's slicing of the free block copies K's rows and then its columns (160 MB each at 257 x 65
nodes), and a permuted copy of K for the band is another; here each is one pass over K's arrays, writing only
the result.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def constrained_block(indptr, indices, data, new, values_at, rhs, upper):
    """The free-free block of a CSR matrix as CSR arrays, row by row (no scatter: a column-wise copy took five
    times as long at 129 x 33 nodes), or with ``upper`` only its upper triangle, diagonal included (half the
    entries, for a symmetric matrix with sorted columns): ``new[i]`` the free index of row/column i or -1 where
    it is prescribed; rhs[new[r]] -= sum over prescribed columns c of A[r, c] values_at[c] (the prescribed
    values moved to the right-hand side, from the whole rows either way). Columns keep their order in each row
    (``new`` is increasing on the free dofs)."""
    nf = 0
    for i in range(len(new)):
        if new[i] >= 0:
            nf += 1
    rptr = np.zeros(nf + 1, np.int64)
    for r in range(len(indptr) - 1):
        nr = new[r]
        if nr < 0:
            continue
        first = nr if upper else 0            # the first free column kept in this row
        count = 0
        for k in range(indptr[r], indptr[r + 1]):
            if new[indices[k]] >= first:
                count += 1
        rptr[nr + 1] = count
    for i in range(nf):
        rptr[i + 1] += rptr[i]
    cols = np.empty(rptr[nf], indices.dtype)
    vals = np.empty(rptr[nf])
    for r in range(len(indptr) - 1):
        nr = new[r]
        if nr < 0:
            continue
        first = nr if upper else 0
        t = rptr[nr]
        for k in range(indptr[r], indptr[r + 1]):
            c = new[indices[k]]
            if c >= first:
                cols[t] = c
                vals[t] = data[k]
                t += 1
            elif c < 0:
                rhs[nr] -= data[k] * values_at[indices[k]]
    return rptr, cols, vals


@njit(cache=True, nogil=True)
def csr_matvec(indptr, indices, data, x, y, r0, r1):
    """y[r] = (A x)[r] for the rows r0 <= r < r1 of the CSR matrix (indptr, indices, data), summed along each row
    in its order (scipy's order: the same bits), so that blocks of rows run on threads."""
    for r in range(r0, r1):
        s = 0.0
        for k in range(indptr[r], indptr[r + 1]):
            s += data[k] * x[indices[k]]
        y[r] = s


@njit(cache=True, nogil=True)
def symmetric_matvec(indptr, indices, data, x, y):
    """y += A x for the symmetric A whose upper triangle (diagonal included) is the CSR (indptr, indices, data):
    one pass over the half, each entry used for its row and, off the diagonal, its column."""
    for r in range(len(indptr) - 1):
        xr = x[r]
        s = 0.0
        for k in range(indptr[r], indptr[r + 1]):
            c = indices[k]
            v = data[k]
            s += v * x[c]
            if c != r:
                y[c] += v * xr
        y[r] += s


@njit(cache=True, nogil=True)
def lower_bandwidth(indptr, indices, rank):
    """max(rank[i] - rank[j]) over the entries (i, j) of a CSR or CSC pattern (symmetric: either half)."""
    bw = 0
    for r in range(len(indptr) - 1):
        for k in range(indptr[r], indptr[r + 1]):
            d = rank[r] - rank[indices[k]]
            if d > bw:
                bw = d
            elif -d > bw:
                bw = -d
    return bw


@njit(cache=True, nogil=True)
def fill_lower_band(indptr, indices, data, rank, ab, average, half):
    """LAPACK's lower band storage of the symmetrically permuted matrix, ab[i - j, j] = A[i, j] for i >= j in
    the permuted numbering ``rank``, from a CSR or CSC matrix with symmetric values (the permuted lower triangle
    is read); with ``half``, from one triangle of a symmetric matrix in the original numbering (every entry is
    placed at its transpose's place where that is the lower one); with ``average``, of the symmetric part
    (A + A^T) / 2 instead, for any A (ab zero on entry)."""
    for r in range(len(indptr) - 1):
        pr = rank[r]
        for k in range(indptr[r], indptr[r + 1]):
            pc = rank[indices[k]]
            if average:
                if pr > pc:
                    ab[pr - pc, pc] += 0.5 * data[k]
                elif pr < pc:
                    ab[pc - pr, pr] += 0.5 * data[k]
                else:
                    ab[0, pc] += data[k]      # a diagonal entry is its own transpose
            elif pr >= pc:
                ab[pr - pc, pc] = data[k]
            elif half:
                ab[pc - pr, pr] = data[k]
