"""The optional linear solvers (``method.solver = "pardiso"`` and ``"amg"``): the answer of the direct default on
symmetric and non-symmetric systems, a singular system or one the iteration cannot solve refused in one line,
a missing package named with how to install it, and ``auto``'s choice of PARDISO on wide-band systems only."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from ctmrpim.errors import ProblemError
from ctmrpim.solvers import linear_solver as ls


def _elastic_block(n: int, skew: float = 0.0) -> tuple[sp.csr_matrix, np.ndarray, np.ndarray]:
    """A 2D five-point Laplacian per displacement component on an n x n square of nodes (both components coupled
    weakly), plus ``skew`` times a non-symmetric part; node positions for the rigid-body modes."""
    lap = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    eye = sp.identity(n)
    L2 = sp.kron(lap, eye) + sp.kron(eye, lap) + 1e-3 * sp.identity(n * n)
    K = sp.kron(L2, sp.identity(2)) + 0.1 * sp.kron(L2, np.array([[0.0, 1.0], [1.0, 0.0]]))
    if skew:
        K = K + skew * sp.kron(sp.diags([1.0, -1.0], [1, -1], shape=(n * n, n * n)), sp.identity(2))
    x, y = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    rhs = np.random.default_rng(1).normal(size=K.shape[0])
    return K.tocsr(), rhs, np.c_[x.ravel(), y.ravel()]


def _needs(solver: str) -> None:
    if not ls.available(solver):
        pytest.skip(f"{ls.OPTIONAL[solver]} is not installed (pip install -e '.[solvers]'; CI installs it)")


@pytest.mark.parametrize("solver", ["pardiso", "amg"])
@pytest.mark.parametrize("skew", [0.0, 0.05])
def test_optional_solver_gives_the_direct_answer(solver: str, skew: float) -> None:
    _needs(solver)
    K, rhs, nodes = _elastic_block(24, skew)
    free = np.arange(K.shape[0])
    U = ls.solve_free(K, rhs, np.zeros(K.shape[0]), free, solver, symmetric=not skew, nodes=nodes)
    reference = ls.solve_free(K, rhs, np.zeros(K.shape[0]), free, "superlu", symmetric=not skew)
    assert np.linalg.norm(U - reference) <= 1e-9 * np.linalg.norm(reference)
    assert np.linalg.norm(K @ U - rhs) <= 1e-10 * np.linalg.norm(rhs)


def test_pardiso_refuses_a_singular_system() -> None:
    _needs("pardiso")
    K, rhs, _ = _elastic_block(8)
    K = K.tolil()
    K[:, 5] = 0.0
    K[5, :] = 0.0
    K = K.tocsr()
    K.eliminate_zeros()
    with pytest.raises(ProblemError, match="singular"):
        ls.solve_free(K, rhs, np.zeros(K.shape[0]), np.arange(K.shape[0]), "pardiso", symmetric=False)


def test_amg_that_does_not_converge_is_refused_not_returned(monkeypatch) -> None:
    _needs("amg")
    monkeypatch.setattr(ls, "ITERATIVE_MAXITER", 2)
    K, rhs, nodes = _elastic_block(24)
    with pytest.raises(ProblemError, match="amg.*relative residual"):
        ls.solve_free(K, rhs, np.zeros(K.shape[0]), np.arange(K.shape[0]), "amg", nodes=nodes)


def test_a_missing_package_is_named_with_its_install_command(monkeypatch) -> None:
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "pypardiso" else real(name, *a))
    K, rhs, _ = _elastic_block(4)
    with pytest.raises(ProblemError, match=r"pypardiso: pip install 'ctmrpim\[solvers\]'"):
        ls.solve_free(K, rhs, np.zeros(K.shape[0]), np.arange(K.shape[0]), "pardiso")


@pytest.mark.parametrize("wide", [True, False])
def test_auto_takes_pardiso_on_wide_bands_above_its_size_only(monkeypatch, wide: bool) -> None:
    _needs("pardiso")
    calls = []
    real = ls._pardiso
    monkeypatch.setattr(ls, "_pardiso", lambda *a: calls.append(1) or real(*a))
    monkeypatch.setattr(ls, "BANDED_MAX_FRACTION", 0.0 if wide else 1.0)   # every band too wide, or none
    K, rhs, _ = _elastic_block(12)
    free = np.arange(K.shape[0])
    monkeypatch.setattr(ls, "PARDISO_MIN_DOFS", K.shape[0] + 1)
    ls.solve_free(K, rhs, np.zeros(K.shape[0]), free, "auto")
    assert not calls                                        # below the size: SuperLU or the band
    monkeypatch.setattr(ls, "PARDISO_MIN_DOFS", K.shape[0])
    ls.solve_free(K, rhs, np.zeros(K.shape[0]), free, "auto")
    assert calls == ([1] if wide else [])
