"""Recovered stresses: a moving least-squares fit of the stresses at the integration points.

Why: the raw stress of a meshfree solution, D B(x) u evaluated where it is asked for, oscillates
along curved boundaries and at the nodes of a boundary it does not converge (the Kirsch plate's
hole-top stress with the paper's integration: 3052, 3385, 4445, 5003 against 3000 as the spacing
halves). The stresses at the integration points are the ones the weak form used, and a local
least-squares fit of them is smooth and converges with the solution (superconvergent patch recovery,
Zienkiewicz & Zhu 1992, with the patch a disc about the evaluation point instead of elements).

At each evaluation point x the stress is the value at x of the polynomial p(x) (complete, of the given
order, in coordinates centred at x and scaled by d_c) that minimises

    sum_p w_p phi(|x_p - x| / rho) |p(x_p) - sigma(x_p)|^2

over the integration points x_p (area weights w_p) within the fitting radius rho, phi the quartic
spline kernel 1 - 6 s^2 + 8 s^3 - 3 s^4. The fit is linear: at a boundary it is one-sided, and a
quadratic one then extrapolates the steep gradient of a stress concentration (Kirsch hole top with the
default scheme, exact 3000, spacings 0.5 / 0.25 / 0.125 / 0.0625: raw 3059 / 3203 / 3247 / 3103;
quadratic fit over 2 d_c 3121 / 3158 / 3183 / 3095; linear fit over 2 d_c 2743 / 2950 / 3041 / 3031;
a linear fit over 1.5 d_c 3091 at 0.125, over 2.5 d_c 2869 at 0.25).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
from numba import njit
from scipy.spatial import cKDTree

from ctmrpim.discretisation import rpim_kernels
from ctmrpim.discretisation.rpim import COMPILED_MIN_POINTS
from ctmrpim.errors import ProblemError

#: fitting radius rho / d_c and polynomial order of the recovery (measured above)
RADIUS = 2.0
ORDER = 1
#: a fit gathers at least this many points per polynomial term: where fewer lie within the radius (a corner
#: under coarse integration, one point per d_c^2), its radius grows to 1.5 times the distance of the last
POINTS_PER_TERM = 2


def _basis(dx: np.ndarray, dy: np.ndarray, order: int) -> np.ndarray:
    """The complete polynomial of ``order`` (1 or 2) at the offsets (dx, dy): (len, 3 or 6)."""
    terms = [np.ones_like(dx), dx, dy]
    if order == 2:
        terms += [dx * dx, dx * dy, dy * dy]
    return np.stack(terms, axis=1)


def recovered_stress(at: np.ndarray, points: np.ndarray, weights: np.ndarray, stress: np.ndarray, d_c: float,
                     radius: float = RADIUS, order: int = ORDER) -> np.ndarray:
    """The recovered stress (k, c) at the k points ``at`` (k, 2) from the stresses ``stress`` (m, c) at the
    integration ``points`` (m, 2) with area ``weights`` (m,): the moving least-squares fit above, radius
    ``radius`` d_c or more (``POINTS_PER_TERM``). Fewer integration points than that in all is an error."""
    return np.asarray(recovery_operator(at, points, weights, d_c, radius, order) @ stress)


def recovery_operator(at: np.ndarray, points: np.ndarray, weights: np.ndarray, d_c: float,
                      radius: float = RADIUS, order: int = ORDER) -> sp.csr_matrix:
    """R (k x m), the recovery as a linear map: the recovered value at ``at`` (k, 2) of any field given at the
    integration ``points`` (m, 2) with area ``weights`` (m,) is R @ values (:func:`recovered_stress`). A consistent
    scheme's Dirichlet term differentiates through it (the traction of a history-dependent stress at a boundary
    point is the recovered stress there)."""
    t = (order + 1) * (order + 2) // 2            # terms of the complete polynomial (_basis)
    need = POINTS_PER_TERM * t
    if len(points) < need:
        raise ProblemError(f"stress recovery: {len(points)} integration points; the fit needs {need}")
    point_tree = cKDTree(points)
    kth = point_tree.query(at, k=need)[0][:, -1]
    rho_i = np.maximum(radius * d_c, 1.5 * kth)
    if rpim_kernels.use_compiled(len(points), COMPILED_MIN_POINTS):
        return _compiled_operator(at, points, weights, d_c, rho_i, t)
    # every pair, those at distance 0 too (an evaluation point on an integration point), as plain arrays
    pairs = cKDTree(at).sparse_distance_matrix(point_tree, rho_i.max(), output_type="ndarray")
    pairs = pairs[pairs["v"] <= rho_i[pairs["i"]]]
    i, p, r = pairs["i"], pairs["j"], pairs["v"]
    s = r / rho_i[i]
    kernel = weights[p] * (1 - 6 * s ** 2 + 8 * s ** 3 - 3 * s ** 4)
    P = _basis((points[p, 0] - at[i, 0]) / d_c, (points[p, 1] - at[i, 1]) / d_c, order)
    k = len(at)
    M = np.zeros((k, t, t))
    for a in range(t):
        for b in range(a, t):
            M[:, a, b] = M[:, b, a] = np.bincount(i, kernel * P[:, a] * P[:, b], k)
    # the fitted polynomial's value at the evaluation point is its constant term: row 0 of M^-1 applied to
    # sum_p kernel P(x_p) sigma_p, so each pair's weight is kernel (M^-1)[0] . P(x_p)
    first = np.linalg.solve(M, np.broadcast_to(np.eye(t)[0], (k, t))[..., None])[..., 0]   # M symmetric
    return sp.csr_matrix((kernel * np.einsum("ea,ea->e", first[i], P), (i, p)), shape=(k, len(points)))


def _compiled_operator(at: np.ndarray, points: np.ndarray, weights: np.ndarray, d_c: float, rho: np.ndarray,
                       terms: int) -> sp.csr_matrix:
    """:func:`recovery_operator` by the compiled kernels, for many integration points: the pairs found on a cell
    grid of the points (as the RPIM supports are), each row's fit solved in place (0.09 -> 0.01 s on the 129 x 33
    cantilever's 38318 points and 4259 nodes)."""
    at = np.ascontiguousarray(at, dtype=float)
    points = np.ascontiguousarray(points, dtype=float)
    grid = rpim_kernels.cell_grid(points, float(rho.max()))
    none = np.zeros((1, 2))
    raw, kept = np.zeros(len(at), np.int64), np.zeros(len(at), np.int64)
    rpim_kernels.support_counts(points, *grid, at, rho, none, none, 0.0, False, raw, kept)
    indptr = np.zeros(len(at) + 1, np.int64)
    np.cumsum(raw, out=indptr[1:])
    indices, data = np.empty(indptr[-1], np.int64), np.empty(indptr[-1])
    bad = _recovery_rows(points, *grid, np.ascontiguousarray(weights, dtype=float), at, rho, float(d_c), terms,
                         indptr, indices, data)
    if bad >= 0:
        raise ProblemError(f"stress recovery: the fit at ({at[bad, 0]:.6g}, {at[bad, 1]:.6g}) is singular "
                           "(its integration points are collinear)")
    R = sp.csr_matrix((data, indices, indptr), shape=(len(at), len(points)), copy=False)
    R.has_sorted_indices = True
    return R


@njit(cache=True, nogil=True, fastmath={"contract"})
def _recovery_rows(points, order, start, origin, h, ncx, ncy, weights, at, rho, d_c, terms, indptr, indices, data):
    """The rows of R (:func:`recovery_operator`) into CSR arrays sized by the pair counts: for each evaluation
    point the integration points within its radius (increasing index), the moment matrix M of the weighted fit,
    M^-1 e_0 by :func:`ctmrpim.discretisation.rpim_kernels.lu_solve` (M symmetric), and each pair's weight
    kernel (M^-1 e_0) . P(x_p). Returns the first evaluation point whose M is singular, else -1."""
    kmax = 1
    for i in range(len(at)):
        kmax = max(kmax, indptr[i + 1] - indptr[i])
    sup = np.empty(kmax, np.int64)
    P = np.empty((kmax, terms))
    kern = np.empty(kmax)
    M = np.empty((terms, terms))
    e = np.empty((1, terms))
    none = np.zeros((1, 2))
    for i in range(len(at)):
        xi, yi, r = at[i, 0], at[i, 1], rho[i]
        s = rpim_kernels.support_nodes(points, order, start, origin, h, ncx, ncy, i, xi, yi, r, none, none, 0.0,
                                       False, sup)
        for a in range(terms):
            e[0, a] = 0.0
            for b in range(terms):
                M[a, b] = 0.0
        e[0, 0] = 1.0
        for q in range(s):
            p = sup[q]
            dx, dy = points[p, 0] - xi, points[p, 1] - yi
            u = math.sqrt(dx * dx + dy * dy) / r
            kern[q] = weights[p] * (1.0 - 6.0 * u ** 2 + 8.0 * u ** 3 - 3.0 * u ** 4)
            bx, by = dx / d_c, dy / d_c
            P[q, 0], P[q, 1], P[q, 2] = 1.0, bx, by
            if terms == 6:
                P[q, 3], P[q, 4], P[q, 5] = bx * bx, bx * by, by * by
            for a in range(terms):
                for b in range(terms):
                    M[a, b] += kern[q] * P[q, a] * P[q, b]
        if not rpim_kernels.lu_solve(M, e, terms, 1):
            return i
        o = indptr[i]
        for q in range(s):
            v = 0.0
            for a in range(terms):
                v += e[0, a] * P[q, a]
            indices[o + q] = sup[q]
            data[o + q] = kern[q] * v
    return -1
