"""`ctmrpim run cantilever --quiet --out DIR` writes a result.vtu that ParaView shows as a surface: triangles
filling the 33 x 9 grid's rectangle, the stress as a six-component tensor with named components."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np

SCRIPT = Path(sys.executable).with_name("ctmrpim")   # the console script of the environment under test


def test_console_script_writes_surface_triangles(tmp_path: Path) -> None:
    cmd = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "ctmrpim.cli"]
    proc = subprocess.run([*cmd, "run", "cantilever", "--quiet", "--out", str(tmp_path / "out")], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and proc.stdout == "" and proc.stderr == "", proc.stderr
    mesh = meshio.read(tmp_path / "out" / "result.vtu")
    tri = mesh.cells_dict["triangle"]
    assert tri.shape == (2 * 32 * 8, 3) and len(mesh.cells_dict["line"]) == 80 and len(mesh.cells_dict["vertex"]) == 297
    a, b, c = (mesh.points[tri[:, k], :2] for k in range(3))
    area = 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    assert area.min() > 0 and abs(area.sum() - 48.0 * 12.0) <= 1e-9 * 576.0
    s = mesh.point_data["stress"]
    assert s.shape == (297, 6)
    np.testing.assert_array_equal(s[:, [2, 4, 5]], 0.0)          # plane stress: zz, and yz = xz = 0
    for k, name in ((0, "stress_xx"), (1, "stress_yy"), (3, "stress_xy")):
        np.testing.assert_array_equal(mesh.point_data[name], s[:, k])
    mises = np.sqrt(s[:, 0] ** 2 - s[:, 0] * s[:, 1] + s[:, 1] ** 2 + 3 * s[:, 3] ** 2)
    np.testing.assert_allclose(mesh.point_data["von_mises"], mises, rtol=1e-12, atol=1e-12 * mises.max())
