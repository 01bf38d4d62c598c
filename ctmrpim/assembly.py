"""Global stiffness and load vectors from CTM points and RPIM shape functions (Eqs. 5-6).

Degrees of freedom are blocked: ``[u_x of nodes 0..n-1, u_y of nodes 0..n-1]``. The stiffness is
built as sparse products of the derivative matrices, K = B^T (w D) B (the paper's Eq. 7 lacks the
transpose on B; Eq. 9's form is used), never by scattering a dense block per integration point.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def stiffness(dNdx: sp.csr_matrix, dNdy: sp.csr_matrix, weights: np.ndarray, D: np.ndarray) -> sp.csr_matrix:
    """K = sum_p B_p^T D B_p w_p (Eq. 5) for a constant, orthotropic-in-shear D (d13 = d23 = 0)."""
    if abs(D[0, 2]) > 0 or abs(D[1, 2]) > 0:
        raise NotImplementedError("stiffness() assumes D[0, 2] = D[1, 2] = 0 (isotropic or orthotropic)")
    wx = dNdx.multiply(weights[:, None]).tocsr()
    wy = dNdy.multiply(weights[:, None]).tocsr()
    xt, yt = dNdx.T.tocsr(), dNdy.T.tocsr()
    xx = xt @ wx
    yy = yt @ wy
    xy = xt @ wy
    yx = xy.T
    kuu = D[0, 0] * xx + D[2, 2] * yy
    kvv = D[1, 1] * yy + D[2, 2] * xx
    kuv = D[0, 1] * xy + D[2, 2] * yx
    return sp.bmat([[kuu, kuv], [kuv.T, kvv]], format="csr")


def load_vector(N: sp.csr_matrix, weights: np.ndarray, tx: np.ndarray, ty: np.ndarray) -> np.ndarray:
    """F = sum_j N_j^T t_j w_j J_j (Eq. 6, second term) in blocked dof order."""
    return np.concatenate([N.T @ (tx * weights), N.T @ (ty * weights)])


def strain(dNdx: sp.csr_matrix, dNdy: sp.csr_matrix, u: np.ndarray) -> np.ndarray:
    """(m, 3) exx, eyy, gxy at the rows' points from nodal displacements u (n, 2)."""
    return np.c_[dNdx @ u[:, 0], dNdy @ u[:, 1], dNdy @ u[:, 0] + dNdx @ u[:, 1]]
