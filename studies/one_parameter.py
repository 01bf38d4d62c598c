"""Shared pieces of the one-parameter studies of Figs. 10-12: cases and the error-against-parameter plot."""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import pandas as pd

from studies.sweep import CaseSpec

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def cantilever_specs(parameter: str, values: list[float], grids: list[tuple[int, int]],
                     override: Callable[[float], tuple[str, ...]]) -> list[CaseSpec]:
    """CTM-RPIM cantilever cases, one per (grid, value); ``override(value)`` gives the --set strings."""
    return [CaseSpec("cantilever", (f"nodes.grid=[{nx}, {ny}]", *override(v)),
                     labels=((parameter, v), ("grid", f"{nx} x {ny}")))
            for nx, ny in grids for v in values]


def error_plot(df: pd.DataFrame, parameter: str, xlabel: str, title: str, band: tuple[float, float] | None = None
               ) -> Figure:
    """Tip and energy-norm errors (%) against ``parameter`` per grid, the paper's recommended ``band`` shaded."""
    fig, axes = new_figure(1, 6.5)
    ax = axes[0, 0]
    for grid, d in df[df.status == "ok"].groupby("grid", sort=False):
        ax.semilogy(d[parameter], 100 * d.tip_error, "o-", label=f"tip error, {grid}")
        ax.semilogy(d[parameter], 100 * d.energy_error, "s--", alpha=0.6, label=f"energy error, {grid}")
    if band:
        ax.axvspan(*band, color="green", alpha=0.1, label="paper's recommended range")
    ax.set(xlabel=xlabel, ylabel="relative error [%]", title=title)
    return finished(fig, axes, "both")
