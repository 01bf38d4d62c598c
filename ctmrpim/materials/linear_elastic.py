"""Linear elasticity in plane stress and plane strain (Voigt order xx, yy, xy with engineering shear)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ctmrpim.errors import ProblemError


@dataclass(frozen=True)
class LinearElastic:
    """Isotropic linear elastic material: Young's modulus E, Poisson's ratio nu, mass density."""
    E: float
    nu: float
    density: float = 0.0

    def __post_init__(self) -> None:
        if not self.E > 0:
            raise ProblemError(f"E = {self.E} must be > 0", key="material.E")
        if not -1.0 < self.nu < 0.5:
            raise ProblemError(f"nu = {self.nu} must lie in (-1, 0.5)", key="material.nu")
        if self.density < 0:
            raise ProblemError(f"density = {self.density} must be >= 0", key="material.density")

    def D(self, plane: str) -> np.ndarray:
        """Elasticity matrix relating (exx, eyy, gxy) to (sxx, syy, sxy)."""
        E, nu = self.E, self.nu
        if plane == "stress":
            c = E / (1.0 - nu * nu)
            return c * np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]])
        if plane == "strain":
            c = E / ((1.0 + nu) * (1.0 - 2.0 * nu))
            return c * np.array([[1.0 - nu, nu, 0.0], [nu, 1.0 - nu, 0.0], [0.0, 0.0, 0.5 - nu]])
        raise ProblemError(f"plane must be 'stress' or 'strain', not {plane!r}", key="problem.plane")
