"""The banded path of the linear solve in mixed precision: a single-precision Cholesky factor of the band
preconditions conjugate gradients (symmetric K) or GMRES (non-symmetric K) with iterative refinement on the
double-precision residual, and a system that single precision cannot factorise or precondition falls back to the
double-precision factor."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ctmrpim.solvers import linear_solver


def _plate(n: int) -> sp.csr_matrix:
    """The 5-point Laplacian of an n x n grid with Dirichlet sides (symmetric positive definite, condition
    number about n^2), with its natural band."""
    T = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    return (sp.kron(sp.identity(n), T) + sp.kron(T, sp.identity(n))).tocsr() * 1e9   # a stiffness's magnitude


def _with_skew(A: sp.csr_matrix) -> sp.csr_matrix:
    """A plus a non-symmetric part of a few per cent, as the consistent schemes' K has."""
    skew = sp.triu(A, 1) * 0.03
    return (A + skew - skew.T).tocsr()


def _recording_factors(monkeypatch: pytest.MonkeyPatch) -> list:
    """The precision of every band factorised, and whether it was positive definite there."""
    seen = []
    original = linear_solver._band_factor

    def record(A, order, symmetric_part, dtype):
        factor = original(A, order, symmetric_part, dtype)
        seen.append((np.dtype(dtype), factor is not None))
        return factor
    monkeypatch.setattr(linear_solver, "_band_factor", record)
    return seen


@pytest.mark.parametrize("symmetric", [True, False])
def test_a_single_precision_band_preconditions_to_the_double_precision_residual(
        monkeypatch: pytest.MonkeyPatch, symmetric: bool) -> None:
    A = _plate(40) if symmetric else _with_skew(_plate(40))
    b = np.random.default_rng(1).standard_normal(A.shape[0])
    seen = _recording_factors(monkeypatch)
    x = linear_solver._solve(A.tocsc(), b, "banded", symmetric, lambda: None)
    assert seen == [(np.dtype(np.float32), True)]                    # one band, in single precision
    assert np.linalg.norm(A @ x - b) <= linear_solver.KRYLOV_RTOL * np.linalg.norm(b)
    ref = spla.spsolve(A.tocsc(), b)
    assert np.abs(x - ref).max() <= 1e-9 * np.abs(ref).max()


def test_a_system_single_precision_cannot_factorise_takes_the_double_precision_factor(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A free-floating chain held by springs 1e-8 of its own stiffness: positive definite with a condition number
    of 4e8, beyond single precision (its round-off times the condition number exceeds one), so the float32 factor
    does not bring the refinement to the residual; the answer is the double-precision factor's, equal to SuperLU's
    within double precision's round-off times the condition number."""
    n = 400
    T = sp.diags([-np.ones(n - 1), np.r_[1.0, 2 * np.ones(n - 2), 1.0], -np.ones(n - 1)], [-1, 0, 1]).tocsr()
    A = (T + 1e-8 * sp.identity(n)).tocsr() * 1e9
    b = np.random.default_rng(2).standard_normal(n)
    seen = _recording_factors(monkeypatch)
    x = linear_solver._solve(A.tocsc(), b, "banded", True, lambda: None)
    assert [dtype for dtype, _ in seen] == [np.float32, np.float64] and seen[-1][1]
    ref = spla.spsolve(A.tocsc(), b)
    assert np.abs(x - ref).max() <= 4e8 * np.finfo(float).eps * np.abs(ref).max()


@pytest.mark.parametrize("symmetric", [True, False])
def test_the_single_precision_path_is_linear_in_the_load_over_any_units(
        monkeypatch: pytest.MonkeyPatch, symmetric: bool) -> None:
    """Loads of 1e-30 or 1e+30 of the unit: the substitution works on the right-hand side scaled to unit size, so
    single precision's range is never left; the answer scales with the load to the residual tolerance."""
    A = (_plate(30) if symmetric else _with_skew(_plate(30))).tocsc()
    b = np.random.default_rng(3).standard_normal(A.shape[0])
    seen = _recording_factors(monkeypatch)
    x = linear_solver._solve(A, b, "banded", symmetric, lambda: None)
    for scale in (1e-30, 1e30):
        xs = linear_solver._solve(A, scale * b, "banded", symmetric, lambda: None)
        assert np.abs(xs / scale - x).max() <= 1e-9 * np.abs(x).max()
    assert all(dtype == np.float32 for dtype, _ in seen)          # never the double-precision fallback
