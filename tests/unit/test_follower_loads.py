"""Follower tractions: where they are allowed, the values of `follower`, and the face-turning couple
(no net force, turns rigidly, a load stiffness)."""
from __future__ import annotations

import numpy as np
import pytest

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError

L = 10.0


def test_follower_loads_need_a_large_deformation_analysis() -> None:
    with pytest.raises(ProblemError, match="follower loads need"):
        benchmarks.load("end-moment", ['problem.analysis="linear"', 'material.model="linear-elastic"'])


def test_face_follower_tractions_stay_a_couple() -> None:
    """follower = "face": both half-face tractions turn with the chord of the whole end face, so at
    any displacement their nodal forces sum to zero (a pure couple) and turn rigidly."""
    from ctmrpim.discretisation.boundary_loads import reference_loads
    from ctmrpim.discretisation.configuration import boundary_tags, reference_configuration
    from ctmrpim.timing import Timer

    case = benchmarks.load("end-moment", ["parameters.m=0.25"])
    conf = reference_configuration(case, Timer())
    tags = boundary_tags(case, conf.x, conf.boundary, conf.lengths)
    X, q = conf.x, tags.traction
    corners = {int(np.argmin(np.hypot(X[:, 0] - L, X[:, 1] - y))) for y in (-0.25, 0.25)}
    assert {frozenset(map(int, pair)) for pair in q.turn_ends} == {frozenset(corners)}
    loads = reference_loads(conf, tags, 1.0, np.zeros(X.size))
    F0, _ = loads.forces(X, 1.0)
    rng = np.random.default_rng(0)
    theta = 1.1
    R = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    x = (X @ R.T) + 0.01 * rng.standard_normal(X.shape) * (X[:, :1] < L - 1.0)   # rotate, perturb the inside
    F, K = loads.forces(x, 1.0)
    scale = np.abs(F).max()
    assert np.abs(F.reshape(-1, 2).sum(axis=0)).max() <= 1e-12 * scale        # no net force
    assert np.abs(F.reshape(-1, 2) - F0.reshape(-1, 2) @ R.T).max() <= 1e-9 * scale   # turned rigidly
    assert K is not None


@pytest.mark.parametrize("value, ok", [(True, True), ("segment", True), ("face", True), ("diagonal", False), (1, False)])
def test_follower_values(value, ok: bool) -> None:
    import tomllib

    from ctmrpim.problem.reader import parse_case

    raw = tomllib.loads(benchmarks.path("end-moment").read_text())
    raw["traction"][0]["follower"] = value
    if ok:
        case = parse_case(raw, "end-moment", benchmarks.FOLDER, [])
        assert case.problem.tractions[0].turn == ("face" if value == "face" else "segment")
    else:
        with pytest.raises(ProblemError, match="must be false, true"):
            parse_case(raw, "end-moment", benchmarks.FOLDER, [])
