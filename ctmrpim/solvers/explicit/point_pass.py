"""The explicit step's pass over the integration points, compiled (numba): the gradient, the relative gradient, the
Mohr-Coulomb update and the internal force of every point, block by block (Section 2.1.4, steps 7-9;
:mod:`ctmrpim.solvers.explicit.step`).

Per point p, from the nodes' displacements d = x - x_r since the frame was built:

    F_new = I + sum_j d_j grad_r N_j(x_p),   f = F_new F^-1,   det f > 0 or the point is inverted,

the weight w_r det F_new and the largest stretch strain of F_new, which the rebuild criterion reads; then, for a
chunk of points while their rows are in cache, the stress update of
:func:`ctmrpim.materials.mohr_coulomb_kernel.update_rows` (Hughes-Winget rotation, return, plastic strain, viscous
stress) and the next step's internal force, w_r P(F_new, sigma_new + viscous) scattered onto the nodes of the
point's row (:func:`ctmrpim.discretisation.gradient_operator.scatter_rows`). A point without weight, or inverted
by the step, integrates nothing: identity gradients, no stress (the caller drops the inverted ones' weights, or
stops the run where there are too many).

Why one pass: as separate products and numpy expressions these were a gradient pass over the ~8 MB shape-function
pattern, eight array passes over the points' (m, 4) gradients and weights, the update kernel, the strain
criterion's pass and the force's pass over the pattern transposed, each over all the points; here a chunk of
points goes through simple loops one after the other while its rows are in cache (one loop doing all of them
vectorised worse), and the blocks run on the threads of :mod:`ctmrpim.discretisation.thread_blocks`. Measured on
the 1071-node column's 9600 points (two threads, best of 300): the pass without the force 0.63 ms plus the
force's own pass 0.31-0.37 ms, against 0.87 ms with the force scattered on the way. Each block of
:attr:`~ctmrpim.discretisation.gradient_operator.GradientOperator.scatter_blocks` scatters into its own nodal
array and the arrays are added in block order, and the plastic dissipation and viscous work are kept per point and
added up afterwards, so the run's numbers do not depend on the threads (a resumed run, whose first force is the
step's own :meth:`~ctmrpim.discretisation.configuration.Configuration.weighted_force`, the same bits, repeats the
uninterrupted one bit for bit).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from ctmrpim.discretisation import thread_blocks
from ctmrpim.discretisation.configuration import Configuration
from ctmrpim.discretisation.gradient_operator import add_blocks, gradient_rows, scatter_rows
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.materials.mohr_coulomb_kernel import refuse_no_apex, return_constants, update_rows
from ctmrpim.materials.objective_stress_kernels import stretch_strain, weighted_first_piola_rows

#: points a block goes through the pass's loops in at a time: their rows (about 43 entries each on the column's
#: clouds, 20 bytes an entry: about 110 kB) stay in the second-level cache from the gradient to the force's scatter
#: (measured on the 1071-node column's points, two threads, best of 300: 8 points 1.0 ms, 32 0.93, 128 0.86,
#: 512 0.87, the whole block at once 0.90)
CHUNK = 128


class PointPass(NamedTuple):
    """What :func:`point_pass` returns for the m points of a frame."""
    F: np.ndarray               # (m, 4) the gradients relative to the frame after the step (identity: dead points)
    stress: np.ndarray          # (m, 4) Cauchy stress
    plastic: np.ndarray         # (m, 4) plastic strain
    viscous: np.ndarray         # (m, 4) viscous stress of the step
    inverted: np.ndarray        # (m,) bool: points with weight that the step turned inside out
    dissipation: float          # plastic dissipation of the step
    viscous_work: float         # work of the last step's viscous stress on this step's strain
    largest_strain: float       # largest |principal stretch - 1| of F (NaN where one is not finite)
    force: np.ndarray | None    # (n, 2) F_int of the new state on the frame (None: not asked for)


@njit(cache=True, nogil=True)
def _relative(F, w, F_new, f, dead, inverted, wJ, strain, p0, p1):
    """f = F_new F^-1, whether the point is dead (no weight) or inverted (det f <= 0; then dead too, with identity
    gradients), its weight w_r det F_new and the stretch strain of F_new, for p0 <= p < p1 (F_new given)."""
    for p in range(p0, p1):
        n00, n01, n10, n11 = F_new[p, 0], F_new[p, 1], F_new[p, 2], F_new[p, 3]
        J = F[p, 0] * F[p, 3] - F[p, 1] * F[p, 2]
        i00, i01, i10, i11 = F[p, 3] / J, -F[p, 1] / J, -F[p, 2] / J, F[p, 0] / J
        f00, f01 = n00 * i00 + n01 * i10, n00 * i01 + n01 * i11
        f10, f11 = n10 * i00 + n11 * i10, n10 * i01 + n11 * i11
        alive = w[p] > 0.0
        inverted[p] = alive and not (f00 * f11 - f01 * f10 > 0.0)
        dead[p] = not alive or inverted[p]
        if dead[p]:
            n00, n01, n10, n11 = 1.0, 0.0, 0.0, 1.0
            f00, f01, f10, f11 = 1.0, 0.0, 0.0, 1.0
            F_new[p, 0], F_new[p, 1], F_new[p, 2], F_new[p, 3] = n00, n01, n10, n11
        f[p, 0], f[p, 1], f[p, 2], f[p, 3] = f00, f01, f10, f11
        wJ[p] = 0.0 if dead[p] else w[p] * (n00 * n11 - n01 * n10)
        strain[p] = stretch_strain(n00, n01, n10, n11)


@njit(cache=True, nogil=True)
def _points(indptr, indices, dx, dy, d, F, stress, plastic, viscous, w, G, K, c, sphi, cphi, spsi, E, nu, beta_dt,
            with_viscous, with_force, F_new, f, dead, wJ, out_stress, out_plastic, out_viscous, region, inverted,
            dissipation, viscous_work, strain, wP, parts, b, p0, p1):
    """A block of points, CHUNK points at a time: their gradients (the gradient operator's loop), relative gradients
    (:func:`_relative`), stress update (:func:`ctmrpim.materials.mohr_coulomb_kernel.update_rows`) and, where
    ``with_force``, the weighted first Piola stress of the new state scattered into the block's nodal force
    ``parts[b]``: one simple loop after the other over a chunk while its rows are in cache."""
    for c0 in range(p0, p1, CHUNK):
        c1 = min(c0 + CHUNK, p1)
        gradient_rows(indptr, indices, dx, dy, d, F_new, 1.0, c0, c1)
        _relative(F, w, F_new, f, dead, inverted, wJ, strain, c0, c1)
        update_rows(f, stress, plastic, viscous, dead, wJ, G, K, c, sphi, cphi, spsi, E, nu, beta_dt, out_stress,
                    out_plastic, out_viscous, region, dissipation, viscous_work, c0, c1)
        if with_force:
            weighted_first_piola_rows(out_stress, out_viscous, with_viscous, F_new, w, wP, c0, c1)
            scatter_rows(indptr, indices, dx, dy, wP, parts[b], c0, c1)


def point_pass(frame: Configuration, d: np.ndarray, F: np.ndarray, stress: np.ndarray, plastic: np.ndarray,
               viscous: np.ndarray, material: MohrCoulomb, beta_dt: float, with_viscous: bool = False,
               force: bool = False) -> PointPass:
    """The step at every point of ``frame``: d (n, 2) the nodes' displacements since the frame was built, F (m, 4)
    the gradients before the step, the stress, plastic strain and viscous stress (m, 4: xx, yy, xy, zz) of the last
    step, the viscosity beta / dt; Mohr-Coulomb without a tension cut-off (the numpy forms of the step take that).
    ``force``: also F_int = sum_p w_r P grad_r N of the new state (its viscous stress added where ``with_viscous``),
    the bits of :meth:`~ctmrpim.discretisation.gradient_operator.GradientOperator.scatter_force` of the new state's
    w_r P (points that the step inverted count as they will once dropped: no stress)."""
    constants = return_constants(material, "point_pass")
    op = frame.compiled_gradient()
    m, blocks = len(frame.w), op.scatter_blocks
    F_new, f, out_stress, out_plastic, out_viscous = (np.empty((m, 4)) for _ in range(5))
    region, inverted, dead = np.empty(m, np.int8), np.empty(m, np.bool_), np.empty(m, np.bool_)
    wJ, dissipation, viscous_work, strain = np.empty(m), np.empty(m), np.empty(m), np.empty(m)
    wP = np.empty((m, 4)) if force else np.empty((0, 4))
    parts = np.zeros((max(len(blocks), 1), op.shape[1], 2) if force else (1, 0, 2))
    f64 = lambda a: np.ascontiguousarray(a, float)
    args = (op.indptr, op.indices, op.dx, op.dy, f64(d), f64(F), f64(stress), f64(plastic), f64(viscous), frame.w,
            *constants, material.E, material.nu,
            float(beta_dt), bool(with_viscous), bool(force), F_new, f, dead, wJ, out_stress, out_plastic, out_viscous,
            region, inverted, dissipation, viscous_work, strain, wP, parts)
    thread_blocks.run_blocks(lambda bab: _points(*args, *bab), blocks, kernel=_points)
    refuse_no_apex(material, region)
    return PointPass(F_new, out_stress, out_plastic, out_viscous, inverted, float(dissipation.sum()),
                     float(viscous_work.sum()), float(strain.max()) if m else 0.0,   # NaN wins the max
                     add_blocks(parts) if force else None)
