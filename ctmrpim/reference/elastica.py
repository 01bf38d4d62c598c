"""Exact large-deflection references for a cantilever: the inextensible Euler elastica.

These are the references for the paper's large-deformation cantilever (Section 3.2, Figs. 13-17:
L = 10 m, W = 1 m, E = 1 GPa, I = W^3/12, tip load P = 100 .. 3000 kN, i.e. lambda = P L^2/(EI)
= 0.12 .. 3.6) and for the ring-closing end moment M = 2 pi E I / L (Eq. 37).  The elastica ignores
axial and shear strain, so it is the thin-beam limit that a 2D continuum solution approaches as
W/L -> 0 (not the continuum answer itself at the paper's W/L = 0.1).

Conventions (all lengths in units of L, arc length s in [0, 1]):

* x along the undeformed beam, y *downward*; theta(s) is the angle of the tangent from the x axis,
  positive clockwise (a downward rotation), so the tangent is (cos theta, sin theta) in (x, y).
* Clamp at s = 0: theta(0) = 0, x(0) = y(0) = 0.  Dead load P downward at the tip.
* Moment balance of the part [s, 1] about the section point (x(s), y(s)) with clockwise-positive
  bending moment EI theta':  EI theta'(s) = P (x_F - x(s)) + M_end, where x_F is the abscissa of the
  load's line of action.  Differentiating (x' = cos theta):  theta'' = -lambda cos(theta).
* Tip results: theta_tip = theta(1); w/L = y(1) (the paper's "theta = w/L"); the horizontal
  shortening u/L = 1 - x(1) (positive, the tip moves towards the root).

Two independent solutions of the tip-force problem are provided, which must agree to 1e-6:

* :func:`tip_load_elliptic`: the classical closed form in elliptic integrals (Bisshopp & Drucker 1945,
  Quart. Appl. Math. 3:272-275; Timoshenko & Gere, Theory of Elastic Stability, 1961, Sec. 2.7;
  Mattiasson 1981, Int. J. Numer. Meth. Eng. 17:145-153), with one scalar root found by brentq.
* :func:`tip_load_bvp`: collocation of the first-order system with scipy.integrate.solve_bvp
  (Kierzenka & Shampine 2001), which also handles the paper's corner-loaded variant (eccentricity).

Derivation of the closed form (kept here because the textbook sketches differ in sign conventions).
With x_F = x(1) and M_end = 0, theta'(1) = 0; multiplying theta'' = -lambda cos theta by theta' and
integrating from s to 1:  theta'^2 = 2 lambda (sin theta0 - sin theta), theta0 = theta(1) > 0, and
theta' >= 0 on [0, 1].  Substitute  1 + sin theta = 2 k^2 sin^2 phi,  k^2 = (1 + sin theta0)/2, so
phi = pi/2 at the tip and sin phi1 = 1/(sqrt(2) k) at the root.  Then sin theta0 - sin theta =
2 k^2 cos^2 phi, cos theta = 2 k sin phi Delta (Delta = sqrt(1 - k^2 sin^2 phi)), and

    ds = d theta / theta' = d phi / (sqrt(lambda) Delta)     =>  sqrt(lambda) = K(k) - F(phi1, k)
    dx = cos theta ds = 2 k sin phi d phi / sqrt(lambda)     =>  x(1) = sqrt(2 sin theta0 / lambda)
    dy = sin theta ds = (1/Delta - 2 Delta) d phi / sqrt(lambda)
                                        =>  y(1) = 1 - 2 (E(k) - E(phi1, k)) / sqrt(lambda)

(x(1) also follows from the root moment: theta'(0) = lambda x(1) and theta'(0)^2 = 2 lambda sin theta0.)
The differences K - F(phi1) and E - E(phi1) cancel badly for small loads (phi1 -> pi/2), so they are
evaluated through the complementary amplitude psi, cot(phi1) cot(psi) = k' = sqrt(1 - k^2) (Legendre's
addition theorem with sum amplitude pi/2, DLMF 19.11.1-19.11.2; also in Byrd & Friedman 1971):
K - F(phi1, k) = F(psi, k) and E - E(phi1, k) = E(psi, k) - k^2 sin(phi1) sin(psi)
(checked against the direct differences in tests/test_elastica.py).  With tan(phi1) = 1/sqrt(sin theta0),
tan(psi) = sqrt(sin theta0)/k', so psi ~ sqrt(2 theta0) -> 0 for small loads and nothing cancels.

Small-load series (derived by expanding theta = lambda theta1 + lambda^3 theta3 + ..., theta1 = s - s^2/2):
theta_tip = lambda/2 - 11 lambda^3/240,  w/L = lambda/3 - 4 lambda^3/105,  u/L = lambda^2/15  (+ h.o.t.).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_bvp
from scipy.optimize import brentq
from scipy.special import ellipeinc, ellipkinc

#: The paper's loads (Section 3.2, Figs. 13-17): P in kN on L = 10 m, W = 1 m, E = 1 GPa, I = W^3/12.
PAPER_LOADS_KN = (100.0, 500.0, 1000.0, 1500.0, 2000.0, 2500.0, 3000.0)
PAPER_L, PAPER_W, PAPER_E = 10.0, 1.0, 1.0e9


def paper_lambda(p_kn: float, L: float = PAPER_L, W: float = PAPER_W, E: float = PAPER_E) -> float:
    """lambda = P L^2 / (E I), I = W^3/12 (unit thickness), for the paper's tip load P in kN."""
    return p_kn * 1e3 * L**2 / (E * W**3 / 12.0)


@dataclass(frozen=True)
class ElasticaTip:
    """Tip of the elastica cantilever (lengths in units of L, angles in radians).

    ``w_over_L`` is the vertical deflection ratio (the paper's theta = w/L in Figs. 14-17),
    ``u_over_L`` the horizontal shortening (L - x_tip)/L.  The shape arrays (arc length ``s``,
    ``x``, ``y`` downward, ``theta``), all in units of L, are filled by :func:`tip_load_bvp` only.
    """

    lam: float
    theta_tip: float
    w_over_L: float
    u_over_L: float
    eccentricity: float = 0.0
    s: np.ndarray | None = field(default=None, repr=False, compare=False)
    x: np.ndarray | None = field(default=None, repr=False, compare=False)
    y: np.ndarray | None = field(default=None, repr=False, compare=False)
    theta: np.ndarray | None = field(default=None, repr=False, compare=False)


def _elliptic_parts(theta0: float) -> tuple[float, float, float, float]:
    """Modulus parameter m = k^2, complementary amplitude psi, sin(phi1), sin(psi) for tip angle theta0."""
    sin0 = np.sin(theta0)
    # 1 - sin(theta0) = 2 sin^2(pi/4 - theta0/2), without cancellation as theta0 -> pi/2
    m1 = np.sin(np.pi / 4 - theta0 / 2) ** 2  # k'^2 = 1 - k^2
    m = (1.0 + sin0) / 2.0
    # tan(phi1) = 1/sqrt(sin theta0), so tan(psi) = 1/(k' tan phi1) = sqrt(sin theta0)/k'
    psi = np.arctan2(np.sqrt(sin0), np.sqrt(m1))
    sin_phi1 = 1.0 / np.sqrt(2.0 * m)
    return m, psi, sin_phi1, np.sin(psi)


def _sqrt_lambda_of(theta0: float) -> float:
    """sqrt(lambda) = K(k) - F(phi1, k) = F(psi, k): increasing from 0 (theta0 = 0) to inf (pi/2)."""
    m, psi, _, _ = _elliptic_parts(theta0)
    return float(ellipkinc(psi, m))


def tip_load_elliptic(lam: float) -> ElasticaTip:
    """Exact tip of a cantilever under a dead tip force, lambda = P L^2/(EI), by elliptic integrals.

    The classical closed form (Bisshopp & Drucker 1945; Timoshenko & Gere 1961, Sec. 2.7; Mattiasson
    1981), derived in the module docstring: the tip angle theta0 solves sqrt(lambda) = K(k) - F(phi1, k),
    k^2 = (1 + sin theta0)/2, sin phi1 = 1/(sqrt(2) k), found by brentq on (0, pi/2) (the left side
    is monotone in theta0 and unbounded at pi/2, so any lambda > 0 has one root); then
    x(1) = sqrt(2 sin theta0/lambda), w/L = 1 - 2 (E(k) - E(phi1, k))/sqrt(lambda).
    Reference for the paper's Section 3.2 (Figs. 13-17), lambda = 0.12 .. 3.6.

    Range and accuracy: any 0 <= lambda <~ 800 (beyond that the tip angle is within 1e-12 of pi/2
    and a ValueError is raised).  All three outputs are accurate to ~1e-13 absolute; for very small
    loads the *relative* accuracy of u/L (~ lambda^2/15, obtained as 1 - x(1)) falls like
    1e-16/lambda^2 and that of w/L like 1e-16/lambda (about 1e-11 and 1e-14 at lambda = 0.01).
    """
    lam = float(lam)
    if not lam > 0.0:
        if lam == 0.0:
            return ElasticaTip(0.0, 0.0, 0.0, 0.0)
        raise ValueError(f"lambda must be >= 0 (the problem is odd in P: flip the sign), got {lam}")
    root = np.sqrt(lam)
    # theta0 <= pi/2 always; the bracket's upper end backs off far enough that F(psi, k) is finite
    hi = np.pi / 2 - 1e-12
    if _sqrt_lambda_of(hi) <= root:
        raise ValueError(f"lambda = {lam} too large for double precision (tip angle within 1e-12 of pi/2)")
    theta0 = brentq(lambda t: _sqrt_lambda_of(t) - root, 0.0, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps,
                    maxiter=200)
    m, psi, sin_phi1, sin_psi = _elliptic_parts(theta0)
    e_diff = ellipeinc(psi, m) - m * sin_phi1 * sin_psi  # E(k) - E(phi1, k)
    w = 1.0 - 2.0 * e_diff / root
    x_tip = np.sqrt(2.0 * np.sin(theta0) / lam)
    return ElasticaTip(lam, float(theta0), float(w), float(1.0 - x_tip))


# ---------------------------------------------------------------------------------------------------
# Collocation (independent of the closed form; also the corner-loaded variant)
# ---------------------------------------------------------------------------------------------------

def _bvp(lam: float, ecc: float, s: np.ndarray, guess: np.ndarray, tol: float):
    """solve_bvp on z = (theta, kappa, x, y) over s in [0, 1] with analytic Jacobians."""

    def fun(_s, z):
        th, ka = z[0], z[1]
        return np.vstack((ka, -lam * np.cos(th), np.cos(th), np.sin(th)))

    def fun_jac(_s, z):
        th = z[0]
        j = np.zeros((4, 4, th.size))
        j[0, 1] = 1.0
        j[1, 0] = lam * np.sin(th)
        j[2, 0] = -np.sin(th)
        j[3, 0] = np.cos(th)
        return j

    def bc(za, zb):
        # clamp: theta = x = y = 0 at the root; tip: EI theta'(L) = P e sin theta(L) (see tip_load_bvp)
        return np.array([za[0], za[2], za[3], zb[1] - lam * ecc * np.sin(zb[0])])

    def bc_jac(za, zb):
        ja = np.zeros((4, 4))
        jb = np.zeros((4, 4))
        ja[0, 0] = ja[1, 2] = ja[2, 3] = 1.0
        jb[3, 1] = 1.0
        jb[3, 0] = -lam * ecc * np.cos(zb[0])
        return ja, jb

    sol = solve_bvp(fun, bc, s, guess, fun_jac=fun_jac, bc_jac=bc_jac, tol=tol, max_nodes=200_000)
    if not sol.success:
        raise RuntimeError(f"solve_bvp failed at lambda = {lam}, e/L = {ecc}: {sol.message}")
    return sol


def tip_load_bvp(lam: float, eccentricity: float = 0.0, n: int = 2001, tol: float = 1e-10,
                 step: float = 0.25) -> ElasticaTip:
    """Tip and shape of the tip-loaded elastica by collocation (scipy.integrate.solve_bvp).

    Solves, in s/L, theta' = kappa, kappa' = -lambda cos theta, x' = cos theta, y' = sin theta with
    theta(0) = x(0) = y(0) = 0 and kappa(1) = lambda (e/L) sin theta(1).  Independent of
    :func:`tip_load_elliptic` (no first integral, no elliptic functions); the two agree to 1e-6.

    ``eccentricity`` = e/L is the paper's corner-loaded variant (Section 3.2: P at the top-right corner
    of the W-deep end section, e = W/2, so e/L = 0.05 for W = 1 m, L = 10 m).  The end section stays
    plane and normal to the axis, so the top corner sits at tip + e (sin theta, -cos theta) in (x, y
    downward): its line of action is e sin theta(1) further from the root than the axis tip.  The
    downward force there exerts about the axis tip a clockwise moment P e sin theta(1), the same
    sense as the bending by P itself, so EI theta'(L) = P e sin theta(L), i.e. theta'(1) =
    lambda (e/L) sin theta(1): a follower-type end moment that increases the deflection.

    Continuation: the solution is continued from lambda = 0 (theta = 0, the straight beam) in steps
    of at most ``step`` in lambda, each solution seeding the next, so Newton always starts close.
    ``n`` nodes on a uniform initial mesh (solve_bvp refines it if needed to meet ``tol``).
    """
    lam = float(lam)
    ecc = float(eccentricity)
    if lam < 0.0:
        raise ValueError(f"lambda must be >= 0, got {lam}")
    s = np.linspace(0.0, 1.0, int(n))
    z = np.vstack((np.zeros_like(s), np.zeros_like(s), s, np.zeros_like(s)))  # straight beam
    if lam > 0.0:
        steps = max(1, int(np.ceil(lam / step)))
        for lam_k in np.linspace(0.0, lam, steps + 1)[1:]:
            sol = _bvp(lam_k, ecc, s, z, tol)
            s, z = sol.x, sol.y
    th, x, y = z[0], z[2], z[3]
    return ElasticaTip(lam, float(th[-1]), float(y[-1]), float(1.0 - x[-1]), ecc,
                       s=s, x=x, y=y, theta=th)


# ---------------------------------------------------------------------------------------------------
# Pure end moment (Eq. 37)
# ---------------------------------------------------------------------------------------------------

def end_moment_tip(m: float) -> tuple[float, float]:
    """Exact tip (x/L, y/L) of a cantilever under an end moment, m = M L/(EI) (clockwise, y downward).

    The curvature is uniform, theta = m s, so the beam is a circular arc of radius L/m:
    x/L = sin(m)/m, y/L = (1 - cos m)/m.  Written with numpy's sinc, x/L = sinc(m/pi) and
    y/L = (m/2) sinc(m/(2 pi))^2, which is exact, has no branch at m = 0 (x -> 1, y -> 0) and
    cancels nothing.  At m = 2 pi (the moment of :func:`ring_moment`, Eq. 37) the arc closes into a
    ring and the tip returns to the root.
    """
    m = float(m)
    return float(np.sinc(m / np.pi)), float(0.5 * m * np.sinc(m / (2.0 * np.pi)) ** 2)


def ring_moment(E: float, I: float, L: float) -> float:
    """End moment M = 2 pi E I / L that rolls the cantilever into a closed ring (paper Eq. 37)."""
    return 2.0 * np.pi * E * I / L
