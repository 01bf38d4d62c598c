"""The corrected test gradients of ``method.integration = "ctm-vci"`` held as their per-node coefficients.

d~_k N_I(x_p) = d_k N_I(x_p) + c_Ik . q_I(x_p), q_I = [1, (x_p - x_I) / d_c, (y_p - y_I) / d_c] (the quadratic
correction; the linear one keeps only c_Ik0), with c from
:func:`ctmrpim.discretisation.consistent_integration.corrected_gradients`. Why coefficients: the corrected
gradients as arrays are two more arrays of the shape functions' size (116 MB at 257 x 65 nodes, the largest
part of the linear solve's peak while the stiffness is assembled); the stiffness kernel
(:func:`ctmrpim.discretisation.stiffness_kernels.stiffness_rows`) adds the correction as it reads each entry,
with the same expression as :meth:`GradientCorrection.applied`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ctmrpim.discretisation import vci_kernels


@dataclass
class GradientCorrection:
    """The coefficients c (n, 3, 2) of the correction at the ``points`` (m, 2) of a pattern over the ``nodes``
    (n, 2); ``d_c`` scales q; ``quadratic``: q = [1, x, y], else q = [1] (only c[:, 0, :] is read)."""
    c: np.ndarray
    points: np.ndarray
    nodes: np.ndarray
    d_c: float
    quadratic: bool

    @property
    def mode(self) -> int:
        """The stiffness kernel's switch: 1 linear, 2 quadratic (0 there: no correction)."""
        return 2 if self.quadratic else 1

    def applied(self, dx: sp.csr_matrix, dy: sp.csr_matrix) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """The corrected gradients d~N/dx, d~N/dy as arrays on the pattern of ``dx`` and ``dy``."""
        f64 = lambda v: np.ascontiguousarray(v, dtype=float)
        out_x, out_y = np.empty(dx.nnz), np.empty(dx.nnz)
        vci_kernels.corrected(dx.indptr, dx.indices, f64(dx.data), f64(dy.data), self.points, self.nodes,
                              float(self.d_c), self.quadratic, self.c, out_x, out_y)
        return tuple(sp.csr_matrix((v, d.indices, d.indptr), shape=d.shape) for v, d in ((out_x, dx), (out_y, dy)))
