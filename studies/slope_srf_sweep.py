"""Slope displacement against the strength reduction factor (paper Fig. 19b): benchmark `slope`
solved on its own at each SRF (gravity ramped from zero at the reduced strength, Griffiths & Lane's
way; the sweep mode of the strength reduction, one case per SRF through the sweep executor, so the
levels run in parallel). A stable level reports its converged maximum displacement; a failed level
(the equilibrium iteration does not converge) the maximum displacement of its last iterate, which grows without bound.
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import pandas as pd

from studies.sweep import CaseSpec, element_for

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "slope_srf_sweep"
TITLE = "Slope: maximum displacement against SRF (cf. Fig. 19b)"
QUICK = {"h": 1.0, "srf": [1.0, 1.3, 1.5]}
FULL = {"h": 0.58, "srf": [0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.35, 1.4, 1.5, 1.6]}


def specs(quick: bool) -> list[CaseSpec]:
    """CTM-RPIM and scikit-fem P2 on the slope, each SRF on its own (gravity ramped at the reduced strength)."""
    p = QUICK if quick else FULL
    return [CaseSpec("slope", (f"parameters.h={p['h']!r}", f"strength-reduction.values=[{s!r}]"), solver, element_for(solver, "p2"),
                     labels=(("srf", s),)) for s in p["srf"] for solver in ("ctm-rpim", "fem")]


def extra(summary: dict) -> dict:
    """The level's outcome: stable or not, maximum displacement, iterations and cut-backs."""
    level = summary["history"][0]
    return {"stable": level["stable"], "max_displacement": level["max_displacement"],
            "iterations": level["iterations"], "cutbacks": level["cutbacks"]}


def figure(df: pd.DataFrame) -> Figure:
    """Maximum displacement against the SRF for both methods, stable and failed levels marked (cf. Fig. 19b)."""
    fig, axes = new_figure(1, 6.0)
    ax = axes[0, 0]
    ok = df[df.status == "ok"]
    for method, colour in (("ctm-rpim", "tab:blue"), ("fem-p2", "tab:orange")):
        d = ok[ok.method == method].sort_values("srf")
        ax.plot(d.srf, d.max_displacement, "-", color=colour, label=f"{method}")
        s, f = d[d.stable.astype(bool)], d[~d.stable.astype(bool)]
        ax.plot(s.srf, s.max_displacement, "o", color=colour)
        ax.plot(f.srf, f.max_displacement, "x", ms=9, color=colour)
    ax.plot([], [], "ko", label="stable (converged)")
    ax.plot([], [], "kx", label="failed (last iterate)")
    ax.set(xlabel="strength reduction factor SRF (-)", ylabel="maximum displacement (m)", yscale="log", title=TITLE)
    return finished(fig, axes)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
