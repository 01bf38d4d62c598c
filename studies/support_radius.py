"""Support radius (paper Fig. 11): r_c/d_c from 1.5 to 6.0 step 0.5, 17 x 5 nodes, r = d_c/3,
eta = 5. The paper claims the error is below 1.5 % and nearly stable from r_c = 3.5 d_c, and
recommends 3.5-4.0 d_c.
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import pandas as pd

from studies.sweep import CaseSpec

from .one_parameter import cantilever_specs, error_plot

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "support_radius"
TITLE = "Support radius (cf. Fig. 11)"
PARAMETER = "rc_over_dc"
QUICK = [2.0, 3.0, 3.5, 4.0, 5.0, 6.0]
FULL = [1.5 + 0.5 * i for i in range(10)]
QUICK_GRIDS = [(17, 5)]
FULL_GRIDS = [(17, 5)]
PAPER_RANGE = (3.5, 4.0)


def specs(quick: bool) -> list[CaseSpec]:
    """The CTM-RPIM cantilever (17 x 5) at each r_c/d_c."""
    return cantilever_specs(PARAMETER, QUICK if quick else FULL, QUICK_GRIDS if quick else FULL_GRIDS,
                            lambda v: (f"method.support_radius={v!r}",))


def figure(df: pd.DataFrame) -> Figure:
    """Tip and energy-norm errors against r_c/d_c, the paper's recommended range shaded (cf. Fig. 11)."""
    return error_plot(df, PARAMETER, "support radius r_c / d_c (-)", TITLE, PAPER_RANGE)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
