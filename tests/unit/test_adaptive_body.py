"""The adaptive updated-Lagrangian body: objectivity under a 90-degree rigid rotation applied in increments
through the whole rebuild cycle (re-tracked boundary, new CTM points, new RPIM shape functions, L2 state
transfer), with a prestress and neo-Hookean, and the L2 state transfer itself."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from ctmrpim.cases import load_case
from ctmrpim.discretisation.state_transfer import convex_average, local_bounds, project_to_nodes, transfer
from ctmrpim.solvers.updated_lagrangian import adaptive_body

E = 1.0e9
BLOCK = f"""
[problem]
name = "block"
analysis = "quasi-static"
plane = "strain"
[geometry]
add = [{{ rectangle = [0, 0, 2, 1] }}]
[nodes]
grid = [13, 7]
[material]
model = "MODEL"
E = {E}
nu = 0.3
[method]
formulation = "updated-lagrangian"
[[constraint]]
where = "x == 0"
ux = "0"
uy = "0"
"""
ROUND_OFF = 1e-9     # of E: stresses created by a rigid rotation, after all increments and rebuilds


def rotation(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


def body_of(tmp_path, model: str = "linear-elastic"):
    path = tmp_path / "block.toml"
    path.write_text(BLOCK.replace("MODEL", model))
    return adaptive_body(load_case(str(path), []))[0]


def rotate(body, degrees: float, increments: int) -> list[tuple[float, int]]:
    """Rotate the body rigidly about its centre in equal increments, committing (and so rebuilding)
    after each; returns the tracked area and loop count after each rebuild."""
    centre = body.X.mean(axis=0)
    seen = []
    for k in range(1, increments + 1):
        target = centre + (body.X - centre) @ rotation(np.radians(degrees * k / increments)).T
        body.commit((target - body.X).ravel())
        seen.append((body.areas[-1], len(body.boundary.loops)))
    return seen


def test_rigid_rotation_leaves_a_stress_free_body_stress_free(tmp_path) -> None:
    body = body_of(tmp_path)
    seen = rotate(body, 90.0, 9)
    assert body.rebuilds == 9 and body.transfers == 9
    assert np.abs(body.state).max() <= ROUND_OFF * E
    assert np.abs(body.stress_nodes()).max() <= ROUND_OFF * E
    # the tracked boundary stays one loop of the body's area throughout
    assert all(loops == 1 for _, loops in seen)
    assert [a for a, _ in seen] == pytest.approx([2.0] * 9, rel=1e-12)


def test_rigid_rotation_turns_a_prestress_with_the_body(tmp_path) -> None:
    body = body_of(tmp_path)
    s0 = np.array([3.0e6, -1.0e6, 2.0e6, 0.5e6])              # sxx, syy, sxy, szz
    body.state = np.tile(s0, (len(body.state), 1))
    rotate(body, 90.0, 9)
    # R(90) s R(90)^T: sxx <-> syy, sxy -> -sxy; szz is out of plane
    expected = np.array([s0[1], s0[0], -s0[2], s0[3]])
    assert np.abs(body.state - expected).max() <= ROUND_OFF * E
    assert body.points.shape[0] > 0 and np.all(body.w > 0)


def test_rigid_rotation_neo_hookean(tmp_path) -> None:
    body = body_of(tmp_path, "neo-hookean")
    rotate(body, 90.0, 5)
    assert np.abs(body.state - [1.0, 1.0, 0.0]).max() <= 1e-9     # b = R R^T = I
    assert np.abs(body.stress_nodes()).max() <= ROUND_OFF * E


def test_transfer_is_exact_for_linear_fields_and_idempotent(tmp_path) -> None:
    body = body_of(tmp_path)
    pts, w, N = body.points, body.w, body.sf.N
    field = np.c_[1.0 + 2.0 * pts[:, 0] - 3.0 * pts[:, 1], 5.0 - pts[:, 1]]
    nodal = project_to_nodes(N, w, field)
    assert np.abs(nodal - np.c_[1.0 + 2.0 * body.x[:, 0] - 3.0 * body.x[:, 1], 5.0 - body.x[:, 1]]).max() < 1e-9
    # a rebuild of the same configuration: the transferred field is the field, and a second
    # transfer changes nothing
    rough = np.c_[np.sin(3 * pts[:, 0]) * pts[:, 1]]
    once, _ = transfer(N, w, rough, N)
    twice, _ = transfer(N, w, once, N)
    assert np.abs(twice - once).max() <= 1e-9 * np.abs(once).max()


def moved_points(body, seed: int, every: int, shift: float):
    """The body's points, shape functions and weights (every ``every``-th weight 0), and new points moved at random
    by up to ``shift`` of the spacing inside the old points' hull with their shape functions, and the generator."""
    pts, N, d_c = body.points, body.sf.N, 2.0 / 12
    rng = np.random.default_rng(seed)
    w = body.w.copy()
    w[::every] = 0.0
    new_pts = np.clip(pts + rng.uniform(-shift, shift, pts.shape) * d_c, pts.min(axis=0), pts.max(axis=0))
    return pts, N, w, new_pts, body.conf.shape_functions_at(new_pts, derivatives=False).N, rng


def test_transfer_bounds_are_the_old_values_each_new_point_depends_on_and_leave_a_linear_field_exact(tmp_path) -> None:
    """local_bounds against a dense search: a new point's range is that of the old points of positive weight in the
    supports of its nodes. A linear field transferred to points moved by a tenth of the spacing, inside the old
    points' hull, lies inside its bounds to round-off (the clip a solver applies changes nothing there)."""
    pts, N, w, new_pts, N_new, rng = moved_points(body_of(tmp_path), seed=4, every=7, shift=0.1)
    values = np.c_[np.sin(5 * pts[:, 0]) * pts[:, 1], rng.normal(size=len(pts))]
    lo, hi = local_bounds(N, w, values, N_new)
    pattern = lambda A: sp.csr_matrix((np.ones(A.nnz), A.indices, A.indptr), shape=A.shape)
    reach = (pattern(N_new) @ pattern(N).T).toarray() > 0
    reach[:, ~(w > 0)] = False
    assert reach.any(axis=1).all()
    for k in range(values.shape[1]):
        np.testing.assert_array_equal(lo[:, k], np.where(reach, values[None, :, k], np.inf).min(axis=1))
        np.testing.assert_array_equal(hi[:, k], np.where(reach, values[None, :, k], -np.inf).max(axis=1))
    linear = np.c_[1.0 + 2.0 * pts[:, 0] - 3.0 * pts[:, 1]]
    at_new, _ = transfer(N, w, linear, N_new)
    assert np.abs(at_new[:, 0] - (1.0 + 2.0 * new_pts[:, 0] - 3.0 * new_pts[:, 1])).max() < 1e-9
    lo, hi = local_bounds(N, w, linear, N_new)
    # at most round-off: a new point on an old one at the hull's corner holds the bound, its projection an ulp off
    assert np.abs(np.clip(at_new, lo, hi) - at_new).max() <= 1e-12 * np.abs(linear).max()


def test_convex_average_stays_in_the_bounds_keeps_a_constant_and_makes_no_energy(tmp_path) -> None:
    """The fallback of a transferred point that leaves its bounds: a weighted mean of the old values the point
    depends on. Each component lies inside local_bounds, a constant state comes through exactly, and a convex
    function of the whole state (a quadratic energy density) is at most its largest old value in reach; the same
    state clipped component by component combines the extremes of different components and exceeds it."""
    pts, N, w, new_pts, N_new, rng = moved_points(body_of(tmp_path), seed=7, every=5, shift=0.2)
    rows = np.arange(0, len(new_pts), 3)
    state = rng.normal(size=(len(pts), 2)) * np.array([1.0, 1e3])    # two components of different scales
    lo, hi = local_bounds(N, w, state, N_new)
    avg = convex_average(N, w, state, N_new, rows)
    scale = np.abs(state).max(axis=0)
    assert np.all(avg >= lo[rows] - 1e-12 * scale) and np.all(avg <= hi[rows] + 1e-12 * scale)
    np.testing.assert_allclose(convex_average(N, w, np.full((len(pts), 2), 3.5), N_new, rows), 3.5, rtol=1e-14)
    density = lambda s: np.einsum("pi,ij,pj->p", s / scale, np.array([[2.0, 1.0], [1.0, 2.0]]), s / scale)
    old_max = local_bounds(N, w, density(state)[:, None], N_new)[1][rows, 0]
    assert np.all(density(avg) <= old_max * (1 + 1e-12))
    corners = np.c_[hi[rows, 0], hi[rows, 1]]           # what a per-component clip can reach
    assert np.any(density(corners) > old_max)
