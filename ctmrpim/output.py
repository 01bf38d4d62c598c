"""Run outputs: ``summary.json`` and ``result.vtu`` (meshio), each written atomically.

A file appears under its final name only once it is complete (written to a temporary name in the
same folder, then renamed), so an interrupted run never leaves a result that looks finished.
"""
from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any

import meshio
import numpy as np

from . import __version__
from .result import Result


def atomic_write(path: Path, write) -> None:
    """Call ``write(tmp_path)`` and rename the file to ``path`` once it succeeded."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; the final file gets the usual permissions
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    atomic_write(path, lambda p: p.write_text(text))


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def summary_dict(result: Result, source: str) -> dict[str, Any]:
    return {
        "ctmrpim_version": __version__,
        "source": source,
        "method": result.method,
        "parameters": result.parameters,
        "defaults_applied": result.defaults,
        "counts": result.counts,
        "timings": result.timings,
        "probes": result.probes,
        "errors": result.errors,
        **result.outcome,
        **({"history": result.history} if result.history else {}),
    }


def write_summary(result: Result, out_dir: Path, source: str) -> Path:
    path = Path(out_dir) / "summary.json"
    atomic_write_text(path, json.dumps(_jsonable(summary_dict(result, source)), indent=2) + "\n")
    return path


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
    the boundary tracked on it where the solver re-tracks, else the reference one moved), and ``result.pvd``, the index ParaView opens as a time series (meshio has
    no PVD writer; DESIGN.md prefers this to XDMF for clouds whose boundary changes). The index is
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
        n = len(points)
        name = f"series/step_{len(self.entries):05d}.vtu"
        mesh = meshio.Mesh(np.c_[points, np.zeros(n)], [("vertex", np.arange(n).reshape(-1, 1)), *cells],
                           point_data=point_data)
        atomic_write(self.out_dir / name, lambda p: meshio.write(p, mesh, file_format="vtu"))
        self.entries.append((float(time), name))
        atomic_write_text(self.out_dir / "result.pvd", pvd_text(self.entries))
        return self.out_dir / name

