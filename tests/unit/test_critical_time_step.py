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
