"""Draw docs/paraview_surface.png: what ParaView shows of a ``result.vtu``, redrawn from the file alone.

Solves the plate-with-hole benchmark (quarter plate, Kirsch), writes its ``result.vtu``, reads it back with
meshio and colours the surface triangles by the point data ``stress_xx`` and ``von_mises`` (Gouraud
shading, as ParaView's "Surface" representation interpolates point data), with the tracked boundary's line
cells on top. Run from the repository root:

    .venv/bin/python docs/make_paraview_picture.py
"""
from __future__ import annotations

import tempfile
from pathlib import Path

import matplotlib
import meshio

import ctmrpim
from ctmrpim.io.atomic import atomic_write
from ctmrpim.io.vtu import write_vtu

OUT = Path(__file__).resolve().parent / "paraview_surface.png"


def draw(vtu: Path) -> "matplotlib.figure.Figure":
    """Two panels of the VTU ``vtu``: its triangles coloured by sxx and by the von Mises stress."""
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mesh = meshio.read(vtu)
    xy = mesh.points[:, :2]
    tri = mesh.cells_dict["triangle"]
    lines = mesh.cells_dict["line"]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.4))
    for ax, name in zip(axes, ("stress_xx", "von_mises")):
        shade = ax.tripcolor(xy[:, 0], xy[:, 1], tri, mesh.point_data[name], shading="gouraud", cmap="viridis")
        ax.triplot(xy[:, 0], xy[:, 1], tri, color="w", lw=0.2, alpha=0.5)
        segments = xy[lines]
        ax.plot(segments[:, :, 0].T, segments[:, :, 1].T, "k-", lw=1.0)
        fig.colorbar(shade, ax=ax, label=name, shrink=0.85)
        ax.set(aspect="equal", xlabel="x", ylabel="y",
               title=f"{name}: {len(tri)} triangles, {len(lines)} boundary lines")
    fig.suptitle("result.vtu of `ctmrpim run plate-hole` read back with meshio (remote tension 1000 along x)")
    fig.tight_layout()
    return fig


def main() -> Path:
    """Solve, write, read back and draw; the PNG's path."""
    result = ctmrpim.solve(ctmrpim.load_case("plate-hole"))
    with tempfile.TemporaryDirectory() as tmp:
        fig = draw(write_vtu(result, Path(tmp)))
    atomic_write(OUT, lambda p: fig.savefig(p, format="png", dpi=110))
    return OUT


if __name__ == "__main__":
    print(main())
