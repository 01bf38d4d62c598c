"""Time to accuracy: cantilever tip error against wall time for CTM-RPIM (the paper's integration and the
consistent one, the default) and scikit-fem Q1, P1 and P2
over a range of node grids (a Pareto plot), and the time each method needs to reach 1 %, 0.1 % and
0.01 % tip error, interpolated in log-log between the grids that bracket it. Every case runs on one
core (the sweep executor's workers), so the times compare.
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from studies.schemes import SCHEMES, scheme_override
from studies.sweep import CaseSpec

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "time_to_accuracy"
TITLE = "Time to accuracy (cantilever tip error)"
TARGETS = (1e-2, 1e-3, 1e-4)
GRIDS = {  # (quick, full) node grids per method (solver, element, overrides); FEM is cheap, so it goes finer
    **{("ctm-rpim", None, (scheme_override(s),)): ([(17, 5), (33, 9), (65, 17)],
                                                   [(17, 5), (33, 9), (65, 17), (129, 33), (257, 65)])
       for s in SCHEMES},
    ("fem", "q1", ()): ([(17, 5), (33, 9), (65, 17), (129, 33)],
                        [(17, 5), (33, 9), (65, 17), (129, 33), (257, 65), (513, 129)]),
    ("fem", "p1", ()): ([(33, 9), (65, 17), (129, 33)], [(33, 9), (65, 17), (129, 33), (257, 65), (513, 129)]),
    ("fem", "p2", ()): ([(9, 3), (17, 5), (33, 9)], [(9, 3), (17, 5), (33, 9), (65, 17)]),
}


def specs(quick: bool) -> list[CaseSpec]:
    """Each method on each of its cantilever grids."""
    return [CaseSpec("cantilever", (f"nodes.grid=[{nx}, {ny}]", *extra), solver, element,
                     labels=(("grid", f"{nx} x {ny}"),))
            for (solver, element, extra), grids in GRIDS.items() for nx, ny in grids[0 if quick else 1]]


def time_to_reach(d: pd.DataFrame, target: float) -> float:
    """Wall time at which the tip error reaches ``target``, NaN if no grid did: walking the grids from
    coarse to fine, interpolated in log-log between the two that bracket the target."""
    d = d.sort_values("nodes")
    t, e = np.log(d.time_s.to_numpy()), np.log(d.tip_error.to_numpy())
    for i in range(len(e)):
        if e[i] <= np.log(target):
            if i == 0:
                return float(np.exp(t[0]))
            f = (np.log(target) - e[i - 1]) / (e[i] - e[i - 1])
            return float(np.exp(t[i - 1] + f * (t[i] - t[i - 1])))
    return float("nan")


def targets_table(df: pd.DataFrame) -> pd.DataFrame:
    """One row per method: the wall time (s) to reach each target tip error (:func:`time_to_reach`)."""
    ok = df[df.status == "ok"]
    rows = [{"method": m, **{f"time_to_{100 * x:g}%": time_to_reach(d, x) for x in TARGETS}}
            for m, d in ok.groupby("method", sort=False)]
    return pd.DataFrame(rows)


def figure(df: pd.DataFrame) -> Figure:
    """Tip error against wall time for each method (a Pareto plot), the targets marked."""
    fig, axes = new_figure(1, 6.5)
    ax = axes[0, 0]
    for method, d in df[df.status == "ok"].groupby("method", sort=False):
        d = d.sort_values("nodes")
        ax.loglog(d.time_s, 100 * d.tip_error, "o-", label=method)
    for x in TARGETS:
        ax.axhline(100 * x, color="grey", lw=0.8, ls=":")
    ax.set(xlabel="wall time per solve, one core [s]", ylabel="tip error [%]", title=TITLE)
    from matplotlib.ticker import LogFormatterSciNotation, NullFormatter
    ax.xaxis.set_major_formatter(LogFormatterSciNotation())
    ax.xaxis.set_minor_formatter(NullFormatter())
    return finished(fig, axes, "both")


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
