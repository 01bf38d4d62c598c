"""Strength reduction and limit load (issue 5): the slopes' factor of safety against Bishop's simplified
method and the footing's limit pressure against Prandtl, with CTM-RPIM and with the scikit-fem P2
reference on the same Problem and the same PlasticSystem, plus the pieces they are built from."""
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve
from verify import check

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import MohrCoulomb, equivalent_plastic_strain, plastic_strain_increment
from ctmrpim.methods import solve
from ctmrpim.solvers.elastoplastic import ctm_plastic_system
from ctmrpim.solvers.load_stepping import Anderson
from ctmrpim.solvers.plastic_system import block_rows
from ctmrpim.solvers.strength_reduction import bracket, reduced
from ctmrpim.timing import Timer

BISHOP = {"slope": 1.368, "slope-gl": 1.378}
PRANDTL = (2.0 + math.pi) * 100e3


@pytest.fixture(scope="module")
def results() -> dict:
    return {}


def _solved(results: dict, name: str, solver: str):
    if (name, solver) not in results:
        results[name, solver] = solve(benchmarks.load(name), solver, None if solver == "ctm-rpim" else "p2")
    return results[name, solver]


@pytest.mark.parametrize("name", ["slope", "slope-gl"])
@pytest.mark.parametrize("solver, tag", [("ctm-rpim", "ctmrpim"), ("fem", "fem-p2")])
def test_factor_of_safety_bracket_against_bishop(results, name: str, solver: str, tag: str) -> None:
    r = _solved(results, name, solver)
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


@pytest.mark.parametrize("solver, tag", [("ctm-rpim", "ctmrpim"), ("fem", "fem-p2")])
def test_footing_limit_pressure_against_prandtl(results, solver: str, tag: str) -> None:
    r = _solved(results, "footing", solver)
    limit = r.outcome["limit_pressure"]
    assert limit["failed"] is not None and limit["carried"] < limit["failed"]
    check(f"footing-{tag}-limit", max(abs(limit["carried"] / PRANDTL - 1), abs(limit["failed"] / PRANDTL - 1)))
    # the load-displacement curve: settlement grows faster than the load towards the limit
    carried = [h for h in r.history if h["converged"]]
    q = np.array([h["load_factor"] for h in carried])
    w = -np.array([h["centre"]["uy"] for h in carried])
    assert np.all(np.diff(w[np.argsort(q)]) > 0)
    assert w[np.argmax(q)] > 5 * w[0] * q.max() / q[0]            # far past the elastic line at the limit


def test_sweep_mode_brackets_from_independent_levels() -> None:
    case = benchmarks.load("slope", ["parameters.h=1.25", "strength-reduction.values=[1.1, 1.7]"])
    r = solve(case)
    assert [h["stable"] for h in r.history] == [True, False]
    assert r.outcome["factor_of_safety"]["stable"] == 1.1 and r.outcome["factor_of_safety"]["failed"] == 1.7
    assert r.outcome["factor_of_safety"]["mode"] == "sweep"


def test_reduced_strength_follows_eqs_38_39() -> None:
    m = MohrCoulomb(E=1e8, nu=0.3, c=1e4, phi=20.0, psi=10.0)
    r = reduced(m, 1.6)
    assert r.c == pytest.approx(1e4 / 1.6)
    assert math.tan(math.radians(r.phi)) == pytest.approx(math.tan(math.radians(20.0)) / 1.6)
    assert math.tan(math.radians(r.psi)) == pytest.approx(math.tan(math.radians(10.0)) / 1.6)
    assert (r.E, r.nu) == (m.E, m.nu)


def test_bracket_takes_the_largest_stable_below_the_smallest_failed() -> None:
    from ctmrpim.solvers.strength_reduction import Level
    levels = [Level(s, ok, 0, 0, 0.0, ()) for s, ok in [(1.0, True), (1.4, False), (1.3, True), (1.5, True)]]
    assert bracket(levels) == (1.3, 1.4)
    assert bracket(levels[:1]) == (1.0, None)


def test_plastic_strain_is_zero_for_elastic_steps_and_isochoric_for_psi_zero() -> None:
    m = MohrCoulomb(E=1e8, nu=0.3, c=1e4, phi=30.0, psi=0.0)
    rng = np.random.default_rng(1)
    stress = np.zeros((200, 4))
    small = rng.normal(scale=1e-6, size=(200, 3))
    s, region = m.update(stress, small)
    assert np.all(region == 0)
    assert np.abs(plastic_strain_increment(m, small, s - stress)).max() < 1e-18
    large = rng.normal(scale=1e-2, size=(200, 3))
    s, region = m.update(stress, large)
    dp = plastic_strain_increment(m, large, s - stress)
    main = region == 1
    assert main.any()
    assert np.abs(dp[main, 0] + dp[main, 1] + dp[main, 3]).max() < 1e-12       # psi = 0: no volume change
    assert np.all(equivalent_plastic_strain(dp)[main] > 0)


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


@pytest.mark.parametrize("change, key", [
    (["strength-reduction.step=0"], "strength-reduction.step"),
    (["strength-reduction.width=0.5"], "strength-reduction.width"),
    (['strength-reduction.solver="dynamic"'], "strength-reduction.solver"),
    (["strength-reduction.values=1.2"], "strength-reduction.values"),
    (['problem.analysis="quasi-static"'], "problem.analysis"),
    (['loading.tangent="secant"'], "loading.tangent"),
])
def test_bad_strength_reduction_input_names_the_key(change, key: str) -> None:
    with pytest.raises(ProblemError, match=key.replace(".", r"\.")):
        benchmarks.load("slope", change)


def test_until_failure_needs_a_mohr_coulomb_quasi_static_analysis() -> None:
    with pytest.raises(ProblemError, match="until_failure"):
        benchmarks.load("tip-load", ["loading.until_failure=true"])


def test_dynamic_relaxation_comes_to_rest_at_the_elastic_solution() -> None:
    """A strong Mohr-Coulomb column under its own weight stays elastic: relaxed to rest it matches the
    linear solve of the same CTM-RPIM discretisation (the exact K0 column within the method's error)."""
    from ctmrpim.problem.settings import Relaxation
    from ctmrpim.solvers.dynamic_relaxation import relax, relaxation_mass
    case = benchmarks.load("self-weight", ['problem.analysis="dynamic"', 'material.model="mohr-coulomb"',
                                           "material.c=1e9", "material.phi=30"])
    system = ctm_plastic_system(case, Timer())[0]
    assert np.all(relaxation_mass(system) > 0)
    path = relax(system, case.problem.material, 1.0, Relaxation(steps=20000, tolerance=1e-8))
    assert path.at_rest
    K = system.elastic_stiffness()
    U = np.zeros(K.shape[0])
    free = system.free
    U[free] = spsolve(K[free][:, free].tocsc(), system.external_force(1.0)[free])
    assert np.abs(system.U - U).max() < 1e-6 * np.abs(U).max()


def test_relaxation_search_brackets_and_records_the_displacement_history() -> None:
    case = benchmarks.load("slope", ["parameters.h=1.25", 'strength-reduction.solver="dynamic-relaxation"',
                                     "strength-reduction.values=[1.0, 1.6]", "dynamic.record_every=50"])
    r = solve(case)
    at_rest, moving = r.history
    assert at_rest["stable"] and not moving["stable"] and "still moving" in moving["criterion"]
    path = np.array(moving["displacement_history"])
    assert path[-1, 1] > 2 * path[len(path) // 2, 1]                 # the displacement keeps growing
    assert r.outcome["factor_of_safety"]["criterion"].startswith("still moving")


def test_dynamic_section_needs_a_relaxation_analysis() -> None:
    with pytest.raises(ProblemError, match="dynamic"):
        benchmarks.load("slope", ["dynamic.steps=100"])


def test_tension_cut_off_is_read_and_reduced_with_the_strength() -> None:
    case = benchmarks.load("slope", ["material.tension=2e3"])
    assert case.problem.material.tension == 2e3 and case.resolved["material"]["tension"] == 2e3
    assert reduced(case.problem.material, 2.0).tension == 1e3
    with pytest.raises(ProblemError, match="material.tension"):
        benchmarks.load("slope", ["material.tension=-1"])


def test_limit_pressure_is_the_same_for_a_traction_and_a_pressure(tmp_path) -> None:
    """The footing's load written as [[pressure]] p instead of [[traction]] ty = -p: same limit, same scale."""
    text = benchmarks.path("footing").read_text()
    path = tmp_path / "footing_pressure.toml"
    path.write_text(text.replace("[[traction]]", "[[pressure]]").replace('ty = "-q_max"', 'p = "q_max"'))
    from ctmrpim.cases import load_case
    coarse = ["parameters.nx=25", "parameters.ny=11"]
    with_pressure = solve(load_case(str(path), coarse), "fem", "p2").outcome["limit_pressure"]
    with_traction = solve(benchmarks.load("footing", coarse), "fem", "p2").outcome["limit_pressure"]
    assert with_pressure == pytest.approx(with_traction, rel=1e-9)
    assert with_pressure["carried"] == pytest.approx(PRANDTL, rel=0.03)
