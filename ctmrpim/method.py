"""CTM-RPIM method settings. Lengths are multiples of the mean node spacing d_c (Eq. 36)."""
from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass

from .errors import ProblemError

POLYNOMIAL_TERMS = {"linear": 3, "quadratic": 6}
BOUNDARIES = ("alpha", "geometry")
SOLVERS = ("auto", "banded", "superlu", "spsolve")
#: large-deformation (quasi-static) formulations: the paper's adaptive one, and the cross-check
FORMULATIONS = ("updated-lagrangian", "total-lagrangian")


def mean_node_spacing(area: float, n_nodes: int) -> float:
    """d_c = sqrt(A) / sqrt(n - 1), Eq. (36)."""
    if n_nodes < 2:
        raise ProblemError(f"{n_nodes} node(s): need at least two to define a node spacing", key="nodes")
    return math.sqrt(area) / math.sqrt(n_nodes - 1)


@dataclass
class Method:
    support_radius: float = 4.0          # r_c / d_c
    eta: float = 5.0                     # TPS exponent, R = r^eta (Eq. 34)
    polynomial: str = "linear"           # augmentation: linear (1, x, y) or quadratic (m = 6)
    line_spacing: tuple[float, float] = (1.0 / 3.0, 1.0 / 3.0)   # (r_x, r_y) / d_c
    gauss_points: int = 1                # Gauss points per sub-segment and per band
    alpha: float = 1.5                   # alpha-shape radius / d_c
    boundary: str = "alpha"              # integrate over the tracked alpha shape, or the exact geometry
    solver: str = "auto"                 # linear solver: auto, banded (RCM + Cholesky), superlu, spsolve
    match_tolerance: float = 0.01        # '==' tolerance in `where` selectors / d_c
    formulation: str = "updated-lagrangian"  # quasi-static: the paper's adaptive one, or total-lagrangian
    point_regeneration: float = 0.0      # UL: lay new CTM points once a point is strained by more than
                                         # this since they were laid; 0 = every increment (the paper)
    min_support: int = 0                 # explicit dynamics: widen a support holding fewer nodes than this to
                                         # its min_support nearest (a thinning flow front); 0 = r_c alone

    def __post_init__(self) -> None:
        self.line_spacing = tuple(float(v) for v in self.line_spacing)
        checks = [
            ("support_radius", self.support_radius > 0, "must be > 0"),
            ("eta", self.eta > 0, "must be > 0"),
            ("polynomial", isinstance(self.polynomial, str) and self.polynomial in POLYNOMIAL_TERMS,
             f"must be one of {sorted(POLYNOMIAL_TERMS)}"),  # a list there is unhashable: test the type first
            ("line_spacing", len(self.line_spacing) == 2 and min(self.line_spacing) > 0,
             "must be two positive numbers [r_x, r_y] (multiples of d_c)"),
            # bool is an int to Python, but `gauss_points = true` is a mistake, not 1
            ("gauss_points", isinstance(self.gauss_points, int) and not isinstance(self.gauss_points, bool)
             and 1 <= self.gauss_points <= 10,
             "must be an integer from 1 to 10"),
            ("alpha", self.alpha > 0, "must be > 0"),
            ("boundary", self.boundary in BOUNDARIES, f"must be one of {list(BOUNDARIES)}"),
            ("solver", self.solver in SOLVERS, f"must be one of {list(SOLVERS)}"),
            ("match_tolerance", 0 < self.match_tolerance < 0.5, "must lie in (0, 0.5)"),
            ("formulation", self.formulation in FORMULATIONS, f"must be one of {list(FORMULATIONS)}"),
            ("point_regeneration", self.point_regeneration >= 0, "must be >= 0 (0: every increment)"),
            ("min_support", isinstance(self.min_support, int) and not isinstance(self.min_support, bool)
             and self.min_support >= 0, "must be an integer >= 0 (0: off)"),
        ]
        for key, ok, why in checks:
            if not ok:
                raise ProblemError(f"{getattr(self, key)!r} {why}", key=f"method.{key}")
        nearest = round(self.eta)
        if nearest % 2 == 0 and abs(self.eta - nearest) < 1e-9:
            raise ProblemError(
                f"eta = {self.eta:g} is an even integer: r^eta is then a polynomial and the RPIM moment "
                "matrix is singular; use an odd integer or a fraction (the paper uses 5.0)", key="method.eta")
        if nearest % 2 == 0 and abs(self.eta - nearest) < 0.1:
            warnings.warn(f"method.eta = {self.eta:g} is close to the even integer {nearest}: the RPIM moment "
                          "matrix is nearly singular there", stacklevel=2)

    @property
    def polynomial_terms(self) -> int:
        return POLYNOMIAL_TERMS[self.polynomial]

    def as_dict(self) -> dict:
        d = asdict(self)
        d["line_spacing"] = list(self.line_spacing)
        return d
