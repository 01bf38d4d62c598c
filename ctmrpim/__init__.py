"""Adaptive CTM-RPIM: Cartesian transformation method integration, radial point interpolation
shape functions and alpha-shape boundary tracking, for large deformations in geomechanics.

    >>> import ctmrpim
    >>> case = ctmrpim.load_case("cantilever", ["nodes.grid=[17, 5]"])
    >>> result = ctmrpim.solve(case)                    # CTM-RPIM
    >>> reference = ctmrpim.solve(case, "fem", "p2")    # the scikit-fem reference on the same nodes

Subpackages: :mod:`ctmrpim.problem` (the continuous problem and its input), :mod:`ctmrpim.materials`,
:mod:`ctmrpim.discretisation` (alpha shape, CTM, RPIM, the configuration), :mod:`ctmrpim.solvers`,
:mod:`ctmrpim.io` and :mod:`ctmrpim.reference` (exact and reference solutions, error norms).
"""

from ctmrpim.cases import load_case
from ctmrpim.errors import ProblemError
from ctmrpim.methods import SolutionMethod, register, solve
from ctmrpim.problem.case import Case
from ctmrpim.problem.model import Problem
from ctmrpim.result import Result
from ctmrpim.version import __version__

__all__ = ["Case", "Problem", "ProblemError", "Result", "SolutionMethod", "__version__", "load_case", "register", "solve"]
