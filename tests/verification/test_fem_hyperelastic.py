"""scikit-fem total-Lagrangian reference (reference_fem.hyperelastic) on the large-deflection tip load:
against the exact elastica, against itself on a refined mesh, and against the meshfree TL solver."""
from __future__ import annotations

import numpy as np
import pytest
from verify import check

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.methods import solve
from ctmrpim.reference import elastica
from reference_fem.hyperelastic import solve_fem_hyperelastic

L = 10.0
LAM = 1.2
OVERRIDES = [f"parameters.lam={LAM}", "loading.steps=4"]


@pytest.fixture(scope="module")
def case():
    return benchmarks.load("tip-load", OVERRIDES)


@pytest.fixture(scope="module")
def p2(case):
    return solve_fem_hyperelastic(case, "p2")


@pytest.fixture(scope="module")
def p2_fine(case):
    return solve_fem_hyperelastic(case, "p2", refine=1)


def _w(result) -> float:
    return -result.probes["tip"]["uy"] / L


def _u(result) -> float:
    return -result.probes["tip"]["ux"] / L


def test_p2_against_the_elastica(p2, p2_fine) -> None:
    exact = elastica.tip_load_elliptic(LAM)
    check("tip-load-fem-p2-elastica", _w(p2) / exact.w_over_L - 1.0)
    check("tip-load-fem-p2-refined-elastica", _w(p2_fine) / exact.w_over_L - 1.0)
    check("tip-load-fem-p2-mesh-convergence", abs(_w(p2) / _w(p2_fine) - 1.0))


def test_q1_against_the_elastica(case) -> None:
    r = solve_fem_hyperelastic(case, "q1")
    assert r.method == "fem-q1-tl" and r.cells[0][0] == "quad" and r.counts["elements"] == 250
    check("tip-load-fem-q1-elastica", abs(_w(r) / elastica.tip_load_elliptic(LAM).w_over_L - 1.0))


def test_meshfree_total_lagrangian_against_fem(case, p2_fine) -> None:
    mf = solve(case)
    check("tip-load-tl-vs-fem-p2", abs(_w(mf) / _w(p2_fine) - 1.0))
    check("tip-load-tl-vs-fem-p2-shortening", abs(_u(mf) / _u(p2_fine) - 1.0))


def test_result_shape_and_history(p2, p2_fine) -> None:
    assert p2.method == "fem-p2-tl"
    assert p2.points.shape == (306, 2) and p2.u.shape == (306, 2) and p2.stress.shape == (306, 3)
    assert p2.cells[0][0] == "triangle" and p2.cells[0][1].shape == (500, 3)
    assert p2_fine.points.shape == (1111, 2) and p2_fine.parameters["derived"]["refine"] == 1
    assert np.array_equal(p2_fine.points[:306], p2.points)     # refinement keeps the grid's vertices first
    assert p2.counts["load_increments"] == 4 and p2.counts["cutbacks"] == 0
    h = p2.history
    assert [r["load_factor"] for r in h] == pytest.approx([0.25, 0.5, 0.75, 1.0])
    assert all(r["converged"] and r["iterations"] <= 8 for r in h)
    deflections = [-r["tip"]["uy"] for r in h]
    assert deflections == sorted(deflections)
    assert h[-1]["tip"]["uy"] == p2.probes["tip"]["uy"]
    assert len(p2.series) == 4 and np.array_equal(p2.series[-1]["u"], p2.u)
    assert np.all(np.isfinite(p2.stress))


def test_zero_load_gives_zero_displacement() -> None:
    r = solve_fem_hyperelastic(benchmarks.load("tip-load", ["parameters.lam=0", "loading.steps=2"]), "p2")
    assert np.all(r.u == 0.0) and np.all(r.stress == 0.0)
    assert all(h["converged"] for h in r.history)


def test_cut_back_is_reported_and_failure_is_an_error() -> None:
    r = solve_fem_hyperelastic(benchmarks.load("tip-load", [f"parameters.lam={LAM}", "loading.steps=1",
                                                            "loading.max_iterations=5"]), "q1")
    assert r.counts["cutbacks"] >= 1
    assert any(not h["converged"] and "cut back" in h["note"] for h in r.history)
    assert r.history[-1]["load_factor"] == pytest.approx(1.0)
    with pytest.raises(ProblemError, match="did not converge"):
        solve_fem_hyperelastic(benchmarks.load("tip-load", [f"parameters.lam={LAM}", "loading.steps=1",
                                                            "loading.max_iterations=1", "loading.max_cutbacks=1"]),
                               "q1")


def test_solve_dispatches_nonlinear_analyses_to_the_fem_reference() -> None:
    r = solve(benchmarks.load("tip-load", ["parameters.lam=0.6", "loading.steps=2"]), "fem", "p2")
    assert r.method == "fem-p2-tl"
    assert _w(r) / elastica.tip_load_elliptic(0.6).w_over_L - 1.0 == pytest.approx(0.0063, abs=5e-4)
