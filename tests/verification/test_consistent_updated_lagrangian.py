"""The consistent scheme in the adaptive updated-Lagrangian solver (method.integration = "ctm-vci"): corrected test
gradients on every rebuilt configuration and the Dirichlet consistency term with the traction of the stress
recovered at the boundary's Gauss points (the state lives at the points).

Two homogeneous large deformations F (neo-Hookean, plain plate, plate with a square hole, L-shape):
- tractions P(F) N on every other edge: the exact field balances the discrete equations on the reference
  configuration to round-off (a load-stepped run is not a patch test here: the loads grow in proportion, so the
  intermediate states are not homogeneous, and the updated-Lagrangian state carries their error on);
- every edge prescribed, u = lambda (F - I) X: every intermediate state is homogeneous, so the solution is exact
  through the rebuilds and state transfers of eight increments.
The paper's one-point CTM misses both by 1e-3 or more."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from test_consistent_total_lagrangian import EDGES, GEOMETRY, F, homogeneous_case
from verify import check

from ctmrpim.methods import solve
from ctmrpim.problem.reader import parse_case
from ctmrpim.solvers.updated_lagrangian import adaptive_body

SCHEMES = ("ctm-vci", "ctm")


def _updated(case):
    return dataclasses.replace(case, method=dataclasses.replace(case.method, formulation="updated-lagrangian"))


@pytest.mark.parametrize("kind", ["plain", "hole", "L"])
def test_the_exact_field_balances_on_the_reference_configuration(kind: str) -> None:
    residual = {}
    for scheme in SCHEMES:
        body, tags = adaptive_body(_updated(homogeneous_case(kind, scheme)))
        U = (body.X @ (F - np.eye(2)).T).ravel()
        f_ext, f_int, _ = body.trial(U, 1.0)
        free = np.ones(len(U), bool)
        free[tags.fixed] = False
        residual[scheme] = float(np.abs((f_ext - f_int)[free]).max() / np.abs(f_ext).max())
    print(f"{kind}: largest free residual of the exact field / largest load: ctm-vci {residual['ctm-vci']:.1e}, "
          f"paper's ctm {residual['ctm']:.1e}")
    check("residual-large-deformation-ul-vci", residual["ctm-vci"])
    assert residual["ctm"] > 1e-3


def dirichlet_case(kind: str, scheme: str, steps: int = 8):
    """``kind`` of body with u = (F - I) X prescribed on every edge, updated-Lagrangian, ``steps`` increments."""
    num = lambda v: f"{float(v):.17g}"
    ux, uy = f"{num(F[0, 0] - 1)}*x + {num(F[0, 1])}*y", f"{num(F[1, 0])}*x + {num(F[1, 1] - 1)}*y"
    raw = {"problem": {"name": f"dirichlet-{kind}", "analysis": "quasi-static", "plane": "strain"},
           "geometry": GEOMETRY[kind], "nodes": {"spacing": 0.1},
           "material": {"model": "neo-hookean", "E": 1000.0, "nu": 0.3}, "loading": {"steps": steps},
           "method": {"formulation": "updated-lagrangian", "integration": scheme},
           "constraint": [{"where": w, "ux": ux, "uy": uy} for w in ["x == 0", *(w for w, _ in EDGES[kind])]]}
    return parse_case(raw, f"dirichlet-{kind}", Path("."))


@pytest.mark.parametrize("kind", ["hole", "L"])
def test_homogeneous_deformation_through_rebuilds(kind: str) -> None:
    errors = {}
    for scheme in SCHEMES:
        r = solve(dirichlet_case(kind, scheme))
        exact = r.points @ (F - np.eye(2)).T
        errors[scheme] = float(np.abs(r.u - exact).max() / np.abs(exact).max())
        assert r.counts["rebuilds"] == 7 and r.counts["state_transfers"] == 7
    print(f"{kind}: largest nodal error / largest displacement after 7 rebuilds: ctm-vci {errors['ctm-vci']:.1e}, "
          f"paper's ctm {errors['ctm']:.1e}")
    check("patch-large-deformation-ul-vci", errors["ctm-vci"])
    assert errors["ctm"] > 1e-3
