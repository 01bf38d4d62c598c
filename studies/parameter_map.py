"""Two-parameter map (not in the paper): the cantilever tip error over support radius r_c/d_c and
shape parameter eta together, 17 x 5 nodes, r = d_c/3, one Gauss point, the paper's integration, as a
heat map. It shows whether the paper's one-at-a-time recommendations (r_c = 3.5-4 d_c, eta = 4.5-7.5) hold
jointly.
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from studies.schemes import PAPER, scheme_override
from studies.sweep import CaseSpec

from .base import new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "parameter_map"
TITLE = "Tip error over r_c and eta (17 x 5)"
QUICK = ([2.0, 3.0, 4.0, 5.0, 6.0], [3.5, 5.5, 7.5])
FULL = ([2.0 + 0.5 * i for i in range(9)], [2.5 + 1.0 * i for i in range(8)])


def specs(quick: bool) -> list[CaseSpec]:
    """The cantilever (17 x 5) at each pair of r_c/d_c and eta."""
    radii, etas = QUICK if quick else FULL
    return [CaseSpec("cantilever", ("nodes.grid=[17, 5]", f"method.support_radius={rc!r}", f"method.eta={eta!r}",
                                    scheme_override(PAPER)),
                     labels=(("rc_over_dc", rc), ("eta", eta)))
            for rc in radii for eta in etas]


def figure(df: pd.DataFrame) -> Figure:
    """Heat map of the tip error (%) over r_c/d_c and eta."""
    grid = df.pivot(index="eta", columns="rc_over_dc", values="tip_error")
    fig, axes = new_figure(1, 6.5)
    ax = axes[0, 0]
    im = ax.imshow(np.log10(100 * grid.to_numpy(dtype=float)), origin="lower", aspect="auto", cmap="viridis")
    ax.set_xticks(range(grid.shape[1]), [f"{v:g}" for v in grid.columns])
    ax.set_yticks(range(grid.shape[0]), [f"{v:g}" for v in grid.index])
    for (i, j), v in np.ndenumerate(grid.to_numpy(dtype=float)):
        ax.text(j, i, f"{100 * v:.2g}", ha="center", va="center", fontsize=7, color="w")
    ax.set(xlabel="r_c / d_c", ylabel="eta", title=TITLE + " [%]")
    fig.colorbar(im, ax=ax, label="log10(tip error [%])")
    fig.tight_layout()
    return fig


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
