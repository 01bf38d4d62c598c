"""Mohr-Coulomb elastic-perfectly plastic material, plane strain, non-associated (docs/design.md, 'Materials').

Yield and plastic potential in principal stresses s1 >= s2 >= s3 (tension positive), sigma_zz carried
as one of the three and sorted with the in-plane two every time:

    f = (s1 - s3) + (s1 + s3) sin(phi) - 2 c cos(phi),     g = (s1 - s3) + (s1 + s3) sin(psi).

The return mapping is de Souza Neto, Peric & Owen (2008), Box 8.4, for perfect plasticity, where
every return is closed form: the main plane, the right edge (s1 = s2), the left edge (s2 = s3) and the
apex. Each is tried in that order and accepted when its multipliers are non-negative and the
returned stresses keep their order. The apex, s_i = c cot(phi), exists only for phi > 0; no cot(phi)
or 1/sin(phi) appears elsewhere, so phi -> 0 (the undrained footing) stays finite.

An optional tension cut-off s1 <= sigma_t (``tension``; Rankine planes, associated) is returned to with
the Mohr-Coulomb planes as one multi-surface problem where it binds (:meth:`MohrCoulomb._cut_off`).

The consistent tangent d sigma_{n+1} / d(strain increment) is the exact derivative of this return
map within its region, by complex steps (three in-plane strain components): every branch decision is
made on the real part, and the 2 x 2 eigen-decomposition is written in closed form.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ctmrpim.errors import ProblemError

#: Complex-step size for the tangent.
COMPLEX_STEP = 1e-30
#: Relative yield tolerance: a trial state with f <= this x (c + |p|) is elastic.
YIELD_TOL = 1e-10
#: In-plane principal stresses closer than this (relative) are separated by a tiny shear, so that the
#: closed-form eigenvectors (and their complex-step derivatives) stay defined.
EIGEN_GAP = 1e-12

ELASTIC, MAIN, RIGHT, LEFT, APEX, TENSION = 0, 1, 2, 3, 4, 5


@dataclass(frozen=True)
class MohrCoulomb:
    """Mohr-Coulomb elastic-perfectly plastic material in plane strain (module docstring): E, nu, cohesion c,
    friction and dilation angles phi, psi (degrees), density and an optional tension cut-off."""
    E: float
    nu: float
    c: float
    phi: float          # degrees
    psi: float = 0.0    # degrees
    density: float = 0.0
    tension: float | None = None    # tension cut-off sigma_t (largest principal stress), None: none

    def __post_init__(self) -> None:
        for key, ok, allowed in (("E", self.E > 0, "> 0"), ("nu", -1.0 < self.nu < 0.5, "in (-1, 0.5)"),
                                 ("c", self.c >= 0, ">= 0"), ("phi", 0.0 <= self.phi < 90.0, "in [0, 90) degrees"),
                                 ("psi", 0.0 <= self.psi <= self.phi, f"in [0, phi] = [0, {self.phi:g}] degrees"),
                                 ("density", self.density >= 0, ">= 0")):
            if not ok:
                raise ProblemError(f"{getattr(self, key)!r} is out of range: it must be {allowed}",
                                   key=f"material.{key}")
        if self.tension is not None and not self.tension >= 0:
            raise ProblemError(f"{self.tension!r} must be >= 0 (a tensile strength)", key="material.tension")
        if self.c == 0 and self.phi == 0:
            raise ProblemError("c = 0 and phi = 0: the material has no strength", key="material.c")

    @property
    def G(self) -> float:
        """Shear modulus E / (2 (1 + nu))."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def K(self) -> float:
        """Bulk modulus E / (3 (1 - 2 nu))."""
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    def D(self, plane: str = "strain") -> np.ndarray:
        """(3, 3) elasticity matrix relating (exx, eyy, gxy) to (sxx, syy, sxy)."""
        from ctmrpim.materials.linear_elastic import LinearElastic
        return LinearElastic(self.E, self.nu, self.density).D(plane)

    def yield_function(self, stress: np.ndarray) -> np.ndarray:
        """f at stresses (m, 4) = sxx, syy, sxy, szz."""
        s, _ = _principal(stress)
        sp = np.sin(np.radians(self.phi))
        return (s[:, 0] - s[:, 2]) + (s[:, 0] + s[:, 2]) * sp - 2.0 * self.c * np.cos(np.radians(self.phi))

    def update(self, stress: np.ndarray, dstrain: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Stress (m, 4) after the strain increment ``dstrain`` (m, 3: exx, eyy, gxy; ezz = 0) from
        ``stress`` (m, 4), and the return region of each point (ELASTIC, MAIN, RIGHT, LEFT, APEX)."""
        return self._update(stress, dstrain)

    def tangent(self, stress: np.ndarray, dstrain: np.ndarray) -> np.ndarray:
        """(m, 3, 3) consistent tangent d(sxx, syy, sxy)_{n+1} / d(exx, eyy, gxy)."""
        m = len(stress)
        out = np.empty((m, 3, 3))
        dc = dstrain.astype(complex)
        for k in range(3):
            dc[:, k] += 1j * COMPLEX_STEP
            s, _ = self._update(stress, dc)
            out[:, :, k] = s[:, :3].imag / COMPLEX_STEP
            dc[:, k] = dstrain[:, k]
        return out

    # ----------------------------------------------------------------------------------------------
    def _update(self, stress: np.ndarray, dstrain: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        G, K = self.G, self.K
        lam = K - 2.0 * G / 3.0
        e = dstrain
        tr = e[:, 0] + e[:, 1]
        trial = np.stack([stress[:, 0] + lam * tr + 2.0 * G * e[:, 0],
                          stress[:, 1] + lam * tr + 2.0 * G * e[:, 1],
                          stress[:, 2] + G * e[:, 2],
                          stress[:, 3] + lam * tr], axis=1)
        out = trial.copy()
        region = np.zeros(len(stress), dtype=np.int8)
        s, vec = _principal(trial)
        sphi, cphi = np.sin(np.radians(self.phi)), np.cos(np.radians(self.phi))
        spsi = np.sin(np.radians(self.psi))
        f = (s[:, 0] - s[:, 2]) + (s[:, 0] + s[:, 2]) * sphi - 2.0 * self.c * cphi
        scale = self.c + np.abs(s.real).max(axis=1)
        plastic = f.real > YIELD_TOL * scale
        if not plastic.any():
            return self._cut_off(trial, out, region)
        s, vec, f = s[plastic], tuple(v[plastic] for v in vec), f[plastic]
        ret = np.empty_like(s)
        reg = np.zeros(len(s), dtype=np.int8)
        # main plane
        a = 4.0 * G * (1.0 + sphi * spsi / 3.0) + 4.0 * K * sphi * spsi
        r1 = 2.0 * G * (1.0 + spsi / 3.0) + 2.0 * K * spsi          # dg/ds1 stiffness terms
        r2 = (4.0 * G / 3.0 - 2.0 * K) * spsi
        r3 = 2.0 * G * (1.0 - spsi / 3.0) - 2.0 * K * spsi
        dg = f / a
        main = np.stack([s[:, 0] - r1 * dg, s[:, 1] + r2 * dg, s[:, 2] + r3 * dg], axis=1)
        ok = (main[:, 0].real >= main[:, 1].real) & (main[:, 1].real >= main[:, 2].real)
        ret[ok], reg[ok] = main[ok], MAIN
        todo = ~ok
        if todo.any():
            right = todo & (main[:, 1].real > main[:, 0].real)      # s2 passed s1: the edge s1 = s2
            left = todo & ~right                                    # s3 passed s2: the edge s2 = s3
            fa = f
            if right.any():
                fb = (s[:, 1] - s[:, 2]) + (s[:, 1] + s[:, 2]) * sphi - 2.0 * self.c * cphi
                b = 2.0 * G * (1.0 - sphi - spsi - sphi * spsi / 3.0) + 4.0 * K * sphi * spsi
                det = a * a - b * b
                ga, gb = (a * fa - b * fb) / det, (a * fb - b * fa) / det
                edge = np.stack([s[:, 0] - r1 * ga + r2 * gb, s[:, 1] + r2 * ga - r1 * gb,
                                 s[:, 2] + r3 * (ga + gb)], axis=1)
                good = right & (ga.real >= 0) & (gb.real >= 0) & (edge[:, 1].real >= edge[:, 2].real)
                ret[good], reg[good] = edge[good], RIGHT
                todo &= ~good
            if left.any():
                fb = (s[:, 0] - s[:, 1]) + (s[:, 0] + s[:, 1]) * sphi - 2.0 * self.c * cphi
                b = 2.0 * G * (1.0 + sphi + spsi - sphi * spsi / 3.0) + 4.0 * K * sphi * spsi
                det = a * a - b * b
                ga, gb = (a * fa - b * fb) / det, (a * fb - b * fa) / det
                edge = np.stack([s[:, 0] - r1 * (ga + gb), s[:, 1] + r2 * ga + r3 * gb,
                                 s[:, 2] + r3 * ga + r2 * gb], axis=1)
                good = left & (ga.real >= 0) & (gb.real >= 0) & (edge[:, 0].real >= edge[:, 1].real)
                ret[good], reg[good] = edge[good], LEFT
                todo &= ~good
            if todo.any():
                if sphi <= 0.0:
                    raise ProblemError("Mohr-Coulomb return: a stress state beyond both edges with phi = 0 "
                                       "(no apex); the strain increment is too large")
                apex = self.c * cphi / sphi
                ret[todo], reg[todo] = apex, APEX
        sigma = _assemble(ret, vec)
        out[plastic] = sigma
        region[plastic] = reg
        return self._cut_off(trial, out, region)

    def _cut_off(self, trial: np.ndarray, out: np.ndarray, region: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The tension cut-off s1 <= sigma_t on top of the Mohr-Coulomb return. Where the Mohr-Coulomb
        answer (or the elastic trial) breaks it, the return is redone from the trial with the tension
        planes active (Rankine, associated: s_i = sigma_t, i = 1 [, 2 [, 3]]) alone or together with
        the main plane and one of its edges: the candidate active sets are tried with the fewest planes
        first, each a small linear system in principal space (the surfaces are planes and the elasticity
        is linear), and the first whose multipliers are non-negative, whose stresses keep their order
        and satisfy every surface is taken (the multi-surface return of Simo & Hughes, Sec. 5.3)."""
        if self.tension is None:
            return out, region
        s_out, _ = _principal(out)
        broken = s_out[:, 0].real > self.tension + YIELD_TOL * (self.c + np.abs(s_out.real).max(axis=1))
        if not broken.any():
            return out, region
        s, vec = _principal(trial[broken])
        ret, reg = _multi_surface_return(s, self._planes(), self.G, self.K)
        out[broken] = _assemble(ret, vec)
        region[broken] = reg
        return out, region

    def _planes(self) -> dict[str, tuple[np.ndarray, np.ndarray, float]]:
        """Yield planes a . s = k in principal space with their flow directions b: (a, b, k)."""
        sp_, cp = np.sin(np.radians(self.phi)), np.cos(np.radians(self.phi))
        sq = np.sin(np.radians(self.psi))
        two_c = 2.0 * self.c * cp
        e = np.eye(3)
        return {"main": (np.array([1 + sp_, 0, -(1 - sp_)]), np.array([1 + sq, 0, -(1 - sq)]), two_c),
                "right": (np.array([0, 1 + sp_, -(1 - sp_)]), np.array([0, 1 + sq, -(1 - sq)]), two_c),
                "left": (np.array([1 + sp_, -(1 - sp_), 0]), np.array([1 + sq, -(1 - sq), 0]), two_c),
                "t1": (e[0], e[0], self.tension), "t2": (e[1], e[1], self.tension), "t3": (e[2], e[2], self.tension)}


def elastic_strain(material: "MohrCoulomb", stress: np.ndarray) -> np.ndarray:
    """(m, 4) C sigma (xx, yy, xy tensor, zz) with the isotropic compliance, of stresses (m, 4)."""
    E, nu = material.E, material.nu
    trace = stress[:, 0] + stress[:, 1] + stress[:, 3]
    return ((1.0 + nu) * stress - nu * trace[:, None] * np.array([1.0, 1.0, 0.0, 1.0])) / E


def plastic_strain_increment(material: "MohrCoulomb", dstrain: np.ndarray, dstress: np.ndarray) -> np.ndarray:
    """(m, 4) plastic strain increment (xx, yy, xy tensor, zz): the total increment (ezz = 0 in plane
    strain) less the elastic one, C dsigma."""
    total = np.c_[dstrain[:, 0], dstrain[:, 1], 0.5 * dstrain[:, 2], np.zeros(len(dstrain))]
    return total - elastic_strain(material, dstress)


def equivalent_plastic_strain(plastic_strain: np.ndarray) -> np.ndarray:
    """sqrt(2/3 e:e) of the deviatoric part e of a plastic strain (m, 4: xx, yy, xy tensor, zz)."""
    mean = (plastic_strain[:, 0] + plastic_strain[:, 1] + plastic_strain[:, 3]) / 3.0
    dev = plastic_strain[:, [0, 1, 3]] - mean[:, None]
    return np.sqrt(2.0 / 3.0 * ((dev ** 2).sum(axis=1) + 2.0 * plastic_strain[:, 2] ** 2))


#: Active sets tried, fewest planes first, where the tension cut-off is broken (one tension plane at least).
CUT_OFF_SETS = (("t1",), ("main", "t1"), ("t1", "t2"), ("main", "right", "t1"), ("main", "left", "t1"),
                ("main", "t1", "t2"), ("t1", "t2", "t3"))


def _multi_surface_return(s: np.ndarray, planes: dict, G: float, K: float) -> tuple[np.ndarray, np.ndarray]:
    """Return sorted principal trial stresses (m, 3) onto the intersection of the planes of the first
    admissible active set of CUT_OFF_SETS: s = s_trial - sum_k gamma_k D b_k with a_j . s = k_j on the
    active planes, gamma >= 0, every plane satisfied and s1 >= s2 >= s3. Complex-step safe."""
    lam = K - 2.0 * G / 3.0
    D = lam * np.ones((3, 3)) + 2.0 * G * np.eye(3)
    a_all = np.array([p[0] for p in planes.values()])
    k_all = np.array([p[2] for p in planes.values()])
    ret = s.copy()
    reg = np.full(len(s), TENSION, dtype=np.int8)
    todo = np.ones(len(s), dtype=bool)
    scale = 1.0 + np.abs(s.real).max(axis=1)
    for active in CUT_OFF_SETS:
        if not todo.any():
            break
        a = np.array([planes[n][0] for n in active])                     # (q, 3)
        Db = np.array([D @ planes[n][1] for n in active])               # (q, 3)
        k = np.array([planes[n][2] for n in active])
        A = a @ Db.T                                                     # (q, q): a_j . D b_l
        gamma = (s[todo] @ a.T - k) @ np.linalg.inv(A).T                 # (t, q)
        cand = s[todo] - gamma @ Db
        tol = 1e-9 * scale[todo]
        ok = ((gamma.real >= -1e-12 * scale[todo, None]).all(axis=1)
              & ((cand.real @ a_all.T - k_all) <= tol[:, None]).all(axis=1)
              & (cand[:, 0].real >= cand[:, 1].real - tol) & (cand[:, 1].real >= cand[:, 2].real - tol))
        idx = np.flatnonzero(todo)[ok]
        ret[idx] = cand[ok]
        todo[idx] = False
    if todo.any():
        raise ProblemError("Mohr-Coulomb with tension cut-off: no admissible return for a trial stress "
                           f"(e.g. principal {s[np.flatnonzero(todo)[0]].real}); the strain increment is too large")
    return ret, reg


def _principal(stress: np.ndarray):
    """Principal stresses (m, 3) sorted s1 >= s2 >= s3 (by real part) and what rebuilds the tensor:
    the in-plane unit eigenvector of the larger in-plane value and which sorted slot holds szz."""
    sxx, syy, sxy, szz = stress[:, 0], stress[:, 1], stress[:, 2], stress[:, 3]
    centre = 0.5 * (sxx + syy)
    half = 0.5 * (sxx - syy)
    gap = np.abs(half.real) + np.abs(sxy.real)
    tiny = EIGEN_GAP * (np.abs(centre.real) + gap + 1e-300)
    sxy = np.where(gap < tiny, sxy + tiny, sxy)
    radius = np.sqrt(half * half + sxy * sxy)
    big, small = centre + radius, centre - radius
    # eigenvector of `big`: (cos t, sin t) with tan 2t = 2 sxy / (sxx - syy)
    nx, ny = radius + half, sxy
    norm = np.sqrt(nx * nx + ny * ny)
    flip = np.abs(norm.real) < 1e-300                       # sxx < syy with sxy ~ 0: the y axis
    nx = np.where(flip, 0.0, nx / np.where(flip, 1.0, norm))
    ny = np.where(flip, 1.0, ny / np.where(flip, 1.0, norm))
    # slot of szz among the three sorted values
    zslot = np.where(szz.real >= big.real, 0, np.where(szz.real >= small.real, 1, 2))
    s = np.empty((len(stress), 3), dtype=np.result_type(stress.dtype, big.dtype))
    s[:, 0] = np.where(zslot == 0, szz, big)
    s[:, 1] = np.where(zslot == 0, big, np.where(zslot == 1, szz, small))
    s[:, 2] = np.where(zslot == 2, szz, small)
    return s, (nx, ny, zslot)


def _assemble(s: np.ndarray, vec) -> np.ndarray:
    """Stress (m, 4) from sorted principal values and the eigen-structure of :func:`_principal`."""
    nx, ny, zslot = vec
    szz = s[np.arange(len(s)), zslot]
    big = np.where(zslot == 0, s[:, 1], s[:, 0])
    small = np.where(zslot == 2, s[:, 1], s[:, 2])
    sxx = big * nx * nx + small * ny * ny
    syy = big * ny * ny + small * nx * nx
    sxy = (big - small) * nx * ny
    return np.stack([sxx, syy, sxy, szz], axis=1)
