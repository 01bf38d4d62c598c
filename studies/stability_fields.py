"""Fields of the stability benchmarks (paper Figs. 20 and 25), drawn from one CTM-RPIM run each (not
cached: they need the fields, not only the summaries): the equivalent plastic strain of `slope` at
the last stable and the first failed SRF of its strength-reduction search (a connected band from the
crest to the toe at failure), and `footing` under the pressure of the paper's Fig. 25
(``FOOTING_KPA``), above every limit load (Prandtl's and the paper's bracket), applied at once and
relaxed for a stated number of dynamic-relaxation steps (the benchmark as an ``analysis = "dynamic"``
run, its ``[loading]`` table left out), so the state drawn is not an equilibrium but a mechanism on its
way: its nodes at their displaced places coloured by the displacement, and arrows showing Prandtl's
mechanism (the wedge under the footing pushed down, the fans and the passive wedge beside it lifted).
Quick mode: a coarser slope and fewer relaxation steps.

Writes ``stability_fields.png``.
"""
from __future__ import annotations

import tomllib
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ctmrpim import benchmarks
from ctmrpim.methods import solve
from ctmrpim.problem.case import Case
from ctmrpim.problem.reader import parse_case

from .base import new_figure, save_figure

NAME = "stability_fields"
#: The footing's pressure of the paper's Fig. 25 (kPa), above every limit load.
FOOTING_KPA = 540.0
#: Dynamic-relaxation steps of the footing at FOOTING_KPA: (quick, full).
FOOTING_STEPS = (1000, 4000)


def footing_case(pressure_kpa: float = FOOTING_KPA, steps: int = FOOTING_STEPS[1]) -> Case:
    """The ``footing`` benchmark as a dynamic-relaxation run: ``pressure_kpa`` applied at once and relaxed for
    at most ``steps`` steps (its ``[loading]`` table, which steps a quasi-static analysis, left out)."""
    source = benchmarks.path("footing")
    raw = tomllib.loads(source.read_text())
    raw.pop("loading", None)
    return parse_case(raw, str(source), source.parent, ['problem.analysis="dynamic"',
                                                         f"parameters.q_max={pressure_kpa * 1e3!r}",
                                                         f"dynamic.steps={steps}"])


def run(quick: bool = True, out_dir: Path = Path("reports"), progress: Callable[[str], object] = print) -> Path:
    """Solve ``slope`` (strength reduction) and ``footing`` (dynamic relaxation at 540 kPa) and draw the slope's
    plastic strain at the last stable and first failed SRF and the footing's mechanism after the relaxation's
    steps (cf. Figs. 20 and 25); the PNG's path."""
    slope_h = 1.0 if quick else 0.58
    steps = FOOTING_STEPS[0 if quick else 1]
    progress(f"stability fields: slope (h = {slope_h}) strength reduction, footing at {FOOTING_KPA:g} kPa "
             f"({steps} relaxation steps)")
    slope = solve(benchmarks.load("slope", [f"parameters.h={slope_h!r}"]))
    footing = solve(footing_case(FOOTING_KPA, steps))
    import matplotlib.pyplot as plt

    new_figure()                                   # the Agg backend
    plt.close("all")
    fig = plt.figure(figsize=(15, 6.5))
    grid = fig.add_gridspec(2, 2, width_ratios=[1.7, 1.3])
    slope_axes = [fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[1, 0])]
    fos = slope.outcome["factor_of_safety"]
    stable = next(s for s in slope.series if s["time"] == fos["stable"])
    failed = next(s for s in slope.series if s["time"] == fos["failed"])
    vmax = float(np.percentile(failed["fields"]["plastic_strain"], 99))
    for ax, step, what in ((slope_axes[0], stable, "last stable"),
                           (slope_axes[1], failed, "first failed, last iterate")):
        sc = ax.scatter(slope.points[:, 0], slope.points[:, 1], c=step["fields"]["plastic_strain"], s=4,
                        cmap="viridis", vmin=0, vmax=vmax)
        ax.set(title=f"slope, SRF = {step['time']:.4f} ({what})", xlabel="x (m)", ylabel="y (m)", aspect="equal")
    fig.colorbar(sc, ax=slope_axes, label="equivalent plastic strain (-)", shrink=0.8)
    draw_footing(fig.add_subplot(grid[:, 1]), footing, quick)
    path = save_figure(fig, Path(out_dir) / f"{NAME}.png")
    plt.close("all")
    return path


def draw_footing(ax, footing, quick: bool, x_max: float = 8.0) -> None:
    """The footing's nodes at their displaced places (true scale) coloured by the displacement, and arrows of its
    direction at the moving nodes (cf. Fig. 25), titled with the relaxation's steps and state."""
    u = footing.u
    size = np.hypot(*u.T)
    top = float(size.max())
    xy = footing.points + u
    sc = ax.scatter(xy[:, 0], xy[:, 1], c=size, s=10, cmap="viridis", vmin=0, vmax=top, zorder=1)
    ax.figure.colorbar(sc, ax=ax, label="displacement magnitude |u| (m)", shrink=0.8, orientation="horizontal",
                       pad=0.12)
    keep = (footing.points[:, 0] <= x_max) & (size > 0.02 * top)
    ax.quiver(footing.points[keep, 0], footing.points[keep, 1], u[keep, 0], u[keep, 1], color="k", alpha=0.6,
              angles="xy", scale_units="xy", scale=top / 0.6, width=0.002, zorder=2)
    ax.plot([], [], ">", color="k", alpha=0.6, label="displacement (arrow at the node's initial place;\n"
                                                 "the largest drawn 0.6 m long)")
    ax.plot([0, 2], [5.0, 5.0], "k-", lw=3, label="loaded width, initial (B/2 = 2 m)")
    relaxed = footing.outcome["relaxation"]
    mode = "quick mode: " if quick else ""
    state = (f"at rest after {relaxed['steps']} relaxation steps" if relaxed["at_rest"] else
             f"not an equilibrium: {FOOTING_KPA:g} kPa is above the limit load;\nafter {relaxed['steps']} "
             "relaxation steps")
    ax.set(title=f"footing at {FOOTING_KPA:g} kPa (cf. Fig. 25), {mode}max |u| = {top:.2f} m\n{state}",
           xlabel="x (m)", ylabel="y (m)", aspect="equal", xlim=(0, x_max))
    ax.legend(fontsize=7, loc="lower right", framealpha=0.9)


if __name__ == "__main__":
    import sys

    from .cli import fields_main
    fields_main(sys.modules[__name__])
