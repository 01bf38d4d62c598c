"""The discrete weak form on any discretisation (Eqs. 5 and 7 in Lagrangian form, G^T (w P) and G^T diag(w A) G).

With a gradient operator G (4m x 2n: row 4p + c, c = xX, xY, yX, yY, gives du_i/dX_J at point p from
interleaved dofs), point weights w and the first Piola-Kirchhoff stress P relative to the configuration G
is written on (P = sigma at small strain),

    F_int[I, i] = sum_p w_p P_iJ(p) dN_I/dX_J(p)                    (G^T (w P))
    K[(I, i), (K, k)] = sum_p w_p dN_I/dX_J A_iJkL dN_K/dX_L         (G^T diag(w A) G)

with A = dP/dF. Method-agnostic: CTM-RPIM's G comes from the RPIM derivatives at the CTM points
(:func:`ctmrpim.discretisation.lagrangian_operators.gradient_operator`), the finite-element
reference's from its element basis at the quadrature points.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def internal_force(G: sp.spmatrix, P: np.ndarray, w: np.ndarray, GT: sp.spmatrix | None = None) -> np.ndarray:
    """G^T (w P): P (m, 4) or (m, 2, 2); ``GT`` = G.T where the caller keeps it."""
    return (G.T if GT is None else GT) @ (P.reshape(-1, 4) * w[:, None]).ravel()


def tangent(G: sp.bsr_matrix, A: np.ndarray, w: np.ndarray, GT: sp.bsr_matrix | None = None) -> sp.csr_matrix:
    """G^T diag(w A) G: A (m, 4, 4) or (m, 2, 2, 2, 2), blocks of dP/dF. ``GT`` = G.T, where the caller
    keeps it across Newton iterations."""
    m = len(w)
    blocks = A.reshape(m, 4, 4) * w[:, None, None]
    WA = sp.bsr_matrix((blocks, np.arange(m), np.arange(m + 1)), shape=(4 * m, 4 * m))
    return ((G.T if GT is None else GT) @ (WA @ G)).tocsr()
