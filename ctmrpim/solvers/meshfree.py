"""The CTM-RPIM method (``METHOD``, ``"ctm-rpim"`` in :mod:`ctmrpim.methods`): each analysis to its solver.

- ``linear`` (linear elastic): :mod:`ctmrpim.solvers.linear_static` (Eqs. 4-6);
- ``quasi-static`` with neo-Hookean or linear elastic (rate form): :mod:`ctmrpim.solvers.updated_lagrangian`
  (the paper's adaptive method) or :mod:`ctmrpim.solvers.total_lagrangian`;
- ``quasi-static`` with Mohr-Coulomb (small strain), ``strength-reduction`` (Eqs. 38-39) and ``dynamic``
  (relaxation, Eq. 11): :mod:`ctmrpim.solvers.elastoplastic`;
- ``explicit`` (Mohr-Coulomb): :mod:`ctmrpim.solvers.explicit` (Eqs. 8-11), with the paper's CTM only: the
  corrected test gradients of ``ctm-vci`` do not conserve momentum there (:mod:`ctmrpim.solvers.explicit.run`).
"""
from __future__ import annotations

import tempfile
from pathlib import Path

from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.methods import SolutionMethod
from ctmrpim.problem.case import Case
from ctmrpim.result import Result
from ctmrpim.run_options import RunOptions


def check_integration(case: Case) -> None:
    """Refuse (ProblemError, one line) a ``method.integration`` the case's analysis does not implement."""
    analysis, scheme = case.problem.analysis, case.method.integration
    if scheme == "ctm-vci" and analysis == "explicit":
        # measured by studies/explicit_conservation.py (docs/design.md, 'Explicit dynamics')
        raise ProblemError("method.integration = \"ctm-vci\" does not conserve momentum in explicit dynamics (its "
                           "corrected test gradients do not sum to zero, so a free body's linear and angular momentum "
                           "drift; the report measures it); explicit analyses integrate with \"ctm\"",
                           key="method.integration")
    if scheme not in ("ctm", "ctm-vci") and analysis != "linear":   # the comparators: linear analyses only
        raise ProblemError(f"method.integration = {scheme!r} is implemented for linear analyses; this {analysis!r} "
                           "analysis integrates with \"ctm\" or \"ctm-vci\"", key="method.integration")


def solve_meshfree(case: Case, element: str | None, options: RunOptions) -> Result:
    """Solve ``case`` with CTM-RPIM (``element`` is always None: the method has none)."""
    check_integration(case)
    analysis = case.problem.analysis
    if analysis == "explicit":
        from ctmrpim.solvers.explicit.run import solve_explicit
        if options.out is None:
            with tempfile.TemporaryDirectory() as tmp:
                return solve_explicit(case, Path(tmp), options.resume, options.progress_bar)
        return solve_explicit(case, options.out, options.resume, options.progress_bar)
    if analysis in ("strength-reduction", "dynamic") or (analysis == "quasi-static"
                                                         and isinstance(case.problem.material, MohrCoulomb)):
        from ctmrpim.solvers.elastoplastic import solve_elastoplastic  # small strain: never re-tracked
        return solve_elastoplastic(case, options.progress)
    if analysis == "quasi-static":
        if case.method.formulation == "updated-lagrangian":
            from ctmrpim.solvers.updated_lagrangian import solve_updated_lagrangian
            return solve_updated_lagrangian(case)
        from ctmrpim.solvers.total_lagrangian import solve_total_lagrangian
        return solve_total_lagrangian(case)
    from ctmrpim.solvers.linear_static import solve_ctmrpim
    return solve_ctmrpim(case)


#: the entry point ``ctmrpim.methods: ctm-rpim``
METHOD = SolutionMethod("ctm-rpim", solve_meshfree, description="adaptive CTM-RPIM (CTM integration, RPIM shape "
                                                                "functions, alpha-shape boundary)")
