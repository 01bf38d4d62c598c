"""Compiled (numba) loops over the evaluation points of the RPIM shape functions (Section 2.3, Eqs. 25-34).

Why compiled: every point has its own moment matrix G of about 50 x 50 (Eq. 32); written with numpy the
points are padded to one size and solved in batches, building G and the right-hand sides through a dozen
temporaries of size points x support x support, and the matrices of a chunk are held at once. Here each
point is one pass: its support from a cell grid, G and the three right-hand sides in a scratch buffer
of one point's size, an LU factorisation with partial pivoting and the two triangular solves, and its
shape functions written straight into the CSR arrays. Nothing larger than one point's system exists at a
time, so the memory is the result's (the CSR rows) plus a few kB per thread.

The LU eliminates four pivot columns per pass over the trailing matrix (each column of the four is brought up
to date by the ones before it before its pivot is chosen, so the pivot sequence is that of ordinary partial
pivoting): a quarter of the loads and stores of one column at a time. G is symmetric, so its rows are its
columns and the LU works on them column-major (every inner loop contiguous) with unsigned indices, which lets
LLVM vectorise it: 11.7 -> 6.5 us per 50 x 50 system with two columns per pass, and a point's shape functions
23 -> 14 us in all on the 129 x 33 cantilever; four columns per pass, 12.0 -> 10.9 us per point (one thread,
this project's two-core machine; the support search 0.4 us, G and the right-hand sides 2.3 us, the LU and the
substitutions 7.9 us of it). The kernels release the GIL, so
:func:`ctmrpim.discretisation.rpim.shape_functions` runs blocks of points on a thread pool.

The fast-math flags are limited to contraction and reassociation (round-off only): no-NaN/no-Inf flags
would let the compiler drop the finiteness checks that detect a singular moment matrix.
"""
from __future__ import annotations

import math
import sys

import numpy as np
from numba import njit

_FAST = {"contract", "reassoc"}

#: status of a point after :func:`rpim_rows`
OK, SINGULAR, NOT_UNITY = 0, 1, 2
#: unsigned index constants: numba compiles ``k + 1`` of an unsigned k as a float unless 1 is unsigned too
_0, _1, _2, _3, _4 = (np.uint64(v) for v in range(5))


def numba_ready() -> bool:
    """Whether numba's compiler is already initialised in this process (a compiled kernel has run): its first
    kernel call, cached or not, loads numba's lowering registries (0.2-0.45 s measured here), later ones
    cost microseconds. Only kernels whose results are bit for bit those of their numpy forms (copies,
    exact sums) are chosen by it."""
    # numba creates its target context when a kernel is decorated (at import); the costly part is the
    # registries and runtime it loads on the first call, which initialises the runtime (NRT)
    from numba.core.runtime.nrt import rtsys
    init = getattr(rtsys, "_init", None)
    return init if isinstance(init, bool) else "numba.np.random.legacy" in sys.modules


def use_compiled(work: int, threshold: int) -> bool:
    """Take the compiled path for ``work`` items: at or above ``threshold``. The choice depends on the size
    alone, never on whether numba already runs in the process: the two paths differ by round-off, and a
    resumed explicit run must repeat the uninterrupted one bit for bit."""
    return work >= threshold


def cell_grid(nodes: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, int, int]:
    """Bucket the ``nodes`` (n, 2) into square cells of side ``h``: (node order by cell, start of each cell in
    that order (ncx * ncy + 1), lower-left corner (2,), h, ncx, ncy). Within a cell the nodes keep index order."""
    origin = nodes.min(axis=0) if len(nodes) else np.zeros(2)
    span = (nodes.max(axis=0) - origin) if len(nodes) else np.zeros(2)
    ncx, ncy = (int(v) for v in np.floor(span / h).astype(np.int64) + 1)
    cx = np.minimum(((nodes[:, 0] - origin[0]) / h).astype(np.int64), ncx - 1)
    cy = np.minimum(((nodes[:, 1] - origin[1]) / h).astype(np.int64), ncy - 1)
    key = cy * ncx + cx
    order = np.argsort(key, kind="stable").astype(np.int64)
    start = np.searchsorted(key[order], np.arange(ncx * ncy + 1)).astype(np.int64)
    return order, start, np.ascontiguousarray(origin, dtype=float), float(h), ncx, ncy


@njit(cache=True, nogil=True)
def _cell_range(v, r, o, h, nc):
    a = int(math.floor((v - r - o) / h))
    b = int(math.floor((v + r - o) / h))
    return max(a, 0), min(b, nc - 1)


@njit(cache=True, nogil=True)
def support_counts(nodes, order, start, origin, h, ncx, ncy, points, radius, node_ref, point_ref, far2,
                   use_ref, raw, kept):
    """raw[p]: nodes within radius[p] of points[p]; kept[p]: those of them also within sqrt(far2) of the
    point in the reference configuration (node_ref, point_ref; all of them unless use_ref)."""
    for p in range(len(points)):
        px, py, r = points[p, 0], points[p, 1], radius[p]
        r2 = r * r
        x0, x1 = _cell_range(px, r, origin[0], h, ncx)
        y0, y1 = _cell_range(py, r, origin[1], h, ncy)
        nr = nk = 0
        for cy in range(y0, y1 + 1):
            for cx in range(x0, x1 + 1):
                c = cy * ncx + cx
                for t in range(start[c], start[c + 1]):
                    j = order[t]
                    dx = nodes[j, 0] - px
                    dy = nodes[j, 1] - py
                    if dx * dx + dy * dy <= r2:
                        nr += 1
                        if use_ref:
                            gx = node_ref[j, 0] - point_ref[p, 0]
                            gy = node_ref[j, 1] - point_ref[p, 1]
                            if gx * gx + gy * gy > far2:
                                continue
                        nk += 1
        raw[p] = nr
        kept[p] = nk


@njit(cache=True, nogil=True, fastmath=_FAST)
def _pivot(C, b, k, j0, n, nr):
    """Partial pivoting on column k of the column-major matrix C (C[j, i] = A[i, j]: column k is C's row k,
    contiguous): the row of the largest |A[i, k]|, i >= k, swapped with row k in the columns j0.. and in b; its
    size. The columns before j0 are not swapped: their multipliers have been applied to b already."""
    ck = C[k]
    p = k
    big = abs(ck[k])
    for i in range(k + _1, n):
        v = abs(ck[i])
        if v > big:
            big = v
            p = i
    if p != k:
        for j in range(j0, n):
            t = C[j, k]
            C[j, k] = C[j, p]
            C[j, p] = t
        for j in range(nr):
            t = b[j, k]
            b[j, k] = b[j, p]
            b[j, p] = t
    return big


@njit(cache=True, nogil=True, fastmath=_FAST)
def lu_solve(C, b, n_, nr_):
    """Solve A x = b in place (x in b) by LU with partial pivoting, four pivot columns per pass over the
    trailing matrix (then two, then one, for the last columns): C (n, n) holds A column by column (C[j, i] = A[i, j]; a symmetric A is its own C) and
    is overwritten; b (nr, n) holds the right-hand sides as rows. Returns False where a pivot is exactly zero
    (singular).

    Column-major, every inner loop runs down a contiguous column (pivot search, multipliers, the rank-4
    (rank-2) update of each trailing column, the right-hand sides, the column-oriented back substitution); only the
    row swaps are strided. Every index is unsigned: numba wraps a signed index that may be negative
    (``i < 0`` -> ``i + len``), and that select keeps LLVM from vectorising the loops. Measured on 50 x 50
    moment systems in cache here: 11.7 us per system row by row with signed indices, 6.5 us so."""
    n, nr = np.uint64(n_), np.uint64(nr_)
    k = _0
    while k + _3 < n:                              # four pivot columns per pass over the trailing matrix
        c0 = C[k]
        for c in range(k, k + _4):
            cc = C[c]
            for q in range(k, c):                  # column c brought up to date by the panel's earlier columns
                u = cc[q]
                cq = C[q]
                for i in range(q + _1, n):
                    cc[i] -= cq[i] * u
            if _pivot(C, b, c, k, n, nr) == 0.0:   # (swaps the rows of the panel's multipliers too)
                return False
            inv = 1.0 / cc[c]
            for i in range(c + _1, n):
                cc[i] *= inv
        k1, k2, k3, k4 = k + _1, k + _2, k + _3, k + _4
        c1, c2, c3 = C[k1], C[k2], C[k3]
        l10, l20, l21, l30, l31, l32 = c0[k1], c0[k2], c1[k2], c0[k3], c1[k3], c2[k3]
        for j in range(k4, n):
            cj = C[j]
            u0 = cj[k]
            u1 = cj[k1] - l10 * u0
            u2 = cj[k2] - l20 * u0 - l21 * u1
            u3 = cj[k3] - l30 * u0 - l31 * u1 - l32 * u2
            cj[k1] = u1
            cj[k2] = u2
            cj[k3] = u3
            for i in range(k4, n):
                cj[i] -= c0[i] * u0 + c1[i] * u1 + c2[i] * u2 + c3[i] * u3
        for j in range(nr):
            bj = b[j]
            u0 = bj[k]
            u1 = bj[k1] - l10 * u0
            u2 = bj[k2] - l20 * u0 - l21 * u1
            u3 = bj[k3] - l30 * u0 - l31 * u1 - l32 * u2
            bj[k1] = u1
            bj[k2] = u2
            bj[k3] = u3
            for i in range(k4, n):
                bj[i] -= c0[i] * u0 + c1[i] * u1 + c2[i] * u2 + c3[i] * u3
        k = k4
    while k + _1 < n:
        if _pivot(C, b, k, k, n, nr) == 0.0:
            return False
        k1 = k + _1
        k2 = k + _2
        ck = C[k]
        inv = 1.0 / ck[k]
        for i in range(k1, n):
            ck[i] *= inv
        c1 = C[k1]
        u = c1[k]
        for i in range(k1, n):                    # column k + 1 brought up to date to choose its pivot
            c1[i] -= ck[i] * u
        if _pivot(C, b, k1, k, n, nr) == 0.0:   # (swaps rows k + 1 and p of column k's multipliers too)
            return False
        inv = 1.0 / c1[k1]
        for i in range(k2, n):
            c1[i] *= inv
        l1 = ck[k1]
        for j in range(k2, n):
            cj = C[j]
            u0 = cj[k]
            u1 = cj[k1] - l1 * u0
            cj[k1] = u1
            for i in range(k2, n):
                cj[i] -= ck[i] * u0 + c1[i] * u1
        for j in range(nr):
            bj = b[j]
            u0 = bj[k]
            u1 = bj[k1] - l1 * u0
            bj[k1] = u1
            for i in range(k2, n):
                bj[i] -= ck[i] * u0 + c1[i] * u1
        k = k2
    if k < n and C[k, k] == 0.0:
        return False
    for kk in range(n):                            # U x = y column by column: x_k, then y_i -= U_ik x_k, i < k
        k = n - _1 - kk
        ck = C[k]
        inv = 1.0 / ck[k]
        for j in range(nr):
            bj = b[j]
            x = bj[k] * inv
            bj[k] = x
            for i in range(k):
                bj[i] -= ck[i] * x
    return True


@njit(cache=True, nogil=True, fastmath=_FAST)
def _rpow_row(q, out, n, eta, half_odd):
    """out[:n] = r^eta from q[:n] = r^2: sqrt(q) q^((eta - 1) / 2) by multiplication for an odd integer eta
    (half_odd = (eta - 1) / 2 >= 0), else q^(eta / 2). One pass over the row per factor: the count is known
    only at run time, and a loop over it inside the loop over the row keeps that loop from vectorising
    (measured: 5.7 -> 2.0 us for a 50 x 50 moment matrix)."""
    if half_odd >= 0:
        for c in range(n):
            out[c] = math.sqrt(q[c])
        for _ in range(half_odd):
            for c in range(n):
                out[c] *= q[c]
    else:
        for c in range(n):
            out[c] = q[c] ** (0.5 * eta)


@njit(cache=True, nogil=True)
def support_nodes(nodes, order, start, origin, h, ncx, ncy, p, px, py, r, node_ref, point_ref, far2, use_ref, sup):
    """The nodes within r of (px, py) (and, with use_ref, within sqrt(far2) of point p in the reference
    configuration) into sup, in increasing order; their number."""
    r2 = r * r
    x0, x1 = _cell_range(px, r, origin[0], h, ncx)
    y0, y1 = _cell_range(py, r, origin[1], h, ncy)
    s = 0
    for cy in range(y0, y1 + 1):
        for cx in range(x0, x1 + 1):
            c = cy * ncx + cx
            for t in range(start[c], start[c + 1]):
                j = order[t]
                dx = nodes[j, 0] - px
                dy = nodes[j, 1] - py
                if dx * dx + dy * dy <= r2:
                    if use_ref:
                        gx = node_ref[j, 0] - point_ref[p, 0]
                        gy = node_ref[j, 1] - point_ref[p, 1]
                        if gx * gx + gy * gy > far2:
                            continue
                    # insertion in increasing node order (the cells' runs are already sorted)
                    i = s
                    while i > 0 and sup[i - 1] > j:
                        sup[i] = sup[i - 1]
                        i -= 1
                    sup[i] = j
                    s += 1
    return s


@njit(cache=True, nogil=True, fastmath=_FAST)
def _moment_system(lx, ly, s_, m_, eta, half_odd, half_odd_d, n_out_, A, b, q):
    """G (Eq. 32) of the s support nodes at local coordinates (lx, ly) into A (s + m, s + m), and the
    right-hand sides [R(0); P(0)] (and their x, y derivatives when n_out = 3) into the rows of b (n_out, s + m);
    q (s,) scratch. G is written whole, row by row (contiguous, so that a row's r^eta vectorise), not as a
    triangle mirrored."""
    s, m, n_out = np.uint64(s_), np.uint64(m_), np.uint64(n_out_)
    n = s + m
    for a in range(s):
        xa, ya = lx[a], ly[a]
        row = A[a]
        for c in range(s):
            dx = xa - lx[c]
            dy = ya - ly[c]
            q[c] = dx * dx + dy * dy
        _rpow_row(q, row, s, eta, half_odd)
        row[s] = 1.0
        row[s + _1] = xa
        row[s + _2] = ya
        if m == 6:
            row[s + np.uint64(3)] = xa * xa
            row[s + np.uint64(4)] = xa * ya
            row[s + np.uint64(5)] = ya * ya
    for t in range(m):
        row = A[s + t]
        for a in range(s):
            row[a] = A[a, s + t]
        for c in range(s, n):
            row[c] = 0.0
    b0 = b[0]
    for a in range(s):
        q[a] = lx[a] * lx[a] + ly[a] * ly[a]
    _rpow_row(q, b0, s, eta, half_odd)
    for a in range(s, n):
        b0[a] = 0.0
    b0[s] = 1.0                                     # P(0) = [1, 0, 0, ...]
    if n_out == 3:
        bx, by = b[1], b[2]
        # d r^eta / dx = eta r^(eta - 2) x, zero at r = 0; bx holds r^(eta - 2) for a moment
        if half_odd_d >= 0:
            _rpow_row(q, bx, s, eta - 2.0, half_odd_d)
        else:
            for a in range(s):
                bx[a] = q[a] ** (0.5 * eta - 1.0) if q[a] > 0.0 else 0.0
        for a in range(s):
            g = eta * bx[a]
            bx[a] = -g * lx[a]
            by[a] = -g * ly[a]
        for a in range(s, n):
            bx[a] = 0.0
            by[a] = 0.0
        bx[s + _1] = 1.0                            # dP/dx(0) = [0, 1, 0, ...]
        by[s + _2] = 1.0                            # dP/dy(0) = [0, 0, 1, ...]


@njit(cache=True, nogil=True, fastmath=_FAST)
def rpim_rows(nodes, order, start, origin, h, ncx, ncy, points, radius, node_ref, point_ref, far2, use_ref,
              eta, m, scale, n_out, tol, indptr, indices, values, status, p0, p1):
    """Shape functions of the points p0 <= p < p1 into the CSR arrays (``indptr`` from the kept counts of
    :func:`support_counts`): ``indices`` the support nodes in increasing order, ``values`` three arrays: phi
    (Eq. 33), and d phi / dx, dy when n_out = 3; ``status[p]`` OK, SINGULAR (zero pivot) or NOT_UNITY (the
    values do not sum to one within ``tol``, or are not finite: a numerically singular G).

    For each point the moment system of Eq. (32) is written in coordinates centred at the point and divided
    by ``scale`` (d_c): G = [[R0, P0], [P0^T, 0]] with R0_ab = r_ab^eta (Eq. 34) and P0 the polynomial basis
    (1, x, y[, x^2, xy, y^2]) at the support nodes, with the right-hand sides [R(0); P(0)] and their x and y
    derivatives, d r_a^eta / dx = -eta r_a^(eta - 2) x_a (zero at r_a = 0). G is symmetric, so the solution's
    first rows are the shape functions of Eq. (33)."""
    kmax = 0
    for p in range(p0, p1):
        kmax = max(kmax, indptr[p + 1] - indptr[p])
    size = kmax + m
    work = np.empty(size * size)          # one point's G, reshaped to its own size (contiguous rows)
    rhs = np.empty(3 * size)
    lx = np.empty(kmax)
    ly = np.empty(kmax)
    q = np.empty(kmax)
    sup = np.empty(kmax, np.int64)
    half_odd = -1
    if eta == math.floor(eta) and eta >= 1.0 and int(eta) % 2 == 1:
        half_odd = (int(eta) - 1) // 2
    half_odd_d = half_odd - 1 if half_odd >= 1 else -1    # r^(eta - 2) of an odd eta >= 3 by multiplication too
    for p in range(p0, p1):
        px, py = points[p, 0], points[p, 1]
        s = support_nodes(nodes, order, start, origin, h, ncx, ncy, p, px, py, radius[p], node_ref, point_ref, far2,
                     use_ref, sup)
        if s == 0:
            status[p] = SINGULAR
            continue
        for a in range(s):
            lx[a] = (nodes[sup[a], 0] - px) / scale
            ly[a] = (nodes[sup[a], 1] - py) / scale
        n = s + m
        A = work[:n * n].reshape(n, n)
        b = rhs[:n_out * n].reshape(n_out, n)
        _moment_system(lx, ly, s, m, eta, half_odd, half_odd_d, n_out, A, b, q)
        if not lu_solve(A, b, n, n_out):      # G is symmetric: its rows are its columns
            status[p] = SINGULAR
            continue
        total = 0.0
        finite = True
        for c in range(n_out):
            for a in range(s):
                if not math.isfinite(b[c, a]):
                    finite = False
        for a in range(s):
            total += b[0, a]
        status[p] = OK if finite and abs(total - 1.0) <= tol else NOT_UNITY
        o = indptr[p]
        for a in range(s):
            indices[o + a] = sup[a]
            values[0][o + a] = b[0, a]
        if n_out == 3:
            for a in range(s):
                values[1][o + a] = b[1, a] / scale
                values[2][o + a] = b[2, a] / scale
