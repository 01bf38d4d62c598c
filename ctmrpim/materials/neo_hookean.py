"""Compressible neo-Hookean material in plane strain, written on the deformation gradient.

Strain energy (F33 = 1):  W = mu/2 (tr C + 1 - 3) - mu ln J + lambda/2 (ln J)^2,  C = F^T F, J = det F.
First Piola-Kirchhoff stress and its derivative (the total-Lagrangian tangent):

    P = mu F + (lambda ln J - mu) F^-T
    A_iJkL = dP_iJ/dF_kL = mu d_ik d_JL + lambda F^-1_Ji F^-1_Lk + (mu - lambda ln J) F^-1_Li F^-1_Jk

Chosen over St Venant-Kirchhoff, which softens in compression and misses the end-moment ring by about
0.15 L (docs/design.md, 'Updated and total Lagrangian'). For small strains it reduces to linear
elasticity with the same E and nu.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ctmrpim.errors import ProblemError
from ctmrpim.materials.linear_elastic import LinearElastic


@dataclass(frozen=True)
class NeoHookean:
    """Compressible neo-Hookean material in plane strain (module docstring), of small-strain E, nu and density."""
    E: float
    nu: float
    density: float = 0.0

    def D(self, plane: str) -> np.ndarray:
        """The small-strain elasticity matrix it reduces to (same E and nu)."""
        return LinearElastic(self.E, self.nu, self.density).D(plane)

    @property
    def mu(self) -> float:
        """Lame's shear modulus mu = E / (2 (1 + nu))."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def lam(self) -> float:
        """Lame's lambda = E nu / ((1 + nu) (1 - 2 nu))."""
        return self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

    def first_piola(self, F: np.ndarray) -> np.ndarray:
        """P (m, 2, 2) at F (m, 2, 2), without the inversion check: analytic in F, so that a complex
        step through it gives exact derivatives (the updated-Lagrangian tangent)."""
        J = F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]
        FinvT = np.stack([np.stack([F[:, 1, 1], -F[:, 1, 0]], -1), np.stack([-F[:, 0, 1], F[:, 0, 0]], -1)], 1)
        FinvT = FinvT / J[:, None, None]
        return self.mu * F + (self.lam * np.log(J) - self.mu)[:, None, None] * FinvT

    def stress_tangent(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """P (m, 2, 2) and A (m, 2, 2, 2, 2) at deformation gradients F (m, 2, 2)."""
        J = F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]
        if np.any(J <= 0):
            i = int(np.argmin(J))
            raise ProblemError(f"neo-Hookean: det F = {J[i]:.3g} <= 0 at integration point #{i} (the material "
                               "inverted); use more load steps")
        Finv = np.empty_like(F)
        Finv[:, 0, 0], Finv[:, 1, 1] = F[:, 1, 1] / J, F[:, 0, 0] / J
        Finv[:, 0, 1], Finv[:, 1, 0] = -F[:, 0, 1] / J, -F[:, 1, 0] / J
        lnJ = np.log(J)
        mu, lam = self.mu, self.lam
        FinvT = Finv.transpose(0, 2, 1)
        P = mu * F + (lam * lnJ - mu)[:, None, None] * FinvT
        eye = np.eye(2)
        A = (mu * np.einsum("ik,JL->iJkL", eye, eye)[None]
             + lam * np.einsum("pJi,pLk->piJkL", Finv, Finv)
             + (mu - lam * lnJ)[:, None, None, None, None] * np.einsum("pLi,pJk->piJkL", Finv, Finv))
        return P, A
