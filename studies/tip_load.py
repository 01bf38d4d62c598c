"""Tip-loaded cantilever with large deflection (paper Fig. 14): tip deflection ratio w/L and
horizontal shortening u/L against lambda = P L^2/(E I) for the paper's loads P = 100 .. 3000 kN,
total-Lagrangian neo-Hookean CTM-RPIM (306 nodes, parabolic end shear, mid-height tip) against the
exact elastica.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

from ctmrpim import elastica
from ctmrpim.sweep import CaseSpec

from .base import new_figure, run_study

NAME = "tip_load"
TITLE = "Tip-loaded cantilever against the elastica (cf. Fig. 14)"
QUICK = [0.6, 1.8]
FULL = [elastica.paper_lambda(p) for p in elastica.PAPER_LOADS_KN]
LENGTH = 10.0


def specs(quick: bool) -> list[CaseSpec]:
    return [CaseSpec("tip-load", (f"parameters.lam={lam!r}", f"loading.steps={max(2, int(np.ceil(4 * lam)))}"),
                     labels=(("lam", lam),))
            for lam in (QUICK if quick else FULL)]


def extra(summary: dict) -> dict:
    lam = summary["parameters"]["parameters"]["lam"]
    exact = elastica.tip_load_elliptic(lam)
    tip = summary["probes"]["tip"]
    w, u = -tip["uy"] / LENGTH, -tip["ux"] / LENGTH
    return {"w_over_L": w, "w_over_L_exact": exact.w_over_L, "w_rel_diff": w / exact.w_over_L - 1.0,
            "u_over_L": u, "u_over_L_exact": exact.u_over_L, "u_rel_diff": u / exact.u_over_L - 1.0,
            "newton_iterations": summary["counts"]["newton_iterations"], "cutbacks": summary["counts"]["cutbacks"]}


def figure(df: pd.DataFrame):
    fig, axes = new_figure(1, 6.5)
    ax = axes[0, 0]
    lam = np.linspace(0.0, max(df.lam.max(), 0.1), 60)[1:]
    ex = [elastica.tip_load_elliptic(v) for v in lam]
    ax.plot(lam, [e.w_over_L for e in ex], "k-", label="elastica w/L")
    ax.plot(lam, [e.u_over_L for e in ex], "k--", label="elastica u/L")
    ok = df[df.status == "ok"]
    ax.plot(ok.lam, ok.w_over_L, "o", label="CTM-RPIM (TL) w/L")
    ax.plot(ok.lam, ok.u_over_L, "s", label="CTM-RPIM (TL) u/L")
    ax.set(xlabel="lambda = P L^2 / (E I)", ylabel="tip displacement / L", title=TITLE)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def run(quick: bool = True, out_dir: Path = Path("reports"), sweep=None, progress=print) -> pd.DataFrame:
    return run_study(sys.modules[__name__], quick, out_dir, sweep, progress)


if __name__ == "__main__":
    from .cli import main
    main(run, __doc__)
