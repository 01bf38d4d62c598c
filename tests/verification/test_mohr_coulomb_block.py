"""Small-strain Mohr-Coulomb CTM-RPIM (issue 5, first solver): a plane-strain block compressed between
smooth platens reaches the analytical uniaxial plateau, -2 c cos(phi) / (1 - sin(phi)) (Tresca: -2 c),
read as the reaction on the loaded face; the history is committed only at converged increments."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from verify import check

import ctmrpim.solvers.elastoplastic as elastoplastic
from ctmrpim.cases import load_case
from ctmrpim.timing import Timer

BLOCK = Path(__file__).parents[1] / "data" / "mc_block.toml"


def plateau_reaction(phi: float, psi: float, monkeypatch) -> tuple[float, float, object]:
    """The reaction on the loaded face at the end of the block's solve, its exact plateau and the Result: one
    solve, the reaction read from the plastic system that solve built (at its final, converged state)."""
    case = load_case(str(BLOCK), [f"parameters.phi={phi!r}", f"material.psi={psi!r}"])
    mat = case.problem.material
    built = []
    build = elastoplastic.ctm_plastic_system
    monkeypatch.setattr(elastoplastic, "ctm_plastic_system", lambda c, timer: built.append(build(c, timer)) or built[-1])
    result = elastoplastic.solve_elastoplastic(case)
    system = built[0][0]
    top = np.isclose(system_points(case), 1.0)
    reaction = -system.internal_force().reshape(-1, 2)[top, 1].sum()     # compressive force on the 1 m wide top
    exact = 2.0 * mat.c * math.cos(math.radians(phi)) / (1.0 - math.sin(math.radians(phi)))
    return reaction, exact, result


def system_points(case) -> np.ndarray:
    from ctmrpim.discretisation.configuration import reference_cloud
    return reference_cloud(case, Timer()).nodes[:, 1]


@pytest.mark.parametrize("phi, psi, key", [(0.001, 0.0, "mc-block-tresca-plateau"), (30.0, 0.0, "mc-block-plateau"),
                                           (30.0, 30.0, "mc-block-plateau-associated")])
def test_compressed_block_reaches_the_plateau(phi: float, psi: float, key: str, monkeypatch) -> None:
    reaction, exact, r = plateau_reaction(phi, psi, monkeypatch)
    check(key, abs(reaction / exact - 1.0))
    assert r.history[-1]["converged"] and r.history[-1]["plastic_points"] > 0
    assert r.counts["plastic_points"] == r.history[-1]["plastic_points"]
