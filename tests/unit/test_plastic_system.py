"""Pieces of the method-agnostic plastic system: Anderson mixing, block rows of the gradient operator, the
finite-element gradient operator, and the safeguarded step where a consistent tangent is singular."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ctmrpim import benchmarks
from ctmrpim.solvers.elastoplastic import ctm_plastic_system
from ctmrpim.solvers.load_stepping import Anderson
from ctmrpim.solvers.plastic_system import block_rows
from ctmrpim.timing import Timer


def test_anderson_solves_a_linear_fixed_point_in_n_plus_one_steps() -> None:
    """For x -> x + P^-1 (b - A x) Anderson with full depth is GMRES: exact after n + 1 steps."""
    rng = np.random.default_rng(0)
    n = 6
    A = np.eye(n) * 3 + rng.normal(scale=0.5, size=(n, n))
    P = np.diag(np.diag(A))
    b = rng.normal(size=n)
    x, mixer = np.zeros(n), Anderson(n)
    for _ in range(n + 1):
        x = x + mixer.step(x, np.linalg.solve(P, b - A @ x), P)
    assert np.linalg.norm(A @ x - b) < 1e-9 * np.linalg.norm(b)


def test_block_rows_match_a_row_slice() -> None:
    case = benchmarks.load("slope", ["parameters.h=2.5"])
    system = ctm_plastic_system(case, Timer())[0]
    points = np.array([0, 5, 17, 3])
    rows = (4 * points[:, None] + np.arange(4)).ravel()
    assert abs(block_rows(system.G, points) - sp.csr_matrix(system.G)[rows]).max() == 0


def test_fem_gradient_operator_is_exact_for_a_linear_field() -> None:
    from skfem import Basis, ElementTriP2, ElementVector, MeshTri

    from reference_fem.elastoplastic import gradient_operator
    basis = Basis(MeshTri().refined(2), ElementVector(ElementTriP2()), intorder=2)
    x = basis.doflocs
    U = np.where(np.arange(basis.N) % 2 == 0, 2 * x[0] + 3 * x[1], -x[0] + 5 * x[1])
    grad = (gradient_operator(basis) @ U).reshape(-1, 4)
    assert np.allclose(grad, [2, 3, -1, 5], atol=1e-12)


def test_a_singular_tangent_gives_the_elastic_step() -> None:
    """A tangent SuperLU finds exactly singular (all of it plastic at the apex: D_ep = 0) is replaced for that
    iteration by the elastic stiffness, and counted; the tangent's own factors are used where it is regular."""
    system = ctm_plastic_system(benchmarks.load("slope", ["parameters.h=2.5"]), Timer())[0]
    K_elastic = system.elastic_stiffness()
    r = np.random.default_rng(0).normal(size=K_elastic.shape[0])
    r[system.fixed] = 0.0
    du = system.solve(sp.csr_matrix(K_elastic.shape), r)
    assert system.safeguarded_steps == 1
    assert np.allclose((K_elastic @ du)[system.free], r[system.free]) and not du[system.fixed].any()
    twice = (2.0 * K_elastic).tocsr()
    assert np.allclose(system.solve(twice, r), 0.5 * du) and system.safeguarded_steps == 1


def test_a_tangent_with_a_zero_column_never_reaches_superlu() -> None:
    """One free dof without stiffness (its column zero, its row not: a non-associated apex return) is refused
    before SuperLU, whose pivoting crashes now and then on such a column (scipy 1.11), and the step is the
    elastic one."""
    system = ctm_plastic_system(benchmarks.load("slope", ["parameters.h=2.5"]), Timer())[0]
    K_elastic = system.elastic_stiffness()
    dof = system.free[len(system.free) // 2]
    keep = sp.diags((np.arange(K_elastic.shape[0]) != dof).astype(float))
    K = (K_elastic @ keep).tocsr()
    r = np.random.default_rng(1).normal(size=K.shape[0])
    r[system.fixed] = 0.0
    du = system.solve(K, r)
    assert system.safeguarded_steps == 1
    assert np.allclose((K_elastic @ du)[system.free], r[system.free])
