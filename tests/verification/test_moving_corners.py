"""Corners on a moving cloud: the updated-Lagrangian solver carries the reference triangulation (corners
kept) while it stays valid, where the alpha shape of the moved nodes cuts a re-entrant corner with a
triangle across the notch. An L-shape turned through 90 degrees by its prescribed edge (neo-Hookean,
eight increments, a rebuild after each), a stepped column's corner in the explicit solver and the sliding slope's toe."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ctmrpim.discretisation.alpha_shape import alpha_shape, carried_boundary
from ctmrpim.methods import solve
from ctmrpim.problem.reader import parse_case

L_SHAPE = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
TURN = "pi/2"


def l_rotation(steps: int = 8):
    raw = {"problem": {"name": "L-rotation", "analysis": "quasi-static", "plane": "strain"},
           "geometry": {"add": [{"polygon": L_SHAPE}]}, "nodes": {"spacing": 0.125},
           "material": {"model": "neo-hookean", "E": 1000.0, "nu": 0.3}, "loading": {"steps": steps},
           "constraint": [{"where": "x == 0", "ux": f"(cos({TURN}) - 1)*x - sin({TURN})*y",
                           "uy": f"sin({TURN})*x + (cos({TURN}) - 1)*y"}],
           "probe": [{"name": "tip", "at": [2, 0]}, {"name": "corner", "at": [1, 1]}]}
    return parse_case(raw, "L-rotation", Path("."))


@pytest.fixture(scope="module")
def turned():
    return solve(l_rotation())


def test_the_re_entrant_corner_stays_a_boundary_vertex(turned) -> None:
    corner = int(np.argmin(np.hypot(turned.points[:, 0] - 1, turned.points[:, 1] - 1)))
    assert len(turned.series) >= 8                              # eight increments (and any cut-back's)
    for step in turned.series:
        assert corner in set(step["boundary"].ravel().tolist())
    tracked = turned.counts["boundaries_tracked"]
    assert tracked["alpha_shape"] == 0 and tracked["carried"] == turned.counts["rebuilds"] + 1
    assert turned.counts["tracked_area"]["initial"] == pytest.approx(3.0, rel=1e-12)


def test_the_body_ends_turned_rigidly(turned) -> None:
    """The end state is a rigid quarter turn (stress-free for an objective material): (2, 0) -> (0, 2), the corner
    (1, 1) -> (-1, 1); the area comes back to 3 within the discretisation's error."""
    tip, corner = turned.probes["tip"], turned.probes["corner"]
    assert (tip["ux"], tip["uy"]) == pytest.approx((-2.0, 2.0), abs=2e-3)
    assert (corner["ux"], corner["uy"]) == pytest.approx((-2.0, 0.0), abs=2e-3)
    assert turned.counts["tracked_area"]["final"] == pytest.approx(3.0, rel=0.005)


def test_alpha_shape_of_the_turned_cloud_cuts_the_corner_the_carried_one_keeps() -> None:
    """The reason for carrying: on the same moved nodes the alpha shape spans the notch."""
    case = l_rotation()
    from ctmrpim.discretisation.configuration import reference_cloud
    from ctmrpim.timing import Timer
    cloud = reference_cloud(case, Timer())
    X = cloud.nodes
    c, s = np.cos(np.pi / 3), np.sin(np.pi / 3)
    x = X @ np.array([[c, s], [-s, c]])                          # turned by 60 degrees
    carried = carried_boundary(x, cloud.boundary.triangles, X, cloud.lengths.alpha)
    alpha = alpha_shape(x, cloud.lengths.alpha, cloud.d_c)
    corner = int(np.argmin(np.hypot(X[:, 0] - 1, X[:, 1] - 1)))
    assert carried is not None and corner in set(carried.edges.ravel().tolist())
    assert carried.area == pytest.approx(3.0, rel=1e-12)
    assert corner not in set(alpha.edges.ravel().tolist()) and alpha.area > 3.0


def test_a_folded_triangulation_is_not_carried() -> None:
    X = np.array([[0, 0], [1, 0], [0, 1], [1, 1.0]])
    tri = np.array([[0, 1, 3], [0, 3, 2]])
    x = X.copy()
    x[3] = [-0.5, -0.5]                                           # node 3 pushed through the opposite edge
    assert carried_boundary(X, tri, X, 2.0) is not None
    assert carried_boundary(x, tri, X, 2.0) is None


def test_the_explicit_solver_keeps_a_stepped_columns_corner(tmp_path) -> None:
    """The explicit solver's first frame and its re-layings carry the reference triangulation while valid: a
    stepped column (an L of granular material against the walls) keeps its re-entrant corner, which the alpha
    shape of the same nodes cuts."""
    from ctmrpim import benchmarks
    from ctmrpim.solvers.explicit.run import ExplicitRun

    step = 'geometry.add=[{polygon = [[0, 0], [0.2, 0], [0.2, 0.05], [0.1, 0.05], [0.1, 0.1], [0, 0.1]]}]'
    run = ExplicitRun(benchmarks.load("column-collapse", ["nodes.grid=[21, 11]", step]), tmp_path, "key")
    run.dropped_points = 0
    frame = run.lay_frame(run.X, np.zeros(len(run.X), bool))
    corner = int(np.argmin(np.hypot(run.X[:, 0] - 0.1, run.X[:, 1] - 0.05)))
    assert corner in set(frame.boundary.edges.ravel().tolist())
    assert frame.boundary.area == pytest.approx(0.015, rel=1e-12) and run.tracking == [1, 0]
    alpha = alpha_shape(run.X, run.lengths.alpha, run.d_c)
    assert corner not in set(alpha.edges.ravel().tolist()) and alpha.area > 0.015


@pytest.mark.slow
def test_the_sliding_slope_keeps_its_toe(tmp_path) -> None:
    """The slope sliding at SRF 1.6 (slope-slide on a coarse cloud, 4 s): the re-entrant toe (40, 5) stays a
    vertex of the tracked boundary, where the alpha shape of the moved nodes cuts it."""
    from ctmrpim import benchmarks
    from ctmrpim.solvers.explicit.run import ExplicitRun

    case = benchmarks.load("slope-slide", ["parameters.h=1.0", "explicit.duration=4.0", "explicit.save_every=4.0"])
    run = ExplicitRun(case, tmp_path, "key")
    run.start()
    run.run(progress=False)
    toe = int(np.argmin(np.hypot(run.X[:, 0] - 40.0, run.X[:, 1] - 5.0)))
    assert np.hypot(*(run.x[toe] - run.X[toe])) > 0.1            # the toe has moved with the slide
    assert toe in set(run.frame.boundary.edges.ravel().tolist()) and run.tracking[1] == 0
    assert toe not in set(alpha_shape(run.x, run.lengths.alpha, run.d_c).edges.ravel().tolist())
