"""The scikit-fem reference as the method ``"fem"`` of :mod:`ctmrpim.methods` (``METHOD``, the entry
point ``ctmrpim.methods: fem``): each analysis of a Case to its finite-element solver."""
from __future__ import annotations

from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.methods import SolutionMethod
from ctmrpim.problem.case import Case
from ctmrpim.result import Result
from ctmrpim.run_options import RunOptions

#: element types, the first the default (bilinear quadrilaterals on a grid, else linear triangles)
ELEMENTS = ("q1", "p1", "p2")


def solve_fem_case(case: Case, element: str | None, options: RunOptions) -> Result:
    """Solve ``case`` with scikit-fem on the case's nodes with ``element``."""
    element = element or ELEMENTS[0]
    problem = case.problem
    if problem.analysis == "explicit":
        raise ProblemError("the FEM reference has no explicit dynamic solver (the column collapse is "
                           "CTM-RPIM's alone)", key="--solver")
    if isinstance(problem.material, MohrCoulomb):
        from reference_fem.elastoplastic import solve_fem_elastoplastic
        return solve_fem_elastoplastic(case, element, options.progress)
    if problem.analysis == "quasi-static":
        from reference_fem.hyperelastic import solve_fem_hyperelastic
        return solve_fem_hyperelastic(case, element)
    from reference_fem.solve import solve_fem
    return solve_fem(case, element)


METHOD = SolutionMethod("fem", solve_fem_case, ELEMENTS, description="scikit-fem reference on the same nodes (Q1, P1, P2)")
