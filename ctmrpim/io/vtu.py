"""VTU files (meshio) of a result, ParaView ``.pvd`` series of its increments or time steps.

``result.vtu``: field nodes (or mesh vertices) as vertex cells with point data ``u`` and ``stress``,
the tracked boundary (or the elements) as further cells. A series is one VTU per saved state with a
``.pvd`` index (meshio has no PVD writer; XDMF time series keep the topology fixed, and a cloud's
boundary changes from step to step). Every file is written atomically.
"""
from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np

from ctmrpim.io.atomic import atomic_write, atomic_write_text
from ctmrpim.result import Result


def _mesh(result: Result, u: np.ndarray, stress: np.ndarray, moved: bool,
          boundary: np.ndarray | None = None, fields: dict[str, np.ndarray] | None = None) -> meshio.Mesh:
    n = len(result.points)
    xy = result.points + u if moved else result.points
    blocks = result.cells if boundary is None else [("line", boundary)]
    cells = [("vertex", np.arange(n).reshape(-1, 1))] + [(k, np.asarray(v)) for k, v in blocks]
    return meshio.Mesh(np.c_[xy, np.zeros(n)], cells,
                       point_data={"u": np.c_[u, np.zeros(n)], "stress": stress, **(fields or {})})


def write_vtu(result: Result, out_dir: Path) -> Path:
    """Field nodes as vertex cells with point data u and stress; boundary / elements as further cells
    (reference configuration: warp by u in ParaView to see the deformed body)."""
    path = Path(out_dir) / "result.vtu"
    mesh = _mesh(result, result.u, result.stress, moved=False, fields=result.fields)
    atomic_write(path, lambda p: meshio.write(p, mesh, file_format="vtu"))
    return path


def write_series(result: Result, out_dir: Path) -> list[Path]:
    """One VTU per converged load increment on the *current* configuration (nodes moved by u, with
    the boundary tracked on it where the solver re-tracks, else the reference one moved), and
    ``result.pvd``, the index ParaView opens as a time series (docs/design.md, 'Output'). The index is
    written last, so a series is only announced once all its files exist."""
    if not result.series:
        return []
    out_dir = Path(out_dir)
    entries: list[tuple[float, str]] = []
    written = []
    for k, step in enumerate(result.series, start=1):
        name = f"series/step_{k:04d}.vtu"
        mesh = _mesh(result, step["u"], step["stress"], moved=True, boundary=step.get("boundary"),
                     fields=step.get("fields"))
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
        connectivity), ``point_data`` arrays (n, ...) by name; then rewrite the index. The new file's path."""
        n = len(points)
        name = f"series/step_{len(self.entries):05d}.vtu"
        mesh = meshio.Mesh(np.c_[points, np.zeros(n)], [("vertex", np.arange(n).reshape(-1, 1)), *cells],
                           point_data=point_data)
        atomic_write(self.out_dir / name, lambda p: meshio.write(p, mesh, file_format="vtu"))
        self.entries.append((float(time), name))
        atomic_write_text(self.out_dir / "result.pvd", pvd_text(self.entries))
        return self.out_dir / name
