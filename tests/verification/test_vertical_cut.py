"""The vertical cut in undrained clay (issue 19): strength reduction by both methods against Taylor's stability
number 3.83 (FS = 1.50), the benchmark that Bishop's search also solves (test_limit_equilibrium.py)."""
from __future__ import annotations

import pytest
from verify import check

from ctmrpim import benchmarks
from ctmrpim.methods import solve

TAYLOR = 3.83 * 78.3e3 / (20e3 * 10.0)


@pytest.mark.long
@pytest.mark.parametrize("solver, element, tag", [("ctm-rpim", None, "ctmrpim"), ("fem", "p2", "fem-p2")])
def test_vertical_cut_factor_of_safety_against_taylor(solver: str, element: str | None, tag: str) -> None:
    """The benchmark's own cloud (h = 0.35 m, 5075 nodes): about two minutes each."""
    r = solve(benchmarks.load("vertical-cut"), solver, element)
    fos = r.outcome["factor_of_safety"]
    assert fos["stable"] < fos["failed"]
    check(f"vertical-cut-{tag}-fs", max(abs(fos["stable"] / TAYLOR - 1), abs(fos["failed"] / TAYLOR - 1)))
    check("slope-fs-bracket-width", fos["failed"] - fos["stable"])
