"""Radial point interpolation shape functions with thin-plate-spline RBFs, R = r^eta (Section 2.3).

For every evaluation point the moment system of Eq. (32),

    G = [[R0, P0^T], [P0, 0]],   G [phi; b] = [R(x); P(x)],

is solved for the shape-function values and, with the differentiated right-hand sides, their x and y
derivatives (three right-hand sides at once). G is symmetric, so the row vector of Eq. (33) equals
G^-1 times the column. Coordinates are local, centred at the evaluation point and scaled by d_c; the
shape functions do not change under this, and the conditioning is far better.

The loops over the points are compiled (:mod:`ctmrpim.discretisation.rpim_kernels`): a count pass over a cell grid of
the nodes sizes the CSR rows, then blocks of points, on the threads of :mod:`ctmrpim.discretisation.thread_blocks`, each
solve their systems one point at a time into those rows. Memory is the result plus one system per thread. Small sets of
points take a numpy path instead (numba's start-up would cost more than it saves): padded supports solved in batches by
LAPACK, chunk by chunk. The two agree to round-off.

The result is stored as sparse rows (point -> support nodes, in increasing node order), ready for
B^T D B products.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ctmrpim.blas_threads import one_blas_thread
from ctmrpim.discretisation import rpim_kernels as kernels
from ctmrpim.discretisation.thread_blocks import run_blocks
from ctmrpim.errors import ProblemError

BLOCK = 2048                 # points per kernel call on the threads (:mod:`ctmrpim.discretisation.thread_blocks`)
CHUNK = 128                  # numpy path: points per batched solve, (CHUNK, k+m, k+m) stays in cache
#: below this many points the numpy path is taken: numba's first kernel call in a process costs about
#: 0.2-0.45 s (its lowering registries load, cached kernels or not), and the compiled path saves about
#: 10-50 us per point (measured on this project's two-core machine)
COMPILED_MIN_POINTS = 8000
PARTITION_OF_UNITY_TOL = 1e-6  # sum_i phi_i - 1 beyond this means the moment matrix was numerically singular


@dataclass
class ShapeFunctions:
    """RPIM shape functions (Eqs. 25-34) of n nodes at m points: sparse rows (point -> support nodes)."""
    N: sp.csr_matrix        # (m, n) values (a linear solve drops them once its loads are built)
    dNdx: sp.csr_matrix     # (m, n) x derivatives
    dNdy: sp.csr_matrix     # (m, n) y derivatives
    support_sizes: np.ndarray  # (m,) nodes in each point's support
    dropped: np.ndarray | None = None   # points left without shape functions (``drop_singular``)


def shape_functions(nodes: np.ndarray, points: np.ndarray, support_radius: float, eta: float,
                    polynomial_terms: int, scale: float, derivatives: bool = True,
                    tree: cKDTree | None = None,
                    reference: tuple[np.ndarray, np.ndarray, float] | None = None,
                    min_nodes: int = 0, drop_singular: bool = False,
                    compiled_from: int | None = None) -> ShapeFunctions:
    """RPIM shape functions (Eqs. 25-34) of ``nodes`` at ``points``.

    ``support_radius`` and ``scale`` (d_c) are absolute lengths. A point whose support holds fewer
    nodes than the polynomial needs, or whose moment matrix is singular, is an error naming it.
    ``reference = (node_positions, point_positions, distance)`` on a deformed cloud drops from a
    support every node farther than ``distance`` from the point in the reference configuration, so
    that parts of the body that were far apart (the two ends of a beam rolled into a ring) never
    share shape functions when they come close. ``min_nodes`` > 0 widens the support of a point that
    holds fewer nodes than that to its ``min_nodes`` nearest (a flow front, where the cloud thins out:
    r^eta with eta = 5 is conditionally positive definite of order 3, so with the linear basis a
    support of a handful of scattered nodes can make the moment matrix singular). ``tree``: a KD-tree
    of ``nodes``, used only to widen supports (built here when needed and not given). ``compiled_from``: the
    number of points from which the compiled kernels take over from numpy (None: :data:`COMPILED_MIN_POINTS`; a
    caller that builds shape functions many times in one run pays numba's start once and may lower it; the choice
    must follow from the input alone).
    """
    nodes = np.ascontiguousarray(nodes, dtype=float).reshape(-1, 2)
    points = np.ascontiguousarray(points, dtype=float).reshape(-1, 2)
    if not kernels.use_compiled(len(points), COMPILED_MIN_POINTS if compiled_from is None else compiled_from):
        return _numpy_shape_functions(nodes, points, support_radius, eta, polynomial_terms, scale, derivatives,
                                      tree, reference, min_nodes, drop_singular)
    m = polynomial_terms
    n_pts = len(points)
    radius = np.full(n_pts, float(support_radius))
    grid = kernels.cell_grid(nodes, float(support_radius)) if len(nodes) else None
    use_ref = reference is not None
    node_ref, point_ref, far2 = ((np.ascontiguousarray(reference[0], dtype=float),
                                  np.ascontiguousarray(reference[1], dtype=float), float(reference[2]) ** 2)
                                 if use_ref else (np.zeros((1, 2)), np.zeros((1, 2)), 0.0))
    raw = np.zeros(n_pts, np.int64)
    kept = np.zeros(n_pts, np.int64)

    def count(sel: slice | np.ndarray) -> None:
        if grid is None:
            return
        pr = point_ref if not use_ref else np.ascontiguousarray(point_ref[sel])
        r_, k_ = np.zeros(len(points[sel]), np.int64), np.zeros(len(points[sel]), np.int64)
        kernels.support_counts(nodes, *grid, np.ascontiguousarray(points[sel]), radius[sel], node_ref, pr, far2,
                               use_ref, r_, k_)
        raw[sel], kept[sel] = r_, k_

    count(slice(None))
    short = raw < min_nodes
    if short.any() and min_nodes <= len(nodes):
        tree = tree if tree is not None else cKDTree(nodes)
        far = tree.query(points[short], k=min_nodes)[0].reshape(-1, min_nodes)[:, -1]
        radius[short] = far * (1.0 + 1e-12)
        count(np.flatnonzero(short))
    need = m + 1
    if n_pts and raw.min() < need:
        i = int(np.argmin(raw))
        raise ProblemError(
            f"RPIM: point #{i} at ({points[i, 0]:.6g}, {points[i, 1]:.6g}) has {raw[i]} node(s) within the "
            f"support radius {support_radius:.6g}; the {'linear' if m == 3 else 'quadratic'} basis needs at least "
            f"{need}: increase method.support_radius")
    if use_ref and n_pts and kept.min() < need:
        i = int(np.flatnonzero(kept < need)[0])
        raise ProblemError(f"RPIM: point #{i} at ({points[i, 0]:.6g}, {points[i, 1]:.6g}) keeps "
                           f"{int(kept[i])} node(s) of its support that were its neighbours in the "
                           "reference configuration; increase method.support_radius")
    n_out = 3 if derivatives else 1
    nnz = int(kept.sum())
    itype = np.int32 if max(nnz, len(nodes)) < 2**31 - 1 else np.int64
    indptr = np.zeros(n_pts + 1, itype)
    np.cumsum(kept, out=indptr[1:])
    indices = np.empty(nnz, itype)
    # one array each (a row of one (n_out, nnz) array is a view that scipy copies for a CSR matrix's data)
    values = tuple(np.empty(nnz) for _ in range(n_out)) + (np.empty(0),) * (3 - n_out)
    status = np.zeros(n_pts, np.int8)
    if n_pts:
        args = (nodes, *grid, points, radius, node_ref, point_ref, far2, use_ref, float(eta), m, float(scale),
                n_out, PARTITION_OF_UNITY_TOL, indptr, indices, values, status)
        blocks = [(a, min(a + BLOCK, n_pts)) for a in range(0, n_pts, BLOCK)]
        run_blocks(lambda ab: kernels.rpim_rows(*args, *ab), blocks, kernel=kernels.rpim_rows)
    bad = status != kernels.OK
    if bad.any():
        if not drop_singular:
            raise _singular_error(points, int(np.flatnonzero(bad)[0]))
        keep = np.repeat(~bad, kept)
        kept = np.where(bad, 0, kept)
        indptr[1:] = np.cumsum(kept)
        indices, values = indices[keep], tuple(v[keep] for v in values[:n_out])
    shape = (n_pts, len(nodes))
    mats = [_csr(values[j], indices, indptr, shape) for j in range(n_out)]
    if not derivatives:
        mats += [None, None]
    sizes = kept.astype(np.int64)
    return ShapeFunctions(N=mats[0], dNdx=mats[1], dNdy=mats[2], support_sizes=sizes,
                          dropped=np.flatnonzero(sizes == 0) if drop_singular else None)


def _csr(data: np.ndarray, indices: np.ndarray, indptr: np.ndarray, shape: tuple[int, int]) -> sp.csr_matrix:
    """A CSR matrix on arrays known to be canonical (sorted, unique column indices per row): no checks, no copies."""
    M = sp.csr_matrix((data, indices, indptr), shape=shape, copy=False)
    M.has_sorted_indices = True
    M.has_canonical_format = True
    return M


def _powr(r2: np.ndarray, p: float) -> np.ndarray:
    """r^p from r^2 (a new array)."""
    out = np.array(r2, dtype=float)
    _powr_inplace(out, p, work=np.empty_like(out))
    return out


def _powr_inplace(r2: np.ndarray, p: float, work: np.ndarray) -> None:
    """r2 <- r^p, ``work`` (same shape) as scratch; an odd integer p takes r2^((p-1)/2) * r (no pow)."""
    if float(p).is_integer() and p >= 1 and int(p) % 2 == 1:
        np.sqrt(r2, out=work)
        for _ in range((int(p) - 1) // 2):
            work *= r2
        r2[...] = work
    else:
        np.power(r2, 0.5 * p, out=r2)


def _polynomial(x: np.ndarray, y: np.ndarray, m: int) -> np.ndarray:
    one = np.ones_like(x)
    cols = [one, x, y] if m == 3 else [one, x, y, x * x, x * y, y * y]
    return np.stack(cols, axis=-1)


def _numpy_shape_functions(nodes: np.ndarray, points: np.ndarray, support_radius: float, eta: float,
                           polynomial_terms: int, scale: float, derivatives: bool = True,
                           tree: cKDTree | None = None,
                           reference: tuple[np.ndarray, np.ndarray, float] | None = None,
                           min_nodes: int = 0, drop_singular: bool = False) -> ShapeFunctions:
    """:func:`shape_functions` by numpy: points padded to their chunk's largest support, each padding slot
    decoupled by an identity row, and solved in batches by LAPACK (``CHUNK`` points at a time, on the
    thread pool); rows in each point's support in distance order."""
    nodes = np.asarray(nodes, float)
    points = np.asarray(points, float)
    m = polynomial_terms
    tree = tree or cKDTree(nodes)
    counts = tree.query_ball_point(points, support_radius, return_length=True)
    radius = np.full(len(points), float(support_radius))
    short = counts < min_nodes
    if short.any() and min_nodes <= len(nodes):
        far = tree.query(points[short], k=min_nodes)[0].reshape(-1, min_nodes)[:, -1]
        radius[short] = far * (1.0 + 1e-12)
        counts[short] = tree.query_ball_point(points[short], radius[short], return_length=True)
    need = m + 1
    if len(points) and counts.min() < need:
        i = int(np.argmin(counts))
        raise ProblemError(
            f"RPIM: point #{i} at ({points[i, 0]:.6g}, {points[i, 1]:.6g}) has {counts[i]} node(s) within the "
            f"support radius {support_radius:.6g}; the {'linear' if m == 3 else 'quadratic'} basis needs at least "
            f"{need}: increase method.support_radius")
    n_out = 3 if derivatives else 1
    # Chunks of points with similar support sizes waste little on padding; chunks run on a thread
    # pool because numpy's batched solve and array arithmetic release the GIL.
    order = np.argsort(counts, kind="stable")
    bounds = [(a, min(a + CHUNK, len(points))) for a in range(0, len(points), CHUNK)]

    done: dict[tuple[int, int], tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

    def work(ab):
        sel = order[ab[0]:ab[1]]
        ref = None if reference is None else (reference[0], reference[1][sel], reference[2])
        done[ab] = _chunk(nodes, points[sel], sel, tree, int(counts[sel].max()), radius[sel], eta, m, scale,
                          derivatives, ref, drop_singular)

    # each small LAPACK solve runs on one thread; BLAS threads on top of ours would only contend
    with one_blas_thread():
        run_blocks(work, bounds)
    parts = [done[ab] for ab in bounds]
    shape = (len(points), len(nodes))
    if parts:
        indices = np.concatenate([p[0] for p in parts])
        values = np.concatenate([p[1] for p in parts], axis=1)
        sizes = np.concatenate([p[2] for p in parts])
    else:
        indices, values, sizes = np.zeros(0, np.int64), np.zeros((n_out, 0)), np.zeros(0, np.int64)
    # rows were computed in `order`; one gather puts them back in point order
    inverse = np.empty_like(order)
    inverse[order] = np.arange(len(order))
    starts = (np.cumsum(sizes) - sizes)[inverse]
    counts = sizes[inverse]
    indptr = np.concatenate([[0], np.cumsum(counts)])
    gather = np.repeat(starts - indptr[:-1], counts) + np.arange(indptr[-1])
    indices = indices[gather]
    mats = [sp.csr_matrix((values[j][gather], indices, indptr), shape=shape) for j in range(n_out)]
    if not derivatives:
        mats += [None, None]
    return ShapeFunctions(N=mats[0], dNdx=mats[1], dNdy=mats[2], support_sizes=counts,
                          dropped=np.flatnonzero(counts == 0) if drop_singular else None)


def _chunk(nodes, pts, point_ids, tree, k, radius, eta, m, scale, derivatives, reference=None, drop=False):
    """``radius`` (c,): each point's support radius."""
    dist, idx = tree.query(pts, k=k, distance_upper_bound=float(radius.max()))
    dist = dist.reshape(len(pts), k)
    idx = idx.reshape(len(pts), k)
    valid = dist <= radius[:, None]
    if reference is not None:
        node_ref, point_ref, far = reference
        gap = node_ref[np.where(valid, idx, 0)] - point_ref[:, None, :]
        valid &= np.einsum("cid,cid->ci", gap, gap) <= far * far
        few = valid.sum(axis=1) < m + 1
        if few.any():
            i = int(np.flatnonzero(few)[0])
            raise ProblemError(f"RPIM: point #{point_ids[i]} at ({pts[i, 0]:.6g}, {pts[i, 1]:.6g}) keeps "
                               f"{int(valid[i].sum())} node(s) of its support that were its neighbours in the "
                               "reference configuration; increase method.support_radius")
    vf = valid.astype(float)
    local = (nodes[np.where(valid, idx, 0)] - pts[:, None, :]) / scale   # (c, k, 2), evaluation point at origin
    local *= vf[..., None]
    c = len(pts)
    size = k + m
    G = np.empty((c, size, size))
    G[:, k:, k:] = 0.0
    R0 = G[:, :k, :k]
    lx, ly = local[..., 0], local[..., 1]
    # r^2 and r^eta built in place in G: fewer large temporaries, fewer fresh pages to fault in
    np.subtract(lx[:, :, None], lx[:, None, :], out=R0)
    np.multiply(R0, R0, out=R0)
    dy = ly[:, :, None] - ly[:, None, :]
    dy *= dy
    R0 += dy
    _powr_inplace(R0, eta, work=dy)
    # chunks hold points of similar support size, so padding is rare: clear only the padded rows/columns
    pc, pi = np.nonzero(~valid)
    if len(pc):
        R0[pc, pi, :] = 0.0
        R0[pc, :, pi] = 0.0
        R0[pc, pi, pi] = 1.0                                      # padding slots: identity, decoupled
    sq = np.einsum("cid,cid->ci", local, local)
    P0 = _polynomial(local[..., 0], local[..., 1], m) * vf[..., None]
    G[:, :k, k:] = P0
    G[:, k:, :k] = P0.transpose(0, 2, 1)

    rhs = np.zeros((c, size, 3 if derivatives else 1))
    rhs[:, :k, 0] = _powr(sq, eta) * vf
    rhs[:, k, 0] = 1.0                                            # P(0) = [1, 0, 0, (0, 0, 0)]
    if derivatives:
        # d/dx r_i^eta at the origin = eta r^(eta-2) (0 - x_i), written eta r^(eta-1) (-x_i / r): 0 at r = 0
        r = np.sqrt(sq)
        with np.errstate(divide="ignore", invalid="ignore"):
            g = np.where(r > 0, eta * _powr(sq, eta - 1.0) / np.where(r > 0, r, 1.0), 0.0) * vf
        rhs[:, :k, 1] = -g * local[..., 0]
        rhs[:, :k, 2] = -g * local[..., 1]
        rhs[:, k + 1, 1] = 1.0                                    # dP/dx(0) = [0, 1, 0, ...]
        rhs[:, k + 2, 2] = 1.0
    try:
        phi = np.linalg.solve(G, rhs)[:, :k, :]
    except np.linalg.LinAlgError:
        if not drop:
            raise _singular_error(pts, _first_singular(G), point_ids) from None
        singular = _singular(G)
        G[singular] = np.eye(size)
        phi = np.linalg.solve(G, rhs)[:, :k, :]
        phi[singular] = np.nan
    with np.errstate(invalid="ignore"):
        pu = np.abs((phi[..., 0] * vf).sum(axis=1) - 1.0)
    bad = ~np.isfinite(phi).all(axis=(1, 2)) | ~(pu <= PARTITION_OF_UNITY_TOL)
    if bad.any():
        if not drop:
            i = int(np.flatnonzero(bad)[0])
            raise _singular_error(pts, i, point_ids)
        valid[bad] = False
    vals = np.moveaxis(phi, 2, 0)[:, valid]                       # (n_out, nnz), row-major
    if derivatives:
        vals[1:] /= scale
    return idx[valid], vals, valid.sum(axis=1)


def _singular(G: np.ndarray) -> np.ndarray:
    """(c,) bool: which of the matrices (c, s, s) LAPACK cannot factorise."""
    out = np.zeros(len(G), bool)
    for i in range(len(G)):   # only after a batched solve failed: rare
        try:
            np.linalg.solve(G[i], np.ones(len(G[i])))
        except np.linalg.LinAlgError:
            out[i] = True
    return out


def _first_singular(G: np.ndarray) -> int:
    return int(np.argmax(_singular(G)))


def _singular_error(pts: np.ndarray, i: int, where: np.ndarray | None = None) -> ProblemError:
    """The error naming point #i at pts[i] (#where[i] of the caller's points where given)."""
    name = i if where is None else int(where[i])
    return ProblemError(
        f"RPIM: the moment matrix of point #{name} at ({pts[i, 0]:.6g}, {pts[i, 1]:.6g}) is singular "
        "(nodes in its support collinear, or eta an even integer); increase method.support_radius or change method.eta")
