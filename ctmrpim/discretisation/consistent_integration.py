"""Variationally consistent CTM integration (``method.integration = "ctm-vci"``; not in the paper).

Why: a Galerkin solution passes the patch test only if the quadrature integrates the divergence
identity of every test function exactly, the integration constraint

    sum_p w_p grad N_I(x_p) = sum_b w_b N_I(x_b) n(x_b)        (and, of second order, times q(x))

over the CTM points x_p (weights w_p) and Gauss points x_b on the boundary (length weights w_b,
outward normals n). With RPIM it fails by about 3 % with the paper's one-point CTM and still by
2-3 % with converged quadrature, because the shape functions jump where a point's support changes;
more Gauss points do not repair it (docs/design.md, 'Consistent integration').

The correction (Chen, Hillman & Rueter 2013, IJNME 95) changes the test gradients only, node by node,
on the points of the node's support:

- linear: d~_k N_I(x_p) = d_k N_I(x_p) + xi_Ik, one constant per node and direction;
- quadratic: d~_k N_I(x_p) = d_k N_I(x_p) + c_Ik . q_I(x_p), q_I = [1, (x - x_I)/d_c, (y - y_I)/d_c],
  c_Ik from a 3 x 3 moment matrix per node, so that the constraints hold against 1, x and y.

The stiffness is then Petrov-Galerkin, K_IJ = sum_p w_p B~_I^T D B_J (the trial gradients stay: correcting
them too breaks the rigid-body cancellation), assembled by
:func:`ctmrpim.discretisation.assembly.stiffness`, and tractions are integrated on the
same boundary Gauss points as the correction. On an edge with a prescribed displacement component the
test functions of free nodes do not vanish between the edge's nodes, so the unknown reaction is
written as the traction of the discrete solution, t = sigma(u_h) n: :func:`dirichlet_consistency`
(the consistency term of Nitsche's method).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ctmrpim.discretisation import assembly, rpim_kernels, vci_kernels
from ctmrpim.discretisation.ctm import BoundaryQuadrature, boundary_points
from ctmrpim.discretisation.gradient_correction import GradientCorrection
from ctmrpim.discretisation.lagrangian_operators import gradient_operator, value_operator
from ctmrpim.discretisation.rpim import ShapeFunctions
from ctmrpim.discretisation.stress_recovery import recovery_operator
from ctmrpim.errors import ProblemError

if TYPE_CHECKING:
    from ctmrpim.discretisation.configuration import Configuration
    from ctmrpim.problem.settings import Method

#: Gauss points per boundary segment, for the correction and the tractions alike (mixing 2 and 3 points
#: per segment failed the patch test at 0.86 % in energy while this was calibrated)
BOUNDARY_GAUSS_POINTS = 3


def boundary_quadrature(nodes: np.ndarray, edges: np.ndarray) -> BoundaryQuadrature:
    """Gauss points on every boundary segment ``edges`` (e, 2; node pairs into ``nodes`` (n, 2), body on the
    left), with the node pair of each point in ``ends``."""
    q = boundary_points(nodes[edges], BOUNDARY_GAUSS_POINTS)
    q.ends = np.repeat(edges, BOUNDARY_GAUSS_POINTS, axis=0)
    return q


def corrected_gradients(nodes: np.ndarray, d_c: float, points: np.ndarray, w: np.ndarray, sf: ShapeFunctions,
                        boundary: BoundaryQuadrature, N_boundary: sp.csr_matrix, order: str,
                        as_correction: bool = False) -> tuple[sp.csr_matrix, sp.csr_matrix] | GradientCorrection:
    """The test gradients d~N/dx, d~N/dy (m, n; the pattern of ``sf``) at the m ``points`` (m, 2) with area
    weights ``w`` (m,), for which the integration constraints of ``order`` ("linear" or "quadratic") hold
    against the ``boundary`` Gauss points, where ``N_boundary`` (b, n) are the shape functions. ``nodes``
    (n, 2), ``d_c`` the node spacing (it scales q). A node in no point's support keeps its gradients.
    ``as_correction``: on the compiled path (large sets), the coefficients (:class:`GradientCorrection`) instead of
    the two arrays, for :func:`ctmrpim.discretisation.assembly.stiffness` to apply as it sums."""
    dx, dy, N = sf.dNdx, sf.dNdy, sf.N
    if not rpim_kernels.use_compiled(dx.nnz, assembly.COMPILED_MIN_ENTRIES):
        return _numpy_corrected_gradients(nodes, d_c, points, w, sf, boundary, N_boundary, order)
    n = len(nodes)
    quadratic = order != "linear"
    f64 = lambda v: np.ascontiguousarray(v, dtype=float)
    indptr, indices = dx.indptr, dx.indices          # int32 or int64: the kernels compile for either
    nodes, points = f64(nodes).reshape(-1, 2), f64(points).reshape(-1, 2)
    # per-node moments of the integration constraints, one compiled pass over the entries (vci_kernels)
    M = np.zeros((n, 3, 3))
    R = np.zeros((n, 3, 2))
    vci_kernels.moments(indptr, indices, f64(dx.data), f64(dy.data), f64(N.data), f64(w), points, nodes,
                        float(d_c), quadratic, N_boundary.indptr, N_boundary.indices,
                        f64(N_boundary.data), f64(boundary.weights), f64(boundary.normals).reshape(-1, 2),
                        f64(boundary.points).reshape(-1, 2), M, R)
    c = np.zeros((n, 3, 2))
    if quadratic:
        used = M[:, 0, 0] > 0
        c[used] = np.linalg.solve(M[used], R[used])
    else:
        total = M[:, 0, 0]
        c[:, 0, :] = R[:, 0, :] / np.where(total > 0, total, 1.0)[:, None]
    correction = GradientCorrection(c, points, nodes, float(d_c), quadratic)
    return correction if as_correction else correction.applied(dx, dy)


def _numpy_corrected_gradients(nodes: np.ndarray, d_c: float, points: np.ndarray, w: np.ndarray, sf: ShapeFunctions,
                               boundary: BoundaryQuadrature, N_boundary: sp.csr_matrix, order: str
                               ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """:func:`corrected_gradients` by numpy: weighted ``bincount`` passes over the entries."""
    dx, dy, N = sf.dNdx, sf.dNdy, sf.N
    n = len(nodes)
    rows, cols = np.repeat(np.arange(dx.shape[0]), np.diff(dx.indptr)), dx.indices
    wp = w[rows]
    brows, bcols = np.repeat(np.arange(N_boundary.shape[0]), np.diff(N_boundary.indptr)), N_boundary.indices
    bw = boundary.weights[brows] * N_boundary.data
    if order == "linear":
        total = np.bincount(cols, wp, n)
        out = []
        for k, d in enumerate((dx, dy)):
            r = np.bincount(bcols, bw * boundary.normals[brows, k], n) - np.bincount(cols, wp * d.data, n)
            xi = r / np.where(total > 0, total, 1.0)
            out.append(sp.csr_matrix((d.data + xi[cols], d.indices, d.indptr), shape=d.shape))
        return out[0], out[1]
    q = np.stack([np.ones(len(rows)), (points[rows, 0] - nodes[cols, 0]) / d_c,
                  (points[rows, 1] - nodes[cols, 1]) / d_c], axis=1)
    qb = np.stack([np.ones(len(brows)), (boundary.points[brows, 0] - nodes[bcols, 0]) / d_c,
                   (boundary.points[brows, 1] - nodes[bcols, 1]) / d_c], axis=1)
    M = np.zeros((n, 3, 3))
    for a in range(3):
        for b in range(a, 3):
            M[:, a, b] = M[:, b, a] = np.bincount(cols, wp * q[:, a] * q[:, b], n)
    R = np.zeros((n, 3, 2))
    for k, d in enumerate((dx, dy)):
        for a in range(3):
            # d_k q_a is 1/d_c for (k, a) = (x, 1) and (y, 2), else 0
            dq = N.data / d_c if a == k + 1 else 0.0
            R[:, a, k] = (np.bincount(bcols, bw * qb[:, a] * boundary.normals[brows, k], n)
                          - np.bincount(cols, wp * (d.data * q[:, a] + dq), n))
    used = M[:, 0, 0] > 0
    c = np.zeros((n, 3, 2))
    c[used] = np.linalg.solve(M[used], R[used])
    return tuple(sp.csr_matrix((d.data + np.einsum("ea,ea->e", q, c[cols, :, k]), d.indices, d.indptr),
                               shape=d.shape) for k, d in enumerate((dx, dy)))


def corrected_test_gradients(conf: Configuration, method: Method, thickness: float, as_correction: bool = False
                             ) -> tuple[BoundaryQuadrature, ShapeFunctions, sp.csr_matrix | GradientCorrection,
                                        sp.csr_matrix | None]:
    """What every solver path with ``method.integration = "ctm-vci"`` starts from, on a configuration ``conf``
    integrated over its tracked node loops: the boundary's Gauss points, the shape functions there and the
    corrected test gradients d~N/dx, d~N/dy at the configuration's points (weights without the ``thickness``).
    ``as_correction``: where :func:`corrected_gradients` gives the coefficients, they come third and None fourth."""
    if method.boundary != "alpha":
        raise ProblemError("method.integration = \"ctm-vci\" integrates over the node loops of the tracked boundary: "
                           "set method.boundary = \"alpha\", or method.integration = \"ctm\" for the paper's scheme",
                           key="method.integration")
    boundary = boundary_quadrature(conf.x, conf.boundary.edges)
    sf_b = conf.shape_functions_at(boundary.points)
    test = corrected_gradients(conf.x, conf.lengths.d_c, conf.points, conf.w / thickness, conf.sf, boundary, sf_b.N,
                               method.correction, as_correction)
    return (boundary, sf_b, test, None) if isinstance(test, GradientCorrection) else (boundary, sf_b, *test)


def dirichlet_consistency(n_nodes: int, fixed: np.ndarray, boundary: BoundaryQuadrature, sf: ShapeFunctions,
                          D: np.ndarray, thickness: float) -> sp.csr_matrix:
    """C (2n x 2n), to be subtracted from K: sum_b w_b N_I(x_b) dt_k/du_Jl over the ``boundary`` Gauss points
    of segments whose two end nodes (``boundary.ends``) both have component k prescribed (``fixed``:
    interleaved dofs), t = sigma(u_h) n with the (uncorrected) shape functions ``sf`` at the points."""
    segment_ends = boundary.ends
    prescribed = np.zeros(2 * n_nodes, bool)
    prescribed[fixed] = True
    nx, ny = boundary.normals[:, 0], boundary.normals[:, 1]
    Nx, Ny = sf.dNdx, sf.dNdy
    # dt_k/du_Jl = a dN_J/dA + b dN_J/dB as (a, dN/dA, b, dN/dB); t_x = nx sxx + ny sxy, t_y = nx sxy + ny syy
    dt = {(0, 0): (nx * D[0, 0], Nx, ny * D[2, 2], Ny), (0, 1): (nx * D[0, 1], Ny, ny * D[2, 2], Nx),
          (1, 0): (nx * D[2, 2], Ny, ny * D[1, 0], Nx), (1, 1): (nx * D[2, 2], Nx, ny * D[1, 1], Ny)}
    C = sp.csr_matrix((2 * n_nodes, 2 * n_nodes))
    for k in (0, 1):
        on = prescribed[2 * segment_ends[:, 0] + k] & prescribed[2 * segment_ends[:, 1] + k]
        if not on.any():
            continue
        NtW = (sf.N[on].T @ sp.diags(boundary.weights[on] * thickness)).tocsr()
        for l in (0, 1):
            a, A, b, B = dt[k, l]
            block = (NtW @ (sp.diags(a[on]) @ A[on] + sp.diags(b[on]) @ B[on])).tocoo()
            C = C + sp.csr_matrix((block.data, (2 * block.row + k, 2 * block.col + l)), shape=C.shape)
    return C.tocsr()


def _constrained_traction_forces(n_nodes: int, fixed: np.ndarray, boundary: BoundaryQuadrature, N: sp.csr_matrix,
                                 thickness: float) -> tuple[sp.csr_matrix, bool]:
    """S (2n x 2b), tractions (b, 2) at the ``boundary`` points -> forces sum_b w_b N_I(x_b) t_k(x_b), on the
    components k prescribed (``fixed``) at both ends of a point's segment only, and whether there is any. The
    rows of prescribed dofs are dropped: their equations are replaced by the prescribed values, and the internal
    force there stays the reaction (the Newton iteration measures its residual against it)."""
    prescribed = np.zeros(2 * n_nodes, bool)
    prescribed[fixed] = True
    ends = boundary.ends
    on = np.stack([prescribed[2 * ends[:, 0] + k] & prescribed[2 * ends[:, 1] + k] for k in (0, 1)], axis=1)
    rows, cols = np.nonzero(on)
    b = len(boundary.weights)
    W = sp.csr_matrix((boundary.weights[rows] * thickness, (2 * rows + cols, 2 * rows + cols)), shape=(2 * b, 2 * b))
    return (sp.diags((~prescribed).astype(float)) @ value_operator(N).T @ W).tocsr(), bool(on.any())


class LagrangianDirichletTerm:
    """The Dirichlet consistency term of a total-Lagrangian (hyperelastic) solve with ``ctm-vci``: the large-
    deformation form of :func:`dirichlet_consistency`, subtracted from the internal force,

        f_(I, k) -= sum_b w_b N_I(x_b) t_k(x_b),   t = P(F) N   (first Piola-Kirchhoff traction, reference normal N)

    over the ``boundary`` Gauss points of segments whose two end nodes have component k prescribed (``fixed``,
    interleaved dofs), F = I + grad_X u at the points from the (uncorrected) shape functions ``sf``; with its
    derivative dt_k/du = (A : grad N) N, A = dP/dF, subtracted from the tangent. A hyperelastic material has no
    history, so the traction at a boundary point is its own, computed from F there."""

    def __init__(self, n_nodes: int, fixed: np.ndarray, boundary: BoundaryQuadrature, sf: ShapeFunctions,
                 thickness: float) -> None:
        self.S, self.active = _constrained_traction_forces(n_nodes, fixed, boundary, sf.N, thickness)
        self.normals = boundary.normals
        self.G = gradient_operator(sf.dNdx, sf.dNdy)

    def __call__(self, U: np.ndarray, stress_tangent: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
                 ) -> tuple[np.ndarray, sp.csr_matrix]:
        """The term's force (2n,) and tangent (2n x 2n) at displacements ``U``; ``stress_tangent(F)`` gives P
        (b, 2, 2) and A (b, 2, 2, 2, 2) at deformation gradients F (b, 2, 2)."""
        F = np.eye(2)[None] + (self.G @ U).reshape(-1, 2, 2)
        P, A = stress_tangent(F)
        t = np.einsum("biJ,bJ->bi", P, self.normals)
        T = np.einsum("biJkL,bJ->bikL", A, self.normals).reshape(-1, 2, 4)   # dt_i / dF_kL
        b = len(T)
        Tm = sp.bsr_matrix((T, np.arange(b), np.arange(b + 1)), shape=(2 * b, 4 * b))
        return self.S @ t.ravel(), (self.S @ (Tm @ self.G)).tocsr()


class RecoveredDirichletTerm:
    """The Dirichlet consistency term of a small-strain, history-dependent (elastoplastic) solve with
    ``ctm-vci``: the stress at a boundary Gauss point is not a state anyone keeps, so it is the stress recovered
    there from the integration points' (:func:`ctmrpim.discretisation.stress_recovery.recovery_operator`, R):

        f_(I, k) -= sum_b w_b N_I(x_b) t_k(x_b),   t = (R sigma)(x_b) n,

    over the ``boundary`` points of segments whose two end nodes have component k prescribed (``fixed``), and
    in the tangent its derivative through the points' tangents, (S N R) diag(A) G. Exact for a constant stress,
    so the patch test holds; the recovery is linear, so the tangent is consistent."""

    def __init__(self, n_nodes: int, fixed: np.ndarray, boundary: BoundaryQuadrature, N_boundary: sp.csr_matrix,
                 recovery: sp.csr_matrix, thickness: float) -> None:
        S, self.active = _constrained_traction_forces(n_nodes, fixed, boundary, N_boundary, thickness)
        b = len(boundary.weights)
        nx, ny = boundary.normals[:, 0], boundary.normals[:, 1]
        # t_x = s_xX n_x + s_xY n_y, t_y = s_yX n_x + s_yY n_y on the stress layout xX, xY, yX, yY
        blocks = np.zeros((b, 2, 4))
        blocks[:, 0, 0], blocks[:, 0, 1], blocks[:, 1, 2], blocks[:, 1, 3] = nx, ny, nx, ny
        Nn = sp.bsr_matrix((blocks, np.arange(b), np.arange(b + 1)), shape=(2 * b, 4 * b))
        R4 = sp.kron(recovery, sp.identity(4), format="csr")
        self.operator = (S @ Nn @ R4).tocsc()     # (2n x 4m): the points' stresses -> forces
        #: (m,) the points whose stress reaches the term (those near the constrained edges): the others' part of
        #: the tangent is zero, and its products need not run over them
        self.reaches = np.diff(self.operator.indptr).reshape(-1, 4).any(axis=1)

    def force(self, P: np.ndarray) -> np.ndarray:
        """(2n,) the term's force of the stresses P (m, 4: xX, xY, yX, yY) at the integration points."""
        return self.operator @ P.ravel()

    def stiffness(self, G: sp.bsr_matrix, A: np.ndarray, points: np.ndarray | None = None) -> sp.csr_matrix:
        """(2n x 2n) its derivative: operator diag(A) G over the rows of G, the tangents A (k, 4, 4) of the k
        ``points`` those rows belong to (all points where None)."""
        k = len(A)
        op = self.operator if points is None else self.operator[:, (4 * points[:, None] + np.arange(4)).ravel()]
        blocks = sp.bsr_matrix((A, np.arange(k), np.arange(k + 1)), shape=(4 * k, 4 * k))
        return (op @ (blocks @ G)).tocsr()


def recovered_consistency(conf: Configuration, method: Method, thickness: float, fixed: np.ndarray,
                          N_boundary: sp.csr_matrix | None = None
                          ) -> tuple[sp.bsr_matrix, RecoveredDirichletTerm, sp.csr_matrix]:
    """The consistent scheme of a solver whose stress state lives at the integration points (small-strain
    Mohr-Coulomb, updated-Lagrangian) on ``conf``: G~ (the gradient operator of the corrected test gradients), the
    Dirichlet term with the stress recovered at the boundary's Gauss points (``fixed``: the constrained dofs), and
    the shape functions there (b, n). ``N_boundary``: those values where the caller keeps them (a configuration
    moved without a rebuild keeps its shape functions, so they are the values computed before the move)."""
    if N_boundary is None:
        boundary, sf_b, test_dx, test_dy = corrected_test_gradients(conf, method, thickness)
        N_boundary = sf_b.N
    else:
        boundary = boundary_quadrature(conf.x, conf.boundary.edges)
        test_dx, test_dy = corrected_gradients(conf.x, conf.lengths.d_c, conf.points, conf.w / thickness, conf.sf,
                                               boundary, N_boundary, method.correction)
    R = recovery_operator(boundary.points, conf.points, conf.w, conf.lengths.d_c)
    term = RecoveredDirichletTerm(len(conf.x), fixed, boundary, N_boundary, R, thickness)
    return gradient_operator(test_dx, test_dy), term, N_boundary
