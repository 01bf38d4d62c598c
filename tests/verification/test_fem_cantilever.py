"""The scikit-fem reference solver on the Timoshenko cantilever: accuracy, convergence, output shape."""
from __future__ import annotations

import numpy as np
import pytest
from verify import check, check_rate

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.problem.node_cloud import make_nodes
from ctmrpim.result import Result
from reference_fem import solve_fem
from studies import tolerances

GRIDS = ((17, 5), (33, 9), (65, 17))
L = 48.0


@pytest.fixture(scope="module")
def solved(solutions) -> dict[tuple[str, tuple[int, int]], Result]:
    """Each (element, grid) solved once for the run (all together well under a second; shared with the
    command-line tests and the README's example)."""
    out = {}
    for element in ("q1", "p2"):
        for grid in GRIDS:
            case = benchmarks.load("cantilever", overrides=[f"nodes.grid=[{grid[0]}, {grid[1]}]"])
            out[element, grid] = solutions(case, method="fem", element=element)
    return out


def test_q1_tip_deflection(solved) -> None:
    res = solved["q1", (33, 9)]
    recorded = tolerances.entry("cantilever-fem-q1-33x9-tip-value")["value"]
    check("cantilever-fem-q1-33x9-tip-value", abs(res.probes["tip"]["uy"] / recorded - 1.0))
    check("cantilever-fem-q1-33x9-tip", res.errors["probes"]["tip"]["uy"])


def test_p2_tip_deflection(solved) -> None:
    check("cantilever-fem-p2-33x9-tip", solved["p2", (33, 9)].errors["probes"]["tip"]["uy"])


def test_p2_beats_q1_in_energy(solved) -> None:
    assert solved["p2", (33, 9)].errors["energy"] < solved["q1", (33, 9)].errors["energy"]


@pytest.mark.parametrize("norm", ["energy", "l2"])
def test_q1_convergence_rates(solved, norm: str) -> None:
    h = np.array([L / (nx - 1) for nx, _ in GRIDS])
    check_rate(f"fem-q1-{norm}-rate", h, [solved["q1", g].errors[norm] for g in GRIDS])


def test_result_shape_matches_meshfree_nodes(solved) -> None:
    res = solved["q1", (33, 9)]
    case = benchmarks.load("cantilever", overrides=["nodes.grid=[33, 9]"])
    nodes = make_nodes(case.problem.geometry, case.nodes, case.base_dir)
    assert np.array_equal(res.points, nodes)  # same points, same order as the meshfree solver
    assert res.u.shape == (len(nodes), 2) and res.stress.shape == (len(nodes), 3)
    kind, cells = res.cells[0]
    assert kind == "quad" and cells.shape == (32 * 8, 4)
    assert res.counts == {"nodes": 297, "dofs": 594, "elements": 256, "integration_points": 1024}
    assert res.method == "fem-q1" and res.parameters["derived"]["element"] == "q1"
    assert set(res.timings) == {"mesh", "assembly", "solve", "postprocess", "total"}
    # the constrained end carries the exact displacement
    exact = case.problem.exact
    root = nodes[:, 0] == 0.0
    assert np.allclose(res.u[root], exact.displacement(*nodes[root].T), rtol=0, atol=1e-15)


def test_p1_on_a_node_cloud() -> None:
    case = benchmarks.load("cantilever", overrides=["nodes.spacing=2.0"])
    res = solve_fem(case, "p1")
    assert res.cells[0][0] == "triangle"
    check("cantilever-fem-p1-spacing2-energy", res.errors["energy"])
    check("cantilever-fem-p1-spacing2-tip", res.errors["probes"]["tip"]["uy"])


def test_q1_needs_a_tensor_grid() -> None:
    case = benchmarks.load("cantilever", overrides=["nodes.spacing=2.0"])
    with pytest.raises(ProblemError, match="q1 needs a rectangular body and nodes.grid"):
        solve_fem(case, "q1")


def test_unknown_element() -> None:
    with pytest.raises(ProblemError, match="not supported"):
        solve_fem(benchmarks.load("cantilever"), "q2")
