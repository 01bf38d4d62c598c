"""Plate with a circular hole (Kirsch): holes, curved boundaries, plane stress and plane strain; the paper's
scheme against its tolerances, the default (consistent) scheme against its own and the stress concentration."""
from __future__ import annotations

import pytest
from verify import check

from ctmrpim.solvers.linear_static import solve_ctmrpim
from reference_fem import solve_fem
from studies.plate_hole_convergence import PLANES, case
from studies.schemes import PAPER


@pytest.fixture(scope="module", params=sorted(PLANES))
def solved(request):
    """The paper's scheme at two spacings and P2 at the finer."""
    return ({h: solve_ctmrpim(case(request.param, h, PAPER)) for h in (0.5, 0.25)},
            solve_fem(case(request.param, 0.25), "p2"))


@pytest.fixture(scope="module", params=sorted(PLANES))
def default(request):
    """The default (consistent) scheme at three spacings."""
    return {h: solve_ctmrpim(case(request.param, h)) for h in (0.5, 0.25, 0.125)}


def test_default_scheme_accuracy(default) -> None:
    check("plate-hole-vci-energy", default[0.25].errors["energy"])
    energy = [default[h].errors["energy"] for h in (0.5, 0.25, 0.125)]
    assert energy[0] > energy[1] > energy[2]


def test_stress_concentration_converges(default) -> None:
    """sxx(0, a) = 3 T within 3 % at the default spacing and the next, recovered from the integration points;
    the change per halving of the spacing shrinks (measured 207 then 91 (stress), 204 then 77 (strain); the
    raw evaluation D B u at the node does not converge: 3059, 3203, 3247)."""
    s = [default[h].probes["hole_top"]["sxx"] for h in (0.5, 0.25, 0.125)]
    for value in s[1:]:
        check("plate-hole-stress-concentration", abs(value / 3000.0 - 1.0))
    assert abs(s[2] - s[1]) < abs(s[1] - s[0]) / 1.5


def test_ctmrpim_accuracy(solved) -> None:
    ours, _ = solved
    check("plate-hole-ctmrpim-energy", ours[0.25].errors["energy"])
    check("plate-hole-ctmrpim-l2", ours[0.25].errors["l2"])
    assert ours[0.25].errors["energy"] < ours[0.5].errors["energy"]
    assert ours[0.25].counts["boundary_loops"] == 1


def test_fem_reference(solved) -> None:
    _, fem = solved
    check("plate-hole-fem-p2-energy", fem.errors["energy"])


def test_hole_boundary_nodes_on_the_arc(solved) -> None:
    import numpy as np

    ours, _ = solved
    r = ours[0.25]
    radius = np.hypot(r.points[:, 0], r.points[:, 1])
    on_arc = np.abs(radius - 1.0) < 1e-3
    assert on_arc.sum() >= 6
    assert np.abs(radius[on_arc] - 1.0).max() < 1e-12
