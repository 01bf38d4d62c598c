"""The explicit solver's stable time step: the LOBPCG estimate of the highest frequency."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from clouds import QUICK_COLUMN as QUICK

from ctmrpim import benchmarks
from ctmrpim.solvers.explicit.run import ExplicitRun


def test_critical_time_step_bounds_the_wave_speed_step():
    """The estimated step is stable and of the order of d / c_p (RPIM is stiffer than linear FEM)."""
    case = benchmarks.load("column-collapse", QUICK)
    run = ExplicitRun(case, Path("unused"), "key")
    run.start()
    assert 0.2 * run.dt_wave < run.dt < 2.0 * run.dt_wave
    import scipy.sparse as sp
    from scipy.sparse.linalg import eigsh
    n = len(run.X)
    K = np.column_stack([run._stiffness(run.frame)(e.reshape(n, 2)).ravel() for e in np.eye(2 * n)])
    m = np.repeat(run.mass, 2)
    lam = eigsh(sp.csr_matrix(K / np.sqrt(m)[:, None] / np.sqrt(m)[None, :]), k=1, which="LA",
                return_eigenvectors=False)[0]
    assert run.omega == pytest.approx(np.sqrt(lam), rel=0.05)     # the estimate is close to omega_max
    assert run.omega <= np.sqrt(lam) * (1 + 1e-9)                 # and from below (a Rayleigh quotient)


@pytest.mark.parametrize("nodes", [20, 400])
def test_omega_max_is_the_largest_frequency_from_below_on_the_free_dofs(nodes):
    """omega_max of M^-1 K over the free dofs: exact on a small body (its matrix's eigenvalues), within 1e-3 from
    below on a larger one (LOBPCG, 30 steps from a random start), with the fixed dofs out of the mode."""
    from ctmrpim.solvers.explicit.time_step import DENSE_BELOW, ITERATIONS, omega_max
    rng = np.random.default_rng(3)
    n = nodes
    A = rng.normal(size=(2 * n, 2 * n))
    K = A @ A.T + np.diag(np.linspace(1.0, 50.0, 2 * n) ** 2)
    mass = rng.uniform(0.5, 2.0, n)
    free = np.ones((n, 2), bool)
    free[:3] = False
    dofs = np.flatnonzero(free.ravel())
    m = np.repeat(mass, 2)[dofs]
    exact = np.sqrt(np.linalg.eigvalsh(K[np.ix_(dofs, dofs)] / np.sqrt(m)[:, None] / np.sqrt(m)[None, :])[-1])
    omega, mode = omega_max(lambda d: (K @ d.ravel()).reshape(-1, 2), mass, rng.normal(size=(n, 2)), free,
                            ITERATIONS)
    assert (2 * n - 6 < DENSE_BELOW) == (nodes == 20)
    assert omega <= exact * (1 + 1e-12)
    assert omega == pytest.approx(exact, rel=1e-12 if nodes == 20 else 1e-3)
    assert np.all(mode[~free] == 0.0)
