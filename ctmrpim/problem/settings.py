"""How a problem is discretised and solved: the settings tables of a problem file.

``[method]`` (:class:`Method`, the CTM-RPIM parameters), ``[loading]`` (:class:`Loading`, load stepping),
``[strength-reduction]`` (:class:`StrengthReduction`), ``[dynamic]`` (:class:`Relaxation`, dynamic
relaxation) and ``[explicit]`` (:class:`Explicit`, explicit dynamics). Each is a dataclass whose
``__post_init__`` states its rules once, as ``(key, ok, why)`` triples checked by :func:`validate`; a
broken rule is a :class:`~ctmrpim.errors.ProblemError` naming ``section.key``.

Lengths of the method are multiples of the mean node spacing d_c (Eq. 36); :meth:`Method.scaled`
turns them into lengths once d_c is known, the only place where that happens.
"""
from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass, field
from typing import Any, Iterable

from ctmrpim.errors import ProblemError

POLYNOMIAL_TERMS = {"linear": 3, "quadratic": 6}
BOUNDARIES = ("alpha", "geometry")
LINEAR_SOLVERS = ("auto", "banded", "superlu", "spsolve", "pardiso", "amg")
#: large-deformation (quasi-static) formulations: the paper's adaptive one, and the cross-check
FORMULATIONS = ("updated-lagrangian", "total-lagrangian")
#: integration schemes: the paper's CTM, CTM with variationally consistent test gradients (VCI), and two
#: comparators of linear analyses: background cells clipped by the boundary, and stabilised conforming
#: nodal integration
INTEGRATIONS = ("ctm", "ctm-vci", "cell-gauss", "scni")
#: ``method.integration`` where the file does not set it, by analysis: the consistent scheme where it is
#: implemented (linear analyses), the paper's elsewhere
DEFAULT_INTEGRATION = {"linear": "ctm-vci"}
#: the order of the VCI correction: the integration constraints it makes hold
CORRECTIONS = ("linear", "quadratic")
#: how a strength-reduction level is equilibrated
REDUCTION_SOLVERS = ("newton", "dynamic-relaxation")


def validate(section: str, settings: Any, rules: Iterable[tuple[str, bool, str]]) -> None:
    """Raise for the first rule ``(key, ok, why)`` that does not hold: ``section.key: value why``."""
    for key, ok, why in rules:
        if not ok:
            raise ProblemError(f"{getattr(settings, key)!r} {why}", key=f"{section}.{key}")


def integer(value: Any, least: int) -> bool:
    """An int (not a bool: ``steps = true`` is a mistake, not 1) of at least ``least``."""
    return isinstance(value, int) and not isinstance(value, bool) and value >= least


@dataclass(frozen=True)
class ScaledMethod:
    """The method's lengths for one node spacing d_c (every length in model units)."""

    d_c: float
    support_radius: float
    r_x: float
    r_y: float
    alpha: float
    match_tolerance: float
    eta: float
    polynomial_terms: int
    gauss_points: int

    def rpim(self) -> dict[str, Any]:
        """Keyword arguments of :func:`ctmrpim.discretisation.rpim.shape_functions` (no tree)."""
        return dict(support_radius=self.support_radius, eta=self.eta, polynomial_terms=self.polynomial_terms,
                    scale=self.d_c)

    def derived(self) -> dict[str, float]:
        """The lengths as ``summary.json`` reports them under ``parameters.derived``."""
        return {"d_c": self.d_c, "support_radius": self.support_radius, "r_x": self.r_x, "r_y": self.r_y,
                "alpha": self.alpha, "match_tolerance": self.match_tolerance}


@dataclass
class Method:
    """The ``[method]`` table: CTM-RPIM settings, lengths as multiples of d_c."""

    support_radius: float = 4.0          # r_c / d_c
    eta: float = 5.0                     # TPS exponent, R = r^eta (Eq. 34)
    polynomial: str = "linear"           # augmentation: linear (1, x, y) or quadratic (m = 6)
    line_spacing: tuple[float, float] = (1.0 / 3.0, 1.0 / 3.0)   # (r_x, r_y) / d_c
    gauss_points: int = 1                # Gauss points per sub-segment and per band
    alpha: float = 1.5                   # alpha-shape radius / d_c
    boundary: str = "alpha"              # integrate over the tracked alpha shape, or the exact geometry
    solver: str = "auto"                 # linear solver: auto, banded (RCM + Cholesky), superlu, spsolve, pardiso, amg
    match_tolerance: float = 0.01        # '==' tolerance in `where` selectors / d_c
    formulation: str = "updated-lagrangian"  # quasi-static: the paper's adaptive one, or total-lagrangian
    point_regeneration: float = 0.0      # UL: lay new CTM points once a point is strained by more than
                                         # this since they were laid; 0 = every increment (the paper)
    min_support: int = 0                 # explicit dynamics: widen a support holding fewer nodes than this to
                                         # its min_support nearest (a thinning flow front); 0 = r_c alone
    integration: str = "ctm"             # "ctm": the paper's; "ctm-vci": test gradients corrected so that the
                                         # integration constraints hold (linear analyses; a problem file's
                                         # default is by analysis: DEFAULT_INTEGRATION)
    correction: str = "quadratic"        # ctm-vci: linear or quadratic integration constraints

    def __post_init__(self) -> None:
        self.line_spacing = tuple(float(v) for v in self.line_spacing)
        validate("method", self, self.rules())
        nearest = round(self.eta)
        if nearest % 2 == 0 and abs(self.eta - nearest) < 1e-9:
            raise ProblemError(
                f"eta = {self.eta:g} is an even integer: r^eta is then a polynomial and the RPIM moment "
                "matrix is singular; use an odd integer or a fraction (the paper uses 5.0)", key="method.eta")
        if nearest % 2 == 0 and abs(self.eta - nearest) < 0.1:
            warnings.warn(f"method.eta = {self.eta:g} is close to the even integer {nearest}: the RPIM moment "
                          "matrix is nearly singular there", stacklevel=2)

    def rules(self) -> list[tuple[str, bool, str]]:
        """(key, holds, what is allowed) per setting: :func:`validate` raises for the first that fails; the
        problem-file reference (:mod:`ctmrpim.problem.schema`) prints the allowed values."""
        return [
            ("support_radius", self.support_radius > 0, "must be > 0"),
            ("eta", self.eta > 0, "must be > 0"),
            ("polynomial", isinstance(self.polynomial, str) and self.polynomial in POLYNOMIAL_TERMS,
             f"must be one of {sorted(POLYNOMIAL_TERMS)}"),  # a list there is unhashable: test the type first
            ("line_spacing", len(self.line_spacing) == 2 and min(self.line_spacing) > 0,
             "must be two positive numbers [r_x, r_y] (multiples of d_c)"),
            ("gauss_points", integer(self.gauss_points, 1) and self.gauss_points <= 10,
             "must be an integer from 1 to 10"),
            ("alpha", self.alpha > 0, "must be > 0"),
            ("boundary", self.boundary in BOUNDARIES, f"must be one of {list(BOUNDARIES)}"),
            ("solver", self.solver in LINEAR_SOLVERS, f"must be one of {list(LINEAR_SOLVERS)}"),
            ("match_tolerance", 0 < self.match_tolerance < 0.5, "must lie in (0, 0.5)"),
            ("formulation", self.formulation in FORMULATIONS, f"must be one of {list(FORMULATIONS)}"),
            ("point_regeneration", self.point_regeneration >= 0, "must be >= 0 (0: every increment)"),
            ("min_support", integer(self.min_support, 0), "must be an integer >= 0 (0: off)"),
            ("integration", self.integration in INTEGRATIONS, f"must be one of {list(INTEGRATIONS)}"),
            ("correction", self.correction in CORRECTIONS, f"must be one of {list(CORRECTIONS)}"),
        ]

    @property
    def polynomial_terms(self) -> int:
        """m, the number of polynomial terms augmenting the RPIM basis: 3 (linear) or 6 (quadratic)."""
        return POLYNOMIAL_TERMS[self.polynomial]

    def scaled(self, d_c: float) -> ScaledMethod:
        """The lengths for the node spacing ``d_c`` (Eq. 36): r_c, r_x, r_y, alpha and the selector tolerance."""
        return ScaledMethod(d_c=d_c, support_radius=self.support_radius * d_c, r_x=self.line_spacing[0] * d_c,
                            r_y=self.line_spacing[1] * d_c, alpha=self.alpha * d_c,
                            match_tolerance=self.match_tolerance * d_c, eta=self.eta,
                            polynomial_terms=self.polynomial_terms, gauss_points=self.gauss_points)

    def as_dict(self) -> dict:
        """The table's settings as ``summary.json`` reports them (``line_spacing`` as a list)."""
        d = asdict(self)
        d["line_spacing"] = list(self.line_spacing)
        return d


@dataclass(frozen=True)
class Loading:
    """The ``[loading]`` table: load stepping of a quasi-static analysis (Section 2.1.3)."""

    steps: int = 10                # equal load increments (halved on non-convergence)
    tolerance: float = 1e-8        # Newton: relative residual and displacement-increment norms
    max_iterations: int = 25       # Newton iterations per increment before a cut-back
    max_cutbacks: int = 8          # increment halvings before the solve gives up
    tangent: str = "consistent"    # Newton's matrix; "elastic" (Mohr-Coulomb only): see solvers.plastic_system
    until_failure: bool = False    # Mohr-Coulomb: a load the body cannot carry ends the run with the limit
                                   # load bracketed (no error); the limit load of a footing
    limit_slope: float = 0.01      # with until_failure: an increment whose pressure-settlement slope is below this
                                   # fraction of the elastic one is not carried (0: non-convergence alone decides)

    def __post_init__(self) -> None:
        validate("loading", self, self.rules())

    def rules(self) -> list[tuple[str, bool, str]]:
        """(key, holds, what is allowed) per setting (see :meth:`Method.rules`)."""
        return [
            ("until_failure", isinstance(self.until_failure, bool), "must be true or false"),
            ("tangent", self.tangent in ("consistent", "elastic"), "must be \"consistent\" or \"elastic\""),
            ("limit_slope", not isinstance(self.limit_slope, bool) and 0 <= self.limit_slope < 1,
             "must lie in [0, 1)"),
            ("steps", integer(self.steps, 1), "must be an integer >= 1"),
            ("tolerance", not isinstance(self.tolerance, bool) and 0 < self.tolerance < 1, "must lie in (0, 1)"),
            ("max_iterations", integer(self.max_iterations, 1), "must be an integer >= 1"),
            ("max_cutbacks", integer(self.max_cutbacks, 0), "must be an integer >= 0"),
        ]


@dataclass(frozen=True)
class StrengthReduction:
    """The ``[strength-reduction]`` table (:mod:`ctmrpim.solvers.strength_reduction`)."""

    solver: str = "newton"          # how each level is equilibrated
    start: float = 1.0              # the SRF of the gravity stage (the search starts stable there)
    step: float = 0.1               # SRF rise per level until the first failure
    width: float = 0.01             # bisection stops when failed - stable <= width; no SRF sub-step is cut
                                    # back below it
    max_srf: float = 5.0            # give up (no failure found) beyond this
    steps: int = 4                  # SRF sub-steps per level (halved on non-convergence like load steps)
    limit_growth: float = 100.0     # search by Newton: a level whose largest displacement from the stable one below,
                                    # per unit relative SRF rise, exceeds this many times the largest at start has
                                    # failed (a runaway; 0: non-convergence alone decides)
    values: tuple[float, ...] = field(default=())   # sweep mode: these SRFs, each from zero

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", tuple(float(v) for v in self.values))
        validate("strength-reduction", self, self.rules())

    def rules(self) -> list[tuple[str, bool, str]]:
        """(key, holds, what is allowed) per setting (see :meth:`Method.rules`)."""
        return [
            ("solver", self.solver in REDUCTION_SOLVERS, f"must be one of {list(REDUCTION_SOLVERS)}"),
            ("start", self.start > 0, "must be > 0"),
            ("step", self.step > 0, "must be > 0"),
            ("width", 0 < self.width <= self.step, "must be > 0 and at most step"),
            ("max_srf", self.max_srf > self.start, "must exceed start"),
            ("steps", integer(self.steps, 1), "must be an integer >= 1"),
            ("limit_growth", not isinstance(self.limit_growth, bool) and self.limit_growth >= 0, "must be >= 0"),
            ("values", all(v > 0 for v in self.values), "must all be > 0"),
        ]


@dataclass(frozen=True)
class Relaxation:
    """The ``[dynamic]`` table: dynamic relaxation (:mod:`ctmrpim.solvers.dynamic_relaxation`)."""

    steps: int = 3000            # at most this many steps per stage
    damping: float = 0.8         # local damping factor f of Eq. (11) (FLAC's default)
    tolerance: float = 1e-4      # at rest when |F_ext - F_int| <= tolerance |F_ext|
    record_every: int = 10       # history: every this many steps

    def __post_init__(self) -> None:
        validate("dynamic", self, self.rules())

    def rules(self) -> list[tuple[str, bool, str]]:
        """(key, holds, what is allowed) per setting (see :meth:`Method.rules`)."""
        return [
            ("steps", integer(self.steps, 1), "must be an integer >= 1"),
            ("damping", 0.0 <= self.damping < 1.0, "must lie in [0, 1)"),
            ("tolerance", 0.0 < self.tolerance < 1.0, "must lie in (0, 1)"),
            ("record_every", integer(self.record_every, 1), "must be an integer >= 1"),
        ]


@dataclass(frozen=True)
class Explicit:
    """The ``[explicit]`` table: explicit dynamics (:mod:`ctmrpim.solvers.explicit`, where each is explained)."""

    duration: float = 1.0          # simulated time after the gate is removed (s)
    dt: float | str = "cfl"        # time step (s), or "cfl": cfl x 2 / omega_max, recomputed at each rebuild
    cfl: float = 0.5               # dt = cfl x 2 / omega_max: the share of the stability limit taken
    damping: float = 0.0           # local damping factor f of Eq. (11); 0: true dynamics
    viscosity: float = 0.0         # beta (s): stiffness-proportional damping, a viscous stress beta D d(eps)/dt
    rebuild_strain: float = 0.2    # RPIM rebuilt once a point is strained this much since the last rebuild
    relay_strain: float = 1.0      # boundary re-tracked, CTM points laid anew (state transferred) once a point
                                   # is strained this much since the points were laid
    area_jump: float = 0.02        # the run stops when a re-tracked area jumps by more than this fraction
    save_every: float = 0.01       # simulated seconds between saved states (VTU series)
    checkpoint_every: int = 1000   # steps between checkpoints (0: none)
    rest: float = 1e-4             # at rest once the kinetic energy is below rest x its peak
    initial: str = "gravity"       # "gravity": damped stage with the gates in place; "none": start unstressed
    stage_damping: float = 0.8     # local damping of the gravity stage
    stage_tolerance: float = 1e-3  # the stage ends when the out-of-balance force is below this x the weight
    stage_steps: int = 20000       # at most this many steps in the gravity stage
    detached: str = "stop"         # a node that leaves the body: "stop" the run, or let it go "free"

    def __post_init__(self) -> None:
        validate("explicit", self, self.rules())

    def rules(self) -> list[tuple[str, bool, str]]:
        """(key, holds, what is allowed) per setting (see :meth:`Method.rules`)."""
        return [
            ("duration", self.duration > 0, "must be > 0"),
            ("dt", self.dt == "cfl" or (isinstance(self.dt, (int, float)) and not isinstance(self.dt, bool)
                                        and self.dt > 0), "must be \"cfl\" or a time step > 0 (s)"),
            ("cfl", 0 < self.cfl <= 1, "must lie in (0, 1]"),
            ("damping", 0 <= self.damping < 1, "must lie in [0, 1)"),
            ("viscosity", self.viscosity >= 0, "must be >= 0 (s)"),
            ("rebuild_strain", self.rebuild_strain > 0, "must be > 0"),
            ("relay_strain", self.relay_strain >= self.rebuild_strain, "must be >= rebuild_strain"),
            ("area_jump", 0 < self.area_jump < 1, "must lie in (0, 1)"),
            ("save_every", self.save_every > 0, "must be > 0 (s)"),
            ("checkpoint_every", integer(self.checkpoint_every, 0), "must be an integer >= 0"),
            ("rest", 0 < self.rest < 1, "must lie in (0, 1)"),
            ("initial", self.initial in ("gravity", "none"), "must be \"gravity\" or \"none\""),
            ("stage_damping", 0 <= self.stage_damping < 1, "must lie in [0, 1)"),
            ("stage_tolerance", 0 < self.stage_tolerance < 1, "must lie in (0, 1)"),
            ("stage_steps", integer(self.stage_steps, 1), "must be an integer >= 1"),
            ("detached", self.detached in ("stop", "free"), "must be \"stop\" or \"free\""),
        ]
