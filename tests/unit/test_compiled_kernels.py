"""The compiled linear-path kernels (issue 20) against independent dense forms: the RPIM moment systems solved
point by point with LAPACK, the stiffness summed point by point as B~^T D B, the corrected test gradients
against the integration constraints they must make hold; the numpy paths that small problems take against
them; and the memory they hold. Every test here takes the compiled path (thresholds set to zero) unless it
says otherwise."""
from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
import scipy.sparse as sp
from clouds import cloud

from ctmrpim.discretisation import assembly, rpim
from ctmrpim.discretisation.consistent_integration import boundary_quadrature, corrected_gradients
from ctmrpim.discretisation.rpim import shape_functions
from studies.tolerances import entry

ROUNDOFF = entry("roundoff")["max"]


@pytest.fixture(autouse=True)
def compiled(monkeypatch):
    monkeypatch.setattr(rpim, "COMPILED_MIN_POINTS", 0)
    monkeypatch.setattr(assembly, "COMPILED_MIN_ENTRIES", 0)


def _numpy_paths(monkeypatch):
    """Force the numpy paths, as in a small run."""
    monkeypatch.setattr(rpim, "COMPILED_MIN_POINTS", 10**12)
    monkeypatch.setattr(assembly, "COMPILED_MIN_ENTRIES", 10**12)
    monkeypatch.setattr("ctmrpim.discretisation.rpim_kernels.numba_ready", lambda: False)


@pytest.fixture(scope="module")
def jittered():
    geometry, nodes, d_c = cloud("plate-with-hole", jitter=0.3, seed=4)
    rng = np.random.default_rng(5)
    x0, y0, x1, y1 = geometry.bounds
    pts = np.c_[rng.uniform(x0, x1, 300), rng.uniform(y0, y1, 300)]
    return nodes, pts[geometry.distance_outside(pts) == 0], d_c


def _dense_rpim(nodes, x, support, eta, m, d_c):
    """phi, dphi/dx, dphi/dy of Eq. (33) at x by numpy's dense solve of Eq. (32), in global coordinates."""
    X = nodes[support]
    r = np.linalg.norm(X[:, None] - X[None], axis=-1)
    P = np.c_[np.ones(len(X)), X, *(() if m == 3 else (X[:, 0] ** 2, X[:, 0] * X[:, 1], X[:, 1] ** 2))]
    G = np.block([[r ** eta, P], [P.T, np.zeros((m, m))]])
    d = X - x
    q = np.linalg.norm(d, axis=1)
    px, py = x
    p = [1, px, py, px * px, px * py, py * py][:m]
    dpx = [0, 1, 0, 2 * px, py, 0][:m]
    dpy = [0, 0, 1, 0, px, 2 * py][:m]
    rhs = np.c_[np.r_[q ** eta, p], np.r_[-eta * q ** (eta - 2) * d[:, 0], dpx],
                np.r_[-eta * q ** (eta - 2) * d[:, 1], dpy]]
    return np.linalg.solve(G, rhs)[:len(X)].T


@pytest.mark.parametrize("m", [3, 6])
def test_shape_functions_match_a_dense_solve_per_point(jittered, m: int) -> None:
    nodes, pts, d_c = jittered
    sf = shape_functions(nodes, pts, 4 * d_c, 5.0, m, d_c)
    for i in range(0, len(pts), 7):
        support = sf.N.indices[sf.N.indptr[i]:sf.N.indptr[i + 1]]
        assert np.all(np.diff(support) > 0)                        # increasing node order
        inside = np.flatnonzero(np.linalg.norm(nodes - pts[i], axis=1) <= 4 * d_c)
        assert np.array_equal(support, inside)
        phi, dx, dy = _dense_rpim(nodes, pts[i], support, 5.0, m, d_c)
        # the dense solve in global coordinates is the worse conditioned one: 1e3 x round-off
        assert np.abs(sf.N.getrow(i).data - phi).max() <= 1e3 * ROUNDOFF
        assert np.abs(sf.dNdx.getrow(i).data - dx).max() <= 1e3 * ROUNDOFF / d_c
        assert np.abs(sf.dNdy.getrow(i).data - dy).max() <= 1e3 * ROUNDOFF / d_c


def test_shape_functions_on_more_points_than_one_block(jittered) -> None:
    """Blocks on the thread pool write disjoint rows: the same rows as one point at a time."""
    from ctmrpim.discretisation import rpim
    nodes, _, d_c = jittered
    rng = np.random.default_rng(8)
    pts = nodes[rng.integers(0, len(nodes), rpim.BLOCK + 500)] + rng.uniform(-0.3, 0.3, (rpim.BLOCK + 500, 2)) * d_c
    pts = pts[cloud("plate-with-hole")[0].distance_outside(pts) == 0]
    full = shape_functions(nodes, pts, 4 * d_c, 5.0, 3, d_c)
    part = shape_functions(nodes, pts[-300:], 4 * d_c, 5.0, 3, d_c)
    assert np.array_equal(full.dNdx[-300:].toarray(), part.dNdx.toarray())


def _dense_stiffness(dNdx, dNdy, w, D, tdx, tdy):
    n = dNdx.shape[1]
    K = np.zeros((2 * n, 2 * n))
    for p in range(dNdx.shape[0]):
        B = np.zeros((3, 2 * n))
        Bt = np.zeros((3, 2 * n))
        for M, (bx, by) in ((B, (dNdx, dNdy)), (Bt, (tdx, tdy))):
            gx, gy = bx.getrow(p).toarray()[0], by.getrow(p).toarray()[0]
            M[0, 0::2], M[1, 1::2], M[2, 0::2], M[2, 1::2] = gx, gy, gy, gx
        K += w[p] * Bt.T @ D @ B
    return K


@pytest.mark.parametrize("general", [False, True], ids=["isotropic-symmetric", "general-D-petrov-galerkin"])
def test_stiffness_matches_a_dense_sum_over_points(general: bool) -> None:
    _, nodes, d_c = cloud("rectangle")
    rng = np.random.default_rng(3)
    pts = np.c_[rng.uniform(0, 4, 120), rng.uniform(0, 1, 120)]
    sf = shape_functions(nodes, pts, 3 * d_c, 5.0, 3, d_c)
    w = rng.uniform(0.5, 1.5, len(pts))
    D = np.array([[3.0, 1.0, 0.0], [1.0, 3.0, 0.0], [0.0, 0.0, 1.0]])
    test = None
    if general:
        D = D + rng.uniform(-0.3, 0.3, (3, 3))
        test = tuple(sp.csr_matrix((M.data + rng.standard_normal(M.nnz), M.indices, M.indptr), shape=M.shape)
                     for M in (sf.dNdx, sf.dNdy))
    K = assembly.stiffness(sf.dNdx, sf.dNdy, w, D, test=test)
    ref = _dense_stiffness(sf.dNdx, sf.dNdy, w, D, *(test or (sf.dNdx, sf.dNdy)))
    assert K.has_sorted_indices and np.all(np.diff(K.indices[K.indptr[0]:K.indptr[1]]) > 0)
    assert np.abs(K.toarray() - ref).max() <= ROUNDOFF * np.abs(ref).max()


def test_projection_mass_matches_a_dense_sum_over_points_and_is_exactly_symmetric(jittered, monkeypatch) -> None:
    """M = sum_p w_p N_p^T N_p (the L2 projection's mass) on an irregular cloud around a hole: the compiled rows
    against a dense sum point by point, sorted columns, M - M^T exactly zero; the numpy path agrees to round-off."""
    nodes, pts, d_c = jittered
    sf = shape_functions(nodes, pts, 4 * d_c, 5.0, 3, d_c)
    w = np.random.default_rng(6).uniform(0.5, 1.5, len(pts))
    M = assembly.mass(sf.N, w)
    N = sf.N.toarray()
    ref = (N * w[:, None]).T @ N
    assert M.has_sorted_indices and all(np.all(np.diff(M.indices[a:b]) > 0) for a, b in zip(M.indptr, M.indptr[1:]))
    assert np.abs(M.toarray() - ref).max() <= ROUNDOFF * np.abs(ref).max()
    assert abs(M - M.T).max() == 0.0
    monkeypatch.setattr(assembly, "COMPILED_MIN_ENTRIES", 10**12)          # the small runs' scipy products
    assert np.abs(assembly.mass(sf.N, w).toarray() - M.toarray()).max() <= ROUNDOFF * np.abs(ref).max()


def test_subtract_in_place_on_the_pattern_or_as_a_new_matrix() -> None:
    K = sp.csr_matrix(np.array([[4.0, 1.0, 0.0], [1.0, 4.0, 1.0], [0.0, 1.0, 4.0]]))
    C = sp.csr_matrix(([0.5, 0.25], ([0, 1], [1, 2])), shape=(3, 3))
    expected = K.toarray() - C.toarray()
    out = assembly.subtract(K, C)
    assert out is K and np.array_equal(out.toarray(), expected)
    C2 = sp.csr_matrix(([0.5], ([0], [2])), shape=(3, 3))          # outside K's pattern
    expected = K.toarray() - C2.toarray()
    out = assembly.subtract(K, C2)
    assert out is not K and np.array_equal(out.toarray(), expected)


@pytest.mark.parametrize("order", ["linear", "quadratic"])
def test_corrected_gradients_meet_the_integration_constraints(order: str) -> None:
    """sum_p w_p (d~_k N_I q_a + N_I d_k q_a) = sum_b w_b N_I q_a n_k for every node I (q = 1 when linear)."""
    from ctmrpim.discretisation.alpha_shape import alpha_shape
    from ctmrpim.discretisation.ctm import integration_points
    geometry, nodes, d_c = cloud("plate-with-hole", jitter=0.2, seed=2)
    boundary = alpha_shape(nodes, 1.5, d_c, inside=geometry.contains)
    quad = integration_points(boundary.loop_coordinates(), d_c / 3, d_c / 3, 1, mode="uniform")
    sf = shape_functions(nodes, quad.points, 4 * d_c, 5.0, 3, d_c)
    bq = boundary_quadrature(nodes, boundary.edges)
    Nb = shape_functions(nodes, bq.points, 4 * d_c, 5.0, 3, d_c, derivatives=False).N
    tx, ty = corrected_gradients(nodes, d_c, quad.points, quad.weights, sf, bq, Nb, order)
    w = quad.weights
    qs = [lambda P: np.ones(len(P))]
    dq = [(0.0, 0.0)]
    if order == "quadratic":
        qs += [lambda P, i=0: P[:, i], lambda P, i=1: P[:, i]]      # q_a up to the per-node shift and 1 / d_c
        dq += [(1.0, 0.0), (0.0, 1.0)]
    for q, (dqx, dqy) in zip(qs, dq, strict=True):
        # with the shifted q_I = (x - x_I) / d_c the constraints are linear combinations of those with 1, x, y
        for k, (T, dk) in enumerate(((tx, dqx), (ty, dqy))):
            lhs = T.T @ (w * q(quad.points)) + sf.N.T @ (w * dk)
            rhs = Nb.T @ (bq.weights * q(bq.points) * bq.normals[:, k])
            assert np.abs(lhs - rhs).max() <= 1e3 * ROUNDOFF * max(np.abs(rhs).max(), 1.0)


@pytest.mark.parametrize("order", ["linear", "quadratic"])
def test_stiffness_from_the_correction_coefficients_is_that_of_the_corrected_arrays(order: str, monkeypatch) -> None:
    """K summed with the correction added entry by entry in the kernel (GradientCorrection) equals K from the
    corrected gradients as arrays, to round-off; on the numpy path the coefficients are applied first."""
    from ctmrpim.discretisation.alpha_shape import alpha_shape
    from ctmrpim.discretisation.ctm import integration_points
    from ctmrpim.discretisation.gradient_correction import GradientCorrection
    geometry, nodes, d_c = cloud("plate-with-hole", jitter=0.3, seed=7)
    boundary = alpha_shape(nodes, 1.5, d_c, inside=geometry.contains)
    quad = integration_points(boundary.loop_coordinates(), d_c / 3, d_c / 3, 1, mode="uniform")
    bq = boundary_quadrature(nodes, boundary.edges)
    sf = shape_functions(nodes, quad.points, 4 * d_c, 5.0, 3, d_c)
    Nb = shape_functions(nodes, bq.points, 4 * d_c, 5.0, 3, d_c, derivatives=False).N
    D = np.array([[3.0, 1.2, 0.1], [0.9, 2.5, -0.2], [0.05, 0.1, 1.0]])     # general D: every term of the kernel
    correction = corrected_gradients(nodes, d_c, quad.points, quad.weights, sf, bq, Nb, order, as_correction=True)
    assert isinstance(correction, GradientCorrection)
    arrays = corrected_gradients(nodes, d_c, quad.points, quad.weights, sf, bq, Nb, order)
    K_arrays = assembly.stiffness(sf.dNdx, sf.dNdy, quad.weights, D, test=arrays)
    K_coefficients = assembly.stiffness(sf.dNdx, sf.dNdy, quad.weights, D, test=correction)
    assert abs(K_arrays - K_coefficients).max() <= ROUNDOFF * abs(K_arrays).max()
    assert abs(K_arrays - assembly.stiffness(sf.dNdx, sf.dNdy, quad.weights, D)).max() > 1e-3 * abs(K_arrays).max()
    _numpy_paths(monkeypatch)
    K_numpy = assembly.stiffness(sf.dNdx, sf.dNdy, quad.weights, D, test=correction)
    assert abs(K_arrays - K_numpy).max() <= ROUNDOFF * abs(K_arrays).max()


def test_shape_function_memory_is_the_result_plus_a_little(jittered) -> None:
    """Nothing of size points x support x support: the traced peak stays within twice the CSR rows' size."""
    nodes, _, d_c = jittered
    rng = np.random.default_rng(6)
    pts = nodes[rng.integers(0, len(nodes), 6000)] + rng.uniform(-0.2, 0.2, (6000, 2)) * d_c
    pts = pts[cloud("plate-with-hole")[0].distance_outside(pts) == 0]
    shape_functions(nodes, pts[:10], 4 * d_c, 5.0, 3, d_c)      # kernels loaded
    tracemalloc.start()
    sf = shape_functions(nodes, pts, 4 * d_c, 5.0, 3, d_c)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    result = sf.N.nnz * (3 * 8 + sf.N.indices.itemsize)
    assert peak <= 2 * result


def test_numpy_paths_give_the_compiled_results(jittered, monkeypatch) -> None:
    """Shape functions, corrected gradients and stiffness of both paths agree to round-off."""
    from ctmrpim.discretisation.alpha_shape import alpha_shape
    from ctmrpim.discretisation.ctm import integration_points
    geometry, nodes, d_c = cloud("plate-with-hole", jitter=0.3, seed=4)
    boundary = alpha_shape(nodes, 1.5, d_c, inside=geometry.contains)
    quad = integration_points(boundary.loop_coordinates(), d_c / 3, d_c / 3, 1, mode="uniform")
    bq = boundary_quadrature(nodes, boundary.edges)
    D = np.array([[3.0, 1.0, 0.0], [1.0, 3.0, 0.0], [0.0, 0.0, 1.0]])

    def run():
        sf = shape_functions(nodes, quad.points, 4 * d_c, 5.0, 3, d_c)
        Nb = shape_functions(nodes, bq.points, 4 * d_c, 5.0, 3, d_c, derivatives=False).N
        test = corrected_gradients(nodes, d_c, quad.points, quad.weights, sf, bq, Nb, "quadratic")
        return sf, test, assembly.stiffness(sf.dNdx, sf.dNdy, quad.weights, D, test=test)

    sf1, t1, K1 = run()
    _numpy_paths(monkeypatch)
    sf0, t0, K0 = run()
    assert not sf0.N.has_sorted_indices or not np.array_equal(sf0.N.indices, sf1.N.indices)  # really the other path
    for a, b, scale in ((sf0.N, sf1.N, 1.0), (sf0.dNdx, sf1.dNdx, 1 / d_c), (t0[0], t1[0], 1 / d_c),
                        (t0[1], t1[1], 1 / d_c)):
        assert abs(a - b).max() <= ROUNDOFF * scale
    assert abs(K0 - K1).max() <= ROUNDOFF * abs(K0).max()


@pytest.mark.parametrize("solver", ["superlu", "banded"])
def test_constrained_solve_builds_the_free_block_in_one_pass(monkeypatch, solver: str) -> None:
    """The compiled free-free block (CSR) and right-hand side give scipy's slicing's solution."""
    from ctmrpim.solvers import linear_solver
    rng = np.random.default_rng(0)
    n = 80
    A = sp.random(n, n, density=0.15, random_state=1, format="csr")
    A = (A + A.T + 10 * sp.identity(n)).tocsr()      # symmetric positive definite: both solvers apply
    A.sort_indices()
    F, fixed, values = rng.random(n), np.array([0, 5, 7, 30, 79]), rng.random(5)
    monkeypatch.setattr("ctmrpim.discretisation.rpim_kernels.numba_ready", lambda: True)
    U1 = linear_solver.solve_constrained(A, F, fixed, values, solver)
    _numpy_paths(monkeypatch)
    U0 = linear_solver.solve_constrained(A, F, fixed, values, solver)
    assert np.array_equal(U1[fixed], values)
    free = np.setdiff1d(np.arange(n), fixed)
    assert np.abs((A @ U1 - F)[free]).max() <= ROUNDOFF * np.abs(F).max()
    assert np.abs(U1 - U0).max() <= ROUNDOFF * np.abs(U0).max()


def test_non_symmetric_solve_by_gmres_on_the_symmetric_part_matches_superlu(monkeypatch) -> None:
    """A non-symmetric K near a symmetric positive definite one: GMRES preconditioned by the banded Cholesky of
    its symmetric part gives SuperLU's solution to round-off, on both ways of filling the band."""
    from ctmrpim.solvers import linear_solver
    rng = np.random.default_rng(2)
    n = 120
    B = sp.random(n, n, density=0.05, random_state=3, format="csr")
    S = (B + B.T + 8 * sp.identity(n)).tocsr()
    skew = sp.random(n, n, density=0.05, random_state=4, format="csr") * 0.2
    A = (S + skew - skew.T * 0.5).tocsr()
    A.sort_indices()
    F, fixed, values = rng.random(n), np.array([1, 9, 50]), rng.random(3)
    calls = []
    original = linear_solver._banded
    monkeypatch.setattr(linear_solver, "_banded", lambda *a: calls.append(x := original(*a)) or x)
    ref = linear_solver.solve_constrained(A, F, fixed, values, "superlu", symmetric=False)
    for numpy_path in (False, True):
        if numpy_path:
            _numpy_paths(monkeypatch)
        U = linear_solver.solve_constrained(A, F, fixed, values, "banded", symmetric=False)
        assert calls[-1] is not None                                  # GMRES, not the fallback
        assert np.abs(U - ref).max() <= 1e3 * ROUNDOFF * np.abs(ref).max()


def test_product_by_blocks_of_rows_is_scipys_bit_for_bit() -> None:
    """The compiled product of the Krylov solves (blocks of rows of about equal entries, on the threads) gives
    scipy's sums exactly, on rows of very unequal length, empty ones at both ends included."""
    from ctmrpim.solvers import linear_solver
    rng = np.random.default_rng(8)
    n = 300
    A = sp.random(n, n, density=0.05, random_state=9, format="lil")
    A[:40, :] = rng.random((40, n))                      # long rows first: the blocks split by entries, not rows
    A[0, :] = 0.0
    A[n - 1, :] = 0.0
    A = A.tocsr()
    A.eliminate_zeros()
    x = rng.standard_normal(n)
    op = linear_solver._product(A)
    assert op is not A
    assert np.array_equal(op @ x, A @ x)


def test_band_of_the_symmetric_part_is_filled_from_the_matrix_itself() -> None:
    """fill_lower_band with average: the band of (A + A^T) / 2, diagonal included, without forming A^T."""
    from ctmrpim.solvers import free_block_kernels
    A = sp.random(40, 40, density=0.2, random_state=5, format="csc") + sp.identity(40, format="csc")
    A = (A + sp.random(40, 40, density=0.2, random_state=6, format="csc")).tocsc()
    A = A + abs(A.T) * 0                                              # a structurally symmetric pattern
    rank = np.random.default_rng(7).permutation(40)
    S = ((A + A.T) * 0.5).tocsr()
    bw = int(free_block_kernels.lower_bandwidth(A.indptr, A.indices, rank))
    band, ref = np.zeros((bw + 1, 40)), np.zeros((bw + 1, 40))
    free_block_kernels.fill_lower_band(A.indptr, A.indices, A.data, rank, band, True, False)
    free_block_kernels.fill_lower_band(S.indptr, S.indices, S.data, rank, ref, False, False)
    assert np.abs(band - ref).max() <= ROUNDOFF * np.abs(ref).max()


@pytest.mark.parametrize("order", [1, 2])
def test_stress_recovery_of_both_paths_agrees_and_reproduces_its_polynomials(order: int, monkeypatch) -> None:
    """The compiled recovery operator (many integration points) equals the numpy one to round-off, on a jittered
    holed cloud whose boundary points have one-sided fits; both recover a field of the fit's order exactly."""
    from ctmrpim.discretisation import stress_recovery
    from ctmrpim.discretisation.alpha_shape import alpha_shape
    from ctmrpim.discretisation.ctm import integration_points
    geometry, nodes, d_c = cloud("plate-with-hole", jitter=0.3, seed=4)
    boundary = alpha_shape(nodes, 1.5, d_c, inside=geometry.contains)
    quad = integration_points(boundary.loop_coordinates(), d_c / 3, d_c / 3, 1, mode="uniform")
    monkeypatch.setattr(stress_recovery, "COMPILED_MIN_POINTS", 0)
    R1 = stress_recovery.recovery_operator(nodes, quad.points, quad.weights, d_c, order=order)
    monkeypatch.setattr(stress_recovery, "COMPILED_MIN_POINTS", 10**12)
    R0 = stress_recovery.recovery_operator(nodes, quad.points, quad.weights, d_c, order=order)
    assert R1.nnz == R0.nnz
    assert abs(R1 - R0).max() <= ROUNDOFF
    x, y = quad.points.T
    field = 3.0 + 2.0 * x - 5.0 * y + (0.7 * x * x - 1.1 * x * y + 0.4 * y * y if order == 2 else 0.0)
    X, Y = nodes.T
    exact = 3.0 + 2.0 * X - 5.0 * Y + (0.7 * X * X - 1.1 * X * Y + 0.4 * Y * Y if order == 2 else 0.0)
    for R in (R0, R1):
        assert np.abs(R @ field - exact).max() <= 1e3 * ROUNDOFF * np.abs(exact).max()


def test_symmetric_free_block_is_held_by_its_upper_triangle() -> None:
    """The free block of a symmetric K as its upper triangle (SymmetricHalf): the whole block and right-hand side
    of the CSC pass exactly, its products to round-off, its band as the whole block's, and every solver's
    solution from it that of the whole block."""
    from ctmrpim.solvers import free_block_kernels, linear_solver
    from ctmrpim.solvers.symmetric_half import SymmetricHalf
    rng = np.random.default_rng(8)
    n = 90
    A = sp.random(n, n, density=0.12, random_state=9, format="csr")
    A = (A + A.T + 12 * sp.identity(n)).tocsr()
    A.sort_indices()
    F, fixed, values = rng.random(n), np.array([2, 3, 40, 89]), rng.random(4)
    U = np.zeros(n)
    U[fixed] = values
    free = np.setdiff1d(np.arange(n), fixed)
    whole, rhs = linear_solver._free_block(A, F, free, U)
    half, rhs_half = linear_solver._free_block(A, F, free, U, half=True)
    assert isinstance(half, SymmetricHalf) and half.nnz == whole.nnz
    assert np.array_equal(rhs_half, rhs)
    assert np.array_equal(half.full().toarray(), whole.toarray())
    assert np.array_equal(half.pattern().toarray() != 0, whole.toarray() != 0)
    x = rng.random(len(free))
    assert np.abs(half @ x - whole @ x).max() <= ROUNDOFF * np.abs(whole @ x).max()
    rank = rng.permutation(len(free))
    bw = int(free_block_kernels.lower_bandwidth(whole.indptr, whole.indices, rank))
    assert int(free_block_kernels.lower_bandwidth(half.indptr, half.indices, rank)) == bw
    band, ref = np.zeros((bw + 1, len(free))), np.zeros((bw + 1, len(free)))
    free_block_kernels.fill_lower_band(half.indptr, half.indices, half.data, rank, band, False, True)
    free_block_kernels.fill_lower_band(whole.indptr, whole.indices, whole.data, rank, ref, False, False)
    assert np.array_equal(band, ref)
    solvers = ["auto", "banded", "superlu", "spsolve"] + [s for s in linear_solver.OPTIONAL if linear_solver.available(s)]
    for solver in solvers:
        ref_u = linear_solver.solve_free(whole, rhs, U.copy(), free, solver)
        u = linear_solver.solve_free(half, rhs, U.copy(), free, solver)
        assert np.abs(u - ref_u).max() <= 1e3 * ROUNDOFF * np.abs(ref_u).max(), solver
    with pytest.raises(ValueError, match="symmetric"):
        linear_solver.solve_free(half, rhs, U.copy(), free, "auto", symmetric=False)


def test_ctm_cantilever_solved_from_the_upper_triangle_is_that_of_the_whole_block(monkeypatch) -> None:
    """The paper's ``ctm`` scheme (symmetric K) on the cantilever: the same displacements, to round-off, whether
    the free block is held whole or by its upper triangle (both solves reach the banded path's residual)."""
    from ctmrpim import benchmarks
    from ctmrpim.solvers import linear_solver, linear_static
    from ctmrpim.solvers.symmetric_half import SymmetricHalf
    case = benchmarks.load("cantilever", ["nodes.grid=[25, 7]", 'method.integration="ctm"'])
    built = []
    original = linear_solver._free_block
    monkeypatch.setattr(linear_solver, "_free_block", lambda *a: built.append(r := original(*a)) or r)
    half = linear_static.solve_ctmrpim(case)
    monkeypatch.setattr(linear_static, "HALF_SOLVERS", ())
    whole = linear_static.solve_ctmrpim(case)
    assert isinstance(built[0][0], SymmetricHalf) and not isinstance(built[1][0], SymmetricHalf)
    scale = np.abs(whole.u).max()
    assert np.abs(half.u - whole.u).max() <= ROUNDOFF * scale      # measured 1.7e-13
