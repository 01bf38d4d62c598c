"""The lumped mass of the explicit solver (ctmrpim.discretisation.lumped_mass)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from clouds import QUICK_COLUMN as QUICK

from ctmrpim import benchmarks
from ctmrpim.discretisation.lumped_mass import lumped_mass
from ctmrpim.errors import ProblemError
from ctmrpim.solvers.explicit.run import ExplicitRun


def test_lumped_mass_is_positive_and_sums_to_the_body_mass():
    case = benchmarks.load("column-collapse", QUICK)
    run = ExplicitRun(case, Path("unused"), "key")
    assert (run.mass > 0).all()
    assert run.mass.sum() == pytest.approx(2650.0 * 0.2 * 0.1, rel=1e-12)   # the grid's alpha shape is the rectangle
    with pytest.raises(ProblemError, match="density"):
        lumped_mass(run.X, np.array([[0, 1, 2]]), 0.0, 1.0)
