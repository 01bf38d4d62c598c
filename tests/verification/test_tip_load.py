"""Tip-loaded cantilever with large deflection (paper Figs. 13-15), total-Lagrangian CTM-RPIM against
the exact elastica; Newton history and cut-backs, the increment series, the corner load (the quick tip-load
study's case: solved through the study cache), displacement-driven loading."""
from __future__ import annotations

import pytest
from verify import check

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.methods import solve
from ctmrpim.reference import elastica
from studies.sweep import CaseSpec

L = 10.0
TL = 'method.formulation="total-lagrangian"'


@pytest.fixture(scope="module")
def solved():
    return solve(benchmarks.load("tip-load", ["parameters.lam=1.2", "loading.steps=4", TL]))


def test_tip_deflection_against_the_elastica(solved) -> None:
    exact = elastica.tip_load_elliptic(1.2)
    w = -solved.probes["tip"]["uy"] / L
    check("tip-load-tl-elastica", abs(w / exact.w_over_L - 1.0))
    u = -solved.probes["tip"]["ux"] / L           # the tip moves back towards the root
    check("tip-load-tl-elastica-shortening", abs(u / exact.u_over_L - 1.0))


def test_history_has_every_increment(solved) -> None:
    h = solved.history
    assert [r["load_factor"] for r in h] == pytest.approx([0.25, 0.5, 0.75, 1.0])
    assert all(r["converged"] and r["iterations"] <= 8 for r in h)
    deflections = [-r["tip"]["uy"] for r in h]
    assert deflections == sorted(deflections)      # monotone load-displacement curve
    assert solved.counts["cutbacks"] == 0


def test_cut_back_is_reported_not_silent() -> None:
    r = solve(benchmarks.load("tip-load", ["parameters.lam=1.2", "loading.steps=1", "loading.max_iterations=6", TL]))
    assert r.counts["cutbacks"] >= 1
    assert any(not h["converged"] and "cut back" in h["note"] for h in r.history)
    assert r.history[-1]["load_factor"] == pytest.approx(1.0)


def test_newton_failure_is_a_clear_error() -> None:
    with pytest.raises(ProblemError, match="did not converge"):
        solve(benchmarks.load("tip-load", ["parameters.lam=1.2", "loading.steps=1", "loading.max_iterations=1",
                                           "loading.max_cutbacks=1"]))


def test_increment_series_round_trip(solved, tmp_path) -> None:
    """result.pvd indexes one VTU per converged increment, on the current configuration."""
    import xml.etree.ElementTree as ET

    import meshio
    import numpy as np

    from ctmrpim.io.run_folder import write_outputs
    from ctmrpim.io.vtu import in_plane_stress

    case = benchmarks.load("tip-load", ["parameters.lam=1.2", "loading.steps=4", TL])
    write_outputs(solved, case, tmp_path)
    sets = ET.parse(tmp_path / "result.pvd").getroot().findall("./Collection/DataSet")
    assert [float(d.get("timestep")) for d in sets] == pytest.approx([h["load_factor"] for h in solved.history])
    last = meshio.read(tmp_path / sets[-1].get("file"))
    assert np.array_equal(last.points[:, :2], solved.points + solved.u)
    assert np.array_equal(last.point_data["u"][:, :2], solved.u)
    assert np.array_equal(in_plane_stress(last.point_data), solved.stress)
    assert np.array_equal(last.point_data["stress_zz"], solved.series[-1]["stress_zz"])
    assert "line" in last.cells_dict   # the boundary travels with the nodes


def test_corner_load_against_the_eccentric_elastica(study_cases) -> None:
    """The paper's set-up: P at the top-right corner acts like a tip moment P (W/2) sin(theta)."""
    r, = study_cases(CaseSpec("tip-load-corner", ("parameters.lam=1.8", "loading.steps=8", TL)))
    w = -r["probes"]["tip"]["uy"] / L
    check("tip-load-corner-tl-elastica", abs(w / elastica.tip_load_bvp(1.8, eccentricity=0.05).w_over_L - 1.0))
    assert w > elastica.tip_load_elliptic(1.8).w_over_L   # the corner load bends more than the end shear


@pytest.mark.parametrize("solver, element", [("ctm-rpim", None), ("fem", "p2")])
def test_displacement_driven_loading_converges(solver: str, element: str) -> None:
    """No external force at all: the prescribed tip displacement drives the beam (the Newton test is
    relative to the reactions then)."""
    import tomllib

    import numpy as np

    from ctmrpim.problem.reader import parse_case

    raw = tomllib.loads(benchmarks.path("tip-load").read_text())
    raw["constraint"].append({"where": "x == L", "uy": "-2.0"})
    case = parse_case(raw, "tip-load", benchmarks.FOLDER, ["parameters.lam=0", "loading.steps=2"])
    r = solve(case, solver, element)
    end = np.abs(r.points[:, 0] - L) < 1e-9
    assert np.array_equal(r.u[end, 1], np.full(end.sum(), -2.0))
    assert r.history[-1]["converged"] and r.history[-1]["load_factor"] == pytest.approx(1.0)
