"""Node density (paper Fig. 9): the cantilever at 17 x 5 ... 129 x 33 nodes (257 x 65 in full mode),
CTM-RPIM with linear and quadratic augmentation against scikit-fem Q1, P1 and P2 on the same node
grids: tip, L2 and energy-norm errors, integration points, wall time, fitted rates in h.

CTM-RPIM uses the project's defaults (eta = 5, r_c = 4 d_c, r_x = r_y = d_c/3, one Gauss point; docs/design.md,
'Parameters and conventions'), not the r_c = 2 d_c / two-point setting printed beside Fig. 9 (1-1.8 % at
33 x 9, not the 0.3 % shown), with the paper's integration (``ctm-rpim``, ``ctm-rpim-quadratic``) and with
the consistent one, the default of a linear analysis (``ctm-rpim-vci``, ``ctm-rpim-quadratic-vci``).
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import pandas as pd

from ctmrpim.problem.expressions import Field
from studies.schemes import SCHEMES, scheme_override
from studies.sweep import CaseSpec

from .base import finished, new_figure
from .fitting import fitted_rate

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "node_density"
TITLE = "Node density (cf. Fig. 9)"
QUICK_GRIDS = [(17, 5), (33, 9), (65, 17)]
FULL_GRIDS = QUICK_GRIDS + [(129, 33), (257, 65)]
LENGTH = 48.0
METHODS = [*(("ctm-rpim", None, (scheme_override(s), *basis)) for s in SCHEMES
             for basis in ((), ('method.polynomial="quadratic"',))),
           ("fem", "q1", ()), ("fem", "p1", ()), ("fem", "p2", ())]


def specs(quick: bool) -> list[CaseSpec]:
    """Each method (CTM-RPIM linear and quadratic with each integration scheme, scikit-fem Q1, P1, P2) on each
    cantilever grid, labelled by the grid and its spacing h."""
    out = []
    for nx, ny in QUICK_GRIDS if quick else FULL_GRIDS:
        for solver, element, extra in METHODS:
            out.append(CaseSpec("cantilever", (f"nodes.grid=[{nx}, {ny}]", *extra), solver, element,
                                labels=(("grid", f"{nx} x {ny}"), ("h", LENGTH / (nx - 1)))))
    return out


def extra(summary: dict) -> dict:
    """The signed tip deflection (m, the paper's unit of length: Table 1) of the run, the exact one (the benchmark's
    ``[exact] uy``, paper Eq. 35) at the tip probe, and their ratio: the paper's Fig. 9a plots the deflection against
    the node count."""
    tip = summary["probes"]["tip"]
    parameters = summary["parameters"]
    exact = float(Field(parameters["exact"]["uy"], parameters["parameters"])(tip["x"], tip["y"]))
    return {"tip_uy": tip["uy"], "tip_uy_exact": exact, "tip_ratio": tip["uy"] / exact}


def rates(df: pd.DataFrame) -> pd.DataFrame:
    """Fitted convergence rate in h of each method and norm over the grids run."""
    rows = []
    for method, d in df[df.status == "ok"].groupby("method", sort=False):
        rows.append({"method": method, **{f"rate_{c}": fitted_rate(d.h, d[c])
                                          for c in ("tip_error", "l2_error", "energy_error")}})
    return pd.DataFrame(rows)


def figure(df: pd.DataFrame) -> Figure:
    """The tip deflection against the exact one (Fig. 9a), the tip and energy-norm errors (Fig. 9b) of each method
    against the node count. A table from before the tip deflection was tabulated draws the errors alone."""
    ok = df[df.status == "ok"]
    deflection = "tip_ratio" in ok and ok.tip_ratio.notna().any()
    fig, axes = new_figure(3 if deflection else 2)
    errors = axes[0, 1:] if deflection else axes[0]
    for method, d in ok.groupby("method", sort=False):
        if deflection:
            axes[0, 0].semilogx(d.nodes, d.tip_ratio, "o-", label=method)
        errors[0].loglog(d.nodes, d.tip_error, "o-", label=method)
        errors[1].loglog(d.nodes, d.energy_error, "o-", label=method)
    if deflection:
        ax = axes[0, 0]
        ax.axhline(1.0, color="k", lw=0.8, ls="--", label="exact (Eq. 35)")
        exact = ok.tip_uy_exact.iloc[0]
        ax.set(xlabel="number of field nodes (-)", ylabel="tip deflection v_h / v_exact (-)",
               title=f"Tip deflection (cf. Fig. 9a); v_exact = {exact:.4g} m")
    errors[0].set(xlabel="number of field nodes (-)", ylabel="relative tip-deflection error |v_h/v_exact - 1| (-)",
                  title="Cantilever tip error (cf. Fig. 9b)")
    errors[1].set(xlabel="number of field nodes (-)", ylabel="relative energy-norm error (-)", title="Energy-norm error")
    return finished(fig, axes, "both", 8)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
