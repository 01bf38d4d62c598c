"""Compiled (numba) assembly of K = sum_p w_p B~_p^T D B_p (Eq. 5, in Eq. 9's form) on one sparse pattern, and of
the scalar mass matrix M = sum_p w_p N_p^T N_p of the L2 projection onto the nodes (:func:`mass_rows`) on the same
node pattern.

Why compiled: as scipy products the stiffness takes sparse matrix products over the points (each with a
symbolic pass, a numeric pass and the output sorted afterwards), then a block matrix and its conversion,
several copies of K at once. Here it is a row-by-row (Gustavson) product straight into the interleaved CSR
of K: the points' rows are transposed once into node -> (point, entry) lists by a counting sort; a symbolic
pass lists each node row's neighbours (nodes sharing a point with it, sorted: K's node pattern), so K's arrays
are allocated once at their final size; the numeric pass accumulates, for node I and every node J sharing a
point with it, the four sums

    xx_IJ = sum_p w_p dN~_I/dx dN_J/dx,  xy_IJ = sum_p w_p dN~_I/dx dN_J/dy,  yx_IJ, yy_IJ likewise,

in a dense accumulator of the row's length (the four sums of a pair side by side), and writes the 2 x 2 block
B~_I^T D B_J of every pair (any symmetric or non-symmetric 3 x 3 D). Rows are independent, so blocks of rows
run on a thread pool (the kernels release the GIL). Working memory is K's arrays, its node pattern and an
integer array of the node count per thread; nothing of size points x support x support exists.

The loops' indices are unsigned: numba wraps a signed index that may be negative (``i < 0`` -> ``i + len``), a
select on every load and store of the inner loops (measured on the 129 x 33 cantilever, one thread: the
numeric pass 0.25 -> 0.13 s with the sums side by side, the symbolic pass 0.23 -> 0.06 s in one pass instead
of a count pass and a listing pass).
"""
from __future__ import annotations

import numpy as np
from numba import njit, uint64

_FAST = {"contract", "reassoc"}
_1, _2, _3, _4 = uint64(1), uint64(2), uint64(3), uint64(4)


@njit(cache=True, nogil=True)
def transpose_pattern(indptr, indices, n, trow, tent):
    """The columns of a CSR pattern (m rows, ``n`` columns) as lists: returns the start of each column
    (n + 1) and fills ``trow`` (the row of each entry in column order) and ``tent`` (its index into
    ``indices``); rows ascending within a column. The caller sizes trow and tent (int32 where they fit)."""
    m = len(indptr) - 1
    tptr = np.zeros(n + 1, np.int64)
    for k in range(len(indices)):
        tptr[indices[k] + 1] += 1
    for j in range(n):
        tptr[j + 1] += tptr[j]
    fill = tptr[:-1].copy()
    for p in range(m):
        for k in range(indptr[p], indptr[p + 1]):
            j = indices[k]
            t = fill[j]
            trow[t] = p
            tent[t] = k
            fill[j] = t + 1
    return tptr


@njit(cache=True, nogil=True)
def node_pattern_rows(indptr, indices, tptr, trow, n, r0, r1):
    """The node pattern of K for the node rows r0 <= I < r1: (counts (r1 - r0), the sorted neighbours of each row
    one row after the other), the neighbours of I being the nodes J that share an integration point with it.
    (tptr, trow) the transpose of the points' pattern (indptr, indices) (:func:`transpose_pattern`)."""
    mark = np.full(n, -1, np.int64)
    counts = np.empty(r1 - r0, np.int64)
    cols = np.empty(max(1024, 64 * (r1 - r0)), indices.dtype)
    used = 0
    for i in range(r0, r1):
        c = 0
        for t in range(uint64(tptr[i]), uint64(tptr[i + 1])):
            p = uint64(trow[t])
            row = indptr[p + _1] - indptr[p]
            if used + c + row > len(cols):          # grow: at most the point's row is new
                grown = np.empty(2 * len(cols) + row, cols.dtype)
                grown[:used + c] = cols[:used + c]
                cols = grown
            for k in range(uint64(indptr[p]), uint64(indptr[p + _1])):
                j = uint64(indices[k])
                if mark[j] != i:
                    mark[j] = i
                    cols[used + c] = j
                    c += 1
        cols[used:used + c].sort()
        counts[i - r0] = c
        used += c
    return counts, cols[:used]


@njit(cache=True, nogil=True)
def _row_scratch(n, node_start, r0, r1):
    """(pos, acc) of the node rows r0 <= I < r1 of :func:`stiffness_rows`, :func:`tangent_rows` and
    :func:`mass_rows`: ``pos`` (n,) each neighbour's place in the row being summed, ``acc`` the row's accumulator,
    four sums per neighbour (the 2 x 2 block of a pair side by side; the mass uses the first one per neighbour),
    sized for the widest of these rows."""
    width = 0
    for i in range(r0, r1):
        width = max(width, node_start[i + 1] - node_start[i])
    return np.empty(n, np.uint32), np.empty(4 * width)


@njit(cache=True, nogil=True)
def _start_row(pos, acc, neighbours, node_start, i):
    """Node row i begins: each of its neighbours' place into ``pos``, its accumulator zeroed; (o, c): where its
    neighbours start in ``neighbours``, and how many there are."""
    o = uint64(node_start[i])
    c = uint64(node_start[i + _1]) - o
    for q in range(c):
        pos[uint64(neighbours[o + q])] = q
    for q in range(_4 * c):
        acc[q] = 0.0
    return o, c


@njit(cache=True, nogil=True)
def _pair_columns(k_indices, neighbours, o, c):
    """The columns of node row I in the interleaved layout of :func:`stiffness_rows`: row 2I from 4 o, row 2I + 1
    from 4 o + 2 c, each 2J, 2J + 1 for its c sorted neighbours J = neighbours[o:o + c]."""
    o0 = _4 * o
    o1 = o0 + _2 * c
    for q in range(c):
        j = uint64(neighbours[o + q])
        k_indices[o0 + _2 * q] = _2 * j
        k_indices[o0 + _2 * q + _1] = _2 * j + _1
        k_indices[o1 + _2 * q] = _2 * j
        k_indices[o1 + _2 * q + _1] = _2 * j + _1


@njit(cache=True, nogil=True, fastmath=_FAST)
def stiffness_rows(indptr, indices, dx, dy, tdx, tdy, w, D, tptr, trow, tent, n, node_start, neighbours, r0, r1,
                   k_indices, k_data, upper, corr, points, nodes, d_c, mode):
    """Rows 2I and 2I + 1 of K for r0 <= I < r1 into the interleaved CSR arrays: node row I owns
    4 node_start[I] .. 4 node_start[I + 1] (its c neighbours ``neighbours[node_start[I]:node_start[I + 1]]``,
    sorted: row 2I first, 2c entries, then row 2I + 1), columns 2J, 2J + 1 for J ascending. (dx, dy) the trial
    and (tdx, tdy) the test gradients on the pattern (indptr, indices), w the points' weights, D (3, 3).
    ``upper``: K symmetric (B~ = B, D symmetric) and the pattern's rows sorted: only the blocks J >= I are summed
    and written (the entries after I's in a point's row are those), half the work; :func:`mirror_lower` writes
    the rest. ``mode`` 1 or 2: the test gradients are (tdx, tdy) plus the correction of
    :class:`ctmrpim.discretisation.gradient_correction.GradientCorrection` (coefficients ``corr`` (n, 3, 2), linear
    or quadratic, at ``points`` over ``nodes``, scaled by ``d_c``), as its ``applied`` writes them; 0: as given."""
    pos, acc = _row_scratch(n, node_start, r0, r1)     # acc: xx, xy, yx, yy of a pair side by side
    d00, d01, d02 = D[0, 0], D[0, 1], D[0, 2]
    d10, d11, d12 = D[1, 0], D[1, 1], D[1, 2]
    d20, d21, d22 = D[2, 0], D[2, 1], D[2, 2]
    for i in range(uint64(r0), uint64(r1)):
        o, c = _start_row(pos, acc, neighbours, node_start, i)
        if mode > 0:
            cx0, cx1, cx2 = corr[i, 0, 0], corr[i, 1, 0], corr[i, 2, 0]
            cy0, cy1, cy2 = corr[i, 0, 1], corr[i, 1, 1], corr[i, 2, 1]
            xi, yi = nodes[i, 0], nodes[i, 1]
        for t in range(uint64(tptr[i]), uint64(tptr[i + _1])):
            p = uint64(trow[t])
            e = uint64(tent[t])
            if mode == 0:
                ax = tdx[e] * w[p]
                ay = tdy[e] * w[p]
            else:
                cx, cy = cx0, cy0
                if mode == 2:
                    q1 = (points[p, 0] - xi) / d_c
                    q2 = (points[p, 1] - yi) / d_c
                    cx += q1 * cx1 + q2 * cx2
                    cy += q1 * cy1 + q2 * cy2
                ax = (tdx[e] + cx) * w[p]
                ay = (tdy[e] + cy) * w[p]
            for k in range(e if upper else uint64(indptr[p]), uint64(indptr[p + _1])):
                q = _4 * uint64(pos[uint64(indices[k])])
                bx = dx[k]
                by = dy[k]
                acc[q] += ax * bx
                acc[q + _1] += ax * by
                acc[q + _2] += ay * bx
                acc[q + _3] += ay * by
        _pair_columns(k_indices, neighbours, o, c)
        o0 = _4 * o
        o1 = o0 + _2 * c
        for q in range(c):
            if upper and uint64(neighbours[o + q]) < i:
                continue
            a, b, g, h = acc[_4 * q], acc[_4 * q + _1], acc[_4 * q + _2], acc[_4 * q + _3]
            # B~_I^T D B_J with B = [[d/dx, 0], [0, d/dy], [d/dy, d/dx]]
            k_data[o0 + _2 * q] = d00 * a + d02 * b + d20 * g + d22 * h
            k_data[o0 + _2 * q + _1] = d01 * b + d02 * a + d21 * h + d22 * g
            k_data[o1 + _2 * q] = d10 * g + d12 * h + d20 * a + d22 * b
            k_data[o1 + _2 * q + _1] = d11 * h + d12 * g + d21 * b + d22 * a


@njit(cache=True, nogil=True)
def mass_rows(indptr, indices, N, w, tptr, trow, tent, n, node_start, neighbours, r0, r1, m_data):
    """Rows r0 <= I < r1 of M = sum_p w_p N_p^T N_p (the L2 projection's mass matrix) into the CSR data of M's node
    pattern (row I: columns ``neighbours[node_start[I]:node_start[I + 1]]``, sorted), with N the shape functions on
    the points' pattern (indptr, indices) and (tptr, trow, tent) its transpose. Each term is w_p (N_I N_J), summed
    over the points in ascending order: M_IJ and M_JI are the same sums, so M is exactly symmetric (no fastmath:
    reassociation would break that)."""
    pos, acc = _row_scratch(n, node_start, r0, r1)
    for i in range(uint64(r0), uint64(r1)):
        o, c = _start_row(pos, acc, neighbours, node_start, i)
        for t in range(uint64(tptr[i]), uint64(tptr[i + _1])):
            p = uint64(trow[t])
            a = N[uint64(tent[t])]
            wp = w[p]
            for k in range(uint64(indptr[p]), uint64(indptr[p + _1])):
                acc[uint64(pos[uint64(indices[k])])] += wp * (a * N[k])
        for q in range(c):
            m_data[o + q] = acc[q]


@njit(cache=True, nogil=True)
def add_on_pattern(indptr, indices, data, c_indptr, c_indices, c_data, scale):
    """data += scale * C on the pattern (indptr, indices) where every entry of C (CSR, any column order) has
    a place in it (column indices sorted per row); False, with data unchanged, where one has none."""
    where = np.empty(len(c_indices), np.int64)
    for r in range(len(c_indptr) - 1):
        a, b = indptr[r], indptr[r + 1]
        for e in range(c_indptr[r], c_indptr[r + 1]):
            j = c_indices[e]
            k = a + np.searchsorted(indices[a:b], j)
            if k >= b or indices[k] != j:
                return False
            where[e] = k
    for e in range(len(c_indices)):
        data[where[e]] += scale * c_data[e]
    return True


@njit(cache=True, nogil=True)
def mirror_lower(k_indptr, k_indices, k_data, r0, r1):
    """K[2J:2J+2, 2I:2I+2] = K[2I:2I+2, 2J:2J+2]^T for the node rows r0 <= J < r1 and every I < J (the blocks
    :func:`stiffness_rows` left with ``upper``); columns sorted within rows."""
    for jn in range(r0, r1):
        a0 = k_indptr[2 * jn]
        a1 = k_indptr[2 * jn + 1]
        for t in range(a0, a1, 2):
            col = k_indices[t]
            inode = col // 2
            if inode >= jn:
                break
            # the position of column 2J in row 2I (binary search; columns sorted)
            s0 = k_indptr[2 * inode]
            s1 = k_indptr[2 * inode + 1]
            u = s0 + np.searchsorted(k_indices[s0:s1], 2 * jn)
            v = s1 + (u - s0)                      # the same column in row 2I + 1
            k_data[t] = k_data[u]                  # K[2J, 2I] = K[2I, 2J]
            k_data[t + 1] = k_data[v]              # K[2J, 2I + 1] = K[2I + 1, 2J]
            k_data[a1 + (t - a0)] = k_data[u + 1]  # K[2J + 1, 2I] = K[2I, 2J + 1]
            k_data[a1 + (t - a0) + 1] = k_data[v + 1]


@njit(cache=True, nogil=True, fastmath=_FAST)
def pointwise_rows(indptr, indices, dx, dy, tdx, tdy, w, slot, D, tptr, trow, tent, r0, r1,
                   k_indptr, k_indices, k_data):
    """k_data += sum_p w_p B~_I^T D_p B_J over the points p with slot[p] >= 0 (D_p = D[slot[p]], any 3 x 3), for
    the node rows r0 <= I < r1, on K's existing CSR pattern in the interleaved layout of :func:`stiffness_rows`
    (rows 2I and 2I + 1 with the same columns, 2J and 2J + 1 side by side); (dx, dy) the trial and (tdx, tdy) the
    test gradients on the points' pattern (indptr, indices), (tptr, trow, tent) its transpose
    (:func:`transpose_pattern`). A row's sums gather in a dense accumulator by neighbour, with T = B~_I^T D_p (2 x 3)
    once per point and node: 8 multiply-adds per pair instead of 16. False where K is not in that layout or a
    block has no place in its pattern (``k_data`` is then partly updated: the caller works on a copy)."""
    n = (len(k_indptr) - 1) // 2
    pos = np.empty(n, np.uint32)
    stamp = np.full(n, -1, np.int64)
    width = 0
    for i in range(r0, r1):
        width = max(width, k_indptr[2 * i + 1] - k_indptr[2 * i])
    acc = np.empty(2 * width)
    for i in range(uint64(r0), uint64(r1)):
        touched = False
        for t in range(uint64(tptr[i]), uint64(tptr[i + _1])):
            if slot[uint64(trow[t])] >= 0:
                touched = True
                break
        if not touched:
            continue
        a0, a1, a2 = uint64(k_indptr[_2 * i]), uint64(k_indptr[_2 * i + _1]), uint64(k_indptr[_2 * i + _2])
        if (a1 - a0) % _2 != 0 or a2 - a1 != a1 - a0:
            return False
        c = (a1 - a0) // _2
        for q in range(c):
            col = k_indices[a0 + _2 * q]
            if (col % 2 != 0 or k_indices[a0 + _2 * q + _1] != col + 1 or k_indices[a1 + _2 * q] != col
                    or k_indices[a1 + _2 * q + _1] != col + 1):
                return False
            pos[col // 2] = q
            stamp[col // 2] = i
        for q in range(_4 * c):
            acc[q] = 0.0
        for t in range(uint64(tptr[i]), uint64(tptr[i + _1])):
            p = uint64(trow[t])
            s = slot[p]
            if s < 0:
                continue
            e = uint64(tent[t])
            ax = tdx[e] * w[p]
            ay = tdy[e] * w[p]
            # T = B~_I^T D_p with B~_I^T = [[ax, 0, ay], [0, ay, ax]]
            t00 = ax * D[s, 0, 0] + ay * D[s, 2, 0]
            t01 = ax * D[s, 0, 1] + ay * D[s, 2, 1]
            t02 = ax * D[s, 0, 2] + ay * D[s, 2, 2]
            t10 = ay * D[s, 1, 0] + ax * D[s, 2, 0]
            t11 = ay * D[s, 1, 1] + ax * D[s, 2, 1]
            t12 = ay * D[s, 1, 2] + ax * D[s, 2, 2]
            for k in range(uint64(indptr[p]), uint64(indptr[p + _1])):
                j = uint64(indices[k])
                if stamp[j] != i:
                    return False
                q = _4 * uint64(pos[j])
                bx = dx[k]
                by = dy[k]
                # T B_J with B_J = [[bx, 0], [0, by], [by, bx]]
                acc[q] += t00 * bx + t02 * by
                acc[q + _1] += t01 * by + t02 * bx
                acc[q + _2] += t10 * bx + t12 * by
                acc[q + _3] += t11 * by + t12 * bx
        for q in range(c):
            k_data[a0 + _2 * q] += acc[_4 * q]
            k_data[a0 + _2 * q + _1] += acc[_4 * q + _1]
            k_data[a1 + _2 * q] += acc[_4 * q + _2]
            k_data[a1 + _2 * q + _1] += acc[_4 * q + _3]
    return True


@njit(cache=True, nogil=True, fastmath=_FAST)
def tangent_rows(indptr, indices, dx, dy, tdx, tdy, w, A, tptr, trow, tent, n, node_start, neighbours, r0, r1,
                 k_indices, k_data, upper):
    """Rows 2I and 2I + 1 of K = sum_p w_p G~_p^T A_p G_p for r0 <= I < r1, in the layout of :func:`stiffness_rows`
    (node row I owns 4 node_start[I] .. 4 node_start[I + 1], its sorted ``neighbours``, columns 2J, 2J + 1 for J
    ascending): A (m, 16) the point's dP/dF (row 4p + c, c = 2i + J for du_i/dX_J: xX, xY, yX, yY) flattened
    row-major, (dx, dy) the trial and (tdx, tdy) the test gradients on the pattern (indptr, indices):
    K[(I, i), (K, k)] = sum_p w_p sum_JL d~N_I/dX_J A[2i + J, 2k + L] dN_K/dX_L. ``upper``: K symmetric (test =
    trial, every A_p symmetric, the pattern's rows sorted): only the blocks K >= I are summed and written, as in
    :func:`stiffness_rows`; :func:`mirror_lower` writes the rest."""
    pos, acc = _row_scratch(n, node_start, r0, r1)     # acc: (x, x), (x, y), (y, x), (y, y) of a pair
    for i in range(uint64(r0), uint64(r1)):
        o, c = _start_row(pos, acc, neighbours, node_start, i)
        for t in range(uint64(tptr[i]), uint64(tptr[i + _1])):
            p = uint64(trow[t])
            e = uint64(tent[t])
            ax = tdx[e] * w[p]
            ay = tdy[e] * w[p]
            # v_ikL = sum_J a_J A[2i + J, 2k + L]: rows 0, 1 (i = x) and 2, 3 (i = y) of A, columns 2k + L
            v000 = ax * A[p, 0] + ay * A[p, 4]
            v001 = ax * A[p, 1] + ay * A[p, 5]
            v010 = ax * A[p, 2] + ay * A[p, 6]
            v011 = ax * A[p, 3] + ay * A[p, 7]
            v100 = ax * A[p, 8] + ay * A[p, 12]
            v101 = ax * A[p, 9] + ay * A[p, 13]
            v110 = ax * A[p, 10] + ay * A[p, 14]
            v111 = ax * A[p, 11] + ay * A[p, 15]
            for k in range(e if upper else uint64(indptr[p]), uint64(indptr[p + _1])):
                q = _4 * uint64(pos[uint64(indices[k])])
                bx = dx[k]
                by = dy[k]
                acc[q] += v000 * bx + v001 * by
                acc[q + _1] += v010 * bx + v011 * by
                acc[q + _2] += v100 * bx + v101 * by
                acc[q + _3] += v110 * bx + v111 * by
        _pair_columns(k_indices, neighbours, o, c)
        o0 = _4 * o
        o1 = o0 + _2 * c
        for q in range(c):
            if upper and uint64(neighbours[o + q]) < i:
                continue
            k_data[o0 + _2 * q] = acc[_4 * q]
            k_data[o0 + _2 * q + _1] = acc[_4 * q + _1]
            k_data[o1 + _2 * q] = acc[_4 * q + _2]
            k_data[o1 + _2 * q + _1] = acc[_4 * q + _3]
