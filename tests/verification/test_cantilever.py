"""The paper's cantilever (Section 3.1, Eq. 35) solved by CTM-RPIM, checked against the tolerances table.

The paper's numbers are pinned to the paper's scheme (``method.integration = "ctm"``); the default of a
linear analysis (``ctm-vci``) is checked beside it."""
from __future__ import annotations

import numpy as np
import pytest
from verify import check, check_rate

from ctmrpim import benchmarks
from ctmrpim.result import Result
from ctmrpim.solvers.linear_static import solve_ctmrpim
from studies import schemes

GRIDS = ((17, 5), (33, 9), (65, 17))
PAPER = schemes.scheme_override(schemes.PAPER)
CONSISTENT = schemes.scheme_override(schemes.CONSISTENT)


@pytest.fixture(scope="module")
def solved(solutions) -> dict[tuple[int, int], Result]:
    """Each grid solved once for the run with the paper's scheme."""
    return {g: solutions("cantilever", [f"nodes.grid=[{g[0]}, {g[1]}]", PAPER]) for g in GRIDS}


@pytest.fixture(scope="module")
def default(solutions) -> dict[tuple[int, int], Result]:
    """Each grid solved with the defaults (shared with the command-line tests and the README's example)."""
    return {g: solutions("cantilever", [f"nodes.grid=[{g[0]}, {g[1]}]"]) for g in GRIDS}


def test_the_default_of_a_linear_analysis_is_the_consistent_scheme(default) -> None:
    method = default[33, 9].parameters["method"]
    assert (method["integration"], method["polynomial"], method["correction"]) == ("ctm-vci", "linear", "quadratic")
    assert "method.integration = 'ctm-vci'" in default[33, 9].defaults


@pytest.mark.parametrize("grid", [(33, 9), (65, 17)])
def test_default_tip_error_no_worse_than_the_papers(solved, default, grid: tuple[int, int]) -> None:
    """At 17 x 5 it is worse (1.12 % against 0.85 %), with any quadrature: converged (line spacing 1/12, 3 Gauss
    points) the consistent scheme gives 1.36 % and the paper's 0.31 %, whose energy error (3.4 %) is nevertheless
    twice the consistent one's (1.8 %) and whose patch test fails; four node intervals through the depth."""
    assert default[grid].errors["probes"]["tip"]["uy"] <= solved[grid].errors["probes"]["tip"]["uy"]


def test_tip_error_33x9(solved) -> None:
    check("cantilever-ctmrpim-33x9-tip", solved[33, 9].errors["probes"]["tip"]["uy"])


def test_tip_error_65x17(solved) -> None:
    check("cantilever-ctmrpim-65x17-tip", solved[65, 17].errors["probes"]["tip"]["uy"])


def test_norms_33x9(solved) -> None:
    check("cantilever-ctmrpim-33x9-l2", solved[33, 9].errors["l2"])
    check("cantilever-ctmrpim-33x9-energy", solved[33, 9].errors["energy"])


def test_tip_convergence_rate(solved) -> None:
    h = np.array([48.0 / (g[0] - 1) for g in GRIDS])
    check_rate("ctmrpim-tip-rate", h, [solved[g].errors["probes"]["tip"]["uy"] for g in GRIDS])


@pytest.mark.parametrize("scheme", ["paper", "default"])
def test_constraints_imposed_exactly_and_symmetry(solved, default, scheme: str) -> None:
    """Kronecker delta: the exact root displacements are the nodal values; the beam's antisymmetry
    about y = 0 (u_x odd, u_y even in y) holds in the discrete solution."""
    r = (solved if scheme == "paper" else default)[33, 9]
    case = benchmarks.load("cantilever")
    x, y = r.points[:, 0], r.points[:, 1]
    root = x == 0.0
    ex = case.problem.exact
    assert np.abs(r.u[root, 0] - ex.ux(x[root], y[root])).max() <= 1e-14
    assert np.abs(r.u[root, 1] - ex.uy(x[root], y[root])).max() <= 1e-14
    mirror = np.lexsort((-y, x))  # node order with y reversed within each column
    base = np.lexsort((y, x))
    scale = np.abs(r.u).max()
    assert np.abs(r.u[base, 0] + r.u[mirror, 0]).max() <= 1e-8 * scale
    assert np.abs(r.u[base, 1] - r.u[mirror, 1]).max() <= 1e-8 * scale


def test_geometry_boundary_gives_same_answer_on_a_rectangle(solved) -> None:
    """On a rectangle the tracked alpha shape is the exact boundary: swapping it changes nothing."""
    r = solve_ctmrpim(benchmarks.load("cantilever", ["method.boundary=\"geometry\"", PAPER]))
    assert r.probes["tip"]["uy"] == pytest.approx(solved[33, 9].probes["tip"]["uy"], rel=1e-12)


def _optional(solver: str):
    from ctmrpim.solvers.linear_solver import OPTIONAL, available

    return pytest.param(solver, marks=pytest.mark.skipif(not available(solver), reason=f"{OPTIONAL[solver]} is not "
                                                         "installed (pip install -e '.[solvers]'; CI installs it)"))


@pytest.mark.parametrize("solver", ["banded", "superlu", "spsolve", _optional("pardiso"), _optional("amg")])
@pytest.mark.parametrize("scheme", ["paper", "default"])
def test_linear_solvers_agree(solved, default, solver: str, scheme: str) -> None:
    reference, extra = (solved, [PAPER]) if scheme == "paper" else (default, [])
    r = solve_ctmrpim(benchmarks.load("cantilever", [f'method.solver="{solver}"', *extra]))
    assert r.probes["tip"]["uy"] == pytest.approx(reference[33, 9].probes["tip"]["uy"], rel=1e-9)


@pytest.mark.parametrize("polynomial", ["linear", "quadratic"])
def test_consistent_integration_converges_at_second_order(solutions, polynomial: str) -> None:
    """ctm-vci (quadratic correction): energy-norm rate >= 1.8 with either basis (the paper's CTM: about 1)."""
    h = np.array([48.0 / (g[0] - 1) for g in GRIDS])
    runs = [solutions("cantilever", [f"nodes.grid=[{g[0]}, {g[1]}]", f'method.polynomial="{polynomial}"', CONSISTENT])
            for g in GRIDS]
    check_rate("cantilever-vci-energy-rate", h, [r.errors["energy"] for r in runs])


def test_consistent_integration_quadratic_basis_33x9(solutions) -> None:
    r = solutions("cantilever", ["nodes.grid=[33, 9]", 'method.polynomial="quadratic"', CONSISTENT])
    check("cantilever-vci-quadratic-33x9-energy", r.errors["energy"])
    assert r.parameters["method"]["integration"] == "ctm-vci"     # the scheme is in the resolved input


def test_coarse_integration_still_recovers_stresses(solutions) -> None:
    """One integration point per d_c^2 (d_c/r = 1, Fig. 10's coarsest) leaves three points within 2 d_c of a
    corner: the recovery widens its reach there instead of failing the solve."""
    r = solutions("cantilever", ["nodes.grid=[17, 5]", "method.line_spacing=[1.0, 1.0]"])
    assert np.isfinite(r.stress).all() and np.isfinite(r.probes["root_top"]["sxx"])
