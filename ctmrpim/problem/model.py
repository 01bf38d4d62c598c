"""The continuous problem: geometry, material, boundary conditions, loads, probes, exact solution.

A :class:`Problem` knows nothing of nodes, meshes or integration points. The CTM-RPIM solver and the
scikit-fem reference both consume the same object. Boundary conditions select boundary points by
``where`` expressions (``x == 0``, ``hypot(x, y) == 1 and y > 0``) in which ``==`` matches within a
tolerance given by the discretisation (a fraction of the node spacing).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ctmrpim.errors import ProblemError
from ctmrpim.materials.linear_elastic import LinearElastic
from ctmrpim.problem.expressions import Field
from ctmrpim.problem.geometry import Geometry


@dataclass
class Constraint:
    """Prescribed displacement components on the points selected by ``where``."""

    where: Field
    ux: Field | None = None
    uy: Field | None = None


@dataclass
class Traction:
    """Surface traction (force per unit area, global x/y components) on selected boundary segments.
    A dead traction keeps its direction and nominal size. A follower traction (large-deformation
    analyses) turns: with the boundary segment it acts on (``turn = "segment"``, pressure-like), or
    with its whole face (``turn = "face"``: every point turns with the chord of the connected stretch
    of face-follower boundary it lies on, so a couple stays a couple)."""

    where: Field
    tx: Field | None = None
    ty: Field | None = None
    follower: bool = False
    turn: str = "segment"


@dataclass
class Pressure:
    """Normal pressure on selected boundary segments, positive pushing into the body."""

    where: Field
    p: Field


@dataclass(frozen=True)
class PointLoad:
    """A concentrated force per unit thickness at a point of the body (like a traction, it is
    multiplied by the thickness), dead: fixed direction and size."""

    x: float
    y: float
    fx: float = 0.0
    fy: float = 0.0


@dataclass(frozen=True)
class Probe:
    """A named point (x, y) whose displacement is reported (and compared with the exact solution where given)."""
    name: str
    x: float
    y: float


@dataclass
class ExactSolution:
    """Analytical fields: the L2 error needs ux and uy, the energy error all three stresses; probes
    compare whichever components are given."""

    ux: Field | None = None
    uy: Field | None = None
    sxx: Field | None = None
    syy: Field | None = None
    sxy: Field | None = None

    def displacement(self, x: np.ndarray, y: np.ndarray) -> np.ndarray | None:
        """(k, 2) ux, uy at points x, y (k,) each; None unless both are given."""
        if self.ux is None or self.uy is None:
            return None
        return np.c_[self.ux(x, y), self.uy(x, y)]

    def stress(self, x: np.ndarray, y: np.ndarray) -> np.ndarray | None:
        """(k, 3) sxx, syy, sxy at points x, y (k,) each; None unless all three are given."""
        if self.sxx is None or self.syy is None or self.sxy is None:
            return None
        return np.c_[self.sxx(x, y), self.syy(x, y), self.sxy(x, y)]


@dataclass(frozen=True)
class BodyForce:
    """A body force per unit volume that varies over the body (``[body-force]``: a manufactured solution's, for
    example), added to density * gravity (Eq. 6, body term)."""

    bx: Field
    by: Field

    def at(self, points: np.ndarray) -> np.ndarray:
        """(k, 2) bx, by at the points (k, 2)."""
        return np.c_[self.bx(points[:, 0], points[:, 1]), self.by(points[:, 0], points[:, 1])]


@dataclass
class Problem:
    """The continuous problem (module docstring): geometry, material (any of :mod:`ctmrpim.materials`), analysis
    (``linear``, ``quasi-static``, ``strength-reduction``, ``dynamic``, ``explicit``), plane ``stress`` or
    ``strain``, thickness, gravity, the expressions' parameters, constraints, loads, probes, walls, exact solution,
    a body force that varies in space."""
    name: str
    geometry: Geometry
    material: LinearElastic
    analysis: str = "linear"
    plane: str = "stress"
    thickness: float = 1.0
    gravity: tuple[float, float] = (0.0, 0.0)     # acceleration; body force density * gravity
    parameters: dict[str, float] = field(default_factory=dict)
    constraints: list[Constraint] = field(default_factory=list)
    tractions: list[Traction] = field(default_factory=list)
    pressures: list[Pressure] = field(default_factory=list)
    probes: list[Probe] = field(default_factory=list)
    point_loads: list[PointLoad] = field(default_factory=list)
    walls: list[Wall] = field(default_factory=list)     # rigid walls of explicit dynamics
    exact: ExactSolution | None = None
    body_load: BodyForce | None = None                  # [body-force], besides density * gravity

    def D(self) -> np.ndarray:
        """(3, 3) the material's (small-strain) elasticity matrix in the problem's plane state."""
        return self.material.D(self.plane)

    @property
    def body_force(self) -> tuple[float, float]:
        """Force per unit volume, density * gravity."""
        rho = self.material.density
        return rho * self.gravity[0], rho * self.gravity[1]


#: the friction of a rough wall: no tangential motion in contact
NO_SLIP = "no-slip"


@dataclass(frozen=True)
class Wall:
    """A rigid wall of explicit dynamics: the line through ``point`` with unit ``normal`` into the body's
    side, its friction (:mod:`ctmrpim.solvers.explicit.contact` enforces it) and whether it is a gate."""

    name: str
    point: tuple[float, float]
    normal: tuple[float, float]       # unit, into the body's side
    friction: float | str = NO_SLIP   # "no-slip", or a Coulomb coefficient >= 0 (0: frictionless)
    gate: bool = False                # only in the gravity stage; removed at t = 0

    def __post_init__(self) -> None:
        n = np.asarray(self.normal, float)
        if n.shape != (2,) or not np.linalg.norm(n) > 0:
            raise ProblemError(f"normal = {self.normal!r} must be a non-zero [nx, ny]", key=f"wall.{self.name}.normal")
        object.__setattr__(self, "normal", tuple(float(v) for v in n / np.linalg.norm(n)))
        object.__setattr__(self, "point", tuple(float(v) for v in self.point))
        if self.friction != NO_SLIP and not (isinstance(self.friction, (int, float))
                                            and not isinstance(self.friction, bool) and self.friction >= 0):
            raise ProblemError(f"friction = {self.friction!r} must be \"no-slip\" or a coefficient >= 0",
                               key=f"wall.{self.name}.friction")

    def slip(self, tangential: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """What the wall's friction leaves of tangential vectors (k, 2) against normal magnitudes (k,)
        (velocity changes or forces): nothing (no-slip), all (frictionless), or each shortened by
        mu x normal, to zero where that is enough (Coulomb: stick)."""
        if self.friction == NO_SLIP:
            return np.zeros_like(tangential)
        if self.friction == 0:
            return tangential
        size = np.linalg.norm(tangential, axis=1)
        keep = np.maximum(size - self.friction * np.abs(normal), 0.0) / np.where(size > 0, size, 1.0)
        return tangential * keep[:, None]

    def gap(self, x: np.ndarray) -> np.ndarray:
        """Signed distance of positions (n, 2) from the wall, positive on the body's side."""
        return (x - np.asarray(self.point)) @ np.asarray(self.normal)
