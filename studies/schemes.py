"""The integration schemes the linear studies show side by side: the paper's one-point CTM and the
consistent CTM (VCI), the default of a linear analysis. Each case names its scheme explicitly, so a
table's rows do not change meaning when a default does."""
from __future__ import annotations

PAPER = "ctm"
CONSISTENT = "ctm-vci"
SCHEMES = (PAPER, CONSISTENT)


def scheme_override(scheme: str) -> str:
    """The --set string that selects ``scheme``."""
    return f'method.integration="{scheme}"'
