"""The adaptive updated-Lagrangian path: objectivity under a 90-degree rigid rotation applied in
increments through the whole rebuild cycle (re-tracked boundary, new CTM points, new RPIM shape
functions, L2 state transfer), the transfer itself, and the neo-Hookean state."""
from __future__ import annotations

import numpy as np
import pytest

from ctmrpim.cases import load_case
from ctmrpim.discretisation.state_transfer import project_to_nodes, transfer
from ctmrpim.materials.neo_hookean import NeoHookean
from ctmrpim.materials.objective_stress import (
    HypoelasticUpdate,
    LeftCauchyGreenUpdate,
    complex_step_tangent,
    hughes_winget,
)
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


def test_hughes_winget_is_exact_for_a_rotation_increment() -> None:
    for theta in (1e-3, 0.3, 1.2):
        de, Q = hughes_winget(rotation(theta)[None])
        assert np.abs(de).max() < 1e-15
        assert np.abs(Q[0] - rotation(theta)).max() < 1e-15


@pytest.mark.parametrize("update", [HypoelasticUpdate(NeoHookean(E, 0.3).D("strain"), "strain"),
                                    LeftCauchyGreenUpdate(NeoHookean(E, 0.3))], ids=["hypoelastic", "neo-hookean"])
def test_complex_step_tangent_matches_finite_differences(update) -> None:
    rng = np.random.default_rng(3)
    f = np.eye(2)[None] + 0.05 * rng.standard_normal((8, 2, 2))
    scale = 1.0 if isinstance(update, LeftCauchyGreenUpdate) else E
    state = update.initial(8) + 0.05 * rng.standard_normal((8, update.n_state)) * scale
    A = complex_step_tangent(update, f, state)
    h = 1e-6
    for k in range(4):
        i, J = divmod(k, 2)
        fp, fm = f.copy(), f.copy()
        fp[:, i, J] += h
        fm[:, i, J] -= h
        fd = (update.first_piola(fp, state) - update.first_piola(fm, state)).reshape(8, 4) / (2 * h)
        assert np.abs(A[:, :, k] - fd).max() <= 1e-7 * np.abs(A).max()


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


# --- the benchmarks, quick versions -------------------------------------------------------------------

UL = 'method.formulation="updated-lagrangian"'
L = 10.0


def test_tip_load_updated_lagrangian_against_the_elastica() -> None:
    from verify import check

    from ctmrpim import benchmarks
    from ctmrpim.methods import solve
    from ctmrpim.reference import elastica

    r = solve(benchmarks.load("tip-load", ["parameters.lam=1.2", "loading.steps=6", UL]))
    exact = elastica.tip_load_elliptic(1.2)
    check("tip-load-ul-elastica", abs(-r.probes["tip"]["uy"] / L / exact.w_over_L - 1.0))
    check("tip-load-ul-elastica-shortening", abs(-r.probes["tip"]["ux"] / L / exact.u_over_L - 1.0))
    assert r.counts["rebuilds"] == 5 and r.counts["rebuilds_skipped"] == 0     # none after the last increment
    # the tracked boundary stays one loop of the beam's area (10 m^2) through every increment
    assert all(h["boundary_loops"] == 1 for h in r.history)
    assert [h["tracked_area"] for h in r.history] == pytest.approx([10.0] * 6, rel=2e-3)
    assert all(len(s["boundary"]) > 0 for s in r.series)


def test_end_moment_quarter_updated_lagrangian() -> None:
    from verify import check

    from ctmrpim import benchmarks
    from ctmrpim.methods import solve
    from ctmrpim.reference import elastica

    r = solve(benchmarks.load("end-moment", ["parameters.m=0.25", "loading.steps=16", UL]))
    x, y = 1.0 + r.probes["tip"]["ux"] / L, r.probes["tip"]["uy"] / L
    ex, ey = elastica.end_moment_tip(2 * np.pi * 0.25)
    check("end-moment-ul-quarter", float(np.hypot(x - ex, y - ey)))
    assert all(h["boundary_loops"] == 1 for h in r.history)
    assert [h["tracked_area"] for h in r.history] == pytest.approx([5.0] * 16, rel=5e-3)


def test_corner_point_load_updated_lagrangian() -> None:
    """The paper's corner load as a material point carried by the RPIM interpolation of each increment."""
    from verify import check

    from ctmrpim import benchmarks
    from ctmrpim.methods import solve
    from ctmrpim.reference import elastica

    r = solve(benchmarks.load("tip-load-corner", ["parameters.lam=1.8", "loading.steps=8", UL]))
    w = -r.probes["tip"]["uy"] / L
    check("tip-load-corner-ul-elastica", abs(w / elastica.tip_load_bvp(1.8, eccentricity=0.05).w_over_L - 1.0))


def test_series_carries_the_tracked_boundary(tmp_path) -> None:
    """Each VTU of the series holds the nodes where they are and the boundary tracked on them."""
    import xml.etree.ElementTree as ET

    import meshio

    from ctmrpim import benchmarks
    from ctmrpim.io.run_folder import write_outputs
    from ctmrpim.methods import solve

    case = benchmarks.load("tip-load", ["parameters.lam=0.6", "loading.steps=2", UL])
    r = solve(case)
    write_outputs(r, case, tmp_path)
    sets = ET.parse(tmp_path / "result.pvd").getroot().findall("./Collection/DataSet")
    assert len(sets) == 2
    first = meshio.read(tmp_path / sets[0].get("file"))
    assert np.array_equal(first.cells_dict["line"], r.series[0]["boundary"])
    assert np.allclose(first.points[:, :2], r.points + r.series[0]["u"])


def test_carried_points_keep_their_state() -> None:
    """method.point_regeneration above the strain reached: no new CTM points, no state transfer, the
    boundary and the RPIM shape functions still rebuilt every increment."""
    from verify import check

    from ctmrpim import benchmarks
    from ctmrpim.methods import solve
    from ctmrpim.reference import elastica

    r = solve(benchmarks.load("end-moment", ["parameters.m=0.25", "loading.steps=16", UL,
                                             "method.point_regeneration=0.5"]))
    assert r.counts["rebuilds"] == 15 and r.counts["state_transfers"] == 0
    x, y = 1.0 + r.probes["tip"]["ux"] / L, r.probes["tip"]["uy"] / L
    ex, ey = elastica.end_moment_tip(2 * np.pi * 0.25)
    check("end-moment-ul-carried-quarter", float(np.hypot(x - ex, y - ey)))


def test_points_are_laid_anew_once_strained_past_the_threshold() -> None:
    from ctmrpim import benchmarks
    from ctmrpim.methods import solve

    r = solve(benchmarks.load("tip-load", ["parameters.lam=1.2", "loading.steps=6", UL, "method.point_regeneration=0.02"]))
    assert r.counts["rebuilds"] == 5 and 0 < r.counts["state_transfers"] < 5
