"""The consistent scheme in the total-Lagrangian solver (method.integration = "ctm-vci", formulation =
"total-lagrangian"): corrected test gradients on the reference configuration and the Dirichlet consistency term
with the first Piola traction of u_h. A large-deformation patch test (a homogeneous deformation F, neo-Hookean,
dead tractions P N on every other edge, the hole's and the re-entrant corner's included) is reproduced to
round-off; the paper's one-point CTM misses it by 3e-3 to 8e-3. The quarter ring moment comes closer."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from verify import check

from ctmrpim import benchmarks
from ctmrpim.materials.neo_hookean import NeoHookean
from ctmrpim.methods import solve
from ctmrpim.problem.reader import parse_case
from ctmrpim.reference import elastica

E, NU = 1000.0, 0.3
F = np.array([[1.2, 0.1], [0.05, 0.9]])            # stretch, shear and compression together
EDGES = {
    "plain": [("x == 2", (1, 0)), ("y == 2", (0, 1)), ("y == 0", (0, -1))],
    "hole": [("x == 2", (1, 0)), ("y == 2", (0, 1)), ("y == 0", (0, -1)),
             ("x == 0.8 and y >= 0.8 and y <= 1.2", (1, 0)), ("x == 1.2 and y >= 0.8 and y <= 1.2", (-1, 0)),
             ("y == 0.8 and x >= 0.8 and x <= 1.2", (0, 1)), ("y == 1.2 and x >= 0.8 and x <= 1.2", (0, -1))],
    "L": [("x == 2", (1, 0)), ("y == 2 and x <= 1", (0, 1)), ("y == 0", (0, -1)), ("y == 1 and x >= 1", (0, 1)),
          ("x == 1 and y >= 1", (1, 0))],
}
GEOMETRY = {"plain": {"add": [{"rectangle": [0, 0, 2, 2]}]},
            "hole": {"add": [{"rectangle": [0, 0, 2, 2]}], "subtract": [{"rectangle": [0.8, 0.8, 1.2, 1.2]}]},
            "L": {"add": [{"polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}]}}


def homogeneous_case(kind: str, scheme: str):
    """``kind`` of body deformed homogeneously by F: x = 0 prescribed, the traction P N on the other edges."""
    P = NeoHookean(E, NU).stress_tangent(F[None])[0][0]
    num = lambda v: f"{float(v):.17g}"
    tractions = [{"where": w, "tx": num((P @ n)[0]), "ty": num((P @ n)[1])} for w, n in EDGES[kind]]
    raw = {"problem": {"name": f"homogeneous-{kind}", "analysis": "quasi-static", "plane": "strain"},
           "geometry": GEOMETRY[kind], "nodes": {"spacing": 0.1},
           "material": {"model": "neo-hookean", "E": E, "nu": NU}, "loading": {"steps": 4},
           "method": {"formulation": "total-lagrangian", "integration": scheme},
           "constraint": [{"where": "x == 0", "ux": f"{num(F[0, 0] - 1)}*x + {num(F[0, 1])}*y",
                           "uy": f"{num(F[1, 0])}*x + {num(F[1, 1] - 1)}*y"}],
           "traction": tractions}
    return parse_case(raw, f"homogeneous-{kind}", Path("."))


@pytest.mark.parametrize("kind", ["plain", "hole", "L"])
def test_large_deformation_patch(kind: str) -> None:
    errors = {}
    for scheme in ("ctm-vci", "ctm"):
        r = solve(homogeneous_case(kind, scheme))
        exact = r.points @ (F - np.eye(2)).T
        errors[scheme] = float(np.abs(r.u - exact).max() / np.abs(exact).max())
    print(f"{kind}: largest nodal error / largest displacement: ctm-vci {errors['ctm-vci']:.1e}, "
          f"paper's ctm {errors['ctm']:.1e}")
    check("patch-large-deformation-tl-vci", errors["ctm-vci"])
    assert errors["ctm"] > 1e-3                 # the paper's scheme is not consistent


@pytest.mark.slow
def test_quarter_ring_moment_comes_closer() -> None:
    L = 10.0
    ex, ey = elastica.end_moment_tip(2 * np.pi * 0.25)
    distance = {}
    for scheme in ("ctm-vci", "ctm"):
        r = solve(benchmarks.load("end-moment", ['method.formulation="total-lagrangian"',
                                                 f'method.integration="{scheme}"']))
        x, y = 1.0 + r.probes["tip"]["ux"] / L, r.probes["tip"]["uy"] / L
        distance[scheme] = float(np.hypot(x - ex, y - ey))
    print(f"quarter ring moment, tip distance / L: ctm-vci {distance['ctm-vci']:.4f}, ctm {distance['ctm']:.4f}")
    check("end-moment-tl-quarter", distance["ctm-vci"])
    assert distance["ctm-vci"] < distance["ctm"]
