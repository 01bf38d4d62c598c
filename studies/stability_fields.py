"""Fields of the stability benchmarks (paper Figs. 20 and 25), drawn from one CTM-RPIM run each (not
cached: they need the fields, not only the summaries): the equivalent plastic strain of `slope` at
the last stable and the first failed SRF of its strength-reduction search (a connected band from the
crest to the toe at failure), and `footing` at the last pressure it carried, deformed, with
displacement arrows showing Prandtl's mechanism (the wedge under the footing pushed down, the fans
and the passive wedge beside it lifted). Quick mode: a coarser slope and a coarser bracket of the
footing's limit.

Writes ``stability_fields.png``.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from ctmrpim import benchmarks
from ctmrpim.methods import solve

from .base import new_figure, save_figure

NAME = "stability_fields"


def run(quick: bool = True, out_dir: Path = Path("reports"), progress: Callable[[str], object] = print) -> Path:
    """Solve ``slope`` (strength reduction) and ``footing`` (to its limit load) and draw the slope's plastic strain
    at the last stable and first failed SRF and the footing's mechanism (cf. Figs. 20 and 25); the PNG's path."""
    slope_h = 1.0 if quick else 0.58
    progress(f"stability fields: slope (h = {slope_h}) strength reduction, footing to its limit")
    slope = solve(benchmarks.load("slope", [f"parameters.h={slope_h!r}"]))
    footing = solve(benchmarks.load("footing", ["loading.max_cutbacks=5"] if quick else []))
    import matplotlib.pyplot as plt

    new_figure()                                   # the Agg backend
    plt.close("all")
    fig = plt.figure(figsize=(14, 6.5))
    grid = fig.add_gridspec(2, 2, width_ratios=[2.0, 1.0])
    slope_axes = [fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[1, 0])]
    fos = slope.outcome["factor_of_safety"]
    stable = next(s for s in slope.series if s["time"] == fos["stable"])
    failed = next(s for s in slope.series if s["time"] == fos["failed"])
    vmax = float(np.percentile(failed["fields"]["plastic_strain"], 99))
    for ax, step, what in ((slope_axes[0], stable, "last stable"),
                           (slope_axes[1], failed, "first failed (last iterate)")):
        sc = ax.scatter(slope.points[:, 0], slope.points[:, 1], c=step["fields"]["plastic_strain"], s=4,
                        cmap="viridis", vmin=0, vmax=vmax)
        ax.set(title=f"slope, SRF = {step['time']:.4f} ({what})", xlabel="x (m)", ylabel="y (m)", aspect="equal")
    fig.colorbar(sc, ax=slope_axes, label="equivalent plastic strain", shrink=0.8)
    ax = fig.add_subplot(grid[:, 1])
    u = footing.u
    xy = footing.points + u * (0.5 / np.abs(u).max())        # displacements drawn to 0.5 m at most
    ax.plot(xy[:, 0], xy[:, 1], ".", ms=1.5, color="0.6")
    keep = (footing.points[:, 0] <= 8.0) & (np.hypot(*u.T) > 0.02 * np.abs(u).max())
    ax.quiver(footing.points[keep, 0], footing.points[keep, 1], u[keep, 0], u[keep, 1], color="tab:red",
              angles="xy", scale_units="xy", scale=np.abs(u).max() / 0.6, width=0.003)
    q = footing.outcome["limit_pressure"]["carried"] / 1e3
    ax.plot([0, 2], [5.05, 5.05], "k-", lw=3)
    ax.set(title=f"footing at {q:.1f} kPa (last carried): Prandtl's mechanism", xlabel="x (m)", ylabel="y (m)",
           aspect="equal", xlim=(0, 8))
    path = save_figure(fig, Path(out_dir) / f"{NAME}.png")
    plt.close("all")
    return path


if __name__ == "__main__":
    import sys

    from .cli import fields_main
    fields_main(sys.modules[__name__])
