"""VTU files (meshio) of a result, ParaView ``.pvd`` series of its increments or time steps.

``result.vtu``: the field nodes (or mesh vertices) as ``vertex`` cells, the tracked boundary as ``line`` cells
and the body as surface cells (CTM-RPIM: the alpha shape's triangles, which fill the tracked loops exactly,
corners included; finite elements: their own triangles or quads), so that ParaView shows a surface coloured
by any field. Point data: ``u`` (n, 3), ``stress`` (n, 6), the symmetric tensor in ParaView's component
order xx, yy, zz, xy, yz, xz (ParaView recognises six components as a symmetric tensor; zz is the
out-of-plane stress, yz = xz = 0), the same components as named scalars ``stress_xx``, ``stress_yy``,
``stress_zz``, ``stress_xy`` (meshio writes no component names), ``von_mises``, and the solver's further
fields. A series is one VTU per saved state with a ``.pvd`` index (meshio has no PVD writer; XDMF time
series keep the topology fixed, and a cloud's boundary changes from step to step). Every file is written
atomically.
"""
from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np

from ctmrpim.io.atomic import atomic_write, atomic_write_text
from ctmrpim.result import Result

#: ParaView's order of the six components of a symmetric tensor, and of ours
TENSOR_COMPONENTS = ("xx", "yy", "zz", "xy", "yz", "xz")


def stress_point_data(stress: np.ndarray, stress_zz: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Point data of the in-plane stress ``stress`` (n, 3: sxx, syy, sxy) and the out-of-plane ``stress_zz`` (n,)
    (None: zero, plane stress): ``stress`` (n, 6) in :data:`TENSOR_COMPONENTS` order, the named components
    ``stress_xx``, ``stress_yy``, ``stress_zz``, ``stress_xy`` (n,) and ``von_mises`` (n,)."""
    stress = np.asarray(stress, float)
    n = len(stress)
    sxx, syy, sxy = stress[:, 0], stress[:, 1], stress[:, 2]
    szz = np.zeros(n) if stress_zz is None else np.asarray(stress_zz, float).reshape(n)
    zero = np.zeros(n)
    mises = np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3.0 * sxy ** 2)
    return {"stress": np.c_[sxx, syy, szz, sxy, zero, zero], "stress_xx": sxx.copy(), "stress_yy": syy.copy(),
            "stress_zz": szz.copy(), "stress_xy": sxy.copy(), "von_mises": mises}


def in_plane_stress(point_data: dict[str, np.ndarray]) -> np.ndarray:
    """(n, 3) sxx, syy, sxy of point data written by :func:`stress_point_data` (read back from a VTU)."""
    s = np.asarray(point_data["stress"])
    return s[:, [0, 1, 3]]


def _mesh(points: np.ndarray, u: np.ndarray, stress: np.ndarray, stress_zz: np.ndarray | None,
          cells: list[tuple[str, np.ndarray]], fields: dict[str, np.ndarray] | None = None) -> meshio.Mesh:
    n = len(points)
    blocks = [("vertex", np.arange(n).reshape(-1, 1))] + [(k, np.asarray(v)) for k, v in cells if len(v)]
    return meshio.Mesh(np.c_[points, np.zeros(n)], blocks,
                       point_data={"u": np.c_[u, np.zeros(n)], **stress_point_data(stress, stress_zz),
                                   **(fields or {})})


def _step_cells(result: Result, step: dict) -> list[tuple[str, np.ndarray]]:
    """The cells of a series step: its own tracked boundary and triangles where the solver re-tracked, else
    the result's (the reference ones, moved with the nodes)."""
    if step.get("boundary") is None:
        return result.cells
    cells = [("line", step["boundary"])]
    if step.get("triangles") is not None:
        cells.append(("triangle", step["triangles"]))
    return cells


def write_vtu(result: Result, out_dir: Path) -> Path:
    """``result.vtu``: the points as vertex cells with ``result.cells`` (boundary lines, surface triangles or
    elements) and the point data of the module docstring, on the reference configuration (warp by u in
    ParaView to see the deformed body)."""
    path = Path(out_dir) / "result.vtu"
    mesh = _mesh(result.points, result.u, result.stress, result.stress_zz, result.cells, result.fields)
    atomic_write(path, lambda p: meshio.write(p, mesh, file_format="vtu"))
    return path


def write_series(result: Result, out_dir: Path) -> list[Path]:
    """One VTU per converged load increment on the *current* configuration (nodes moved by u, with
    the boundary and triangles tracked on it where the solver re-tracks, else the reference ones moved), and
    ``result.pvd``, the index ParaView opens as a time series (docs/design.md, 'Output'). The index is
    written last, so a series is only announced once all its files exist."""
    if not result.series:
        return []
    out_dir = Path(out_dir)
    entries: list[tuple[float, str]] = []
    written = []
    for k, step in enumerate(result.series, start=1):
        name = f"series/step_{k:04d}.vtu"
        mesh = _mesh(result.points + step["u"], step["u"], step["stress"], step.get("stress_zz"),
                     _step_cells(result, step), step.get("fields"))
        atomic_write(out_dir / name, lambda p, m=mesh: meshio.write(p, m, file_format="vtu"))
        written.append(out_dir / name)
        entries.append((step["time"] if "time" in step else step["load_factor"], name))  # strength reduction: SRF
    atomic_write_text(out_dir / "result.pvd", pvd_text(entries))
    return written + [out_dir / "result.pvd"]


def pvd_text(entries: list[tuple[float, str]]) -> str:
    """A ParaView collection (``.pvd``) of (time, file) entries."""
    lines = "\n".join(f'    <DataSet timestep="{t:.10g}" part="0" file="{name}"/>' for t, name in entries)
    return ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            "  <Collection>\n" + lines + "\n  </Collection>\n</VTKFile>\n")


def read_pvd(path: Path) -> list[tuple[float, Path]]:
    """(time, file) of each state of a ``.pvd`` index, the files as paths beside the index."""
    import xml.etree.ElementTree as ET
    path = Path(path)
    return [(float(d.get("timestep")), path.parent / d.get("file")) for d in ET.parse(path).iter("DataSet")]


class SeriesWriter:
    """A time series written as a run goes: ``series/step_NNNNN.vtu`` per saved state and ``result.pvd``
    rewritten (atomically) after each, so that ParaView can open a run that is still going, and a
    resumed run continues the same index (``entries`` come back from its checkpoint)."""

    def __init__(self, out_dir: Path, entries: list[tuple[float, str]] | None = None) -> None:
        self.out_dir = Path(out_dir)
        self.entries = [(float(t), str(f)) for t, f in (entries or [])]

    def add(self, time: float, points: np.ndarray, cells: list[tuple[str, np.ndarray]],
            point_data: dict[str, np.ndarray]) -> Path:
        """Write the state at ``time``: nodes ``points`` (n, 2) as vertex cells, further ``cells`` (type,
        connectivity: the boundary lines and surface triangles), ``point_data`` arrays (n, ...) by name (the
        stress as :func:`stress_point_data` lays it out); then rewrite the index. The new file's path."""
        n = len(points)
        name = f"series/step_{len(self.entries):05d}.vtu"
        blocks = [("vertex", np.arange(n).reshape(-1, 1))] + [(k, np.asarray(v)) for k, v in cells if len(v)]
        mesh = meshio.Mesh(np.c_[points, np.zeros(n)], blocks, point_data=point_data)
        atomic_write(self.out_dir / name, lambda p: meshio.write(p, mesh, file_format="vtu"))
        self.entries.append((float(time), name))
        atomic_write_text(self.out_dir / "result.pvd", pvd_text(self.entries))
        return self.out_dir / name
