"""Gravity as a body force (density x gravity): the column under its own weight (benchmark self-weight)
against the exact oedometric solution, by CTM-RPIM, scikit-fem P2, and the small-strain Mohr-Coulomb
solver while it stays elastic (the K0 state it will start the slope and footing from)."""
from __future__ import annotations

import numpy as np
import pytest
from verify import check

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.methods import solve


def test_self_weight_ctmrpim_and_fem(solutions) -> None:
    case = benchmarks.load("self-weight")
    check("self-weight-ctmrpim-top", solutions(case).errors["probes"]["top"]["uy"])
    check("self-weight-fem-p2-top", solve(case, "fem", "p2").errors["probes"]["top"]["uy"])


@pytest.mark.filterwarnings(r"ignore:\[exact\] is not compared:UserWarning")
def test_mohr_coulomb_column_under_gravity_stays_elastic_and_matches(solutions) -> None:
    """A strong Mohr-Coulomb column takes the same K0 state as the linear solve, in one increment."""
    elastic = solutions("self-weight", ['method.integration="ctm"'])     # the plastic solvers' scheme
    case = benchmarks.load("self-weight", ['problem.analysis="quasi-static"', 'material.model="mohr-coulomb"',
                                           "material.c=1e7", "material.phi=30", "loading.steps=1"])
    plastic = solve(case)
    assert plastic.counts["plastic_points"] == 0
    assert np.abs(plastic.u - elastic.u).max() <= 1e-9 * np.abs(elastic.u).max()


def test_gravity_is_refused_where_it_is_not_implemented() -> None:
    with pytest.raises(ProblemError, match="gravity"):
        solve(benchmarks.load("tip-load", ["problem.gravity=[0, -9.81]", "material.density=1000",
                                           "parameters.lam=0.1", "loading.steps=1"]))
