"""State transfer across a rebuild of the integration points (docs/design.md, 'State under
re-tracking').

History lives at the CTM integration points. When the configuration is rebuilt (new boundary, new
CTM points) each state component s is L2-projected onto the nodal RPIM space over the old points,

    M_c s_nodal = sum_p N_p^T w_p s_p,      M_c = sum_p N_p^T w_p N_p,

(one factorisation, one right-hand side per component) and evaluated at the new points with the new
shape functions. Fields the RPIM space holds (constants, linear fields: the basis reproduces them)
come through exactly, a second transfer without motion changes nothing, and a rigid move carries the
field with it. Projection smooths: solvers count the transfers they make.

The projection is a least-squares fit, and it is only as good as the old points' hold on each node. Where nodes
crowd into a thin layer (the toe of a collapsing column, pressed flat on its base), M_c is singular to round-off
(measured on the 496-node collapse at t = 0.55 s: four eigenvalues of the diagonally scaled M_c below 3e-15), the
nodal values there are set by round-off (5e7 Pa from point stresses of at most 2.6e3 Pa) and new points beside
those nodes take them. :func:`local_bounds` gives each new point the range of the old values that it depends on:
the old points of positive weight in the supports of the new point's nodes. A field the RPIM space holds stays
inside that range at every new point inside the old points' hull. A solver replaces the state of a new point whose
projected value leaves that range by :func:`convex_average`, the weighted mean of those same old values, and counts
the points it replaced: the exact cases stay exact, and the replaced points make neither a new extremum nor
elastic energy (clipping each component to its range instead still combined the extremes of different components:
on the 496-node collapse one transfer tripled the column's elastic energy that way, docs/design.md).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from ctmrpim.discretisation import assembly
from ctmrpim.errors import ProblemError
from ctmrpim.solvers import linear_solver

#: the projection's mass matrix is factorised as a band (reverse Cuthill-McKee, LAPACK's banded Cholesky) while the
#: band holds at most this many numbers (128 MB), else by SuperLU. Measured on the mass matrices of square-grid
#: clouds with CTM-like points, one thread: band against SuperLU (MMD_AT_PLUS_A) 5.4 / 17 ms at 51 x 21 nodes,
#: 15 / 42 ms at 63 x 32, 32 / 105 ms at 129 x 33, 72 / 162 ms at 65 x 65, 291 / 562 ms at 97 x 97 (band 74 MB),
#: 853 / 1477 ms at 129 x 129 (band 176 MB: above the limit, memory before time).
BAND_MAX_ENTRIES = 16_000_000


class NodalProjection:
    """The L2 projection onto the nodal RPIM space from points with shape-function rows ``N`` (m, n)
    and quadrature weights (m,): the mass matrix (:func:`ctmrpim.discretisation.assembly.mass`) is factorised once,
    each call is one solve."""

    def __init__(self, N: sp.csr_matrix, weights: np.ndarray) -> None:
        self.N, self.weights = N, weights
        M = assembly.mass(N, weights)
        self.band = linear_solver.banded_cholesky(M, BAND_MAX_ENTRIES)
        self.lu = None
        if self.band is None:       # too wide a band, or not positive definite: SuperLU says whether it is singular
            try:
                self.lu = splu(M.tocsc(), permc_spec="MMD_AT_PLUS_A")
            except RuntimeError:
                raise ProblemError("state transfer: the projection's mass matrix is singular (a node has no "
                                   "integration point in its support)") from None

    def __call__(self, values: np.ndarray) -> np.ndarray:
        """Nodal values (n, k) of ``values`` (m, k) given at the points."""
        rhs = np.asarray(self.N.T @ (values * self.weights[:, None]))
        return linear_solver.banded_solve(self.band, rhs) if self.band is not None else self.lu.solve(rhs)


def project_to_nodes(N: sp.csr_matrix, weights: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Nodal values (n, k) of the L2 projection of ``values`` (m, k) given at points with shape-function
    rows ``N`` (m, n) and quadrature weights ``weights`` (m,)."""
    return NodalProjection(N, weights)(values)


def transfer(N_old: sp.csr_matrix, w_old: np.ndarray, values: np.ndarray, N_new: sp.csr_matrix
             ) -> tuple[np.ndarray, np.ndarray]:
    """``values`` (m_old, k) at the old points (shape functions ``N_old`` (m_old, n), weights ``w_old`` (m_old,)),
    L2-projected and evaluated at the new points (``N_new`` (m_new, n)): (m_new, k), and the nodal values (n, k)."""
    nodal = project_to_nodes(N_old, w_old, values)
    return np.asarray(N_new @ nodal), nodal


def local_bounds(N_old: sp.csr_matrix, w_old: np.ndarray, values: np.ndarray, N_new: sp.csr_matrix
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(m_new, k) lowest and highest of ``values`` (m_old, k) over the old points of positive weight ``w_old``
    (m_old,) in the supports of each new point's nodes: the values a transfer from ``N_old`` (m_old, n) to ``N_new``
    (m_new, n) depends on. A new point without such a point in reach gets (-inf, inf)."""
    live = np.flatnonzero(w_old > 0)
    by_node = sp.csc_matrix(N_old[live])
    v = np.asarray(values, float)[live]
    node_lo = _segment_reduce(by_node.indptr, by_node.indices, v, np.minimum, np.inf)
    node_hi = _segment_reduce(by_node.indptr, by_node.indices, v, np.maximum, -np.inf)
    rows = sp.csr_matrix(N_new)
    lo = _segment_reduce(rows.indptr, rows.indices, node_lo, np.minimum, np.inf)
    hi = _segment_reduce(rows.indptr, rows.indices, node_hi, np.maximum, -np.inf)
    unbounded = ~(lo <= hi)
    lo[unbounded], hi[unbounded] = -np.inf, np.inf
    return lo, hi


def convex_average(N_old: sp.csr_matrix, w_old: np.ndarray, values: np.ndarray, N_new: sp.csr_matrix,
                   rows: np.ndarray) -> np.ndarray:
    """(len(rows), k) averages of ``values`` (m_old, k) for the new points ``rows`` over the old points that each
    depends on (those of :func:`local_bounds`), weighted by |N_new| |N_old|^T w_old: a convex combination, so every
    component stays inside its local bounds, and a convex function of the state (the elastic energy density, the
    yield function) is at most the weighted mean of its old values (Jensen). A new point without an old point of
    positive weight in reach gets NaN."""
    live = np.flatnonzero(w_old > 0)
    weights = sp.csr_matrix(abs(sp.csr_matrix(N_new)[rows]) @ (abs(sp.csr_matrix(N_old)[live]).T
                                                                @ sp.diags(np.asarray(w_old, float)[live])))
    total = np.asarray(weights.sum(axis=1)).ravel()
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(weights @ np.asarray(values, float)[live]) / total[:, None]


def _segment_reduce(indptr: np.ndarray, indices: np.ndarray, values: np.ndarray, ufunc: np.ufunc,
                    empty: float) -> np.ndarray:
    """(len(indptr) - 1, k) ``ufunc`` over values[indices[indptr[i]:indptr[i + 1]]] for each segment i (``empty``
    where a segment is empty)."""
    out = np.full((len(indptr) - 1, values.shape[1]), empty)
    filled = np.diff(indptr) > 0
    if filled.any():
        out[filled] = ufunc.reduceat(values[indices], indptr[:-1][filled], axis=0)
    return out
