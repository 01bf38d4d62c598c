"""Integration schemes side by side (not in the paper): the paper's one-point CTM, the consistent CTM (VCI,
the default of linear analyses), background cells clipped by the boundary ("cell-gauss") and stabilised
conforming nodal integration ("scni"), each at a few integration densities, on the same nodes, boundary,
RPIM and assembly. The paper's claim is that CTM avoids background cells' inconsistency without the cost
of high-order Gauss rules; this measures it: the cantilever's errors against integration points and against
wall time (a Pareto figure), the same cantilever on jittered clouds (every interior node moved by up to 0.3
of the spacing), the manufactured solution (a smooth field with a body force on a plate with a hole and a
curved end), the plate with a hole's stress concentration, and the constant-stress patch test on a plate with
a square hole. The table condenses it per setting: the patch-test error, the fitted energy-error rates and
the wall time to 0.1 % energy error on the cantilever.
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from studies.fitting import fitted_rate
from studies.sweep import CaseSpec
from studies.time_to_accuracy import time_to_reach

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "integration_schemes"
TITLE = "Integration schemes"
#: scheme label -> its --set strings; the first of each scheme is its usual setting (the quick mode's)
SETTINGS = {
    "ctm (1/3, 1 pt)": ('method.integration="ctm"',),
    "ctm-vci (1/3, 1 pt)": ('method.integration="ctm-vci"',),
    "cell-gauss (d_c, 2x2)": ('method.integration="cell-gauss"', "method.line_spacing=[1, 1]", "method.gauss_points=2"),
    "scni (1 per node)": ('method.integration="scni"',),
    "ctm (1/2, 1 pt)": ('method.integration="ctm"', "method.line_spacing=[0.5, 0.5]"),
    "ctm (1/6, 1 pt)": ('method.integration="ctm"', 'method.line_spacing=["1/6", "1/6"]'),
    "ctm-vci (1/2, 1 pt)": ('method.integration="ctm-vci"', "method.line_spacing=[0.5, 0.5]"),
    "cell-gauss (d_c, 3x3)": ('method.integration="cell-gauss"', "method.line_spacing=[1, 1]", "method.gauss_points=3"),
    "cell-gauss (d_c/2, 2x2)": ('method.integration="cell-gauss"', "method.line_spacing=[0.5, 0.5]",
                                "method.gauss_points=2"),
}
QUICK_SETTINGS = list(SETTINGS)[:4]
GRIDS = ([(17, 5), (33, 9), (65, 17)], [(17, 5), (33, 9), (65, 17), (129, 33)])
SPACINGS = ([0.5, 0.25], [0.5, 0.25, 0.125])
MANUFACTURED_SPACINGS = ([0.1, 0.05], [0.1, 0.05, 0.025])
JITTER = 0.3    # of the spacing: the jittered cantilever's clouds (seed 0)
TARGET = 1e-3   # energy error the time is measured to


def specs(quick: bool) -> list[CaseSpec]:
    """Every setting on the cantilever's grids (regular and jittered), the manufactured solution's and the plate
    with a hole's spacings, and the patch test."""
    settings = QUICK_SETTINGS if quick else list(SETTINGS)
    k = 0 if quick else 1
    out = [CaseSpec("cantilever", (f"nodes.grid=[{nx}, {ny}]", *SETTINGS[s]),
                    labels=(("problem", "cantilever"), ("setting", s), ("size", f"{nx} x {ny}"), ("h", 48 / (nx - 1))))
           for s in settings for nx, ny in GRIDS[k]]
    out += [CaseSpec("cantilever", (f"nodes.grid=[{nx}, {ny}]", f"nodes.jitter={JITTER}", *SETTINGS[s]),
                     labels=(("problem", "cantilever-jittered"), ("setting", s), ("size", f"{nx} x {ny}"),
                             ("h", 48 / (nx - 1))))
            for s in settings for nx, ny in GRIDS[k]]
    out += [CaseSpec("manufactured", (f"nodes.spacing={h}", *SETTINGS[s]),
                     labels=(("problem", "manufactured"), ("setting", s), ("size", f"h = {h}"), ("h", h)))
            for s in settings for h in MANUFACTURED_SPACINGS[k]]
    out += [CaseSpec("plate-hole", (f"nodes.spacing={h}", *SETTINGS[s]),
                     labels=(("problem", "plate-hole"), ("setting", s), ("size", f"h = {h}"), ("h", h)))
            for s in settings for h in SPACINGS[k]]
    out += [CaseSpec("patch", SETTINGS[s], labels=(("problem", "patch"), ("setting", s), ("size", "h = 0.1"),
                                                   ("h", 0.1)))
            for s in settings]
    return out


def extra(summary: dict) -> dict:
    """The scheme, and sxx at the top of the hole where the problem has that probe (plate with a hole)."""
    top = summary["probes"].get("hole_top")
    return {"scheme": summary["parameters"]["method"]["integration"],
            "sxx_hole_top": top["sxx"] if top else np.nan}


def scheme_table(df: pd.DataFrame) -> pd.DataFrame:
    """Per setting: the patch test's larger error (L2, energy), the cantilever's fitted energy-error rate and
    finest energy error, the wall time to 0.1 % energy error (interpolated, NaN where no grid reached it), and
    the fitted energy-error rates and finest errors of the jittered cantilever and the manufactured solution."""
    ok = df[df.status == "ok"]
    rows = []
    for setting, d in ok.groupby("setting", sort=False):
        beam = d[d.problem == "cantilever"].sort_values("nodes")
        jittered = d[d.problem == "cantilever-jittered"].sort_values("nodes")
        smooth = d[d.problem == "manufactured"].sort_values("nodes")
        patch = d[d.problem == "patch"]
        rows.append({
            "setting": setting,
            "patch_error": float(patch[["l2_error", "energy_error"]].max(axis=1).iloc[0]) if len(patch) else np.nan,
            "energy_rate": _rate(beam),
            "finest_energy_error": _finest(beam),
            "points_finest": int(beam.integration_points.iloc[-1]) if len(beam) else 0,
            "time_to_0.1%_energy_s": (time_to_reach(beam[["nodes", "time_s"]].assign(tip_error=beam.energy_error),
                                                    TARGET) if len(beam) else np.nan),
            "jittered_energy_rate": _rate(jittered),
            "jittered_finest_energy_error": _finest(jittered),
            "manufactured_energy_rate": _rate(smooth),
            "manufactured_finest_energy_error": _finest(smooth),
        })
    return pd.DataFrame(rows)


def _rate(rows: pd.DataFrame) -> float:
    """The fitted energy-error rate in h of ``rows`` (sorted by nodes); NaN with fewer than two."""
    return fitted_rate(rows.h, rows.energy_error) if len(rows) > 1 else np.nan


def _finest(rows: pd.DataFrame) -> float:
    """The energy error of the finest of ``rows`` (sorted by nodes); NaN without any."""
    return float(rows.energy_error.iloc[-1]) if len(rows) else np.nan


def figure(df: pd.DataFrame) -> Figure:
    """Cantilever energy error against integration points and against wall time, plate-hole stress concentration
    against nodes; the jittered cantilever's and the manufactured solution's energy error, and the latter's L2
    error, against h."""
    fig, axes = new_figure(3, 6.0, nrows=2)
    ok = df[df.status == "ok"]
    for setting, d in ok[ok.problem == "cantilever"].groupby("setting", sort=False):
        d = d.sort_values("nodes")
        style = "o-" if setting in QUICK_SETTINGS else ".--"
        axes[0, 0].loglog(d.integration_points, 100 * d.energy_error, style, label=setting)
        axes[0, 1].loglog(d.time_s, 100 * d.energy_error, style, label=setting)
    for ax, problem, error in ((axes[1, 0], "cantilever-jittered", "energy_error"),
                               (axes[1, 1], "manufactured", "energy_error"), (axes[1, 2], "manufactured", "l2_error")):
        for setting, d in ok[ok.problem == problem].groupby("setting", sort=False):
            d = d.sort_values("h")
            ax.loglog(d.h, 100 * d[error], "o-" if setting in QUICK_SETTINGS else ".--", label=setting)
    for setting, d in ok[ok.problem == "plate-hole"].groupby("setting", sort=False):
        d = d.sort_values("nodes")
        axes[0, 2].semilogx(d.nodes, d.sxx_hole_top / 1000.0, "o-" if setting in QUICK_SETTINGS else ".--",
                            label=setting)
    axes[0, 2].axhline(3.0, color="k", lw=0.8, label="exact 3 T")
    axes[0, 0].set(xlabel="integration points", ylabel="energy-norm error [%]", title="Cantilever: error vs points")
    axes[0, 1].set(xlabel="wall time per solve, one core [s]", ylabel="energy-norm error [%]",
                   title="Cantilever: error vs time")
    axes[0, 2].set(xlabel="nodes", ylabel="sxx(0, a) / T", title="Plate with a hole: stress concentration")
    axes[1, 0].set(xlabel="node spacing h (problem length unit)", ylabel="energy-norm error [%]",
                   title=f"Cantilever, nodes jittered by {JITTER:g} h")
    axes[1, 1].set(xlabel="node spacing h (problem length unit)", ylabel="energy-norm error [%]", title="Manufactured solution")
    axes[1, 2].set(xlabel="node spacing h (problem length unit)", ylabel="L2 displacement error [%]", title="Manufactured solution")
    return finished(fig, axes, "both", 6)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
