"""Integration density (paper Fig. 10): d_c/r from 1.0 to 5.0 step 0.5 with r_x = r_y = r,
17 x 5 and 33 x 9 nodes, support radius 4 d_c, eta = 5, one Gauss point per sub-segment. The paper
claims the error falls roughly exponentially in d_c/r and is satisfactory from d_c/r = 3.
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import pandas as pd

from studies.sweep import CaseSpec

from .one_parameter import cantilever_specs, error_plot

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "integration_density"
TITLE = "Integration density (cf. Fig. 10)"
PARAMETER = "dc_over_r"
QUICK = [1.0, 2.0, 3.0, 4.0, 5.0]
FULL = [1.0 + 0.5 * i for i in range(9)]
QUICK_GRIDS = [(17, 5), (33, 9)]
FULL_GRIDS = [(17, 5), (33, 9)]
PAPER_RANGE = (3.0, 5.0)


def specs(quick: bool) -> list[CaseSpec]:
    """The CTM-RPIM cantilever at each d_c/r (r_x = r_y = r) on each grid."""
    return cantilever_specs(PARAMETER, QUICK if quick else FULL, QUICK_GRIDS if quick else FULL_GRIDS,
                            lambda q: (f"method.line_spacing=[{1 / q!r}, {1 / q!r}]",))


def figure(df: pd.DataFrame) -> Figure:
    """Tip and energy-norm errors against d_c/r, the paper's satisfactory range shaded (cf. Fig. 10)."""
    return error_plot(df, PARAMETER, "integration density d_c / r, r = r_x = r_y (-)", TITLE, PAPER_RANGE)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
