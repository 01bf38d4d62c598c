"""Cantilever under a follower end moment (paper Figs. 16-17): total-Lagrangian CTM-RPIM and scikit-fem P2 against
the exact circular arc, a quarter ring (the quick end-moment study's cases: solved through the study cache)."""
from __future__ import annotations

import numpy as np
import pytest
from verify import check

from ctmrpim.reference import elastica
from studies.sweep import CaseSpec

L = 10.0
QUARTER = ("parameters.m=0.25", "loading.steps=8")


@pytest.fixture(scope="module")
def quarter(study_cases) -> dict[str, dict]:
    """The quarter ring by each method (summary.json), solved side by side."""
    ours, fem = study_cases(CaseSpec("end-moment", QUARTER + ('method.formulation="total-lagrangian"',)),
                            CaseSpec("end-moment", QUARTER, "fem", "p2"))
    return {"ctm-rpim": ours, "fem-p2": fem}


def test_quarter_ring_moment_against_the_exact_arc(quarter) -> None:
    r = quarter["ctm-rpim"]
    x, y = 1.0 + r["probes"]["tip"]["ux"] / L, r["probes"]["tip"]["uy"] / L
    ex, ey = elastica.end_moment_tip(2 * np.pi * 0.25)
    check("end-moment-tl-quarter", float(np.hypot(x - ex, y - ey)))
    assert r["counts"]["cutbacks"] == 0


def test_fem_p2_end_moment_with_face_followers(quarter) -> None:
    """The scikit-fem reference (reference_fem.hyperelastic) applies the same face-turning couple (rank-2 load
    stiffness)."""
    r = quarter["fem-p2"]
    x, y = 1.0 + r["probes"]["tip"]["ux"] / L, r["probes"]["tip"]["uy"] / L
    ex, ey = elastica.end_moment_tip(2 * np.pi * 0.25)
    check("end-moment-fem-p2-quarter", float(np.hypot(x - ex, y - ey)))
    assert r["counts"]["cutbacks"] == 0
