"""What ParaView shows of a result (ctmrpim.io.vtu): the body's surface triangles inside the tracked boundary,
the stress as a symmetric tensor with named components, read back with meshio."""
from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
import pytest

import ctmrpim
from ctmrpim.io.vtu import in_plane_stress, stress_point_data, write_series, write_vtu
from ctmrpim.problem.reader import parse_case
from ctmrpim.result import Result

E, NU = 1000.0, 0.25
#: a constant strain (exx, eyy, gxy): a linear displacement the default scheme reproduces to round-off
EXX, EYY, GXY = 1e-3, -4e-4, 6e-4
GEOMETRIES = {
    "plate-with-hole": {"add": [{"rectangle": [0, 0, 4, 2]}], "subtract": [{"circle": [2, 1, 0.5]}]},
    "l-shape": {"add": [{"polygon": [[0, 0], [3, 0], [3, 1], [1, 1], [1, 3], [0, 3]]}]},
}


def _signed_areas(points: np.ndarray, tri: np.ndarray) -> np.ndarray:
    a, b, c = (points[tri[:, k]] for k in range(3))
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def _expected_stress() -> np.ndarray:
    """sxx, syy, szz, sxy of the constant strain in plane strain (ezz = 0)."""
    lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    sxx, syy = (lam + 2 * mu) * EXX + lam * EYY, lam * EXX + (lam + 2 * mu) * EYY
    return np.array([sxx, syy, lam * (EXX + EYY), mu * GXY])


def _constant_strain(geometry: str) -> ctmrpim.Case:
    """The constant strain prescribed on the whole boundary of ``geometry``, plane strain, spacing 0.1."""
    ux, uy = f"{EXX}*x + {GXY / 2}*y", f"{GXY / 2}*x + {EYY}*y"
    raw = {"problem": {"name": f"surface-{geometry}", "plane": "strain"}, "geometry": GEOMETRIES[geometry],
           "nodes": {"spacing": 0.1}, "material": {"model": "linear-elastic", "E": E, "nu": NU},
           "constraint": [{"where": "x > -1", "ux": ux, "uy": uy}]}
    return parse_case(raw, f"surface-{geometry}", Path("."))


@pytest.mark.parametrize("geometry", list(GEOMETRIES))
def test_surface_triangles_fill_the_tracked_boundary(geometry: str, tmp_path: Path) -> None:
    """Written and read back: triangles counter-clockwise, their area the tracked area (1e-9), inside the body
    (the L-shape's re-entrant corner kept: its area exact), and the six stress components of the field."""
    case = _constant_strain(geometry)
    r = ctmrpim.solve(case)
    mesh = meshio.read(write_vtu(r, tmp_path))
    cells = mesh.cells_dict
    assert set(cells) == {"vertex", "line", "triangle"}
    xy = mesh.points[:, :2]
    tri = cells["triangle"]
    areas = _signed_areas(xy, tri)
    tracked = r.parameters["derived"]["tracked_area"]
    assert areas.min() > 0
    assert abs(areas.sum() - tracked) <= 1e-9 * tracked
    # the lines are exactly the edges of one triangle each: the surface ends at the tracked boundary
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    keys, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.array_equal(keys[counts == 1], np.unique(np.sort(cells["line"], axis=1), axis=0))
    g = case.problem.geometry
    h = 0.1
    assert g.contains(xy[tri].mean(axis=1)).all()
    on_or_in = g.contains(xy[tri].reshape(-1, 2)) | (g.distance_to_boundary(xy[tri].reshape(-1, 2)) < 1e-3 * h)
    assert on_or_in.all()
    if geometry == "l-shape":
        assert tracked == pytest.approx(g.area, rel=1e-12) and g.area == pytest.approx(5.0)
        corner = int(np.argmin(np.hypot(xy[:, 0] - 1, xy[:, 1] - 1)))
        assert np.allclose(xy[corner], [1, 1]) and (tri == corner).any()
        mid = 0.5 * (xy[edges[:, 0]] + xy[edges[:, 1]])
        assert (g.contains(mid) | (g.distance_to_boundary(mid) < 1e-12)).all()   # nothing spans the notch
    else:
        assert tracked == pytest.approx(g.area, rel=0.01)     # chords of the hole's arc
    s = mesh.point_data["stress"]
    expected = _expected_stress()
    assert s.shape == (len(xy), 6)
    scale = np.abs(expected).max()
    np.testing.assert_allclose(s[:, [0, 1, 2, 3]], np.broadcast_to(expected, (len(xy), 4)), atol=1e-9 * scale)
    np.testing.assert_array_equal(s[:, 4:], 0.0)
    for k, name in enumerate(("stress_xx", "stress_yy", "stress_zz", "stress_xy")):
        np.testing.assert_array_equal(mesh.point_data[name], s[:, k])
    np.testing.assert_array_equal(in_plane_stress(mesh.point_data), r.stress)


def test_stress_point_data_is_paraviews_symmetric_tensor() -> None:
    """Components xx, yy, zz, xy, yz, xz; plane stress (no szz) gives zz = 0; von Mises of uniaxial stress is
    its magnitude, of pure shear sqrt(3) times it, of a hydrostatic state zero."""
    stress = np.array([[-5.0, 0.0, 0.0], [0.0, 0.0, 2.0], [3.0, 3.0, 0.0], [1.0, 2.0, 3.0]])
    zz = np.array([0.0, 0.0, 3.0, 4.0])
    d = stress_point_data(stress, zz)
    np.testing.assert_array_equal(d["stress"], [[-5, 0, 0, 0, 0, 0], [0, 0, 0, 2, 0, 0], [3, 3, 3, 0, 0, 0],
                                                [1, 2, 4, 3, 0, 0]])
    np.testing.assert_allclose(d["von_mises"][:3], [5.0, 2.0 * np.sqrt(3.0), 0.0], atol=1e-15)
    assert d["von_mises"][3] == pytest.approx(np.sqrt(0.5 * (1 + 4 + 9) + 27))
    plane_stress = stress_point_data(stress)
    np.testing.assert_array_equal(plane_stress["stress_zz"], 0.0)
    assert set(d) == {"stress", "stress_xx", "stress_yy", "stress_zz", "stress_xy", "von_mises"}


def test_series_steps_carry_their_own_or_the_results_triangles(tmp_path: Path) -> None:
    """A step with a re-tracked boundary writes its triangles, one without it the result's, moved."""
    points = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    square = np.array([[0, 1, 2], [0, 2, 3]])
    loop = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    stress = np.tile([1.0, 2.0, 0.5], (4, 1))
    steps = [{"load_factor": 0.5, "u": np.zeros((4, 2)), "stress": stress, "stress_zz": np.full(4, 0.9)},
             {"load_factor": 1.0, "u": np.full((4, 2), 0.1), "stress": 2 * stress,
              "boundary": np.array([[0, 1], [1, 3], [3, 0]]),
              "triangles": np.array([[0, 1, 3]])}]
    r = Result(method="test", points=points, u=np.zeros((4, 2)), stress=stress,
               cells=[("line", loop), ("triangle", square)], series=steps)
    first, second, pvd = write_series(r, tmp_path)
    a, b = meshio.read(first), meshio.read(second)
    assert np.array_equal(a.cells_dict["triangle"], square) and np.array_equal(a.cells_dict["line"], loop)
    assert np.array_equal(b.cells_dict["triangle"], [[0, 1, 3]]) and len(b.cells_dict["line"]) == 3
    np.testing.assert_array_equal(a.point_data["stress"][0], [1.0, 2.0, 0.9, 0.5, 0.0, 0.0])
    np.testing.assert_array_equal(b.point_data["stress"][0], [2.0, 4.0, 0.0, 1.0, 0.0, 0.0])
    np.testing.assert_allclose(b.points[:, :2], points + 0.1)
    assert pvd.name == "result.pvd"
