"""One entry point for every method that solves a Case: CTM-RPIM or the scikit-fem reference."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

from .problem_file import Case
from .result import Result

METHODS = ("ctm-rpim", "fem")
ELEMENTS = ("q1", "p1", "p2")


def solve(case: Case, solver: str = "ctm-rpim", element: str = "q1",
          progress: Callable[[Any], None] | None = None, out: Path | None = None, resume: bool = False,
          progress_bar: bool = False) -> Result:
    """Solve ``case`` with CTM-RPIM, or with scikit-fem ``element`` when ``solver == "fem"``;
    ``progress`` gets each strength-reduction level as it finishes. An explicit dynamic run writes its
    time series and checkpoints into ``out`` as it goes (a temporary folder if None), continues from
    the checkpoint there with ``resume``, and shows a progress bar with ``progress_bar``."""
    progress = progress or (lambda level: None)
    if case.problem.analysis == "explicit":
        if solver == "fem":
            from .errors import ProblemError
            raise ProblemError("the FEM reference has no explicit dynamic solver (the column collapse is "
                               "CTM-RPIM's alone)", key="--solver")
        from .explicit_dynamics import solve_explicit
        if out is None:
            import tempfile
            with tempfile.TemporaryDirectory() as tmp:
                return solve_explicit(case, Path(tmp), resume, progress_bar)
        return solve_explicit(case, out, resume, progress_bar)
    if solver == "fem":
        from .mohr_coulomb import MohrCoulomb
        if isinstance(case.problem.material, MohrCoulomb):
            from reference_fem.elastoplastic import solve_fem_elastoplastic
            return solve_fem_elastoplastic(case, element, progress)
        if case.problem.analysis == "quasi-static":
            from reference_fem.hyperelastic import solve_fem_hyperelastic
            return solve_fem_hyperelastic(case, element)
        from reference_fem import solve_fem
        return solve_fem(case, element)
    if case.problem.analysis in ("strength-reduction", "dynamic"):
        from .elastoplastic import solve_elastoplastic
        return solve_elastoplastic(case, progress)
    if case.problem.analysis == "quasi-static":
        from .mohr_coulomb import MohrCoulomb
        if isinstance(case.problem.material, MohrCoulomb):     # small strain: never re-tracked
            from .elastoplastic import solve_elastoplastic
            return solve_elastoplastic(case)
        if case.method.formulation == "updated-lagrangian":
            from .updated_lagrangian import solve_updated_lagrangian
            return solve_updated_lagrangian(case)
        from .total_lagrangian import solve_total_lagrangian
        return solve_total_lagrangian(case)
    from .linear_static import solve_ctmrpim
    return solve_ctmrpim(case)
