"""Newton solves for tangents whose sparsity pattern changes now and then: the updated-Lagrangian iteration's, one
pattern per configuration (its points and their supports). Each tangent is factorised in the pattern's reverse
Cuthill-McKee band (:mod:`ctmrpim.solvers.banded_lu`, the layout found once per pattern) where the band is narrow
against the rows, else by SuperLU (:mod:`ctmrpim.solvers.linear_solver`)."""
from __future__ import annotations

from typing import Callable

import numpy as np
import scipy.sparse as sp

from ctmrpim.errors import ProblemError
from ctmrpim.solvers.banded_lu import BandedLU
from ctmrpim.solvers.linear_solver import solve_constrained


class PatternSolver:
    """du (2n,) with K du = r at the free dofs and du = 0 at ``fixed``, for Newton tangents K whose sparsity pattern
    changes now and then (the updated-Lagrangian iteration's: one pattern per configuration, the points and their
    supports): the band's layout is found once per pattern and each tangent is one gather and one banded LU with
    partial pivoting (a non-symmetric tangent as it is); SuperLU where the band is not worthwhile."""

    def __init__(self, n_dofs: int, fixed: np.ndarray, nodes: Callable[[], np.ndarray] | None = None) -> None:
        self.fixed = fixed
        self.free = np.setdiff1d(np.arange(n_dofs), fixed)
        self.band: BandedLU | None = None
        self.nodes = nodes          # () -> (n, 2) where the dofs sit now, for the band's ordering (None: unknown)

    def __call__(self, K: sp.csr_matrix, residual: np.ndarray) -> np.ndarray:
        if self.band is None or not self.band.fits(K):
            self.band = BandedLU(K, self.free, None if self.nodes is None else self.nodes())
        if not self.band.worthwhile:
            return solve_constrained(K, residual, self.fixed, np.zeros(len(self.fixed)), "superlu")
        du = np.zeros_like(residual)
        try:
            du[self.free] = self.band.factorise(K).solve(residual[self.free])
        except RuntimeError as exc:
            raise ProblemError(f"the tangent stiffness is singular ({exc}): the constraints do not prevent "
                               "rigid-body motion, or part of the body is detached") from None
        return du
