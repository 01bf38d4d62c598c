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

__version__ = "0.1.0"

from ctmrpim.cases import load_case  # noqa: E402
from ctmrpim.errors import ProblemError  # noqa: E402
from ctmrpim.methods import register, solve  # noqa: E402
from ctmrpim.problem.case import Case  # noqa: E402
from ctmrpim.problem.model import Problem  # noqa: E402
from ctmrpim.result import Result  # noqa: E402

__all__ = ["Case", "Problem", "ProblemError", "Result", "__version__", "load_case", "register", "solve"]
