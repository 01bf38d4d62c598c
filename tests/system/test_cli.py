"""The command line: the installed console script in a subprocess (list, run, its exit status, ``python -m
ctmrpim.cli``), and ``ctmrpim.cli.main`` in-process for the rest (the FEM solver, --set, --quiet, the default
folder); summary.json and result.vtu against the Python API's result of the same problem."""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest

from ctmrpim import benchmarks, methods
from ctmrpim.cli import main
from ctmrpim.io.vtu import in_plane_stress
from ctmrpim.result import Result
from studies import tolerances

SCRIPT = Path(sys.executable).with_name("ctmrpim")   # the console script of the environment under test


def ctmrpim(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    cmd = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "ctmrpim.cli"]
    return subprocess.run([*cmd, *args], cwd=cwd, capture_output=True, text=True, timeout=120)


def completed(proc: subprocess.CompletedProcess) -> subprocess.CompletedProcess:
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr
    return proc


@pytest.fixture(scope="module")
def run(tmp_path_factory) -> tuple[subprocess.CompletedProcess, Path, dict]:
    """`ctmrpim run cantilever --out DIR`, once for the module."""
    tmp = tmp_path_factory.mktemp("cli")
    proc = completed(ctmrpim("run", "cantilever", "--out", str(tmp / "out"), cwd=tmp))
    return proc, tmp / "out", json.loads((tmp / "out" / "summary.json").read_text())


@pytest.fixture(scope="module")
def api(solutions) -> Result:
    """The same problem solved through the Python API, in this process."""
    return solutions("cantilever")


@pytest.fixture
def in_process(solutions, capsys, monkeypatch, tmp_path):
    """``ctmrpim ARGS`` run by ``ctmrpim.cli.main`` in ``tmp_path``: (exit status, stdout, stderr); its solves
    are shared with the other tests of the run."""
    monkeypatch.setattr(methods, "solve", solutions.solve)
    monkeypatch.chdir(tmp_path)

    def call(*args: str) -> tuple[int, str, str]:
        capsys.readouterr()
        code = main(list(args))
        out, err = capsys.readouterr()
        assert code == 0, err
        assert "Traceback" not in out + err
        return code, out, err
    return call


def test_list(tmp_path: Path) -> None:
    proc = completed(ctmrpim("list", cwd=tmp_path))
    assert proc.stderr == ""
    line = next(ln for ln in proc.stdout.splitlines() if ln.startswith("cantilever "))
    assert "Timoshenko cantilever" in line


def test_run_prints_a_summary_and_writes_both_files(run) -> None:
    proc, out, _ = run
    assert sorted(p.name for p in out.iterdir()) == ["result.vtu", "status.json", "summary.json"]   # no temporary files
    assert proc.stderr == ""
    text = proc.stdout
    assert text.startswith("cantilever (ctm-rpim): 297 nodes, d_c = 1.395")
    assert "probe tip (48, 0): ux = " in text and "error in uy" in text
    assert "relative errors: l2 " in text and "time: " in text
    assert f"wrote {out / 'result.vtu'}, {out / 'summary.json'}" in text


def test_summary_holds_the_resolved_input(run) -> None:
    _, _, s = run
    assert s["method"] == "ctm-rpim" and s["source"].endswith("cantilever.toml")
    p = s["parameters"]
    assert set(p) >= {"problem", "parameters", "geometry", "nodes", "material", "method", "constraint",
                      "traction", "pressure", "probe", "exact", "derived"}
    assert p["problem"] == {"name": "cantilever", "analysis": "linear", "plane": "stress", "thickness": 1.0,
                            "gravity": [0.0, 0.0]}
    assert p["parameters"] == {"P": -1000.0, "E": 3.0e7, "nu": 0.3, "L": 48.0, "W": 12.0, "I": 144.0}
    assert p["geometry"] == {"add": [{"rectangle": [0.0, -6.0, 48.0, 6.0]}], "subtract": []}
    assert p["nodes"] == {"grid": [33, 9]}
    assert p["material"] == {"model": "linear-elastic", "E": 3.0e7, "nu": 0.3, "density": 0.0}
    assert p["method"] == {"support_radius": 4.0, "eta": 5.0, "polynomial": "linear", "line_spacing": [1 / 3, 1 / 3],
                           "gauss_points": 1, "alpha": 1.5, "boundary": "alpha", "solver": "auto",
                           "match_tolerance": 0.01, "formulation": "updated-lagrangian", "point_regeneration": 0.0,
                           "min_support": 0, "integration": "ctm-vci", "correction": "quadratic"}
    assert p["constraint"][0]["where"] == "x == 0" and p["traction"][0]["where"] == "x == L"
    assert p["probe"] == [{"name": "tip", "at": [48.0, 0.0]}, {"name": "root_top", "at": [0.0, 6.0]}]
    d_c = math.sqrt(48.0 * 12.0) / math.sqrt(297 - 1)       # Eq. (36)
    assert p["derived"]["d_c"] == pytest.approx(d_c, rel=1e-14)
    assert p["derived"]["support_radius"] == pytest.approx(4.0 * d_c, rel=1e-14)
    # the defaults that were applied are listed
    assert s["defaults_applied"] == ["problem.gravity = [0.0, 0.0]", "material.density = 0.0",
                                     "method.boundary = 'alpha'", "method.solver = 'auto'",
                                     "method.match_tolerance = 0.01", "method.formulation = 'updated-lagrangian'",
                                     "method.point_regeneration = 0.0", "method.min_support = 0",
                                     "method.integration = 'ctm-vci'", "method.correction = 'quadratic'"]


def test_summary_counts_timings_probes_errors(run, api) -> None:
    _, _, s = run
    c = s["counts"]
    assert c["nodes"] == 297 and c["integration_points"] > 0
    sizes = c["support_size"]
    assert set(sizes) == {"min", "mean", "max"} and sizes["min"] <= sizes["mean"] <= sizes["max"]
    assert c == api.counts
    t = s["timings"]
    phases = {"boundary", "integration", "shape_functions", "assembly", "solve"}
    assert set(t) >= phases | {"total"}
    assert all(v >= 0 for v in t.values()) and t["total"] >= sum(t[k] for k in phases)
    tip = s["probes"]["tip"]
    assert set(tip) == {"x", "y", "ux", "uy", "sxx", "syy", "sxy"} and (tip["x"], tip["y"]) == (48.0, 0.0)
    for k in ("ux", "uy", "sxx", "syy", "sxy"):
        assert tip[k] == pytest.approx(api.probes["tip"][k], rel=1e-9, abs=1e-9 * abs(api.probes["tip"]["sxy"]))
    e = s["errors"]
    assert e["l2"] == pytest.approx(api.errors["l2"], rel=1e-9)
    assert e["energy"] == pytest.approx(api.errors["energy"], rel=1e-9)
    exact_uy = benchmarks.load("cantilever").problem.exact.uy(np.array([48.0]), np.array([0.0]))[0]
    assert e["probes"]["tip"]["uy"] == pytest.approx(abs(tip["uy"] / exact_uy - 1), rel=1e-9)
    assert tolerances.passes("cantilever-ctmrpim-33x9-tip", e["probes"]["tip"]["uy"])


def test_vtu_round_trip(run, api) -> None:
    _, out, s = run
    mesh = meshio.read(out / "result.vtu")
    np.testing.assert_array_equal(mesh.points[:, :2], api.points)
    assert np.all(mesh.points[:, 2] == 0.0)
    u, stress = mesh.point_data["u"], in_plane_stress(mesh.point_data)   # the tensor's xx, yy, xy
    assert u.shape == (297, 3) and mesh.point_data["stress"].shape == (297, 6) and np.all(u[:, 2] == 0.0)
    np.testing.assert_allclose(u[:, :2], api.u, rtol=1e-12, atol=1e-12 * np.abs(api.u).max())
    np.testing.assert_allclose(stress, api.stress, rtol=1e-12, atol=1e-12 * np.abs(api.stress).max())
    # the tip (48, 0) is a node; RPIM shape functions interpolate (Kronecker delta), so the nodal
    # values there are the probe values of summary.json
    tip = s["probes"]["tip"]
    k = int(np.argmin(np.hypot(mesh.points[:, 0] - 48.0, mesh.points[:, 1])))
    assert tuple(mesh.points[k, :2]) == (48.0, 0.0)
    scale = np.abs(stress).max()
    assert u[k, 0] == pytest.approx(tip["ux"], abs=1e-9 * abs(tip["uy"]))
    assert u[k, 1] == pytest.approx(tip["uy"], rel=1e-9)
    for j, name in enumerate(("sxx", "syy", "sxy")):
        assert stress[k, j] == pytest.approx(tip[name], abs=1e-9 * scale)
    # the tracked boundary as line cells: one closed loop round the 33 x 9 grid
    cells = mesh.cells_dict
    assert set(cells) == {"vertex", "line", "triangle"}   # the body's surface: 2 x 32 x 8 triangles
    assert np.array_equal(cells["vertex"].ravel(), np.arange(297))
    lines = cells["line"]
    assert lines.shape == (2 * (33 + 9) - 4, 2) == (s["counts"]["boundary_nodes"], 2)
    assert np.all(np.bincount(lines.ravel(), minlength=297)[np.unique(lines)] == 2)
    ends = mesh.points[lines, :2]
    x, y = ends[..., 0], ends[..., 1]
    assert np.all((x == 0) | (x == 48) | (np.abs(y) == 6))
    np.testing.assert_allclose(np.hypot(*(ends[:, 1] - ends[:, 0]).T), 1.5, rtol=1e-12)   # 48/32 = 12/8


def test_fem_q1(tmp_path: Path, run, in_process) -> None:
    _, stdout, _ = in_process("run", "cantilever", "--solver", "fem", "--element", "q1", "--out", str(tmp_path / "o"))
    assert stdout.startswith("cantilever (fem-q1): 297 nodes")
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == ["result.vtu", "status.json", "summary.json"]
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["method"] == "fem-q1" and s["parameters"]["derived"]["element"] == "q1"
    assert set(s["probes"]["tip"]) == {"x", "y", "ux", "uy", "sxx", "syy", "sxy"}
    assert tolerances.passes("cantilever-fem-q1-33x9-tip", s["errors"]["probes"]["tip"]["uy"])
    mesh = meshio.read(tmp_path / "o" / "result.vtu")
    ours = meshio.read(run[1] / "result.vtu")
    np.testing.assert_array_equal(mesh.points, ours.points)   # the same nodes as CTM-RPIM
    assert mesh.cells_dict["quad"].shape == (32 * 8, 4)
    assert mesh.point_data["u"].shape == (297, 3) and mesh.point_data["stress"].shape == (297, 6)


def test_set_grid_quiet_and_default_folder(tmp_path: Path, in_process) -> None:
    _, stdout, stderr = in_process("run", "cantilever", "--set", "nodes.grid=[17,5]", "--quiet")
    assert stdout == "" and stderr == ""
    out = tmp_path / "runs" / "cantilever"           # the default output folder
    s = json.loads((out / "summary.json").read_text())
    assert s["counts"]["nodes"] == 85 and s["parameters"]["nodes"] == {"grid": [17, 5]}
    assert len(meshio.read(out / "result.vtu").points) == 85


def test_python_dash_m_matches_the_script(tmp_path: Path) -> None:
    proc = subprocess.run([sys.executable, "-m", "ctmrpim.cli", "list"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 0 and proc.stdout == ctmrpim("list", cwd=tmp_path).stdout


def test_console_script_exits_2_on_bad_input(tmp_path: Path) -> None:
    """The console script's exit status is main's: 2 for bad input, one line, nothing written (every kind
    of bad input is in test_cli_bad_input.py, in-process)."""
    proc = ctmrpim("run", "cantilevr", "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.splitlines() == [proc.stderr.strip()] and "did you mean 'cantilever'?" in proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "out").exists()
