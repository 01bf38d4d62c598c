"""Linear static solve K U = F (Eq. 4) with constraints imposed directly on nodal values.

RPIM shape functions have the Kronecker delta property, so a prescribed displacement is the nodal
value itself: the constrained dofs are eliminated and their values moved to the right-hand side.

Solvers (``method.solver``):

* ``superlu``: SuperLU with the MMD_AT_PLUS_A ordering; measured, it is 4-6 times faster than scipy's
  default COLAMD ordering on these stiffness matrices (docs/design.md, 'Linear solvers').
* ``banded``: reverse Cuthill-McKee ordering, then LAPACK's banded Cholesky (K is symmetric positive
  definite once constrained). On elongated bodies such as the cantilever the band is narrow and this
  wins: 0.48 s against 0.76 s for SuperLU at 129 x 33 nodes, measured here.
* ``auto`` (default): ``banded`` when the band is at most BANDED_MAX_FRACTION of the dofs, else
  ``superlu``; a banded factorisation that finds K indefinite falls back to SuperLU, which then
  reports the singular matrix.
* ``spsolve``: scipy's default, for comparison.

The factorisations run on one BLAS thread: on this project's two-core machine, with other work running, the
banded Cholesky of the 129 x 33 cantilever took 4.6 s on OpenBLAS's default threads against 0.73 s on one
(its threads spin-wait for a core), and SuperLU gains nothing from them.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import reverse_cuthill_mckee
from threadpoolctl import threadpool_limits

from ctmrpim.discretisation import assembly, rpim_kernels, stiffness_kernels
from ctmrpim.errors import ProblemError

BANDED_MAX_FRACTION = 0.1   # auto: banded Cholesky when the RCM half-bandwidth is at most this share of the dofs


def solve_constrained(K: sp.csr_matrix, F: np.ndarray, fixed: np.ndarray, values: np.ndarray,
                      solver: str = "superlu") -> np.ndarray:
    """U (2n,) with U[fixed] = values and (K U - F)[free] = 0, for K (2n x 2n) and F (2n,); ``fixed`` (k,) dof
    indices with ``values`` (k,)."""
    return solve_free(*constrained_system(K, F, fixed, values), solver)


def constrained_system(K: sp.csr_matrix, F: np.ndarray, fixed: np.ndarray, values: np.ndarray
                       ) -> tuple[sp.csr_matrix | sp.csc_matrix, np.ndarray, np.ndarray, np.ndarray]:
    """The system of the free dofs: (K_ff, F_f - K_fc values, U with the prescribed values and zeros
    elsewhere, the free dofs). A caller that drops K before :func:`solve_free` keeps one copy of the
    stiffness, not two, while it is factorised."""
    n = K.shape[0]
    U = np.zeros(n)
    U[fixed] = values
    free = np.setdiff1d(np.arange(n), fixed)
    Kff, rhs = _free_block(K, F, free, U)
    return Kff, rhs, U, free


def solve_free(Kff: sp.csr_matrix | sp.csc_matrix, rhs: np.ndarray, U: np.ndarray, free: np.ndarray,
               solver: str = "superlu") -> np.ndarray:
    """U with U[free] solving Kff U[free] = rhs (:func:`constrained_system`), by ``solver``."""
    with threadpool_limits(limits=1, user_api="blas"):
        U[free] = _solve(Kff, rhs, solver)
    if not np.all(np.isfinite(U)):
        raise ProblemError("the linear solve produced non-finite displacements: the stiffness matrix is singular")
    return U


def _solve(Kff: sp.csr_matrix | sp.csc_matrix, rhs: np.ndarray, solver: str) -> np.ndarray:
    if solver == "spsolve":
        return spla.spsolve(Kff.tocsc(), rhs)
    if solver in ("auto", "banded") and (x := _banded_cholesky(Kff, rhs, solver == "banded")) is not None:
        return x
    try:
        lu = spla.splu(Kff.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise ProblemError(f"the stiffness matrix is singular ({exc}): the constraints do not prevent "
                           "rigid-body motion, or part of the body is detached") from None
    return lu.solve(rhs)


def _free_block(K: sp.csr_matrix, F: np.ndarray, free: np.ndarray, U: np.ndarray
                ) -> tuple[sp.csr_matrix | sp.csc_matrix, np.ndarray]:
    """K's free-free block and the right-hand side F[free] - K[free, fixed] U[fixed] (U zero on the free dofs).
    For a large K one compiled pass builds the block as CSC (what SuperLU takes): no copies of K's rows and
    columns on the way, which at 257 x 65 nodes are 160 MB each. The right-hand side's sums differ from
    scipy's by round-off, so the path is chosen by size alone (a resumed run repeats the first)."""
    if not (rpim_kernels.use_compiled(K.nnz, assembly.COMPILED_MIN_ENTRIES) and isinstance(K, sp.csr_matrix)):
        Kfree = K[free]
        return Kfree[:, free].tocsr(), F[free] - Kfree @ U
    new = np.full(K.shape[0], -1, np.int64)
    new[free] = np.arange(len(free))
    rhs = np.array(F[free], dtype=float)
    cptr, rows, vals = stiffness_kernels.constrained_csc(K.indptr, K.indices, K.data, new, U, rhs)
    itype = K.indices.dtype
    A = sp.csc_matrix((vals, rows, cptr.astype(itype)), shape=(len(free), len(free)), copy=False)
    A.has_sorted_indices = True
    return A, rhs


def _banded_cholesky(A: sp.csr_matrix | sp.csc_matrix, b: np.ndarray, always: bool) -> np.ndarray | None:
    """Solve with RCM + banded Cholesky; None when the band is too wide (auto) or A is not positive definite.
    The band is filled straight from A's arrays where numba already runs (no permuted copies of A; the same
    band bit for bit) and factorised in place."""
    perm = reverse_cuthill_mckee(A, symmetric_mode=True)
    n = A.shape[0]
    if rpim_kernels.numba_ready():
        rank = np.empty(n, np.int64)
        rank[perm] = np.arange(n)
        bw = int(stiffness_kernels.lower_bandwidth(A.indptr, A.indices, rank))
        if not always and bw > BANDED_MAX_FRACTION * n:
            return None
        ab = np.zeros((bw + 1, n))
        stiffness_kernels.fill_lower_band(A.indptr, A.indices, A.data, rank, ab)
    else:
        Ap = A[perm][:, perm].tocoo()
        lower = Ap.row >= Ap.col
        offset = Ap.row[lower] - Ap.col[lower]
        bw = int(offset.max()) if len(offset) else 0
        if not always and bw > BANDED_MAX_FRACTION * n:
            return None
        ab = np.zeros((bw + 1, n))
        ab[offset, Ap.col[lower]] = Ap.data[lower]
    try:
        xp = sla.solveh_banded(ab, b[perm], lower=True, check_finite=False, overwrite_ab=True)
    except np.linalg.LinAlgError:
        return None
    x = np.empty_like(xp)
    x[perm] = xp
    return x
