"""The integration comparators of CTM (not in the paper): stabilised conforming nodal integration ("scni")
and background cells clipped by the boundary ("cell-gauss"). SCNI passes the linear patch tests to
round-off and converges; background cells integrate polynomials exactly on cut cells but not RPIM's shape
functions, so their patch-test error stays at 1e-3 whatever the Gauss order (printed, asserted as a floor)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import shapely
from test_patch import LINEAR_FIELD, irregular_nodes, patch_case
from verify import check, check_rate

import ctmrpim
from ctmrpim import benchmarks
from ctmrpim.discretisation.background_cells import cell_points
from ctmrpim.discretisation.nodal_integration import smoothing_cells


@pytest.mark.parametrize("kind", ["plain", "hole", "L", "irregular"])
def test_scni_linear_patch(kind: str, tmp_path: Path) -> None:
    nodes = irregular_nodes(tmp_path) if kind == "irregular" else None
    geometry = "plain" if kind == "irregular" else kind
    r = ctmrpim.solve(patch_case(geometry, LINEAR_FIELD, {"integration": "scni"}, nodes))
    cells = ctmrpim.solve(patch_case(geometry, LINEAR_FIELD, {"integration": "cell-gauss", "gauss_points": 3,
                                                              "line_spacing": [1, 1]}, nodes))
    print(f"{kind}: scni L2 {r.errors['l2']:.2e}, energy {r.errors['energy']:.2e}; cell-gauss (d_c cells, 3 x 3) "
          f"L2 {cells.errors['l2']:.2e}, energy {cells.errors['energy']:.2e}")
    check("patch-linear-scni", max(r.errors["l2"], r.errors["energy"]))
    assert r.counts["integration_points"] == r.counts["nodes"]
    # the background cells' inconsistency: not repaired by more Gauss points
    assert cells.errors["energy"] > 1e-3


def test_scni_cantilever_converges() -> None:
    grids = [(17, 5), (33, 9), (65, 17)]
    runs = [ctmrpim.solve(benchmarks.load("cantilever", [f"nodes.grid=[{nx},{ny}]", 'method.integration="scni"']))
            for nx, ny in grids]
    energy = [r.errors["energy"] for r in runs]
    print("scni cantilever energy errors:", [f"{100 * e:.3g} %" for e in energy])
    check_rate("cantilever-scni-energy-rate", [48 / (nx - 1) for nx, _ in grids], energy)


def test_smoothing_cells_tile_the_body() -> None:
    square = np.array([[0, 0], [2, 0], [2, 2], [0, 2.0]])
    hole = np.array([[0.8, 0.8], [0.8, 1.2], [1.2, 1.2], [1.2, 0.8]])      # clockwise: a hole
    rng = np.random.default_rng(3)
    nodes = np.vstack([rng.uniform(0, 2, (200, 2)), square, hole])
    nodes = nodes[~((np.abs(nodes - 1.0) < 0.2 - 1e-12).all(axis=1))]
    cells = smoothing_cells(nodes, [square, hole])
    assert shapely.area(cells).sum() == pytest.approx(4.0 - 0.16, rel=1e-12)
    assert shapely.area(shapely.union_all(cells)) == pytest.approx(4.0 - 0.16, rel=1e-12)   # no overlaps


@pytest.mark.parametrize("gauss_points", [1, 2, 3])
def test_cut_cells_integrate_polynomials(gauss_points: int) -> None:
    """Cells cut by a triangular hole: area exact for every rule; x^2 and x y exact once the rule is of degree 2."""
    square = np.array([[0, 0], [4, 0], [4, 1], [0, 1.0]])
    hole = np.array([[1.6, 0.3], [1.3, 0.6], [1.0, 0.3]])
    p, w = cell_points([square, hole], 0.37, 0.29, gauss_points)
    assert w.sum() == pytest.approx(4 - 0.5 * 0.6 * 0.3, rel=1e-13)
    if gauss_points >= 2:
        # exact moments: the rectangle's minus the triangle's (vertices a, b, c: area/12 (sum + squares ...))
        a, b, c = hole
        area = 0.09
        xx_tri = area / 6 * (a[0]**2 + b[0]**2 + c[0]**2 + a[0] * b[0] + b[0] * c[0] + c[0] * a[0])
        assert (w * p[:, 0] ** 2).sum() == pytest.approx(64 / 3 - xx_tri, rel=1e-12)
