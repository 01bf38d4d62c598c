"""Slope by dynamic relaxation, the paper's own solver (Section 2.1.4, Eq. 11; Fig. 19): benchmark
`slope` at each SRF on its own, gravity applied at once on the reduced strength and relaxed by
explicit central differences with local damping f = 0.8 (fictitious Gershgorin mass, so one step is
one pseudo-time unit) for a fixed budget of steps (``dynamic.steps``, as in the paper), CTM-RPIM and
scikit-fem P2 through the same driver. A level is stable when the out-of-balance force falls below 1e-4 of
the weight; a failed level is still moving at the end of its budget and its displacement grows without
bound. Quick mode: the coarser cloud (h = 1.0 m) and three SRF values.
"""
from __future__ import annotations

import json
import sys
from typing import TYPE_CHECKING

import pandas as pd

from studies.sweep import CaseSpec, element_for

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "slope_relaxation"
TITLE = "Slope by dynamic relaxation: maximum displacement against step (cf. Fig. 19a)"
QUICK = {"h": 1.0, "srf": [1.0, 1.3, 1.5]}
FULL = {"h": 0.58, "srf": [0.8, 1.0, 1.2, 1.3, 1.35, 1.4, 1.5, 1.6]}
SOLVER = ('strength-reduction.solver="dynamic-relaxation"', "dynamic.steps=3000", "dynamic.record_every=20")


def specs(quick: bool) -> list[CaseSpec]:
    """CTM-RPIM and scikit-fem P2 on the slope, each SRF on its own, by dynamic relaxation."""
    p = QUICK if quick else FULL
    return [CaseSpec("slope", (f"parameters.h={p['h']!r}", f"strength-reduction.values=[{s!r}]", *SOLVER), solver,
                     element_for(solver, "p2"), labels=(("srf", s),)) for s in p["srf"] for solver in ("ctm-rpim", "fem")]


def extra(summary: dict) -> dict:
    """The level's outcome: at rest or not, steps, maximum displacement and its history (JSON [step, maximum
    displacement])."""
    level = summary["history"][0]
    return {"stable": level["stable"], "steps": level["iterations"], "max_displacement": level["max_displacement"],
            "history": json.dumps(level["displacement_history"])}


def figure(df: pd.DataFrame) -> Figure:
    """CTM-RPIM's maximum displacement against the step for each SRF (cf. Fig. 19a), and the final maximum
    displacement against the SRF for both methods (cf. Fig. 19b)."""
    fig, axes = new_figure(2, 5.5)
    ok = df[df.status == "ok"].sort_values("srf")
    ax = axes[0, 0]
    cmap = __import__("matplotlib").colormaps["viridis"]
    srfs = sorted(ok.srf.unique())
    for _, r in ok[ok.method == "ctm-rpim"].iterrows():
        h = json.loads(r.history)
        colour = cmap(srfs.index(r.srf) / max(len(srfs) - 1, 1))
        ax.plot([p[0] for p in h], [p[1] for p in h], "-", color=colour,
                label=f"SRF {r.srf:g} ({'at rest' if r.stable else 'moving'})")
    ax.set(xlabel="dynamic-relaxation step (-)", ylabel="maximum displacement (m)",
           title="CTM-RPIM: maximum displacement at every step (cf. Fig. 19a)", yscale="log")
    ax = axes[0, 1]
    for method, colour in (("ctm-rpim", "tab:blue"), ("fem-p2", "tab:orange")):
        d = ok[ok.method == method]
        ax.plot(d.srf, d.max_displacement, "-o", color=colour, label=method)
        f = d[~d.stable.astype(bool)]
        ax.plot(f.srf, f.max_displacement, "kx", ms=9)
    ax.plot([], [], "kx", label=f"not at rest after {int(ok.steps.max())} steps")
    ax.set(xlabel="strength reduction factor SRF (-)", ylabel="final maximum displacement (m)",
           title="Final maximum displacement against SRF (cf. Fig. 19b)", yscale="log")
    return finished(fig, axes, fontsize=7)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
