"""The slope sliding at SRF = 1.6 (paper Fig. 21): benchmark `slope-slide`, the `slope` embankment with
c and tan(phi) divided by 1.6, released under gravity and followed by the explicit adaptive solver with
local damping 0.8 (the paper's dynamic relaxation) for the benchmark's duration. Its factor of safety by
strength reduction (`slope_stability`, above) lies well below 1.6, so at SRF 1.6 it cannot stand: the
figure shows the initial and the final configuration coloured by displacement and by equivalent plastic strain (the slip
surface from crest to toe), with the boundary re-tracked on the moved nodes. Quick mode (CI): a coarse
cloud (h = 1.5 m) for 1.5 s.
"""
from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import meshio
import numpy as np
import pandas as pd

from ctmrpim.io.vtu import read_pvd
from studies.sweep import CaseSpec

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "slope_slide"
TITLE = "Slope at SRF = 1.6: the slide at large deformation (cf. Fig. 21)"
QUICK = ("parameters.h=1.5", "explicit.duration=1.5", "explicit.save_every=0.5")


def specs(quick: bool) -> list[CaseSpec]:
    """The one slope-slide case (quick: the coarse cloud for 1.5 s)."""
    return [CaseSpec("slope-slide", QUICK if quick else (), labels=(("cloud", "quick" if quick else "default"),))]


def extra(summary: dict, folder: Path) -> dict:
    """The run's counts, maximum displacement, crest settlement, toe advance, plastic dissipation and time per
    step, from its summary and the series in its ``folder``."""
    dyn = summary["dynamics"]
    states = read_pvd(Path(folder) / "result.pvd")
    first, last = meshio.read(states[0][1]), meshio.read(states[-1][1])
    u = last.point_data["u"][:, :2]
    top = crest_point()
    crest = np.argmin(np.hypot(first.points[:, 0] - top[0], first.points[:, 1] - top[1]))
    return {"folder": str(folder), "end_time_s": dyn["end_time"], "steps": dyn["steps"], "rebuilds": dyn["rebuilds"],
            "re_layings": dyn["state_transfers"], "max_displacement_m": float(np.linalg.norm(u, axis=1).max()),
            "crest_settlement_m": float(-u[crest, 1]), "toe_advance_m": float(u[:, 0].max()),
            "plastic_dissipation_J": dyn["energy"]["plastic_dissipation"],
            "ms_per_step": 1e3 * dyn["seconds_per_step"]["total"]}


def crest_point() -> np.ndarray:
    """(2,) the slope's crest: the end of its top surface above the slope face (the vertex of the benchmark's
    outer loop with the largest ordinate, the farthest along x of those)."""
    from ctmrpim import benchmarks

    vertices = benchmarks.load("slope-slide").problem.geometry.loops()[0]
    top = vertices[vertices[:, 1] == vertices[:, 1].max()]
    return top[np.argmax(top[:, 0])]


def figure(df: pd.DataFrame) -> Figure:
    """The initial and the final configuration, coloured by displacement and by equivalent plastic strain, with
    the tracked boundary (cf. Fig. 21)."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(11, 10))
    ok = df[df.status == "ok"]
    if len(ok):
        r = ok.iloc[-1]
        states = read_pvd(Path(r.folder) / "result.pvd")
        first, last = meshio.read(states[0][1]), meshio.read(states[-1][1])
        fig.suptitle(TITLE if r.cloud != "quick" else (
            f"Slope at SRF = 1.6, quick run: {r.nodes} nodes, {r.max_displacement_m:.2g} m of displacement\n"
            "(the large-deformation slide of Fig. 21 is the full run's)"))
        for ax, mesh, field, label, title in (
                (axes[0], first, None, "", "initial configuration"),
                (axes[1], last, "displacement", "displacement (m)", f"t = {states[-1][0]:.2f} s ({r.steps} steps)"),
                (axes[2], last, "plastic_strain", "equivalent plastic strain", "plastic strain")):
            x = mesh.points[:, :2]
            style = dict(c=mesh.point_data[field], cmap="viridis") if field else dict(color="0.5")
            sc = ax.scatter(x[:, 0], x[:, 1], s=2, **style)
            for block in mesh.cells:
                if block.type == "line":
                    for e in block.data:
                        ax.plot(x[e, 0], x[e, 1], "k-", lw=0.5)
            if field:
                fig.colorbar(sc, ax=ax, label=label)
            ax.set(aspect="equal", xlim=(-1, 61), ylim=(-1, 16), title=title, xlabel="x (m)",
                   ylabel="y (m)")
    fig.tight_layout()
    return fig


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
