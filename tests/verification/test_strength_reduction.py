"""Strength reduction (issue 5, Eqs. 38-39): the slopes' factor of safety against Bishop's simplified method,
with CTM-RPIM and with the scikit-fem P2 reference on the same Problem and the same PlasticSystem (the shear
band at failure, cf. Fig. 20), a sweep of given levels, and a search by dynamic relaxation."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from verify import check

from ctmrpim import benchmarks
from ctmrpim.methods import solve

BISHOP = {"slope": 1.368, "slope-gl": 1.378}
#: what fails a level of the Newton search: the SRF-displacement curve's runaway, or non-convergence re-checked
FAILED = ("displacement runaway", "non-convergence")


@pytest.mark.slow
@pytest.mark.parametrize("name", ["slope", "slope-gl"])
@pytest.mark.parametrize("solver, tag", [("ctm-rpim", "ctmrpim"), ("fem", "fem-p2")])
def test_factor_of_safety_bracket_against_bishop(name: str, solver: str, tag: str) -> None:
    """The benchmarks' own clouds (about 1900 nodes; the full slope-stability study's finer cases), solved
    here: the shear band needs the plastic strain fields, which summary.json does not hold."""
    r = solve(benchmarks.load(name), solver, None if solver == "ctm-rpim" else "p2")
    fos = r.outcome["factor_of_safety"]
    stable, failed = fos["stable"], fos["failed"]
    assert stable < failed
    check(f"{name}-{tag}-fs", max(abs(stable / BISHOP[name] - 1), abs(failed / BISHOP[name] - 1)))
    check("slope-fs-bracket-width", failed - stable)
    levels = r.history
    assert levels[0]["srf"] == 1.0 and levels[0]["stable"]
    assert all(h["stable"] for h in levels if h["srf"] <= stable)
    assert all(not h["stable"] and h["criterion"].startswith(FAILED) for h in levels if h["srf"] >= failed)
    # as the paper's Fig. 20: isolated plastic zones at SRF = 1, a band from the toe up through the slope at the
    # last stable level, the last equilibrium before failure (a failed level's state is the last iterate of an
    # iteration that did not converge, of Newton's re-check where it ran away: no equilibrium to read a field from)
    problem = benchmarks.load(name).problem
    at = {s["time"]: s for s in r.series}
    assert r.series[0]["time"] == 1.0 and stable in at and failed in at
    assert not shear_band_connects_crest_and_toe(r.points, r.series[0]["fields"]["plastic_strain"], problem)
    assert shear_band_connects_crest_and_toe(r.points, at[stable]["fields"]["plastic_strain"], problem)


def shear_band_connects_crest_and_toe(points: np.ndarray, plastic: np.ndarray, problem) -> bool:
    """The strained nodes (equivalent plastic strain above 0.3 x its 99th percentile) hold one connected
    cluster (neighbours within 1.5 spacings) that contains the toe of the slope and rises to three
    quarters of the slope's height: a shear band through the slope, not isolated plastic zones."""
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    from ctmrpim.reference.limit_equilibrium import top_surface
    surface = top_surface(problem.geometry)
    crest, toe = surface[1], surface[-2] if len(surface) > 3 else surface[-1]   # the slope's upper and lower ends
    band = np.flatnonzero(plastic > 0.3 * np.percentile(plastic, 99))
    spacing = np.sqrt(problem.geometry.area / len(points))
    pairs = cKDTree(points[band]).query_pairs(1.5 * spacing, output_type="ndarray")
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(band),) * 2)
    _, label = connected_components(graph, directed=False)
    at_toe = np.linalg.norm(points[band] - toe, axis=1) < 3 * spacing
    for cluster in set(label[at_toe]):
        if points[band][label == cluster, 1].max() >= toe[1] + 0.75 * (crest[1] - toe[1]):
            return True
    return False


@pytest.mark.parametrize("solver, element", [("ctm-rpim", None), ("fem", "p2")])
def test_search_brackets_the_factor_of_safety_on_a_coarse_cloud(solver: str, element: str | None) -> None:
    """The search of the benchmarks (gravity stage, SRF up by steps, bisection to the width) on a coarse cloud,
    by each method: the fast tier's version of the test above (its slopes run in the slow tier)."""
    r = solve(benchmarks.load("slope", ["parameters.h=1.25"]), solver, element)
    fos = r.outcome["factor_of_safety"]
    stable, failed = fos["stable"], fos["failed"]
    assert fos["mode"] == "search" and stable < failed
    check("slope-fs-bracket-width", failed - stable)
    levels = r.history
    assert levels[0]["srf"] == 1.0 and levels[0]["stable"]
    assert all(h["stable"] for h in levels if h["srf"] <= stable)
    assert all(not h["stable"] and h["criterion"].startswith(FAILED) for h in levels if h["srf"] >= failed)
    # one saved state per level, in the order the search computed them (a bisection may end on a stable level)
    times = [s["time"] for s in r.series]
    assert times == [h["srf"] for h in levels] and times[0] == 1.0 and failed in times
    # summary.json's curve: every level by SRF, its largest displacement and verdict
    curve = r.outcome["srf_displacement"]
    assert curve["srf"] == sorted(h["srf"] for h in levels) and curve["stable"][0]
    assert fos["decided_by"] in FAILED and fos["limit_growth"] == 100.0


def test_a_level_whose_displacement_runs_away_has_failed() -> None:
    """The response criterion on its own: a level in equilibrium whose largest displacement from the stable level
    below, per unit relative SRF rise, exceeds limit_growth times the displacement at SRF = start has failed."""
    from ctmrpim.solvers.strength_reduction import Level, _judge
    def level(srf: float, uy: float) -> Level:
        U = np.zeros(4)
        U[1] = uy
        return Level(srf, True, 1, 0, 0.0, (U, None, None, None))
    stable = level(1.5, -0.05)
    creeping, running = level(1.515, -0.06), level(1.515, -0.2)
    _judge(stable, creeping, 0.03, 100.0)                   # 0.01 m per 1 % rise: 33 x 0.03 m
    _judge(stable, running, 0.03, 100.0)                    # 0.15 m per 1 % rise: 500 x 0.03 m
    assert creeping.stable and creeping.growth == pytest.approx(0.01 / 0.01 / 0.03)
    assert not running.stable and running.criterion.startswith("displacement runaway")
    off = level(1.515, -0.2)
    _judge(stable, off, 0.03, 0.0)                          # limit_growth = 0: non-convergence alone decides
    assert off.stable and off.growth == pytest.approx(500.0)


@pytest.mark.slow
def test_newton_on_the_plateau_is_not_stable() -> None:
    """Newton on the consistent tangent converges far along the plateau (before item 2 of issue 19: the vertical
    cut "stable" at SRF 1.70 with 145 m of displacement, CTM-RPIM); with the runaway criterion its factor of safety
    on a coarse vertical cut is the elastic-stiffness iteration's (about a minute)."""
    fs = {}
    for tangent in ("consistent", "elastic"):
        extra = ["parameters.h=1.0", f"loading.tangent=\"{tangent}\""]
        r = solve(benchmarks.load("vertical-cut", extra + (["loading.max_iterations=15"] if tangent == "consistent"
                                                          else [])))
        fs[tangent] = r.outcome["factor_of_safety"]
        assert all(h.get("growth", 0.0) <= 100.0 for h in r.history if h["stable"])
    assert fs["consistent"]["decided_by"] == "displacement runaway"
    check("vertical-cut-fs-tangent-change",
          max(abs(fs["consistent"][k] / fs["elastic"][k] - 1) for k in ("stable", "failed")))


def test_sweep_mode_brackets_from_independent_levels() -> None:
    case = benchmarks.load("slope", ["parameters.h=1.25", "strength-reduction.values=[1.1, 1.7]"])
    r = solve(case)
    assert [h["stable"] for h in r.history] == [True, False]
    assert r.outcome["factor_of_safety"]["stable"] == 1.1 and r.outcome["factor_of_safety"]["failed"] == 1.7
    assert r.outcome["factor_of_safety"]["mode"] == "sweep"


def test_relaxation_search_brackets_and_records_the_displacement_history() -> None:
    case = benchmarks.load("slope", ["parameters.h=1.25", 'strength-reduction.solver="dynamic-relaxation"',
                                     "strength-reduction.values=[1.0, 1.6]", "dynamic.record_every=50"])
    r = solve(case)
    at_rest, moving = r.history
    assert at_rest["stable"] and not moving["stable"] and "still moving" in moving["criterion"]
    path = np.array(moving["displacement_history"])
    assert path[-1, 1] > 2 * path[len(path) // 2, 1]                 # the displacement keeps growing
    assert r.outcome["factor_of_safety"]["criterion"].startswith("still moving")
