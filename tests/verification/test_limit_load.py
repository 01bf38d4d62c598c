"""The footing's limit pressure against Prandtl's, with CTM-RPIM and the scikit-fem P2 reference, and the
load written as a pressure or as a traction."""
from __future__ import annotations

import math

import numpy as np
import pytest
from verify import check

from ctmrpim import benchmarks
from ctmrpim.methods import solve
from studies.sweep import CaseSpec

PRANDTL = (2.0 + math.pi) * 100e3


@pytest.mark.parametrize("solver, element, tag", [pytest.param("ctm-rpim", None, "ctmrpim", marks=pytest.mark.slow),
                                                   ("fem", "p2", "fem-p2")])
def test_footing_limit_pressure_against_prandtl(study_cases, solver: str, element: str | None, tag: str) -> None:
    """The footing benchmark's summary.json, solved through the study cache (the quick footing-bearing study's
    case too)."""
    r, = study_cases(CaseSpec("footing", (), solver, element))
    limit = r["limit_pressure"]
    assert limit["failed"] is not None and limit["carried"] < limit["failed"]
    check(f"footing-{tag}-limit", max(abs(limit["carried"] / PRANDTL - 1), abs(limit["failed"] / PRANDTL - 1)))
    # the load-displacement curve: settlement grows faster than the load towards the limit
    carried = [h for h in r["history"] if h["converged"]]
    q = np.array([h["load_factor"] for h in carried])
    w = -np.array([h["centre"]["uy"] for h in carried])
    assert np.all(np.diff(w[np.argsort(q)]) > 0)
    assert w[np.argmax(q)] > 2 * w[0] * q.max() / q[0]            # past the elastic line at the limit
    # the limit is the curve's (issue 19, item 2): the first increment not carried is in equilibrium, its slope
    # below loading.limit_slope of the elastic one; the last carried one above it
    criterion = r["limit_criterion"]
    assert criterion["decided_by"] == "settlement runaway"
    assert criterion["slope_ratio_at_carried"] >= criterion["limit_slope"] > criterion["slope_ratio_at_failed"]
    assert r["load_settlement"]["pressure"][-1] == limit["failed"]


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
