"""Plate with a circular hole (Kirsch): holes, curved boundaries, plane stress and plane strain."""
from __future__ import annotations

import pytest
from verify import check

from ctmrpim.solvers.linear_static import solve_ctmrpim
from reference_fem import solve_fem
from studies.plate_hole_convergence import PLANES, case


@pytest.fixture(scope="module", params=sorted(PLANES))
def solved(request):
    return {h: solve_ctmrpim(case(request.param, h)) for h in (0.5, 0.25)}, solve_fem(case(request.param, 0.25), "p2")


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
