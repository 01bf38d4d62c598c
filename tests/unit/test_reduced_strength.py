"""Strength reduction's pieces (ctmrpim.solvers.strength_reduction): the reduced strength of Eqs. 38-39
(tension cut-off included) and the bracket of a list of levels."""
from __future__ import annotations

import math

import pytest

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.solvers.strength_reduction import bracket, reduced


def test_reduced_strength_follows_eqs_38_39() -> None:
    m = MohrCoulomb(E=1e8, nu=0.3, c=1e4, phi=20.0, psi=10.0)
    r = reduced(m, 1.6)
    assert r.c == pytest.approx(1e4 / 1.6)
    assert math.tan(math.radians(r.phi)) == pytest.approx(math.tan(math.radians(20.0)) / 1.6)
    assert math.tan(math.radians(r.psi)) == pytest.approx(math.tan(math.radians(10.0)) / 1.6)
    assert (r.E, r.nu) == (m.E, m.nu)


def test_bracket_takes_the_largest_stable_below_the_smallest_failed() -> None:
    from ctmrpim.solvers.strength_reduction import Level
    levels = [Level(s, ok, 0, 0, 0.0, ()) for s, ok in [(1.0, True), (1.4, False), (1.3, True), (1.5, True)]]
    assert bracket(levels) == (1.3, 1.4)
    assert bracket(levels[:1]) == (1.0, None)


def test_tension_cut_off_is_read_and_reduced_with_the_strength() -> None:
    case = benchmarks.load("slope", ["material.tension=2e3"])
    assert case.problem.material.tension == 2e3 and case.resolved["material"]["tension"] == 2e3
    assert reduced(case.problem.material, 2.0).tension == 1e3
    with pytest.raises(ProblemError, match="material.tension"):
        benchmarks.load("slope", ["material.tension=-1"])
