"""Column collapse: the deposit against the viscosity (stiffness-proportional damping beta) (issue 7)

The paper's model as written (rate-independent Mohr-Coulomb, no damping: ``explicit.viscosity = 0``)
and four viscosities beta (s; a viscous stress beta D d(eps)/dt, :mod:`ctmrpim.solvers.explicit`) on the
coarse cloud (31 x 16 nodes), each run until at rest (at most 1.5 s). Without viscosity the
surface layer of the upper slope keeps sliding after the front has stopped and the surface flattens
well below the measured one; the benchmark's beta = 5e-6 s was chosen from this sweep (it is fitted
to the experiment, not derived). Measured against the experiment as in ``column_collapse``: run-out,
height at the wall, the surface's largest and mean distance, the failure line, the inclination, the
time at which the run came to rest and the share of the work of gravity that the viscosity
dissipated. Quick mode (CI): no viscosity and the benchmark's, 16 x 9 nodes for 0.1 s.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd

from ctmrpim import benchmarks
from studies.sweep import CaseSpec

from . import column_collapse

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "column_collapse_viscosity"
TITLE = "Column collapse: the deposit against the viscosity beta (496 nodes, each run to rest)"
GRID = "nodes.grid=[31, 16]"
VALUES = {"full": (0.0, 2.5e-6, 5e-6, 1e-5, 2e-5), "quick": (0.0, 5e-6)}


def specs(quick: bool) -> list[CaseSpec]:
    """One case per viscosity beta on the coarse cloud, each to rest (at most 1.5 s; quick: none and the
    benchmark's, 16 x 9 nodes for 0.1 s)."""
    grid = ("nodes.grid=[16, 9]",) + column_collapse.QUICK if quick else (GRID, "explicit.duration=1.5")
    return [CaseSpec("column-collapse", grid + (f"explicit.viscosity={beta!r}",), labels=(("viscosity_s", beta),))
            for beta in VALUES["quick" if quick else "full"]]


def extra(summary: dict, folder: Path) -> dict:
    """:func:`column_collapse.extra` plus the share of the work of gravity that the viscosity dissipated."""
    e = summary["dynamics"]["energy"]
    share = e["viscous_dissipation"] / e["gravity_work"] if e["gravity_work"] else float("nan")
    return {**column_collapse.extra(summary, folder), "viscous_share": share}


def figure(df: pd.DataFrame) -> Figure:
    """The final surface of each beta against the experiment, and the surface's distance and run-out error
    against beta."""
    import matplotlib.pyplot as plt

    ok = df[df.status == "ok"]
    surface = benchmarks.data(column_collapse.DATA, "final_surface")
    fig, axes = plt.subplots(1, 2, figsize=(14, 4), gridspec_kw={"width_ratios": [2.5, 1]})
    ax = axes[0]
    ax.plot(surface[:, 0], surface[:, 1], "ko", ms=4, label="experiment: final surface")
    for _, r in ok.iterrows():
        p = json.loads(r.profile)
        ax.plot(p["x"], p["h"], lw=1.2, label=f"beta = {r.viscosity_s:g} s: at t = {r.end_time_s:.2f} s, "
                                               f"run-out {r.run_out_m:.3f} m, {r.slope_deg:.1f} deg")
    ax.set(xlabel="x (m)", ylabel="surface height (m)", xlim=(0, 0.5), ylim=(0, 0.11), title=TITLE)
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    ax = axes[1]
    if len(ok):
        x = [max(b, 1e-7) for b in ok.viscosity_s]
        ax.semilogx(x, ok.surface_max_dev_m, "o-", label="surface: largest distance (m)")
        ax.semilogx(x, ok.run_out_m - ok.run_out_measured_m, "s-", label="run-out - measured (m)")
        ax.axhline(0.01, color="k", ls=":", lw=0.8, label="0.01 m")
        ax.axhline(0.0, color="k", lw=0.5)
    ax.set(xlabel="viscosity beta (s; 0 drawn at 1e-7)", ylabel="distance from the experiment (m)",
           title="against the experiment")
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    return fig


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
