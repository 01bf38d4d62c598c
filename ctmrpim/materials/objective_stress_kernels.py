"""Compiled (numba) loops over the points for the component forms of :mod:`ctmrpim.materials.objective_stress`.

The explicit solver evaluates these on every point every step (tens of thousands of points, tens of thousands of
steps); as numpy expressions each is a dozen passes over (m,) arrays and a stack into (m, 4), 0.1-0.3 ms
apiece on the 1071-node column's 9600 points. Here each is one pass. The arithmetic is the numpy forms',
operation for operation, without fast-math flags (no fused multiply-adds, no reassociation), so the results are
the same bits. A gradient is stored (m, 4) as xx, xy, yx, yy (F[:, 1] = dx/dY); a stress (m, 4) as xx, yy,
xy, zz.
"""
from __future__ import annotations

import math

from numba import njit


@njit(cache=True, nogil=True)
def det(F, out):
    """out (m,) <- det F of gradients F (m, 4)."""
    for p in range(F.shape[0]):
        out[p] = F[p, 0] * F[p, 3] - F[p, 1] * F[p, 2]


@njit(cache=True, nogil=True)
def first_piola(stress, F, out):
    """out (m, 4) <- P = det F sigma F^-T (xX, xY, yX, yY) of Cauchy stresses (m, >= 3) at gradients F (m, 4)."""
    for p in range(F.shape[0]):
        sxx, syy, sxy = stress[p, 0], stress[p, 1], stress[p, 2]
        F00, F01, F10, F11 = F[p, 0], F[p, 1], F[p, 2], F[p, 3]
        out[p, 0] = sxx * F11 - sxy * F01
        out[p, 1] = sxy * F00 - sxx * F10
        out[p, 2] = sxy * F11 - syy * F01
        out[p, 3] = syy * F00 - sxy * F10


@njit(cache=True, nogil=True)
def relative(F_new, F, out):
    """out (m, 4) <- f = F_new F^-1."""
    for p in range(F.shape[0]):
        J = F[p, 0] * F[p, 3] - F[p, 1] * F[p, 2]
        i00, i01, i10, i11 = F[p, 3] / J, -F[p, 1] / J, -F[p, 2] / J, F[p, 0] / J
        a00, a01, a10, a11 = F_new[p, 0], F_new[p, 1], F_new[p, 2], F_new[p, 3]
        out[p, 0] = a00 * i00 + a01 * i10
        out[p, 1] = a00 * i01 + a01 * i11
        out[p, 2] = a10 * i00 + a11 * i10
        out[p, 3] = a10 * i01 + a11 * i11


@njit(cache=True, nogil=True)
def stretch_strain(F00, F01, F10, F11):
    """|principal stretch - 1|, the larger of the two, of one gradient (xx, xy, yx, yy), from C = F^T F; NaN for a
    gradient that is not finite."""
    C00 = F00 ** 2 + F10 ** 2
    C11 = F01 ** 2 + F11 ** 2
    C01 = F00 * F01 + F10 * F11
    mean, half = 0.5 * (C00 + C11), math.hypot(0.5 * (C00 - C11), C01)
    low = mean - half
    if low < 0.0:          # a NaN stays NaN, as under np.maximum
        low = 0.0
    big, small = math.sqrt(mean + half), math.sqrt(low)
    if math.isnan(big) or math.isnan(small):
        return math.nan
    return max(abs(big - 1.0), abs(small - 1.0))


@njit(cache=True, nogil=True)
def largest_strain(F):
    """Largest |principal stretch - 1| over gradients F (m, 4), from C = F^T F; 0 for none."""
    big_out = 0.0
    for p in range(F.shape[0]):
        v = stretch_strain(F[p, 0], F[p, 1], F[p, 2], F[p, 3])
        if math.isnan(v):
            return math.nan    # as numpy's max: a gradient that is not finite is no small strain
        big_out = max(big_out, v)
    return big_out


@njit(cache=True, nogil=True)
def weighted_first_piola_rows(stress, viscous, with_viscous, F, w, out, p0, p1):
    """out[p] <- w P, P = det F (sigma + viscous) F^-T (xX, xY, yX, yY) (:func:`first_piola`) for p0 <= p < p1, the
    viscous stress added where ``with_viscous``: the explicit step's internal force density."""
    for p in range(p0, p1):
        sxx, syy, sxy = stress[p, 0], stress[p, 1], stress[p, 2]
        if with_viscous:
            sxx, syy, sxy = sxx + viscous[p, 0], syy + viscous[p, 1], sxy + viscous[p, 2]
        F00, F01, F10, F11 = F[p, 0], F[p, 1], F[p, 2], F[p, 3]
        wp = w[p]
        out[p, 0] = (sxx * F11 - sxy * F01) * wp
        out[p, 1] = (sxy * F00 - sxx * F10) * wp
        out[p, 2] = (sxy * F11 - syy * F01) * wp
        out[p, 3] = (syy * F00 - sxy * F10) * wp


@njit(cache=True, nogil=True)
def weighted_first_piola(stress, viscous, with_viscous, F, w, out):
    """:func:`weighted_first_piola_rows` at every point, in one pass."""
    weighted_first_piola_rows(stress, viscous, with_viscous, F, w, out, 0, F.shape[0])
