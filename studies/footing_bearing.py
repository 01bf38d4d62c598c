"""Strip footing bearing capacity (paper Section 3.3.2, Figs. 22-24): the pressure on the flexible
footing is raised in increments (halved near the limit) until the undrained soil (phi = psi ~ 0)
cannot carry it; the limit pressure is the bracket [last carried, first not carried], against Prandtl's
(2 + pi) c_u. CTM-RPIM and scikit-fem P2 on the same node grids (the default 49 x 21 has the paper's node
count), with the load-settlement curve of the footing centre, beside the published values of Smith &
Griffiths and of the paper (the table below). The full run adds a coarser and a finer grid.
"""
from __future__ import annotations

import json
import math
import sys
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from studies.sweep import CaseSpec, element_for

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "footing_bearing"
TITLE = "Strip footing: pressure against settlement (cf. Fig. 24)"
PRANDTL = (2.0 + math.pi) * 100.0      # kPa
GRIDS = {"quick": [(49, 21)], "full": [(37, 16), (49, 21), (73, 31)]}


def specs(quick: bool) -> list[CaseSpec]:
    """CTM-RPIM and scikit-fem P2 on each node grid."""
    grids = GRIDS["quick" if quick else "full"]
    return [CaseSpec("footing", (f"parameters.nx={nx}", f"parameters.ny={ny}"), solver,
                     element_for(solver, "p2"), labels=(("grid", f"{nx} x {ny}"),))
            for nx, ny in grids for solver in ("ctm-rpim", "fem")]


def extra(summary: dict) -> dict:
    """The limit-pressure bracket (kPa) and its worst relative difference from Prandtl's (Eq. 40), the
    settlement at 500 kPa, the Newton iterations and the load-settlement curve (JSON)."""
    limit = summary["limit_pressure"]
    carried = [h for h in summary["history"] if h["converged"]]
    q_max = summary["parameters"]["parameters"]["q_max"]
    q = np.array([h["load_factor"] * q_max / 1e3 for h in carried])
    w = np.array([-h["centre"]["uy"] for h in carried])
    order = np.argsort(q)
    q, w = q[order], w[order]
    at500 = float(np.interp(500.0, q, w)) if q.max() >= 500.0 else float("nan")
    carried_kpa = limit["carried"] / 1e3
    failed_kpa = limit["failed"] / 1e3 if limit["failed"] is not None else float("nan")
    return {"limit_carried_kPa": carried_kpa, "limit_failed_kPa": failed_kpa,
            "worst_rel_diff": max(abs(carried_kpa / PRANDTL - 1), abs(failed_kpa / PRANDTL - 1)),
            "settlement_at_500_kPa_m": at500, "newton_iterations": summary["counts"]["newton_iterations"],
            "curve": json.dumps({"q_kPa": q.round(3).tolist(), "w_m": w.tolist()})}


def figure(df: pd.DataFrame) -> Figure:
    """Pressure against the settlement of the footing centre for every case, with Prandtl's limit and the
    published points (cf. Fig. 24)."""
    fig, axes = new_figure(1, 6.0)
    ax = axes[0, 0]
    ok = df[df.status == "ok"]
    styles = {"ctm-rpim": "-", "fem-p2": "--"}
    for _, r in ok.iterrows():
        c = json.loads(r.curve)
        ax.plot(np.array(c["w_m"]) * 100, c["q_kPa"], styles[r.method], marker=".", ms=3,
                label=f"{r.method}, {r.grid}: limit {r.limit_carried_kPa:.1f}-{r.limit_failed_kPa:.1f} kPa")
    ax.axhline(PRANDTL, color="k", lw=0.8, label="Prandtl (2 + pi) c_u = 514.2 kPa")
    ax.plot([5.1], [500], "ks", mfc="none", label="Smith & Griffiths: 5.1 cm at 500 kPa")
    ax.plot([6.0], [500], "k^", mfc="none", label="paper: about 6 cm at 500 kPa")
    ax.set(xlabel="settlement of the footing centre (cm)", ylabel="pressure (kPa)", xlim=(0, 30), ylim=(0, 560),
           title=TITLE)
    return finished(fig, axes, fontsize=7)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
