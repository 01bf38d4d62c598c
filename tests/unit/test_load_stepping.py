"""The re-check of a non-converged increment (issue 19, item 2): non-convergence is a symptom, so an iteration that
still makes progress is given the time it needs, an iteration on a fixed matrix is checked by Newton, and a body
without an equilibrium fails all the same."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ctmrpim.problem.settings import Loading
from ctmrpim.solvers.load_stepping import HAND_OVER_RISES, NEWTON_ITERATIONS, RECHECK_LIMIT, step_loads


def _run(kappa: float, recheck: bool = True, newton=None):
    """One dof with f_int = u under f_ext = t, iterated with the 'stiffness' kappa: the error contracts by
    1 - 1 / kappa per iteration (a linear rate, as the elastic-stiffness iteration's near a limit)."""
    K = sp.csr_matrix([[kappa]])
    loading = Loading(steps=1, tolerance=1e-6, max_iterations=100, max_cutbacks=0)
    return step_loads(1, loading, np.array([], int), np.array([]),
                      lambda U, t: (np.array([t]), U.copy(), K), lambda K, r: r / K[0, 0],
                      lambda t, U: {}, stop_on_failure=True, recheck=recheck, recheck_assemble=newton)


def _tanh_body(U, t):
    """f_int = tanh(u) under f_ext = 1.5 t, with its true tangent: no equilibrium at t = 1 (tanh < 1)."""
    return np.array([1.5 * t]), np.tanh(U), sp.csr_matrix([[1.0 / np.cosh(np.clip(U[0], -50, 50)) ** 2 + 1e-12]])


def _tanh_path(max_iterations: int):
    """The tanh body iterated with the fixed 'stiffness' 2, re-checked by Newton on its true tangent."""
    loading = Loading(steps=1, tolerance=1e-6, max_iterations=max_iterations, max_cutbacks=0)
    return step_loads(1, loading, np.array([], int), np.array([]),
                      lambda U, t: (np.array([1.5 * t]), np.tanh(U), sp.csr_matrix([[2.0]])),
                      lambda K, r: r / K[0, 0], lambda t, U: {}, stop_on_failure=True, recheck=True,
                      recheck_assemble=_tanh_body)


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
    assert f"no convergence on the re-check ({RECHECK_LIMIT * 100} iterations)" in last["note"]
    assert last["iterations"] == RECHECK_LIMIT * 100


def test_an_iteration_on_a_fixed_matrix_is_rechecked_by_newton() -> None:
    """The fixed 'stiffness' 1e5 cannot converge within the re-check's patience, but the equilibrium exists: Newton
    on the true tangent (1) finds it in two iterations, and the history says which iteration carried it."""
    exact = sp.csr_matrix([[1.0]])
    path = _run(1e5, newton=lambda U, t: (np.array([t]), U.copy(), exact))
    assert path.failed_at is None and np.isclose(path.U[0], 1.0, rtol=1e-9)
    last = path.history[-1]
    assert "Newton on the consistent tangent" in last["note"] and last["iterations"] <= 2


def test_newton_recheck_fails_a_body_without_equilibrium() -> None:
    """f_int = tanh(u) cannot carry f_ext = 1.5: Newton's re-check runs away (or reaches its cap) and the increment
    fails after at most RECHECK_LIMIT x NEWTON_ITERATIONS iterations."""
    path = _tanh_path(100)
    assert path.failed_at == 1.0
    assert path.history[-1]["iterations"] <= RECHECK_LIMIT * NEWTON_ITERATIONS
    assert "no convergence on the re-check (Newton" in path.history[-1]["note"]


def test_a_failed_recheck_keeps_the_fixed_matrix_iterate_as_the_failed_state() -> None:
    """Where Newton's re-check runs away (f_int = tanh u under 1.5: its iterates grow without bound), the failed
    level's state is the fixed-matrix iteration's last iterate, a bounded field, not Newton's runaway one."""
    path = _tanh_path(10)
    assert path.failed_at == 1.0
    # ten plain steps of (1.5 - tanh u) / 2 from u = 0 stay below 10 * 1.5 / 2
    assert np.isfinite(path.failed_trial[0]) and abs(path.failed_trial[0]) < 7.5


def test_a_non_converged_increment_is_handed_over_to_newton_before_a_cut_back() -> None:
    """With cut-backs left, an increment the fixed-matrix iteration does not converge goes to Newton from its last
    iterate first: where Newton converges, the increment is carried without a cut-back and the history says how;
    where it cannot (no equilibrium), the increment is cut back as before."""
    exact = sp.csr_matrix([[1.0]])
    loading = Loading(steps=1, tolerance=1e-6, max_iterations=100, max_cutbacks=2)
    path = step_loads(1, loading, np.array([], int), np.array([]),
                      lambda U, t: (np.array([t]), U.copy(), sp.csr_matrix([[1e5]])), lambda K, r: r / K[0, 0],
                      lambda t, U: {}, stop_on_failure=True, recheck=True,
                      recheck_assemble=lambda U, t: (np.array([t]), U.copy(), exact))
    assert path.failed_at is None and path.cutbacks == 0 and np.isclose(path.U[0], 1.0, rtol=1e-9)
    assert "converged by Newton on the consistent tangent" in path.history[-1]["note"]
    without = Loading(steps=1, tolerance=1e-6, max_iterations=10, max_cutbacks=2)
    failing = step_loads(1, without, np.array([], int), np.array([]),
                         lambda U, t: (np.array([1.5 * t]), np.tanh(U), sp.csr_matrix([[2.0]])),
                         lambda K, r: r / K[0, 0], lambda t, U: {}, stop_on_failure=True, recheck=True,
                         recheck_assemble=_tanh_body)
    assert failing.cutbacks == 2 and failing.failed_at is not None


def test_a_hand_over_whose_residual_keeps_rising_gives_up_early() -> None:
    """A hand-over's Newton whose residual rises HAND_OVER_RISES times in a row after its second iteration is out of
    the basin: the increment is cut back then, not after NEWTON_ITERATIONS. f_int = 0.4 tanh(u) under f_ext = 0.5 t
    with the 'tangent' -1: every step goes the wrong way, the residual rising in every iteration but by steps too
    short for the divergence test; the re-check of the last increment keeps its whole cap."""
    def body(U, t, K):
        return np.array([0.5 * t]), 0.4 * np.tanh(U), sp.csr_matrix([[K]])
    loading = Loading(steps=1, tolerance=1e-6, max_iterations=10, max_cutbacks=1)
    path = step_loads(1, loading, np.array([], int), np.array([]), lambda U, t: body(U, t, 1e5),
                      lambda K, r: r / K[0, 0], lambda t, U: {}, stop_on_failure=True, recheck=True,
                      recheck_assemble=lambda U, t: body(U, t, -1.0))
    first = path.history[0]
    assert not first["converged"] and "cut back" in first["note"]
    assert first["iterations"] == 2 + HAND_OVER_RISES < NEWTON_ITERATIONS
    assert path.failed_at is not None and path.history[-1]["iterations"] > 2 + HAND_OVER_RISES


def test_stop_ends_the_path_at_the_increment_it_names() -> None:
    """A linear body f_int = u under f_ext = t in ten increments, ``stop`` naming the fourth: the path ends there
    with the reason recorded, that increment carried (u = 0.4) and none after it; the last increment (t = 1) is
    never read, so a criterion met only there leaves the path whole."""
    loading = Loading(steps=10, tolerance=1e-10, max_iterations=10, max_cutbacks=0)
    K = sp.csr_matrix([[1.0]])

    def path(stop):
        return step_loads(1, loading, np.array([], int), np.array([]),
                          lambda U, t: (np.array([t]), U.copy(), K), lambda K, r: r / K[0, 0],
                          lambda t, U: {}, stop_on_failure=True, stop=stop)

    seen = []
    stopped = path(lambda t, U: seen.append(t) or ("runaway" if t > 0.35 else None))
    assert stopped.stopped == "runaway" and np.isclose(stopped.U[0], 0.4)
    assert np.allclose([h["load_factor"] for h in stopped.history], [0.1, 0.2, 0.3, 0.4])
    assert np.allclose(seen, [0.1, 0.2, 0.3, 0.4])
    whole = path(lambda t, U: "runaway" if t > 0.95 else None)
    assert whole.stopped is None and np.isclose(whole.U[0], 1.0) and len(whole.history) == 10


def test_an_increment_within_the_resolution_is_not_cut_back() -> None:
    """The tanh body (no equilibrium beyond t = 2/3) by Newton on its true tangent in four increments, eight
    cut-backs allowed: with ``resolution`` 0.1 an increment that fails is halved only while it is longer than 0.1,
    and the path ends at the first failing one of 0.0625 (three cut-backs, the history saying why), its bracket
    [last carried, failed] holding t = 2/3 and at most 0.1 wide; without it the eight cut-backs are all spent for a
    narrower bracket, the same increments carried up to the coarse path's failure."""
    loading = Loading(steps=4, tolerance=1e-8, max_iterations=30, max_cutbacks=8)

    def path(resolution):
        return step_loads(1, loading, np.array([], int), np.array([]), _tanh_body, lambda K, r: r / K[0, 0],
                          lambda t, U: {}, stop_on_failure=True, resolution=resolution)

    coarse, fine = path(0.1), path(0.0)
    assert (coarse.cutbacks, fine.cutbacks) == (3, 8)
    for p in (coarse, fine):
        carried = max(h["load_factor"] for h in p.history if h["converged"])
        assert carried < 2 / 3 < p.failed_at
    assert coarse.failed_at - max(h["load_factor"] for h in coarse.history if h["converged"]) <= 0.1
    assert "the increment (0.0625) within the resolution asked for (0.1)" in coarse.history[-1]["note"]
    assert "no convergence after 8 cut-backs" in fine.history[-1]["note"]
    assert coarse.history == fine.history[:len(coarse.history) - 1] + coarse.history[-1:]
    assert coarse.history[-1]["load_factor"] == fine.history[len(coarse.history) - 1]["load_factor"]
    assert coarse.newton_iterations < fine.newton_iterations
