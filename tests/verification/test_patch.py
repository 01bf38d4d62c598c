"""Patch tests: a linear (and a quadratic) displacement field reproduced on a plain plate, a plate with a
square hole, an L-shape with a re-entrant corner and an irregular cloud, every other edge loaded with the
exact traction (the hole's and the corner's edges too), the left edge prescribed.

With ``method.integration = "ctm-vci"`` the Galerkin solution reproduces the field to round-off; the
paper's one-point CTM does not (its integration constraint fails), and its errors are printed beside.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from manufactured import exact_traction
from verify import check

import ctmrpim
from ctmrpim.problem.reader import parse_case

E, NU = 1000.0, 0.25
A = E / (1 - NU**2)               # plane stress
G = E / (2 * (1 + NU))
#: a constant-stress field: u, v and sxx, syy, sxy as expressions
LINEAR = {"c": 1.0}
EXX, EYY, GXY = (1.0 - NU * 0.5) / E, (0.5 - NU * 1.0) / E, 2 * (1 + NU) * 0.25 / E
LINEAR_FIELD = {"ux": f"{EXX}*x + {GXY / 2}*y", "uy": f"{GXY / 2}*x + {EYY}*y",
                "sxx": "1.0 + 0*x", "syy": "0.5 + 0*x", "sxy": "0.25 + 0*x"}
#: a quadratic field u = c x y, v = 0: linear stresses, a constant body force (gravity of a unit density)
C = 1e-3
QUADRATIC_FIELD = {"ux": f"{C}*x*y", "uy": "0*x", "sxx": f"{A * C}*y", "syy": f"{NU * A * C}*y", "sxy": f"{G * C}*x"}
QUADRATIC_GRAVITY = [0.0, -(G * C + NU * A * C)]


def _edges(kind: str) -> list[tuple[str, float, float]]:
    outer = [("x == 2", 1, 0), ("y == 2", 0, 1), ("y == 0", 0, -1)]
    if kind == "L":
        return [("x == 2", 1, 0), ("y == 2 and x <= 1", 0, 1), ("y == 0", 0, -1), ("y == 1 and x >= 1", 0, 1),
                ("x == 1 and y >= 1", 1, 0)]
    if kind == "hole":
        return outer + [("x == 0.8 and y >= 0.8 and y <= 1.2", 1, 0), ("x == 1.2 and y >= 0.8 and y <= 1.2", -1, 0),
                        ("y == 0.8 and x >= 0.8 and x <= 1.2", 0, 1), ("y == 1.2 and x >= 0.8 and x <= 1.2", 0, -1)]
    return outer


def patch_case(kind: str, field: dict, method: dict, nodes: dict | None = None, gravity=(0.0, 0.0)):
    """The patch test ``kind`` ("plain", "hole", "L") of ``field`` on a 0.1 spacing, with ``method`` settings."""
    geometry = {"add": [{"rectangle": [0, 0, 2, 2]}]}
    if kind == "hole":
        geometry["subtract"] = [{"rectangle": [0.8, 0.8, 1.2, 1.2]}]
    if kind == "L":
        geometry = {"add": [{"polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}]}
    raw = {"problem": {"name": f"patch-{kind}", "plane": "stress", "gravity": list(gravity)},
           "geometry": geometry, "nodes": nodes or {"spacing": 0.1},
           "material": {"model": "linear-elastic", "E": E, "nu": NU, "density": 1.0 if any(gravity) else 0.0},
           "constraint": [{"where": "x == 0", "ux": field["ux"], "uy": field["uy"]}],
           "traction": [exact_traction(w, nx, ny, field) for w, nx, ny in _edges(kind)],
           "exact": dict(field), "method": dict(method)}
    return parse_case(raw, f"patch-{kind}", Path("."))


def irregular_nodes(folder: Path) -> dict:
    """A cloud of the plain plate with every interior node moved by up to 30 % of the spacing."""
    h = 0.1
    x, y = np.meshgrid(np.linspace(0, 2, 21), np.linspace(0, 2, 21))
    xy = np.c_[x.ravel(), y.ravel()]
    inner = (xy > 1e-9).all(axis=1) & (xy < 2 - 1e-9).all(axis=1)
    xy[inner] += np.random.default_rng(7).uniform(-0.3 * h, 0.3 * h, (inner.sum(), 2))
    path = folder / "cloud.csv"
    np.savetxt(path, xy, delimiter=",", header="x,y", comments="")
    return {"file": str(path)}


VCI = {"integration": "ctm-vci", "correction": "quadratic"}
PAPER = {"integration": "ctm"}


@pytest.mark.parametrize("kind", ["plain", "hole", "L", "irregular"])
@pytest.mark.parametrize("correction", ["linear", "quadratic"])
def test_linear_patch(kind: str, correction: str, tmp_path: Path) -> None:
    nodes = irregular_nodes(tmp_path) if kind == "irregular" else None
    geometry = "plain" if kind == "irregular" else kind
    r = ctmrpim.solve(patch_case(geometry, LINEAR_FIELD, {**VCI, "correction": correction}, nodes))
    paper = ctmrpim.solve(patch_case(geometry, LINEAR_FIELD, PAPER, nodes))
    print(f"{kind}: ctm-vci ({correction}) L2 {r.errors['l2']:.2e}, energy {r.errors['energy']:.2e}; "
          f"paper's ctm L2 {paper.errors['l2']:.2e}, energy {paper.errors['energy']:.2e}")
    check("patch-linear-ctm-vci", max(r.errors["l2"], r.errors["energy"]))


@pytest.mark.parametrize("kind", ["plain", "hole"])
def test_quadratic_patch(kind: str) -> None:
    method = {**VCI, "polynomial": "quadratic"}
    r = ctmrpim.solve(patch_case(kind, QUADRATIC_FIELD, method, gravity=QUADRATIC_GRAVITY))
    paper = ctmrpim.solve(patch_case(kind, QUADRATIC_FIELD, {**PAPER, "polynomial": "quadratic"},
                                     gravity=QUADRATIC_GRAVITY))
    print(f"{kind}: ctm-vci L2 {r.errors['l2']:.2e}, energy {r.errors['energy']:.2e}; "
          f"paper's ctm L2 {paper.errors['l2']:.2e}, energy {paper.errors['energy']:.2e}")
    check("patch-quadratic-ctm-vci", max(r.errors["l2"], r.errors["energy"]))


def test_re_entrant_corner_is_a_boundary_vertex() -> None:
    """The tracked boundary of the L-shape keeps the corner node (1, 1) and encloses the exact area."""
    r = ctmrpim.solve(patch_case("L", LINEAR_FIELD, {}))      # the default: ctm-vci, exact to round-off
    check("patch-linear-ctm-vci", max(r.errors["l2"], r.errors["energy"]))
    corner = int(np.argmin(np.hypot(r.points[:, 0] - 1, r.points[:, 1] - 1)))
    edges = r.cells[0][1]
    assert corner in set(edges.ravel().tolist())
    assert r.parameters["derived"]["tracked_area"] == pytest.approx(3.0, rel=1e-12)
