"""The explicit solver's per-point stress update, compiled (numba): one pass over the integration points.

Each step of :mod:`ctmrpim.solvers.explicit` updates every integration point (about 10000 for the
1071-node column): the Hughes-Winget strain increment and rotation of the relative deformation
gradient f (:func:`ctmrpim.materials.objective_stress.hughes_winget_c`), the rotation of the stress and plastic
strain (:func:`ctmrpim.materials.objective_stress.rotate_c`), the Mohr-Coulomb return of de Souza Neto et al.
(2008), Box 8.4 (:meth:`ctmrpim.materials.mohr_coulomb.MohrCoulomb.update`, without a tension cut-off), the
plastic strain increment (:func:`ctmrpim.materials.mohr_coulomb.plastic_strain_increment`) and the plastic
dissipation. Written with numpy arrays of the points' size these are a temporary array per operation; here
they are one loop per point in registers (:func:`update_rows`, which the explicit step's point pass runs per
block of points: :mod:`ctmrpim.solvers.explicit.point_pass`). Measured in one script on 10000 points
(Mohr-Coulomb states, 11 % of them yielding): 0.75 ms per step against 4.1 ms for the numpy forms; on the
1071-node column's 9625 points, one thread, 0.46 ms.

The same return serves the implicit solvers: their residuals' small-strain update (:func:`small_strain_update`)
and their Newton tangents' complex steps (:func:`consistent_tangent`), the return's kernels compiled for real and
for complex numbers alike. The numpy forms stay the definition (and the tension cut-off's only form);
``tests/unit/test_mohr_coulomb_kernel.py`` checks these kernels against them point for point in every return
region (elastic, main plane, both edges, apex), to round-off.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import APEX, COMPLEX_STEP, EIGEN_GAP, YIELD_TOL, MohrCoulomb
from ctmrpim.materials.objective_stress import hughes_winget_components, rotate_components

_hughes_winget = njit(cache=True, nogil=True)(hughes_winget_components)
_rotate = njit(cache=True, nogil=True)(rotate_components)


class PointUpdate(NamedTuple):
    """What :func:`point_update` returns for m integration points."""
    stress: np.ndarray          # (m, 4) Cauchy stress after the step
    plastic: np.ndarray         # (m, 4) plastic strain after the step
    region: np.ndarray          # (m,) return region
    dissipation: float          # plastic dissipation of the step
    viscous: np.ndarray         # (m, 4) viscous stress of the step (zero without damping)
    viscous_work: float         # work of the last step's viscous stress on this step's strain


@njit(cache=True, nogil=True)
def _sorted_principal(sxx, syy, sxy, szz):
    """Sorted principal stresses s1 >= s2 >= s3, the in-plane unit eigenvector of the larger in-plane
    value and the slot of szz: :func:`ctmrpim.materials.mohr_coulomb._principal` for one stress, real or complex
    (every decision on the real part, as there; np.sqrt is the correctly rounded square root on reals)."""
    centre = 0.5 * (sxx + syy)
    half = 0.5 * (sxx - syy)
    gap = abs(half.real) + abs(sxy.real)
    tiny = EIGEN_GAP * (abs(centre.real) + gap + 1e-300)
    if gap < tiny:
        sxy = sxy + tiny
    radius = np.sqrt(half * half + sxy * sxy)
    big, small = centre + radius, centre - radius
    nx, ny = radius + half, sxy
    norm = np.sqrt(nx * nx + ny * ny)
    if abs(norm.real) < 1e-300:
        nx, ny = 0.0, 1.0
    else:
        nx, ny = nx / norm, ny / norm
    if szz.real >= big.real:
        return szz, big, small, nx, ny, 0
    if szz.real >= small.real:
        return big, szz, small, nx, ny, 1
    return big, small, szz, nx, ny, 2


@njit(cache=True, nogil=True)
def _return(s1, s2, s3, G, K, c, sphi, cphi, spsi):
    """Box 8.4 return of sorted principal trial stresses (perfect plasticity): main plane, right edge
    (s1 = s2), left edge (s2 = s3), apex; returns the stresses and the region (1-4)."""
    f = (s1 - s3) + (s1 + s3) * sphi - 2.0 * c * cphi
    a = 4.0 * G * (1.0 + sphi * spsi / 3.0) + 4.0 * K * sphi * spsi
    r1 = 2.0 * G * (1.0 + spsi / 3.0) + 2.0 * K * spsi
    r2 = (4.0 * G / 3.0 - 2.0 * K) * spsi
    r3 = 2.0 * G * (1.0 - spsi / 3.0) - 2.0 * K * spsi
    dg = f / a
    m1, m2, m3 = s1 - r1 * dg, s2 + r2 * dg, s3 + r3 * dg
    if m1.real >= m2.real and m2.real >= m3.real:
        return m1, m2, m3, 1
    if m2.real > m1.real:
        fb = (s2 - s3) + (s2 + s3) * sphi - 2.0 * c * cphi
        b = 2.0 * G * (1.0 - sphi - spsi - sphi * spsi / 3.0) + 4.0 * K * sphi * spsi
        det = a * a - b * b
        ga, gb = (a * f - b * fb) / det, (a * fb - b * f) / det
        e1, e2, e3 = s1 - r1 * ga + r2 * gb, s2 + r2 * ga - r1 * gb, s3 + r3 * (ga + gb)
        if ga.real >= 0.0 and gb.real >= 0.0 and e2.real >= e3.real:
            return e1, e2, e3, 2
    else:
        fb = (s1 - s2) + (s1 + s2) * sphi - 2.0 * c * cphi
        b = 2.0 * G * (1.0 + sphi + spsi - sphi * spsi / 3.0) + 4.0 * K * sphi * spsi
        det = a * a - b * b
        ga, gb = (a * f - b * fb) / det, (a * fb - b * f) / det
        e1, e2, e3 = s1 - r1 * (ga + gb), s2 + r2 * ga + r3 * gb, s3 + r3 * ga + r2 * gb
        if ga.real >= 0.0 and gb.real >= 0.0 and e1.real >= e2.real:
            return e1, e2, e3, 3
    apex = c * cphi / sphi if sphi > 0.0 else math.nan      # phi = 0 beyond both edges: no apex
    return apex, apex, apex, 4


@njit(cache=True, nogil=True)
def _trial_and_return(r0, r1, r2, r3, e0, e1, e2, lam, G, K, c, sphi, cphi, spsi):
    """The elastic trial stress from (r0, r1, r2, r3) (xx, yy, xy, zz) and the strain increment (e0, e1, e2) (exx,
    eyy, gxy; ezz = 0), returned to the yield surface where it lies outside (MohrCoulomb._update): the new stress
    and the return region (0: elastic)."""
    tr = e0 + e1
    t0 = r0 + lam * tr + 2.0 * G * e0
    t1 = r1 + lam * tr + 2.0 * G * e1
    t2 = r2 + G * e2
    t3 = r3 + lam * tr
    s1, s2, s3, nx, ny, zslot = _sorted_principal(t0, t1, t2, t3)
    fy = (s1 - s3) + (s1 + s3) * sphi - 2.0 * c * cphi
    reg = 0
    if fy.real > YIELD_TOL * (c + max(abs(s1.real), abs(s2.real), abs(s3.real))):
        s1, s2, s3, reg = _return(s1, s2, s3, G, K, c, sphi, cphi, spsi)
        if zslot == 0:
            szz, big, small = s1, s2, s3
        elif zslot == 1:
            szz, big, small = s2, s1, s3
        else:
            szz, big, small = s3, s1, s2
        t0 = big * nx * nx + small * ny * ny
        t1 = big * ny * ny + small * nx * nx
        t2 = (big - small) * nx * ny
        t3 = szz
    return t0, t1, t2, t3, reg


@njit(cache=True, nogil=True)
def update_rows(f, stress, plastic, viscous, dead, w, G, K, c, sphi, cphi, spsi, E, nu, beta_dt, out_stress,
                out_plastic, out_viscous, region, dissipation, viscous_work, p0, p1):
    """:func:`point_update` for the points p0 <= p < p1, each point's plastic dissipation and viscous work into
    ``dissipation[p]`` and ``viscous_work[p]`` (summed by the caller, so that blocks of points on threads give the
    same sums)."""
    lam = K - 2.0 * G / 3.0
    for p in range(p0, p1):
        if dead[p]:
            for k in range(4):
                out_stress[p, k] = 0.0
                out_plastic[p, k] = 0.0
                out_viscous[p, k] = 0.0
            region[p] = 0
            dissipation[p] = 0.0
            viscous_work[p] = 0.0
            continue
        e0, e1, e2, cq, sq = _hughes_winget(f[p, 0], f[p, 1], f[p, 2], f[p, 3])
        r0, r1, r2 = _rotate(stress[p, 0], stress[p, 1], stress[p, 2], cq, sq)
        r3 = stress[p, 3]
        q0, q1, q2 = _rotate(plastic[p, 0], plastic[p, 1], plastic[p, 2], cq, sq)
        q3 = plastic[p, 3]
        # the viscous stress of the step, beta D de / dt. The force of the state after step n carries the viscous
        # stress of step n and does work over (de_n + de_{n+1}) / 2 in the central-difference ledger, so each
        # viscous stress is booked half on the strain that made it and half on the next step's
        tr = e0 + e1
        v0, v1, v2 = beta_dt * (lam * tr + 2.0 * G * e0), beta_dt * (lam * tr + 2.0 * G * e1), beta_dt * G * e2
        out_viscous[p, 0], out_viscous[p, 1], out_viscous[p, 2] = v0, v1, v2
        out_viscous[p, 3] = beta_dt * lam * tr
        viscous_work[p] = 0.5 * w[p] * ((viscous[p, 0] + v0) * e0 + (viscous[p, 1] + v1) * e1
                                        + (viscous[p, 2] + v2) * e2)
        t0, t1, t2, t3, reg = _trial_and_return(r0, r1, r2, r3, e0, e1, e2, lam, G, K, c, sphi, cphi, spsi)
        region[p] = reg
        out_stress[p, 0], out_stress[p, 1], out_stress[p, 2], out_stress[p, 3] = t0, t1, t2, t3
        # plastic strain increment: total (ezz = 0) less C (sigma_new - sigma_rotated)
        d0, d1, d2, d3 = t0 - r0, t1 - r1, t2 - r2, t3 - r3
        trace = d0 + d1 + d3
        dp0 = e0 - ((1.0 + nu) * d0 - nu * trace) / E
        dp1 = e1 - ((1.0 + nu) * d1 - nu * trace) / E
        dp2 = 0.5 * e2 - (1.0 + nu) * d2 / E
        dp3 = -((1.0 + nu) * d3 - nu * trace) / E
        out_plastic[p, 0], out_plastic[p, 1] = q0 + dp0, q1 + dp1
        out_plastic[p, 2], out_plastic[p, 3] = q2 + dp2, q3 + dp3
        dissipation[p] = w[p] * 0.5 * ((r0 + t0) * dp0 + (r1 + t1) * dp1 + 2.0 * (r2 + t2) * dp2 + (r3 + t3) * dp3)


def return_constants(material: MohrCoulomb, caller: str, instead: str = "the numpy forms") -> tuple[float, ...]:
    """(G, K, c, sin phi, cos phi, sin psi): the material as the compiled return takes it. The tension cut-off is
    not compiled: ``caller`` refuses it, naming what to use ``instead``."""
    if material.tension is not None:
        raise ValueError(f"{caller}: the tension cut-off is not compiled; use {instead}")
    phi, psi = math.radians(material.phi), math.radians(material.psi)
    return material.G, material.K, material.c, math.sin(phi), math.cos(phi), math.sin(psi)


def refuse_no_apex(material: MohrCoulomb, region: np.ndarray) -> None:
    """Refuse returns to the apex with phi = 0, where there is none (the compiled return leaves them NaN)."""
    if material.phi == 0 and np.any(region == APEX):
        raise ProblemError("Mohr-Coulomb return: a stress state beyond both edges with phi = 0 (no apex); the "
                           "strain increment is too large")


def point_update(material: MohrCoulomb, f: np.ndarray, stress: np.ndarray, plastic: np.ndarray,
                 dead: np.ndarray, w: np.ndarray, viscous: np.ndarray | None = None,
                 beta_dt: float = 0.0) -> PointUpdate:
    """One step at every point: from the relative deformation gradients ``f`` (m, 4: xx, xy, yx, yy) and
    the Cauchy stress and plastic strain (m, 4: xx, yy, xy, zz) of the last step to the new ones, the
    return region of each point (:data:`ctmrpim.materials.mohr_coulomb.ELASTIC`, ...) and the plastic dissipation
    sum_p w_p (sigma_rotated + sigma_new) / 2 : d eps_p. With ``beta_dt`` = beta / dt > 0, also the
    viscous stress of the step, beta D d eps / dt (stiffness-proportional damping), and the viscous work on this
    step's strain: half of it done by the last step's viscous stress ``viscous``, half by this step's (each viscous
    stress acts over two half steps in the central-difference ledger). Points marked ``dead`` come out
    stress-free with no plastic strain. Mohr-Coulomb without a tension cut-off only."""
    constants = return_constants(material, "point_update")
    m = len(f)
    out_stress, out_plastic, out_viscous = np.empty((m, 4)), np.empty((m, 4)), np.empty((m, 4))
    region, dissipation, viscous_work = np.empty(m, np.int8), np.empty(m), np.empty(m)
    viscous = np.zeros((m, 4)) if viscous is None else np.ascontiguousarray(viscous, float)
    update_rows(np.ascontiguousarray(f, float), np.ascontiguousarray(stress, float),
                np.ascontiguousarray(plastic, float), viscous, np.ascontiguousarray(dead, np.bool_),
                np.ascontiguousarray(w, float), *constants, material.E, material.nu, float(beta_dt),
                out_stress, out_plastic, out_viscous, region, dissipation, viscous_work, 0, m)
    refuse_no_apex(material, region)
    return PointUpdate(out_stress, out_plastic, region, float(dissipation.sum()), out_viscous,
                       float(viscous_work.sum()))


@njit(cache=True)
def _small_strain(stress, de, G, K, c, sphi, cphi, spsi, out, region):
    lam = K - 2.0 * G / 3.0
    for p in range(stress.shape[0]):
        t0, t1, t2, t3, reg = _trial_and_return(stress[p, 0], stress[p, 1], stress[p, 2], stress[p, 3], de[p, 0],
                                                de[p, 1], de[p, 2], lam, G, K, c, sphi, cphi, spsi)
        region[p] = reg
        out[p, 0], out[p, 1], out[p, 2], out[p, 3] = t0, t1, t2, t3


def small_strain_update(material: MohrCoulomb, stress: np.ndarray, dstrain: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """:meth:`ctmrpim.materials.mohr_coulomb.MohrCoulomb.update` compiled, for real increments and no tension
    cut-off: the stress (m, 4) after the strain increments ``dstrain`` (m, 3: exx, eyy, gxy) from ``stress``
    (m, 4), and the return region of each point. One pass over the points instead of about 40 array passes
    (the implicit solvers' residuals; their tangents: :func:`consistent_tangent`)."""
    constants = return_constants(material, "small_strain_update", "MohrCoulomb.update")
    m = len(stress)
    out, region = np.empty((m, 4)), np.empty(m, np.int8)
    _small_strain(np.ascontiguousarray(stress, float), np.ascontiguousarray(dstrain, float), *constants, out, region)
    refuse_no_apex(material, region)
    return out, region


@njit(cache=True)
def _tangent(stress, de, G, K, c, sphi, cphi, spsi, h, out):
    lam = K - 2.0 * G / 3.0
    for p in range(stress.shape[0]):
        for k in range(3):
            e0 = complex(de[p, 0], h if k == 0 else 0.0)
            e1 = complex(de[p, 1], h if k == 1 else 0.0)
            e2 = complex(de[p, 2], h if k == 2 else 0.0)
            t0, t1, t2, _, _ = _trial_and_return(stress[p, 0], stress[p, 1], stress[p, 2], stress[p, 3], e0, e1,
                                                 e2, lam, G, K, c, sphi, cphi, spsi)
            out[p, 0, k], out[p, 1, k], out[p, 2, k] = t0.imag / h, t1.imag / h, t2.imag / h


def consistent_tangent(material: MohrCoulomb, stress: np.ndarray, dstrain: np.ndarray) -> np.ndarray:
    """:meth:`ctmrpim.materials.mohr_coulomb.MohrCoulomb.tangent` compiled, for no tension cut-off: the (m, 3, 3)
    consistent tangent d(sxx, syy, sxy)_{n+1} / d(exx, eyy, gxy) of the return from ``stress`` (m, 4) by
    ``dstrain`` (m, 3), by the same three complex steps per point (the compiled return above run on complex
    numbers, every branch decided on the real part) in one pass instead of three complex numpy passes of about
    40 arrays each (the implicit solvers' Newton tangents)."""
    constants = return_constants(material, "consistent_tangent", "MohrCoulomb.tangent")
    out = np.empty((len(stress), 3, 3))
    _tangent(np.ascontiguousarray(stress, float), np.ascontiguousarray(dstrain, float), *constants, COMPLEX_STEP,
             out)
    return out
