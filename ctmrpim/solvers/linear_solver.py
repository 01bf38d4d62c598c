"""Linear static solve K U = F (Eq. 4) with constraints imposed directly on nodal values.

RPIM shape functions have the Kronecker delta property, so a prescribed displacement is the nodal
value itself: the constrained dofs are eliminated and their values moved to the right-hand side.

Solvers (``method.solver``):

* ``superlu``: SuperLU with the MMD_AT_PLUS_A ordering; measured, it is 4-6 times faster than scipy's
  default COLAMD ordering on these stiffness matrices (docs/design.md, 'Linear solvers').
* ``banded``: the narrower band of the reverse Cuthill-McKee ordering and the dofs sorted along the body's
  principal axis (:func:`ctmrpim.solvers.banded_lu.principal_axis_order`), then LAPACK's banded Cholesky (K is
  symmetric positive definite once constrained; in mixed precision, below). On elongated bodies such as the
  cantilever the band is narrow and this wins: 0.48 s against 0.76 s for SuperLU at 129 x 33 nodes, measured here
  with the RCM band alone.
* ``auto`` (default): ``banded`` when the band is at most BANDED_MAX_FRACTION of the dofs, else
  ``pardiso`` where pypardiso is installed and there are at least PARDISO_MIN_DOFS free dofs, else
  ``superlu``; a banded factorisation that finds K indefinite falls back to SuperLU, which then
  reports the singular matrix. (So on a wide-band system above that size the answer differs by round-off,
  about 1e-12 relative, with and without pypardiso installed.)
* ``spsolve``: scipy's default, for comparison.
* ``pardiso``: Intel MKL's PARDISO through pypardiso (optional: ``pip install 'ctmrpim[solvers]'``), a symmetric
  K as positive definite (its upper triangle), any other as real non-symmetric. On square bodies, whose band is
  wide, it wins over SuperLU from a few thousand dofs: measured here (one thread, beside other work) on a square
  cantilever block, 65 x 65 nodes (8320 dofs) 0.58 s against 1.45 s, 129 x 129 (33024 dofs) 4.8 s against 14.5 s;
  its start (loading MKL) costs about 0.15 s, so below about 2000 dofs it loses (33 x 33: 0.19 s against 0.08 s).
* ``amg``: pyamg's smoothed aggregation (optional, as above) with the three rigid-body modes of the free nodes as
  near-null space, preconditioning CG (symmetric K) or GMRES (non-symmetric K: the hierarchy of its symmetric
  part) to the relative residual ITERATIVE_RTOL. Its cost grows more slowly with the size than a direct solve's;
  at the sizes of this project it does not win yet (129 x 129 square: 6.0 s; 257 x 65 cantilever: 6.6 s against
  the banded path's 2.4 s). It is refused in one line when it does not reach the residual.

A non-symmetric K (the consistent schemes' Dirichlet terms and corrected test gradients) takes, under
``auto`` or ``banded``, GMRES preconditioned by the banded Cholesky factor of its symmetric part, where that
part is positive definite and its band narrow, else SuperLU.

Either band is factorised in single precision first
(half the memory and time; the band is the largest array of a large solve) and used as the preconditioner of
conjugate gradients (symmetric K) or GMRES, with iterative refinement on the double-precision residual to
KRYLOV_RTOL (1e-11; SuperLU's is 2-5e-12 on these systems); where that factor breaks down or does not bring the
residual there, the double-precision band: the factor itself for a symmetric K, the preconditioner again for a
non-symmetric one (docs/design.md, 'Linear solvers', with the measurements).

The factorisations run on one BLAS thread: on this project's two-core machine, with other work running, the
banded Cholesky of the 129 x 33 cantilever took 4.6 s on OpenBLAS's default threads against 0.73 s on one
(its threads spin-wait for a core), and SuperLU gains nothing from them.
"""
from __future__ import annotations

import inspect
from typing import Callable

import numpy as np
import scipy.linalg as sla
import scipy.linalg.lapack as lapack
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ctmrpim.blas_threads import one_blas_thread
from ctmrpim.discretisation import assembly, rpim_kernels
from ctmrpim.discretisation.thread_blocks import run_blocks
from ctmrpim.errors import ProblemError
from ctmrpim.solvers import free_block_kernels
from ctmrpim.solvers.banded_lu import principal_axis_order
from ctmrpim.solvers.symmetric_half import SymmetricHalf

#: a free block as the solvers take it
Matrix = sp.csr_matrix | sp.csc_matrix | SymmetricHalf

BANDED_MAX_FRACTION = 0.1   # auto: banded Cholesky when the half-bandwidth is at most this share of the dofs
KRYLOV_RTOL = 1e-11         # banded preconditioner: relative residual reached (SuperLU reaches 2-5e-12; the floor is 2e-12)
KRYLOV_ITERATIONS, REFINEMENTS = 60, 4     # Krylov iterations per refinement, refinements at most
KRYLOV_INNER_RTOL = 1e-6    # each refinement's relative residual (of its own right-hand side)
#: the band's precisions, in the order tried: single precision halves the band's memory and its factorisation's
#: time, for a few more Krylov iterations (16 against 12 on the 257 x 65 cantilever's default K)
PRECONDITIONER_PRECISIONS = (np.float32, np.float64)
PARDISO_MIN_DOFS = 4000     # auto: PARDISO (where installed) on wide-band systems from this many free dofs
MATVEC_BLOCKS = 4            # blocks of rows of the compiled product with a CSR free block (:func:`_product`)
ITERATIVE_RTOL = 1e-11      # amg: relative residual of CG / GMRES, as KRYLOV_RTOL
ITERATIVE_MAXITER = 2000    # amg: iterations before it is refused
#: the optional solvers and the package each needs (``pip install 'ctmrpim[solvers]'``)
OPTIONAL = {"pardiso": "pypardiso", "amg": "pyamg"}
#: the solvers that work on a symmetric free block's upper triangle (:class:`SymmetricHalf`) without the whole
HALF_SOLVERS = ("auto", "banded", "pardiso")


def available(solver: str) -> bool:
    """Whether ``solver``'s optional package (:data:`OPTIONAL`) is installed; True for the built-in ones."""
    from importlib.util import find_spec

    return solver not in OPTIONAL or find_spec(OPTIONAL[solver]) is not None


def solve_constrained(K: sp.csr_matrix, F: np.ndarray, fixed: np.ndarray, values: np.ndarray,
                      solver: str = "superlu", symmetric: bool = True, nodes: np.ndarray | None = None
                      ) -> np.ndarray:
    """U (2n,) with U[fixed] = values and (K U - F)[free] = 0, for K (2n x 2n) and F (2n,); ``fixed`` (k,) dof
    indices with ``values`` (k,); ``symmetric``: whether K is (the choice of the method under ``auto``);
    ``nodes`` (n, 2): the positions, for ``amg``'s rigid-body modes (translations only without them)."""
    return solve_free(*constrained_system(K, F, fixed, values), solver, symmetric, nodes)


def constrained_system(K: sp.csr_matrix, F: np.ndarray, fixed: np.ndarray, values: np.ndarray,
                       half: bool = False
                       ) -> tuple[Matrix, np.ndarray, np.ndarray, np.ndarray]:
    """The system of the free dofs: (K_ff, F_f - K_fc values, U with the prescribed values and zeros
    elsewhere, the free dofs). A caller that drops K before :func:`solve_free` keeps one copy of the
    stiffness, not two, while it is factorised. With ``half`` (a symmetric K with sorted columns, to be solved
    by one of HALF_SOLVERS), a large K_ff is its upper triangle (:class:`SymmetricHalf`): half the memory."""
    n = K.shape[0]
    U = np.zeros(n)
    U[fixed] = values
    free = np.setdiff1d(np.arange(n), fixed)
    Kff, rhs = _free_block(K, F, free, U, half)
    return Kff, rhs, U, free


def solve_free(Kff: Matrix, rhs: np.ndarray, U: np.ndarray, free: np.ndarray,
               solver: str = "superlu", symmetric: bool = True, nodes: np.ndarray | None = None) -> np.ndarray:
    """U with U[free] solving Kff U[free] = rhs (:func:`constrained_system`), by ``solver`` (``symmetric``:
    whether Kff is; ``nodes``: as for :func:`solve_constrained`)."""
    if not available(solver):
        raise ProblemError(f"method.solver = \"{solver}\" needs the optional package {OPTIONAL[solver]}: "
                           "pip install 'ctmrpim[solvers]'")
    places = None if nodes is None else np.asarray(nodes, float)[free // 2]    # each free dof's node
    with one_blas_thread():
        U[free] = _solve(Kff, rhs, solver, symmetric, lambda: _rigid_body_modes(nodes, free, U.size), places)
    if not np.all(np.isfinite(U)):
        raise ProblemError("the linear solve produced non-finite displacements: the stiffness matrix is singular")
    return U


def _solve(Kff: Matrix, rhs: np.ndarray, solver: str, symmetric: bool,
           modes: Callable[[], np.ndarray], places: np.ndarray | None = None) -> np.ndarray:
    if isinstance(Kff, SymmetricHalf):
        if not symmetric:
            raise ValueError("a SymmetricHalf is the free block of a symmetric K only")
        if solver not in HALF_SOLVERS:
            Kff = Kff.full()
    if solver == "spsolve":
        return spla.spsolve(Kff.tocsc(), rhs)
    if solver == "amg":
        return _amg(Kff, rhs, symmetric, modes())
    if solver in ("auto", "banded"):
        if (x := _banded(Kff, rhs, solver == "banded", symmetric, places)) is not None:
            return x
    if solver == "pardiso" or (solver == "auto" and len(rhs) >= PARDISO_MIN_DOFS and available("pardiso")):
        return _pardiso(Kff, rhs, symmetric)
    if isinstance(Kff, SymmetricHalf):   # auto, where neither the band nor PARDISO took it
        Kff = Kff.full()
    # a CSR block's arrays are the CSC of its transpose: SuperLU factorises that, and solves transposed (no copy)
    transposed = isinstance(Kff, sp.csr_matrix)
    A = sp.csc_matrix((Kff.data, Kff.indices, Kff.indptr), shape=Kff.shape[::-1]) if transposed else Kff.tocsc()
    try:
        lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise ProblemError(f"the stiffness matrix is singular ({exc}): the constraints do not prevent "
                           "rigid-body motion, or part of the body is detached") from None
    return lu.solve(rhs, trans="T" if transposed else "N")


def _pardiso(A: Matrix, b: np.ndarray, symmetric: bool) -> np.ndarray:
    """A^-1 b by PARDISO: positive definite on A's upper triangle where A is symmetric, else real non-symmetric;
    a singular or indefinite A is refused in one line."""
    import pypardiso

    pardiso = pypardiso.PyPardisoSolver(mtype=2 if symmetric else 11)
    try:
        upper = A.upper if isinstance(A, SymmetricHalf) else sp.triu(A, format="csr") if symmetric else None
        x = pardiso.solve(upper if symmetric else sp.csr_matrix(A), b)
    except (pypardiso.pardiso_wrapper.PyPardisoError, ValueError) as exc:   # ValueError: an empty row
        raise ProblemError(f"the stiffness matrix is singular or not positive definite (PARDISO: {exc}): the "
                           "constraints do not prevent rigid-body motion, or part of the body is detached") from None
    finally:
        pardiso.free_memory(everything=True)
    return x


def _rigid_body_modes(nodes: np.ndarray | None, free: np.ndarray, n_dofs: int) -> np.ndarray:
    """The plane rigid-body modes (two translations, the rotation about the centroid) on the ``free`` dofs of
    ``n_dofs`` (dof 2i, 2i + 1 of node i): AMG's near-null space; the translations alone without ``nodes``."""
    B = np.zeros((n_dofs, 3 if nodes is not None else 2))
    B[0::2, 0] = B[1::2, 1] = 1.0
    if nodes is not None:
        x = nodes - nodes.mean(axis=0)
        B[0::2, 2], B[1::2, 2] = -x[:, 1], x[:, 0]
    return B[free]


def _amg(A: sp.csr_matrix | sp.csc_matrix, b: np.ndarray, symmetric: bool, modes: np.ndarray) -> np.ndarray:
    """A^-1 b by CG (symmetric A) or GMRES, preconditioned by a smoothed-aggregation hierarchy of A (of its
    symmetric part) with the rigid-body ``modes`` as near-null space, to ITERATIVE_RTOL; refused in one line
    where it does not get there in ITERATIVE_MAXITER iterations."""
    import pyamg

    A = sp.csr_matrix(A)
    if not np.any(b):
        return np.zeros_like(b)
    hierarchy = pyamg.smoothed_aggregation_solver(A if symmetric else ((A + A.T) * 0.5).tocsr(), B=modes,
                                                  symmetry="symmetric")
    M = hierarchy.aspreconditioner(cycle="V")
    tol = "rtol" if "rtol" in inspect.signature(spla.cg).parameters else "tol"   # scipy < 1.12: tol
    if symmetric:
        x, info = spla.cg(A, b, M=M, atol=0.0, maxiter=ITERATIVE_MAXITER, **{tol: ITERATIVE_RTOL})
    else:
        x, info = spla.gmres(A, b, M=M, atol=0.0, restart=100, maxiter=ITERATIVE_MAXITER // 100,
                             **{tol: ITERATIVE_RTOL})
    residual = np.linalg.norm(A @ x - b) / np.linalg.norm(b)
    if info != 0 or not residual <= 2 * ITERATIVE_RTOL:
        raise ProblemError(f"method.solver = \"amg\": {'CG' if symmetric else 'GMRES'} reached a relative "
                           f"residual of {residual:.1e}, not {ITERATIVE_RTOL:g}, in {ITERATIVE_MAXITER} "
                           "iterations; use solver = \"auto\" or \"superlu\"")
    return x


def _free_block(K: sp.csr_matrix, F: np.ndarray, free: np.ndarray, U: np.ndarray, half: bool = False
                ) -> tuple[Matrix, np.ndarray]:
    """K's free-free block and the right-hand side F[free] - K[free, fixed] U[fixed] (U zero on the free dofs).
    For a large K one compiled pass builds the block as CSR (row by row), or with ``half`` its upper
    triangle as a :class:`SymmetricHalf`: no copies of K's rows and columns on the way, which at 257 x 65 nodes
    are 160 MB each. The right-hand side's sums differ from scipy's by round-off, so the path is chosen by size
    alone (a resumed run repeats the first)."""
    if not (rpim_kernels.use_compiled(K.nnz, assembly.COMPILED_MIN_ENTRIES) and isinstance(K, sp.csr_matrix)):
        Kfree = K[free]
        return Kfree[:, free].tocsr(), F[free] - Kfree @ U
    new = np.full(K.shape[0], -1, np.int64)
    new[free] = np.arange(len(free))
    rhs = np.array(F[free], dtype=float)
    itype = K.indices.dtype
    if half:
        if not K.has_sorted_indices:
            K.sort_indices()
        rptr, cols, vals = free_block_kernels.constrained_block(K.indptr, K.indices, K.data, new, U, rhs, True)
        upper = sp.csr_matrix((vals, cols, rptr.astype(itype)), shape=(len(free), len(free)), copy=False)
        upper.has_sorted_indices = True
        return SymmetricHalf(upper), rhs
    rptr, cols, vals = free_block_kernels.constrained_block(K.indptr, K.indices, K.data, new, U, rhs, False)
    A = sp.csr_matrix((vals, cols, rptr.astype(itype)), shape=(len(free), len(free)), copy=False)
    A.has_sorted_indices = K.has_sorted_indices
    return A, rhs


def _banded(A: Matrix, b: np.ndarray, always: bool, symmetric: bool,
            places: np.ndarray | None = None) -> np.ndarray | None:
    """Solve A x = b on A's band (:func:`_band_order`): a ``symmetric`` positive definite A by conjugate gradients
    on the single-precision banded Cholesky factor (:func:`_refined`), else by the double-precision factor directly; a
    non-symmetric A by GMRES preconditioned with the factor of (A + A^T) / 2, single precision first
    (PRECONDITIONER_PRECISIONS). None when the band is too wide (auto, not ``always``), the factor's matrix is not
    positive definite, or GMRES does not reach KRYLOV_RTOL with either factor. ``places`` (n, 2): where each row's
    dof sits (:func:`_band_order`)."""
    order = _band_order(A, always, places)
    if order is None:
        return None
    if not np.any(b):
        return np.zeros_like(b)
    if not symmetric:
        return _preconditioned(A, b, order, symmetric=False, precisions=PRECONDITIONER_PRECISIONS)
    if (x := _preconditioned(A, b, order, symmetric=True, precisions=PRECONDITIONER_PRECISIONS[:-1])) is not None:
        return x
    factor = _band_factor(A, order, symmetric_part=False, dtype=np.float64)
    return None if factor is None else _band_solve(factor, b)


def _preconditioned(A: Matrix, b: np.ndarray, order: tuple[np.ndarray, np.ndarray, int],
                    symmetric: bool, precisions: tuple[type, ...]) -> np.ndarray | None:
    """x solving A x = b by :func:`_refined` on the banded Cholesky factor of A (``symmetric``) or of its
    symmetric part, in the first of ``precisions`` whose factor exists and reaches KRYLOV_RTOL; else None."""
    for dtype in precisions:
        factor = _band_factor(A, order, symmetric_part=not symmetric, dtype=dtype)
        if factor is not None:
            M = spla.LinearOperator(A.shape, lambda v, f=factor: _band_solve(f, np.ravel(v)), dtype=float)
            x = _refined(A, b, M, symmetric)
            del factor, M   # the next precision's band is not allocated beside this one's
            if x is not None:
                return x
    return None


def _refined(A: Matrix, b: np.ndarray, M: spla.LinearOperator, symmetric: bool
             ) -> np.ndarray | None:
    """x with |A x - b| <= KRYLOV_RTOL |b| by iterative refinement: conjugate gradients (``symmetric``) or GMRES
    (one cycle) of at most KRYLOV_ITERATIONS to the relative residual KRYLOV_INNER_RTOL, on the true residual,
    at most REFINEMENTS times; None when that does not reach it. Refinement, not one Krylov solve to the final
    tolerance: a single-precision M is not a fixed linear operator to double precision, and the solver's own
    residual estimate then stops far from the true residual (GMRES at 2e-8 instead of 1e-11 on the 129 x 33
    cantilever)."""
    tol = "rtol" if "rtol" in inspect.signature(spla.gmres).parameters else "tol"   # scipy < 1.12: tol
    A = _product(A)
    x = np.zeros_like(b)
    r, target = b, KRYLOV_RTOL * np.linalg.norm(b)
    for _ in range(REFINEMENTS):
        if symmetric:
            dx, _info = spla.cg(A, r, M=M, atol=0.0, maxiter=KRYLOV_ITERATIONS, **{tol: KRYLOV_INNER_RTOL})
        else:
            dx, _info = spla.gmres(A, r, M=M, atol=0.0, restart=KRYLOV_ITERATIONS, maxiter=1,
                                   **{tol: KRYLOV_INNER_RTOL})
        x += dx
        r = b - A @ x
        if np.linalg.norm(r) <= target:
            return x
    return None


def _product(A: Matrix) -> Matrix | spla.LinearOperator:
    """A, or for a large CSR A (the compiled path, by size as :func:`_compiled`) the operator x -> A x by
    :func:`~ctmrpim.solvers.free_block_kernels.csr_matvec` on blocks of rows of about equal entries, on the threads
    (:mod:`ctmrpim.discretisation.thread_blocks`); the same sums as scipy's product, in the same order. The product
    streams A's arrays from memory once per Krylov iteration (33 MB at 129 x 33 nodes: 1.8 ms on one core)."""
    if not (isinstance(A, sp.csr_matrix) and _compiled(A)):
        return A
    cuts = np.searchsorted(A.indptr, np.linspace(0, A.nnz, MATVEC_BLOCKS + 1))
    cuts[0], cuts[-1] = 0, A.shape[0]
    blocks = [(int(a), int(b)) for a, b in zip(cuts[:-1], cuts[1:]) if b > a]
    indptr, indices, data = A.indptr, A.indices, A.data

    def apply(v: np.ndarray) -> np.ndarray:
        x = np.ascontiguousarray(np.ravel(v), dtype=float)
        y = np.empty(A.shape[0])
        run_blocks(lambda ab: free_block_kernels.csr_matvec(indptr, indices, data, x, y, *ab), blocks,
                   free_block_kernels.csr_matvec)
        return y

    return spla.LinearOperator(A.shape, matvec=apply, dtype=float)


def banded_cholesky(A: sp.csr_matrix, max_entries: int) -> tuple[np.ndarray, np.ndarray] | None:
    """(permutation, double-precision lower banded Cholesky factor) of a symmetric positive definite A on the
    narrower band of :func:`_band_order`, for :func:`banded_solve`, on one BLAS thread; None where the band would
    hold more than ``max_entries`` numbers or A is not positive definite."""
    with one_blas_thread():
        order = _band_order(A, always=True)
        if (order[2] + 1) * A.shape[0] > max_entries:
            return None
        return _band_factor(A, order, symmetric_part=False, dtype=np.float64)


def banded_solve(factor: tuple[np.ndarray, np.ndarray], b: np.ndarray) -> np.ndarray:
    """A^-1 b (b (n,) or (n, k)) from :func:`banded_cholesky`'s factor, on one BLAS thread."""
    with one_blas_thread():
        return _band_solve(factor, b)


def _band_order(A: Matrix, always: bool, places: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, int] | None:
    """(permutation, its inverse: the rank of each row, lower half-bandwidth) of the narrower of two orderings of
    A's symmetrised pattern: reverse Cuthill-McKee, and, where ``places`` (n, 2) says where each row's dof sits,
    the rows sorted along the principal axis of those places (:func:`ctmrpim.solvers.banded_lu.principal_axis_order`);
    None when the band is wider than BANDED_MAX_FRACTION of the rows and not ``always``."""
    n = A.shape[0]
    candidates = [reverse_cuthill_mckee(A.pattern(), symmetric_mode=True) if isinstance(A, SymmetricHalf)
                  else reverse_cuthill_mckee(A, symmetric_mode=True)]
    if places is not None:
        candidates.append(principal_axis_order(places))
    best = None
    for perm in candidates:
        rank = np.empty(n, np.int64)
        rank[perm] = np.arange(n)
        if _compiled(A):
            bw = int(free_block_kernels.lower_bandwidth(A.indptr, A.indices, rank))
        else:
            coo = A.tocoo()
            bw = int(np.abs(rank[coo.row] - rank[coo.col]).max()) if A.nnz else 0
        if best is None or bw < best[2]:
            best = (perm, rank, bw)
    return None if not always and best[2] > BANDED_MAX_FRACTION * n else best


def _band_factor(A: Matrix, order: tuple[np.ndarray, np.ndarray, int], symmetric_part: bool,
                 dtype: type) -> tuple[np.ndarray, np.ndarray] | None:
    """(permutation, lower banded Cholesky factor in ``dtype``) of a symmetric A, or of (A + A^T) / 2 with
    ``symmetric_part``, in the ordering ``order`` (:func:`_band_order`); None when it is not positive definite
    (in that precision). The band of a large A is filled straight from its arrays (no permuted copies of A, no
    A^T; chosen by size, as the symmetric part's sums may differ from scipy's by round-off) and factorised in
    place."""
    perm, rank, bw = order
    n = A.shape[0]
    ab = np.zeros((bw + 1, n), dtype=dtype, order="F")   # LAPACK's layout: factorised in place, not copied
    if _compiled(A):
        free_block_kernels.fill_lower_band(A.indptr, A.indices, A.data, rank, ab, symmetric_part,
                                          isinstance(A, SymmetricHalf))
    else:
        Ap = ((A + A.T) * 0.5 if symmetric_part else A)[perm][:, perm].tocoo()
        lower = Ap.row >= Ap.col
        ab[Ap.row[lower] - Ap.col[lower], Ap.col[lower]] = Ap.data[lower]
    try:
        return perm, sla.cholesky_banded(ab, lower=True, overwrite_ab=True, check_finite=False)
    except np.linalg.LinAlgError:
        return None


def _compiled(A: Matrix) -> bool:
    """Whether the band's ordering and fill take the compiled path: by size, as :func:`_free_block` (which makes a
    SymmetricHalf on that path only)."""
    return isinstance(A, SymmetricHalf) or rpim_kernels.use_compiled(A.nnz, assembly.COMPILED_MIN_ENTRIES)


def _band_solve(factor: tuple[np.ndarray, np.ndarray], b: np.ndarray) -> np.ndarray:
    """A^-1 b from :func:`_band_factor`'s (permutation, factor)."""
    perm, cb = factor
    x = np.empty_like(b, dtype=float)
    if cb.dtype == np.float32:   # cho_solve_banded would take the common type: a double copy of the band
        # scaled to unit size: the refinements' residuals shrink by 1e-6 each and would leave single precision's
        # range for loads in small units
        scale = float(np.abs(b).max())
        if scale == 0.0:
            return np.zeros_like(b, dtype=float)
        y, _info = lapack.spbtrs(cb, (b[perm] / scale).astype(np.float32), lower=1)
        x[perm] = y
        x *= scale      # in double precision (a Python float times a float32 array stays float32)
    else:
        x[perm] = sla.cho_solve_banded((cb, True), b[perm], check_finite=False)
    return x
