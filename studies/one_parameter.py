"""Shared pieces of the one-parameter studies of Figs. 10-12: cases and the error-against-parameter plot."""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import pandas as pd

from studies.schemes import SCHEMES, scheme_override
from studies.sweep import CaseSpec

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def cantilever_specs(parameter: str, values: list[float], grids: list[tuple[int, int]],
                     override: Callable[[float], tuple[str, ...]], schemes: tuple[str, ...] = SCHEMES
                     ) -> list[CaseSpec]:
    """CTM-RPIM cantilever cases, one per (integration scheme, grid, value); ``override(value)`` gives the
    --set strings."""
    return [CaseSpec("cantilever", (f"nodes.grid=[{nx}, {ny}]", *override(v), scheme_override(s)),
                     labels=((parameter, v), ("grid", f"{nx} x {ny}"), ("scheme", s)))
            for s in schemes for nx, ny in grids for v in values]


def error_plot(df: pd.DataFrame, parameter: str, xlabel: str, title: str, band: tuple[float, float] | None = None
               ) -> Figure:
    """Tip and energy-norm errors (%) against ``parameter`` per grid, one panel per integration scheme, the
    paper's recommended ``band`` shaded."""
    ok = df[df.status == "ok"]
    schemes = list(dict.fromkeys(ok.scheme))
    fig, axes = new_figure(len(schemes), 6.5)
    for ax, scheme in zip(axes[0], schemes):
        for grid, d in ok[ok.scheme == scheme].groupby("grid", sort=False):
            ax.semilogy(d[parameter], 100 * d.tip_error, "o-", label=f"tip error, {grid}")
            ax.semilogy(d[parameter], 100 * d.energy_error, "s--", alpha=0.6, label=f"energy error, {grid}")
        if band:
            ax.axvspan(*band, color="green", alpha=0.1, label="paper's recommended range")
        ax.set(xlabel=xlabel, ylabel="relative error [%]", title=f"{title}: integration {scheme}")
    return finished(fig, axes, "both")
