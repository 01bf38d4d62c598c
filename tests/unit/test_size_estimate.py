"""The size of a solve estimated from its input (ctmrpim.problem.size_estimate) against what a solve lays."""
from __future__ import annotations

import pytest

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.methods import solve
from ctmrpim.problem import size_estimate


@pytest.mark.parametrize("grid", [[17, 5], [65, 17]])
def test_nodes_and_points_match_a_solve(grid) -> None:
    case = benchmarks.load("cantilever", [f"nodes.grid={grid}", 'method.integration="ctm"'])
    size = size_estimate.estimate(case)
    counts = solve(case).counts
    assert size.nodes == counts["nodes"]
    assert size.points == pytest.approx(counts["integration_points"], rel=0.02)
    assert counts["support_size"]["max"] <= 1.05 * size.support    # an upper bound: thin bodies clip supports


def test_a_grid_beyond_the_memory_is_refused_before_allocating() -> None:
    case = benchmarks.load("cantilever", ["nodes.grid=[100000, 100000]"])
    with pytest.raises(ProblemError, match=r"too large for this machine: 1e\+10 nodes .* GiB of memory, and it has"):
        solve(case)
    with pytest.raises(ProblemError, match=r"too large for this machine: 1e\+10 nodes need"):
        solve(case, "fem", "p2")


def test_the_memory_limit_is_known_here() -> None:
    assert size_estimate.memory_limit() > 2 ** 28
