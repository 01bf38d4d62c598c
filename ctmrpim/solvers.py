"""One entry point for every method that solves a Case: CTM-RPIM or the scikit-fem reference."""
from __future__ import annotations

from .problem_file import Case
from .result import Result

METHODS = ("ctm-rpim", "fem")
ELEMENTS = ("q1", "p1", "p2")


def solve(case: Case, solver: str = "ctm-rpim", element: str = "q1") -> Result:
    """Solve ``case`` with CTM-RPIM, or with scikit-fem ``element`` when ``solver == "fem"``."""
    if solver == "fem":
        from reference_fem import solve_fem
        return solve_fem(case, element)
    from .linear_static import solve_ctmrpim
    return solve_ctmrpim(case)
