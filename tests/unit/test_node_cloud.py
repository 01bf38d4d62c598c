"""Node placement (ctmrpim.problem.node_cloud): tensor grids, spacing on curved boundaries, no clumps."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from ctmrpim import benchmarks
from ctmrpim.problem.geometry import Geometry, Shape
from ctmrpim.problem.node_cloud import NodeSpec, check_nodes_inside, make_nodes


def test_grid_on_a_rectangle_is_the_tensor_grid() -> None:
    case = benchmarks.load("cantilever", ["nodes.grid=[17,5]"])
    nodes = make_nodes(case.problem.geometry, case.nodes)
    assert nodes.shape == (85, 2)
    assert np.unique(nodes[:, 0]).tolist() == np.linspace(0, 48, 17).tolist()
    assert np.unique(nodes[:, 1]).tolist() == np.linspace(-6, 6, 5).tolist()


@pytest.mark.parametrize("h", [0.5, 0.25])
def test_spacing_on_a_plate_with_a_hole(h: float) -> None:
    r = 1.0
    g = Geometry(add=[Shape("rectangle", (-4.0, -4.0, 4.0, 4.0))], subtract=[Shape("circle", (0.0, 0.0, r))])
    nodes = make_nodes(g, NodeSpec(spacing=h))
    assert np.all(g.distance_outside(nodes) == 0.0)          # inside the body or on its boundary
    check_nodes_inside(g, nodes, tol=1e-12)                  # and no two coincide
    d = np.hypot(nodes[:, 0], nodes[:, 1])
    on_hole = d < r + 0.1 * h
    assert abs(on_hole.sum() - 2 * math.pi * r / h) <= 1
    assert np.abs(d[on_hole] - r).max() < 1e-12 * r          # exactly on the true arc, not on a chord
    # the interior grid keeps clear of the boundary nodes: no clumps
    gap, _ = cKDTree(nodes).query(nodes, k=2)
    assert gap[:, 1].min() > 0.4 * h
    assert len(nodes) > g.area / h**2


def test_boundary_nodes_on_a_large_arc_lie_on_it() -> None:
    """A spacing far below the radius: the sagitta (1e-5 r), not the spacing, bounds how far off the
    arc the polygon's points are, and the snapping must reach that far (it once used 1e-3 h)."""
    r, h = 1.0, 0.002
    g = Geometry(add=[Shape("rectangle", (0.0, 0.0, 0.1, 0.1))], subtract=[Shape("circle", (1.05, 0.05, r))])
    nodes = make_nodes(g, NodeSpec(spacing=h))
    d = np.hypot(nodes[:, 0] - 1.05, nodes[:, 1] - 0.05)
    on_arc = d < r + 0.1 * h
    assert on_arc.sum() > 40
    assert np.abs(d[on_arc] - r).max() < 1e-12 * r


def test_a_circle_tangent_to_a_rectangle_gives_no_coincident_nodes() -> None:
    """The union's polygon has two vertices a hair apart where the circle touches the rectangle's edge."""
    g = Geometry(add=[Shape("rectangle", (0.0, 0.0, 2.0, 1.0)), Shape("circle", (2.0, 0.5, 0.5))])
    nodes = make_nodes(g, NodeSpec(spacing=0.1))
    check_nodes_inside(g, nodes, tol=1e-3)


def test_a_node_set_without_a_corner_is_refused() -> None:
    """A corner that is not a node would be cut off by the tracked boundary: refused, naming the corner."""
    from ctmrpim.errors import ProblemError

    g = Geometry(add=[Shape("polygon", ((0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)))])
    nodes = make_nodes(g, NodeSpec(spacing=0.25))
    check_nodes_inside(g, nodes, tol=1e-3)
    without = nodes[np.hypot(nodes[:, 0] - 1.0, nodes[:, 1] - 1.0) > 1e-9]      # the re-entrant corner
    with pytest.raises(ProblemError, match=r"corner\(s\) of the geometry have no node, e\.g\. \(1, 1\)"):
        check_nodes_inside(g, without, tol=1e-3)


def test_a_hole_the_cloud_cannot_resolve_is_refused(tmp_path) -> None:
    """A hole narrower than the node spacing leaves one boundary loop: refused, never dropped silently."""
    import ctmrpim
    from ctmrpim.errors import ProblemError
    from ctmrpim.problem.reader import parse_case

    raw = {"problem": {"name": "p"}, "geometry": {"add": [{"rectangle": [0, 0, 2, 1]}],
                                                  "subtract": [{"circle": [1.0, 0.5, 0.02]}]},
           "nodes": {"spacing": 0.1}, "material": {"model": "linear-elastic", "E": 1000.0, "nu": 0.3},
           "constraint": [{"where": "x == 0", "ux": 0, "uy": 0}], "traction": [{"where": "x == 2", "tx": 1.0}]}
    with pytest.raises(ProblemError, match="the geometry has 2 boundary loops, the node cloud resolves 1"):
        ctmrpim.solve(parse_case(raw, "p", tmp_path))
    raw["geometry"]["subtract"][0]["circle"][2] = 0.12            # resolved: two loops
    assert ctmrpim.solve(parse_case(raw, "p", tmp_path)).counts["boundary_loops"] == 2


@pytest.mark.parametrize("spec", [NodeSpec(grid=(17, 9), jitter=0.4), NodeSpec(spacing=0.5, jitter=0.4, seed=3)])
def test_jitter_moves_interior_nodes_only_within_bounds(spec: NodeSpec) -> None:
    """An L-shape (re-entrant corner): boundary nodes stay, interior nodes move by at most jitter h per axis, keep
    JITTER_CLEARANCE h from the boundary, the tensor order is kept, and one seed gives one cloud."""
    from ctmrpim.problem.node_cloud import JITTER_CLEARANCE

    g = Geometry(add=[Shape("polygon", ((0.0, 0.0), (8.0, 0.0), (8.0, 4.0), (4.0, 4.0), (4.0, 8.0), (0.0, 8.0)))])
    plain = make_nodes(g, NodeSpec(grid=spec.grid, spacing=spec.spacing))
    moved = make_nodes(g, spec)
    h = np.array([8 / 16, 8 / 8]) if spec.grid else np.array([0.5, 0.5])
    step = moved - plain
    on_boundary = g.distance_to_boundary(plain) < 1e-12
    assert np.all(step[on_boundary] == 0.0)
    assert np.all(np.abs(step) <= spec.jitter * h + 1e-12)
    assert np.count_nonzero(step.any(axis=1)) > 0.8 * np.count_nonzero(~on_boundary)   # most moved
    assert np.all(g.distance_to_boundary(moved[~on_boundary]) > JITTER_CLEARANCE * h.min())
    assert np.all(g.distance_outside(moved) == 0.0)
    check_nodes_inside(g, moved, tol=1e-12)
    np.testing.assert_array_equal(make_nodes(g, spec), moved)
    other = make_nodes(g, NodeSpec(grid=spec.grid, spacing=spec.spacing, jitter=spec.jitter, seed=(spec.seed or 0) + 1))
    assert not np.array_equal(other, moved)


@pytest.mark.parametrize("kwargs, key", [({"grid": (5, 5), "jitter": 0.5}, "nodes.jitter"),
                                          ({"grid": (5, 5), "jitter": -0.1}, "nodes.jitter"),
                                          ({"file": "n.csv", "jitter": 0.2}, "nodes.jitter"),
                                          ({"grid": (5, 5), "seed": 2}, "nodes.seed")])
def test_jitter_settings_that_cannot_act_are_refused(kwargs: dict, key: str) -> None:
    from ctmrpim.errors import ProblemError

    with pytest.raises(ProblemError) as info:
        NodeSpec(**kwargs)
    assert info.value.key == key


def test_jitter_on_the_command_line_keeps_the_grid() -> None:
    """--set nodes.jitter=... adds to the file's grid (the placement keys alone replace each other)."""
    case = benchmarks.load("cantilever", ["nodes.grid=[17, 5]", "nodes.jitter=0.3", "nodes.seed=2"])
    assert case.nodes.grid == (17, 5) and case.nodes.jitter == 0.3 and case.nodes.seed == 2
    assert case.nodes.as_dict() == {"grid": [17, 5], "jitter": 0.3, "seed": 2}
    case = benchmarks.load("cantilever", ["nodes.jitter=0.3", "nodes.spacing=1.5"])
    assert case.nodes.grid is None and case.nodes.spacing == 1.5 and case.nodes.jitter == 0.3
