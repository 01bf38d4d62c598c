"""The re-check of a non-converged increment (issue 19, item 2): non-convergence is a symptom, so an iteration that
still makes progress is given the time it needs, and one whose residual stalls is not waited for."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ctmrpim.problem.settings import Loading
from ctmrpim.solvers.load_stepping import RECHECK_LIMIT, step_loads


def _run(kappa: float, recheck: bool = True):
    """One dof with f_int = u under f_ext = t, iterated with the 'stiffness' kappa: the error contracts by
    1 - 1 / kappa per iteration (a linear rate, as the elastic-stiffness iteration's near a limit)."""
    K = sp.csr_matrix([[kappa]])
    loading = Loading(steps=1, tolerance=1e-6, max_iterations=100, max_cutbacks=0)
    return step_loads(1, loading, np.array([], int), np.array([]),
                      lambda U, t: (np.array([t]), U.copy(), K), lambda K, r: r / K[0, 0],
                      lambda t, U: {}, stop_on_failure=True, recheck=recheck)


def test_a_slow_but_steady_iteration_converges_on_the_recheck() -> None:
    """Contraction 0.98 per iteration needs about 680 iterations: more than twice the cap of 100, within the
    re-check's limit; the increment is carried and the history says it converged only on the re-check."""
    path = _run(50.0)
    assert path.failed_at is None and np.isclose(path.U[0], 1.0, rtol=1e-5)
    assert "converged only on the re-check" in path.history[-1]["note"]
    assert 2 * 100 < path.history[-1]["iterations"] <= RECHECK_LIMIT * 100
    assert _run(50.0, recheck=False).failed_at == 1.0   # without the re-check the cap alone decides


def test_a_failing_iteration_fails_after_the_recheck() -> None:
    """An iteration that cannot converge within the re-check's limit (contraction 1 - 1e-5 per iteration) fails
    the increment after RECHECK_LIMIT x max_iterations, and the history says so."""
    path = _run(1e5)
    assert path.failed_at == 1.0
    last = path.history[-1]
    assert f"no convergence with {RECHECK_LIMIT} x max_iterations" in last["note"]
    assert last["iterations"] == RECHECK_LIMIT * 100
