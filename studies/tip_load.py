"""Tip-loaded cantilever with large deflection (paper Fig. 14): tip deflection ratio w/L and
horizontal shortening u/L against lambda = P L^2/(E I) for the paper's loads
(``ctmrpim.reference.elastica.PAPER_LOADS_KN``; quick mode two of them), neo-Hookean CTM-RPIM (the benchmark's
cloud, mid-height tip), adaptive updated-Lagrangian (UL: boundary
re-tracked and CTM / RPIM rebuilt after every increment) and total-Lagrangian (TL, the cross-check),
against the exact elastica, for
two ways of applying P: a parabolic shear on the end face (benchmark tip-load, against the clean
elastica) and the paper's concentrated force at the top-right corner (tip-load-corner, against the
elastica with the matching end moment, e = W/2); scikit-fem P2 (total-Lagrangian, same nodes) on the
end-shear variant as the finite-element reference of the same continuum.
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

NAME = "tip_load"
TITLE = "Tip-loaded cantilever against the elastica (cf. Fig. 14)"
QUICK = [0.6, 1.8]
FULL = [elastica.paper_lambda(p) for p in elastica.PAPER_LOADS_KN]
LENGTH = 10.0
ECCENTRICITY = 0.05        # e / L = (W / 2) / L of the corner load
VARIANTS = {"tip-load": "end shear", "tip-load-corner": "corner"}
FORMULATIONS = {"UL": "updated-lagrangian", "TL": "total-lagrangian"}
MIN_STEPS = {"UL": 6, "TL": 2}


def specs(quick: bool) -> list[CaseSpec]:
    """UL and TL CTM-RPIM on both load variants at each lambda, and scikit-fem P2 (TL) on the end shear;
    increments in proportion to lambda."""
    lams = QUICK if quick else FULL

    def overrides(lam, fewest=2):
        return (f"parameters.lam={lam!r}", f"loading.steps={max(fewest, int(np.ceil(4 * lam)))}")

    # UL: at least 6 increments (with 3 at lambda = 0.6 the shortening u/L is 2.2 % off, with 6 0.1 %)
    ours = [CaseSpec(target, overrides(lam, MIN_STEPS[short]) + (f'method.formulation="{formulation}"',),
                     labels=(("formulation", short), ("load", variant), ("lam", lam)))
            for short, formulation in FORMULATIONS.items() for target, variant in VARIANTS.items() for lam in lams]
    # scikit-fem P2 total-Lagrangian on the same nodes (end shear only: the FEM reference has no point loads)
    fem = [CaseSpec("tip-load", overrides(lam), "fem", "p2",
                    labels=(("formulation", "TL"), ("load", "end shear"), ("lam", lam)))
           for lam in lams]
    return ours + fem


def extra(summary: dict) -> dict:
    """Tip deflection w/L and shortening u/L against the elastica (with the end moment for the corner load),
    their relative differences, the Newton iterations and cut-backs."""
    lam = summary["parameters"]["parameters"]["lam"]
    corner = summary["parameters"]["problem"]["name"] == "tip-load-corner"
    exact = elastica.tip_load_bvp(lam, eccentricity=ECCENTRICITY) if corner else elastica.tip_load_elliptic(lam)
    tip = summary["probes"]["tip"]
    w, u = -tip["uy"] / LENGTH, -tip["ux"] / LENGTH
    return {"w_over_L": w, "w_over_L_exact": exact.w_over_L, "w_rel_diff": w / exact.w_over_L - 1.0,
            "u_over_L": u, "u_over_L_exact": exact.u_over_L, "u_rel_diff": u / exact.u_over_L - 1.0,
            "newton_iterations": summary["counts"]["newton_iterations"], "cutbacks": summary["counts"]["cutbacks"]}


def figure(df: pd.DataFrame) -> Figure:
    """w/L and u/L against lambda of every case on the elastica's curves (cf. Fig. 14)."""
    fig, axes = new_figure(1, 6.5)
    ax = axes[0, 0]
    lam = np.linspace(0.0, max(df.lam.max(), 0.1), 60)[1:]
    ex = [elastica.tip_load_elliptic(v) for v in lam]
    ax.plot(lam, [e.w_over_L for e in ex], "k-", label="elastica w/L")
    ax.plot(lam, [e.u_over_L for e in ex], "k--", label="elastica u/L")
    ecc = [elastica.tip_load_bvp(v, eccentricity=ECCENTRICITY) for v in lam]
    ax.plot(lam, [e.w_over_L for e in ecc], "-", color="grey", label="elastica w/L, corner load")
    ok = df[df.status == "ok"]
    for formulation, variant, marker in (("UL", "end shear", "o"), ("UL", "corner", "^"),
                                         ("TL", "end shear", "s"), ("TL", "corner", "v")):
        d = ok[(ok.load == variant) & (ok.method == "ctm-rpim") & (ok.formulation == formulation)]
        ax.plot(d.lam, d.w_over_L, marker, label=f"CTM-RPIM ({formulation}) w/L, {variant}")
        ax.plot(d.lam, d.u_over_L, marker, mfc="none", label=f"CTM-RPIM ({formulation}) u/L, {variant}")
    d = ok[ok.method == "fem-p2"]
    ax.plot(d.lam, d.w_over_L, "k+", ms=9, label="scikit-fem P2 (TL) w/L, end shear")
    ax.set(xlabel="lambda = P L^2 / (E I)", ylabel="tip displacement / L", title=TITLE)
    return finished(fig, axes)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
