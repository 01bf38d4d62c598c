"""Cantilever rolled up by a follower end moment (paper Figs. 16-17, Eq. 37): tip position against
the exact circular arc x = L sin(t)/t, y = L (1 - cos t)/t, t = 2 pi m, for fractions m of the ring
moment 2 pi E I / L; 81 x 5 nodes, neo-Hookean CTM-RPIM: adaptive updated-Lagrangian (UL, 64
increments per ring, boundary re-tracked, CTM points laid anew and RPIM rebuilt after each, as in the
paper), the same with the integration points carried by the body (UL carried: boundary and RPIM
rebuilt, points and their state kept), total-Lagrangian (TL, 32 increments per ring), and scikit-fem
P2 (total-Lagrangian, same nodes). The two end tractions turn with the end face as a whole
(`follower = "face"`), so the moment stays a pure couple.
At m = 1 the exact beam closes into a circle of radius L / (2 pi).
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from ctmrpim.reference import elastica
from studies.sweep import CaseSpec

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "end_moment"
TITLE = "End moment: tip against the exact arc (cf. Figs. 16-17)"
QUICK = [0.25]
FULL = [0.25, 0.5, 0.75, 1.0]
LENGTH = 10.0
STEPS_PER_RING = {"UL": 64, "UL carried": 64, "TL": 32}
#: UL lays new CTM points every increment (the paper); "UL carried" keeps the points the body carries
#: (method.point_regeneration = 0.5: the beams never strain that much) and rebuilds boundary and RPIM
FORMULATIONS = {"UL": ('method.formulation="updated-lagrangian"',),
                "UL carried": ('method.formulation="updated-lagrangian"', "method.point_regeneration=0.5"),
                "TL": ('method.formulation="total-lagrangian"',)}


def specs(quick: bool) -> list[CaseSpec]:
    """Each formulation (UL, UL carried, TL; and scikit-fem P2, TL) at each moment fraction m, with increments in
    proportion to m."""
    ms = QUICK if quick else FULL
    ours = [CaseSpec("end-moment", (f"parameters.m={m!r}", f"loading.steps={int(np.ceil(STEPS_PER_RING[short] * m))}",
                                    *overrides),
                     labels=(("formulation", short), ("m", m)))
            for short, overrides in FORMULATIONS.items() for m in ms]
    fem = [CaseSpec("end-moment", (f"parameters.m={m!r}", f"loading.steps={int(np.ceil(STEPS_PER_RING['TL'] * m))}"),
                    "fem", "p2", labels=(("formulation", "TL"), ("m", m))) for m in ms]
    return ours + fem


def extra(summary: dict) -> dict:
    """The tip (x/L, y/L) against the exact arc (Eq. 37), their distance, the Newton iterations and cut-backs."""
    m = summary["parameters"]["parameters"]["m"]
    tip = summary["probes"]["tip"]
    x, y = 1.0 + tip["ux"] / LENGTH, tip["uy"] / LENGTH
    ex, ey = elastica.end_moment_tip(2 * np.pi * m)
    return {"x_over_L": x, "x_exact": ex, "y_over_L": y, "y_exact": ey, "tip_distance_over_L": float(np.hypot(x - ex, y - ey)),
            "newton_iterations": summary["counts"]["newton_iterations"], "cutbacks": summary["counts"]["cutbacks"]}


def figure(df: pd.DataFrame) -> Figure:
    """The tip of every case on the exact tip path (cf. Figs. 16-17)."""
    fig, axes = new_figure(1, 6.0)
    ax = axes[0, 0]
    t = np.linspace(1e-6, 2 * np.pi, 200)
    path = np.array([elastica.end_moment_tip(v) for v in t])
    ax.plot(path[:, 0], path[:, 1], "k-", label="exact tip path")
    ok = df[df.status == "ok"]
    for formulation, marker in (("UL", "o"), ("UL carried", "D"), ("TL", "s")):
        d = ok[(ok.formulation == formulation) & (ok.method == "ctm-rpim")]
        ax.plot(d.x_over_L, d.y_over_L, marker, mfc="none" if formulation != "UL" else None,
                label=f"CTM-RPIM ({formulation})")
    d = ok[ok.method == "fem-p2"]
    ax.plot(d.x_over_L, d.y_over_L, "k+", ms=9, label="scikit-fem P2 (TL)")
    for _, r in ok[(ok.formulation == "UL") & (ok.method == "ctm-rpim")].iterrows():
        ax.annotate(f"m = {r.m:g}", (r.x_over_L, r.y_over_L), textcoords="offset points", xytext=(6, 4), fontsize=8)
    ax.set(xlabel="x / L", ylabel="y / L", title=TITLE, aspect="equal")
    return finished(fig, axes)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
