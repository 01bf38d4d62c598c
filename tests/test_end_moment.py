"""Cantilever under a follower end moment (paper Figs. 16-17): total-Lagrangian CTM-RPIM against the
exact circular arc; follower loads and their stiffness."""
from __future__ import annotations

import numpy as np
import pytest
from verify import check

from ctmrpim import benchmarks, elastica
from ctmrpim.errors import ProblemError
from ctmrpim.solvers import solve

L = 10.0


def test_quarter_ring_moment_against_the_exact_arc() -> None:
    r = solve(benchmarks.load("end-moment", ["parameters.m=0.25", "loading.steps=8", 'method.formulation="total-lagrangian"']))
    x, y = 1.0 + r.probes["tip"]["ux"] / L, r.probes["tip"]["uy"] / L
    ex, ey = elastica.end_moment_tip(2 * np.pi * 0.25)
    check("end-moment-tl-quarter", float(np.hypot(x - ex, y - ey)))
    assert r.counts["cutbacks"] == 0


def test_follower_loads_need_a_large_deformation_analysis() -> None:
    with pytest.raises(ProblemError, match="follower loads need"):
        benchmarks.load("end-moment", ['problem.analysis="linear"', 'material.model="linear-elastic"'])
