"""The paper's adaptive updated-Lagrangian method on the large-deflection benchmarks (quick versions) against
the exact elastica: the tip load, the end moment (a quarter ring) and the corner load, the tracked boundary
in the increment series, points carried or laid anew. The cases that are also the quick tip-load and
end-moment studies' are solved through the study cache (their summary.json)."""
from __future__ import annotations

import numpy as np
import pytest
from verify import check

from ctmrpim import benchmarks
from ctmrpim.methods import solve
from ctmrpim.reference import elastica
from studies.sweep import CaseSpec

UL = 'method.formulation="updated-lagrangian"'
L = 10.0
#: the cases that are also the quick studies' (tip-load and end-moment)
STUDY_CASES = {"end-moment": CaseSpec("end-moment", ("parameters.m=0.25", "loading.steps=16", UL)),
               "corner": CaseSpec("tip-load-corner", ("parameters.lam=1.8", "loading.steps=8", UL)),
               "carried": CaseSpec("end-moment", ("parameters.m=0.25", "loading.steps=16", UL,
                                                  "method.point_regeneration=0.5"))}


@pytest.fixture(scope="module")
def summaries(study_cases) -> dict[str, dict]:
    """The summary.json of each of STUDY_CASES, solved side by side through the study cache."""
    return dict(zip(STUDY_CASES, study_cases(*STUDY_CASES.values())))


def test_tip_load_updated_lagrangian_against_the_elastica() -> None:
    r = solve(benchmarks.load("tip-load", ["parameters.lam=1.2", "loading.steps=6", UL]))
    exact = elastica.tip_load_elliptic(1.2)
    check("tip-load-ul-elastica", abs(-r.probes["tip"]["uy"] / L / exact.w_over_L - 1.0))
    check("tip-load-ul-elastica-shortening", abs(-r.probes["tip"]["ux"] / L / exact.u_over_L - 1.0))
    assert r.counts["rebuilds"] == 5 and r.counts["rebuilds_skipped"] == 0     # none after the last increment
    # the tracked boundary stays one loop of the beam's area (10 m^2) through every increment
    assert all(h["boundary_loops"] == 1 for h in r.history)
    assert [h["tracked_area"] for h in r.history] == pytest.approx([10.0] * 6, rel=2e-3)
    assert all(len(s["boundary"]) > 0 for s in r.series)


def test_end_moment_quarter_updated_lagrangian(summaries) -> None:
    r = summaries["end-moment"]
    x, y = 1.0 + r["probes"]["tip"]["ux"] / L, r["probes"]["tip"]["uy"] / L
    ex, ey = elastica.end_moment_tip(2 * np.pi * 0.25)
    check("end-moment-ul-quarter", float(np.hypot(x - ex, y - ey)))
    assert all(h["boundary_loops"] == 1 for h in r["history"])
    assert [h["tracked_area"] for h in r["history"]] == pytest.approx([5.0] * 16, rel=5e-3)


def test_corner_point_load_updated_lagrangian(summaries) -> None:
    """The paper's corner load as a material point carried by the RPIM interpolation of each increment."""
    r = summaries["corner"]
    w = -r["probes"]["tip"]["uy"] / L
    check("tip-load-corner-ul-elastica", abs(w / elastica.tip_load_bvp(1.8, eccentricity=0.05).w_over_L - 1.0))


def test_series_carries_the_tracked_boundary(tmp_path) -> None:
    """Each VTU of the series holds the nodes where they are and the boundary tracked on them."""
    import xml.etree.ElementTree as ET

    import meshio

    from ctmrpim.io.run_folder import write_outputs

    case = benchmarks.load("tip-load", ["parameters.lam=0.6", "loading.steps=2", UL])
    r = solve(case)
    write_outputs(r, case, tmp_path)
    sets = ET.parse(tmp_path / "result.pvd").getroot().findall("./Collection/DataSet")
    assert len(sets) == 2
    first = meshio.read(tmp_path / sets[0].get("file"))
    assert np.array_equal(first.cells_dict["line"], r.series[0]["boundary"])
    assert np.allclose(first.points[:, :2], r.points + r.series[0]["u"])


def test_carried_points_keep_their_state(summaries) -> None:
    """method.point_regeneration above the strain reached: no new CTM points, no state transfer, the
    boundary and the RPIM shape functions still rebuilt every increment."""
    r = summaries["carried"]
    assert r["counts"]["rebuilds"] == 15 and r["counts"]["state_transfers"] == 0
    x, y = 1.0 + r["probes"]["tip"]["ux"] / L, r["probes"]["tip"]["uy"] / L
    ex, ey = elastica.end_moment_tip(2 * np.pi * 0.25)
    check("end-moment-ul-carried-quarter", float(np.hypot(x - ex, y - ey)))


def test_points_are_laid_anew_once_strained_past_the_threshold() -> None:
    r = solve(benchmarks.load("tip-load", ["parameters.lam=1.2", "loading.steps=6", UL, "method.point_regeneration=0.02"]))
    assert r.counts["rebuilds"] == 5 and 0 < r.counts["state_transfers"] < 5


def test_banded_newton_solve_gives_superlus_iterates(monkeypatch) -> None:
    """The Newton tangents factorised in their configuration's band (banded LU with partial pivoting, the
    non-symmetric rate-form tangent as it is) give SuperLU's answer: same iterations, tip to round-off."""
    from ctmrpim.solvers import banded_lu

    overrides = ["parameters.m=0.125", "loading.steps=4", UL]
    banded = solve(benchmarks.load("end-moment", overrides))
    monkeypatch.setattr(banded_lu, "MAX_BAND_PER_ROW", 0.0)     # no band is worthwhile: SuperLU throughout
    superlu = solve(benchmarks.load("end-moment", overrides))
    assert banded.counts["newton_iterations"] == superlu.counts["newton_iterations"]
    tip_b, tip_s = (np.array([r.probes["tip"]["ux"], r.probes["tip"]["uy"]]) for r in (banded, superlu))
    assert np.abs(tip_b - tip_s).max() <= 1e-9 * np.abs(tip_s).max()
