"""Compiled (numba) loops over the evaluation points of the RPIM shape functions (Section 2.3, Eqs. 25-34).

Why compiled: every point has its own moment matrix G of about 50 x 50 (Eq. 32); written with numpy the
points are padded to one size and solved in batches, building G and the right-hand sides through a dozen
temporaries of size points x support x support, and the matrices of a chunk are held at once. Here each
point is one pass: its support from a cell grid, G and the three right-hand sides in a scratch buffer
of one point's size, an LU factorisation with partial pivoting and the two triangular solves, and its
shape functions written straight into the CSR arrays. Nothing larger than one point's system exists at a
time, so the memory is the result's (the CSR rows) plus a few kB per thread.

The LU eliminates two pivot columns per pass over the trailing matrix (the second column is brought up to
date before its pivot is chosen, so the pivot sequence is that of ordinary partial pivoting): half the
loads and stores of one column at a time, measured 1.3-1.5 times faster on 49 x 49 systems here, and on
par with OpenBLAS's dgesv without its per-call overhead. The kernels release the GIL, so
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
def _pivot(A, b, k, n, nr):
    """Partial pivoting on column k: swap the row of the largest |A[i, k]|, i >= k, into row k; its size."""
    p = k
    big = abs(A[k, k])
    for i in range(k + 1, n):
        v = abs(A[i, k])
        if v > big:
            big = v
            p = i
    if p != k:
        for j in range(n):
            t = A[k, j]
            A[k, j] = A[p, j]
            A[p, j] = t
        for j in range(nr):
            t = b[k, j]
            b[k, j] = b[p, j]
            b[p, j] = t
    return big


@njit(cache=True, nogil=True, fastmath=_FAST)
def lu_solve(A, b, n, nr):
    """Solve A[:n, :n] x = b[:n, :nr] in place (x in b) by LU with partial pivoting, two pivot columns per
    pass over the trailing matrix; A is overwritten. Returns False where a pivot is exactly zero (singular)."""
    k = 0
    while k + 1 < n:
        if _pivot(A, b, k, n, nr) == 0.0:
            return False
        inv = 1.0 / A[k, k]
        k1 = k + 1
        for i in range(k1, n):
            A[i, k] *= inv
            A[i, k1] -= A[i, k] * A[k, k1]       # column k + 1 brought up to date to choose its pivot
        if _pivot(A, b, k1, n, nr) == 0.0:
            return False
        inv = 1.0 / A[k1, k1]
        l1 = A[k1, k]
        for j in range(k + 2, n):
            A[k1, j] -= l1 * A[k, j]
        for j in range(nr):
            b[k1, j] -= l1 * b[k, j]
        for i in range(k + 2, n):
            A[i, k1] *= inv
            li = A[i, k]
            mi = A[i, k1]
            for j in range(k + 2, n):
                A[i, j] -= li * A[k, j] + mi * A[k1, j]
            for j in range(nr):
                b[i, j] -= li * b[k, j] + mi * b[k1, j]
        k += 2
    if k < n and A[k, k] == 0.0:
        return False
    for k in range(n - 1, -1, -1):
        inv = 1.0 / A[k, k]
        for j in range(nr):
            s = b[k, j]
            for i in range(k + 1, n):
                s -= A[k, i] * b[i, j]
            b[k, j] = s * inv
    return True


@njit(cache=True, nogil=True, fastmath=_FAST)
def _rpow(q, eta, half_odd):
    """r^eta from q = r^2: sqrt(q) q^((eta - 1) / 2) by multiplication for an odd integer eta (half_odd =
    (eta - 1) / 2 >= 0), else q^(eta / 2)."""
    if half_odd >= 0:
        v = math.sqrt(q)
        for _ in range(half_odd):
            v *= q
        return v
    return q ** (0.5 * eta)


@njit(cache=True, nogil=True)
def _support(nodes, order, start, origin, h, ncx, ncy, p, px, py, r, node_ref, point_ref, far2, use_ref, sup):
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
def _moment_system(lx, ly, s, m, eta, half_odd, half_odd_d, n_out, A, b):
    """G (Eq. 32) of the s support nodes at local coordinates (lx, ly) into A[:s + m, :s + m], and the
    right-hand sides [R(0); P(0)] (and their x, y derivatives when n_out = 3) into b."""
    n = s + m
    for a in range(s):
        xa, ya = lx[a], ly[a]
        A[a, a] = 0.0
        for c in range(a + 1, s):
            dx = xa - lx[c]
            dy = ya - ly[c]
            v = _rpow(dx * dx + dy * dy, eta, half_odd)
            A[a, c] = v
            A[c, a] = v
        A[a, s] = 1.0
        A[a, s + 1] = xa
        A[a, s + 2] = ya
        if m == 6:
            A[a, s + 3] = xa * xa
            A[a, s + 4] = xa * ya
            A[a, s + 5] = ya * ya
        for t in range(m):
            A[s + t, a] = A[a, s + t]
        q = xa * xa + ya * ya
        b[a, 0] = _rpow(q, eta, half_odd)
        if n_out == 3:
            g = 0.0
            if q > 0.0:
                g = eta * (_rpow(q, eta - 2.0, half_odd_d) if half_odd_d >= 0 else q ** (0.5 * eta - 1.0))
            b[a, 1] = -g * xa
            b[a, 2] = -g * ya
    for a in range(s, n):
        for c in range(s, n):
            A[a, c] = 0.0
        for c in range(n_out):
            b[a, c] = 0.0
    b[s, 0] = 1.0                                   # P(0) = [1, 0, 0, ...]
    if n_out == 3:
        b[s + 1, 1] = 1.0                           # dP/dx(0) = [0, 1, 0, ...]
        b[s + 2, 2] = 1.0                           # dP/dy(0) = [0, 0, 1, ...]


@njit(cache=True, nogil=True, fastmath=_FAST)
def rpim_rows(nodes, order, start, origin, h, ncx, ncy, points, radius, node_ref, point_ref, far2, use_ref,
              eta, m, scale, n_out, tol, indptr, indices, values, status, p0, p1):
    """Shape functions of the points p0 <= p < p1 into the CSR arrays (``indptr`` from the kept counts of
    :func:`support_counts`): ``indices`` the support nodes in increasing order, ``values[0]`` phi (Eq. 33),
    ``values[1:3]`` d phi / dx, dy when n_out = 3; ``status[p]`` OK, SINGULAR (zero pivot) or NOT_UNITY (the
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
    A = np.empty((size, size))
    b = np.empty((size, 3))
    lx = np.empty(kmax)
    ly = np.empty(kmax)
    sup = np.empty(kmax, np.int64)
    half_odd = -1
    if eta == math.floor(eta) and eta >= 1.0 and int(eta) % 2 == 1:
        half_odd = (int(eta) - 1) // 2
    half_odd_d = half_odd - 1 if half_odd >= 1 else -1    # r^(eta - 2) of an odd eta >= 3 by multiplication too
    for p in range(p0, p1):
        px, py = points[p, 0], points[p, 1]
        s = _support(nodes, order, start, origin, h, ncx, ncy, p, px, py, radius[p], node_ref, point_ref, far2,
                     use_ref, sup)
        for a in range(s):
            lx[a] = (nodes[sup[a], 0] - px) / scale
            ly[a] = (nodes[sup[a], 1] - py) / scale
        _moment_system(lx, ly, s, m, eta, half_odd, half_odd_d, n_out, A, b)
        if s == 0 or not lu_solve(A, b, s + m, n_out):
            status[p] = SINGULAR
            continue
        total = 0.0
        finite = True
        for a in range(s):
            for c in range(n_out):
                if not math.isfinite(b[a, c]):
                    finite = False
            total += b[a, 0]
        status[p] = OK if finite and abs(total - 1.0) <= tol else NOT_UNITY
        o = indptr[p]
        for a in range(s):
            indices[o + a] = sup[a]
            values[0, o + a] = b[a, 0]
        if n_out == 3:
            for a in range(s):
                values[1, o + a] = b[a, 1] / scale
                values[2, o + a] = b[a, 2] / scale
