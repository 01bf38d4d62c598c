"""Shape parameter (paper Fig. 12): eta from 1.5 in steps of 1.0 over the paper's range, 17 x 5 nodes, r = d_c/3,
r_c = 4 d_c. The paper claims eta in [3.5, 9.5] is accurate and [4.5, 7.5] low and stable.
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import pandas as pd

from studies.sweep import CaseSpec

from .one_parameter import cantilever_specs, error_plot

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "shape_parameter"
TITLE = "Shape parameter (cf. Fig. 12)"
PARAMETER = "eta"
QUICK = [1.5, 3.5, 4.5, 5.5, 6.5, 7.5, 9.5]
FULL = [1.5 + 1.0 * i for i in range(10)]
QUICK_GRIDS = [(17, 5)]
FULL_GRIDS = [(17, 5)]
PAPER_RANGE = (4.5, 7.5)


def specs(quick: bool) -> list[CaseSpec]:
    """The CTM-RPIM cantilever (17 x 5) at each eta."""
    return cantilever_specs(PARAMETER, QUICK if quick else FULL, QUICK_GRIDS if quick else FULL_GRIDS,
                            lambda v: (f"method.eta={v!r}",))


def figure(df: pd.DataFrame) -> Figure:
    """Tip and energy-norm errors against eta, the paper's low and stable range shaded (cf. Fig. 12)."""
    return error_plot(df, PARAMETER, "shape parameter eta (-)", TITLE, PAPER_RANGE)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
