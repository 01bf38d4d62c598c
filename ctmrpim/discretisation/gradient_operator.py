"""The RPIM gradient at the integration points and its transpose, the internal force (compiled, numba).

With dN/dx and dN/dy of every point in one sparse pattern (a point's support), the explicit solver
needs two products each step:

    F_p = I + sum_j (x_j - x_r,j) (dN_j/dx, dN_j/dy)(x_p)                        (the gradient)
    f_j = sum_p w_p P_p (dN_j/dx, dN_j/dy)(x_p)^T                              (the internal force)

As scipy products these are four passes over the matrix (two columns each way, CSR and its
transpose); here each is one pass over the shared pattern with both derivative values. Measured on the
1071-node column's 9591 points (416391 entries), best of 7 in one script: gradient 0.9-1.3 ms against
1.2-1.4 ms, force 1.0 ms against 1.7 ms for scipy's products. The force scatters into the nodes in point
order, so the sums come out in the same order every run (a resumed run repeats the uninterrupted one
bit for bit).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit


@njit(cache=True, fastmath={"reassoc", "contract"})
def _gradient(indptr, indices, dx, dy, d, out, identity):
    for p in range(len(indptr) - 1):
        a = b = c = e = 0.0
        for k in range(indptr[p], indptr[p + 1]):
            j = indices[k]
            a += dx[k] * d[j, 0]
            b += dy[k] * d[j, 0]
            c += dx[k] * d[j, 1]
            e += dy[k] * d[j, 1]
        out[p, 0], out[p, 1], out[p, 2], out[p, 3] = identity + a, b, c, identity + e


@njit(cache=True, fastmath={"reassoc", "contract"})
def _force(indptr, indices, dx, dy, wP, out):
    for p in range(len(indptr) - 1):
        P0, P1, P2, P3 = wP[p, 0], wP[p, 1], wP[p, 2], wP[p, 3]
        for k in range(indptr[p], indptr[p + 1]):
            j = indices[k]
            out[j, 0] += P0 * dx[k] + P1 * dy[k]
            out[j, 1] += P2 * dx[k] + P3 * dy[k]


class GradientOperator:
    """dN/dx and dN/dy (m points x n nodes, one sparsity pattern) as the two products above."""

    def __init__(self, dNdx: sp.csr_matrix, dNdy: sp.csr_matrix) -> None:
        if not (np.array_equal(dNdx.indptr, dNdy.indptr) and np.array_equal(dNdx.indices, dNdy.indices)):
            raise ValueError("dN/dx and dN/dy must share one sparsity pattern")
        self.shape = dNdx.shape
        self.indptr, self.indices = dNdx.indptr, dNdx.indices
        self.dx, self.dy = np.ascontiguousarray(dNdx.data, float), np.ascontiguousarray(dNdy.data, float)

    def gradient(self, d: np.ndarray, identity: float = 1.0) -> np.ndarray:
        """(m, 4) F = I + grad d (xx, xy, yx, yy) of nodal displacements d (n, 2); ``identity = 0``: grad d."""
        out = np.empty((self.shape[0], 4))
        _gradient(self.indptr, self.indices, self.dx, self.dy, np.ascontiguousarray(d, float), out, identity)
        return out

    def force(self, wP: np.ndarray) -> np.ndarray:
        """(n, 2) sum_p wP_p grad N of weighted first Piola stresses wP (m, 4: xX, xY, yX, yY)."""
        out = np.zeros((self.shape[1], 2))
        _force(self.indptr, self.indices, self.dx, self.dy, np.ascontiguousarray(wP, float), out)
        return out


def rpim_layout(G: sp.bsr_matrix) -> bool:
    """Whether G (4m x 2n) is block-sparse with every 4 x 2 block [[a, 0], [b, 0], [0, a], [0, b]] (a = dN/dX,
    b = dN/dY: :func:`ctmrpim.discretisation.lagrangian_operators.gradient_operator`'s layout)."""
    if not (isinstance(G, sp.bsr_matrix) and G.blocksize == (4, 2)):
        return False
    d = G.data
    return bool(np.array_equal(d[:, 2, 1], d[:, 0, 0]) and np.array_equal(d[:, 3, 1], d[:, 1, 0])
                and not np.any(d[:, 2:, 0]) and not np.any(d[:, :2, 1]))


def from_blocks(G: sp.bsr_matrix) -> GradientOperator | None:
    """The operator of a G in :func:`rpim_layout`, or None."""
    if not rpim_layout(G):
        return None
    m, n = G.shape[0] // 4, G.shape[1] // 2
    return GradientOperator(sp.csr_matrix((G.data[:, 0, 0], G.indices, G.indptr), shape=(m, n)),
                            sp.csr_matrix((G.data[:, 1, 0], G.indices, G.indptr), shape=(m, n)))
