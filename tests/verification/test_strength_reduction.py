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
    assert all(not h["stable"] and h["criterion"] == "non-convergence" for h in levels if h["srf"] >= failed)
    # as the paper's Fig. 20: isolated plastic zones at SRF = 1, a band from the toe up through the slope at failure
    problem = benchmarks.load(name).problem
    assert r.series[0]["time"] == 1.0 and r.series[-1]["time"] == failed
    assert not shear_band_connects_crest_and_toe(r.points, r.series[0]["fields"]["plastic_strain"], problem)
    assert shear_band_connects_crest_and_toe(r.points, r.series[-1]["fields"]["plastic_strain"], problem)


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
    assert all(not h["stable"] and h["criterion"] == "non-convergence" for h in levels if h["srf"] >= failed)
    assert r.series[0]["time"] == 1.0 and r.series[-1]["time"] == failed


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
