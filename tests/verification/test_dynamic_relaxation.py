"""Dynamic relaxation (Eq. 11) comes to rest at the elastic solution of the same discretisation."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse.linalg import spsolve

from ctmrpim import benchmarks
from ctmrpim.solvers.elastoplastic import ctm_plastic_system
from ctmrpim.timing import Timer


@pytest.mark.filterwarnings(r"ignore:\[exact\] is not compared:UserWarning")
def test_dynamic_relaxation_comes_to_rest_at_the_elastic_solution() -> None:
    """A strong Mohr-Coulomb column under its own weight stays elastic: relaxed to rest it matches the
    linear solve of the same CTM-RPIM discretisation (the exact K0 column within the method's error)."""
    from ctmrpim.problem.settings import Relaxation
    from ctmrpim.solvers.dynamic_relaxation import relax, relaxation_mass
    case = benchmarks.load("self-weight", ['problem.analysis="dynamic"', 'material.model="mohr-coulomb"',
                                           "material.c=1e9", "material.phi=30"])
    system = ctm_plastic_system(case, Timer())[0]
    assert np.all(relaxation_mass(system) > 0)
    path = relax(system, case.problem.material, 1.0, Relaxation(steps=20000, tolerance=1e-8))
    assert path.at_rest
    K = system.elastic_stiffness()
    U = np.zeros(K.shape[0])
    free = system.free
    U[free] = spsolve(K[free][:, free].tocsc(), system.external_force(1.0)[free])
    assert np.abs(system.U - U).max() < 1e-6 * np.abs(U).max()
