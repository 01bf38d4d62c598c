"""Stable time step of the central-difference scheme (Section 2.1.4; docs/design.md, 'Explicit dynamics').

Central differences are stable for dt <= 2 / omega_max, omega_max^2 the largest eigenvalue of
M^-1 K (lumped mass, elastic stiffness). omega_max is estimated by LOBPCG with the elastic
internal-force operator of the current configuration (one gradient and one transposed product per
iteration, no matrix assembled), started at each rebuild from the last estimate's vector plus a fresh
checkerboard (:func:`warm_start`); the step is dt = cfl x 2 / omega_max (cfl = 0.5 covers the estimate's
shortfall, plasticity and contact), shortened by the stiffness-proportional damping where there is one
(:func:`stable_step`).
The textbook bound 0.4 d_min / c_p (c_p the P-wave speed) is reported beside it. The explicit run
recomputes the step on its frame at every rebuild (:class:`TimeStepping`).

Why the estimate is sound: with the paper's CTM (the only scheme of explicit analyses) the operator
K = G^T W C G is symmetric positive semi-definite (the same gradients G test and trial, C the elasticity
tensor with its symmetries), so M^-1/2 K M^-1/2 has real, non-negative eigenvalues and the Rayleigh quotient
rises to omega_max^2 (measured on the quick column: asymmetry 8e-17, omega_max 4696.91 rad/s from 30 LOBPCG
steps against 4696.93 from the eigenvalues; 30 power iterations gave 4680). The corrected test gradients of
``ctm-vci`` would make it non-symmetric (asymmetry 1.5e-2, eigenvalues with imaginary parts up to 1.1e-4 of the
largest): one of the reasons explicit analyses integrate with ``ctm`` (:mod:`ctmrpim.solvers.explicit.run`).
"""
from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np
from scipy.sparse.linalg import LinearOperator, lobpcg
from scipy.spatial import cKDTree

from ctmrpim.discretisation.configuration import Configuration

#: LOBPCG steps of the first estimate, and of the later ones (warm-started from the last vector: the
#: stiffest mode changes little between rebuilds).
ITERATIONS = 30
WARM_ITERATIONS = 10
#: free dofs below which the operator's matrix is built and its eigenvalues taken instead
DENSE_BELOW = 64


def omega_max(stiffness: Callable[[np.ndarray], np.ndarray], mass: np.ndarray, start: np.ndarray,
              free: np.ndarray | None = None, iterations: int = ITERATIONS) -> tuple[float, np.ndarray]:
    """Largest circular frequency of M^-1 K and its vector, by ``iterations`` steps of LOBPCG (scipy) on the
    symmetric M^-1/2 K M^-1/2 from ``start``: its Ritz value is a Rayleigh quotient, a lower bound that rises to
    omega_max^2, and each step costs one product with K like a power iteration's, but the three-vector
    Rayleigh-Ritz step converges where the power iteration stalls on a cluster of stiff modes. ``stiffness`` maps
    nodal displacements (n, 2) to forces (n, 2), ``mass`` is (n,), ``free`` (n, 2) bool masks fixed dofs out."""
    root = np.sqrt(mass)[:, None]
    mask = np.ones_like(start, bool) if free is None else free
    dofs = np.flatnonzero(mask.ravel())

    def apply(block: np.ndarray) -> np.ndarray:
        out = np.empty_like(block)
        z = np.zeros(start.size)
        for j in range(block.shape[1]):
            z[dofs] = block[:, j]
            out[:, j] = (stiffness(z.reshape(-1, 2) / root) / root).ravel()[dofs]
        return out

    if dofs.size < DENSE_BELOW:        # LOBPCG needs five times its block; a small body's matrix is cheap to build
        lam, vec = np.linalg.eigh(apply(np.eye(dofs.size)))
        lam, vec = lam[-1:], vec[:, -1:]
    else:
        operator = LinearOperator((dofs.size, dofs.size), matvec=lambda v: apply(v.reshape(-1, 1))[:, 0],
                                  matmat=apply, dtype=float)
        x0 = (start * root).ravel()[dofs]
        with warnings.catch_warnings():    # a fixed number of steps: "not reaching the requested tolerance" is expected
            warnings.simplefilter("ignore", UserWarning)
            lam, vec = lobpcg(operator, (x0 / np.linalg.norm(x0))[:, None], largest=True, tol=1e-12,
                              maxiter=iterations)
    mode = np.zeros(start.size)
    mode[dofs] = vec[:, 0]
    return float(np.sqrt(max(float(lam[0]), 0.0))), mode.reshape(-1, 2) / root


def stable_step(omega: float, cfl: float, beta: float = 0.0) -> float:
    """cfl x the stable step of central differences for the highest mode omega with stiffness-proportional
    damping beta (s), whose damping ratio there is z = beta omega / 2: 2 / omega (sqrt(1 + z^2) - z)."""
    zeta = 0.5 * beta * omega
    return cfl * 2.0 / omega * (float(np.sqrt(1.0 + zeta * zeta)) - zeta)


def checkerboard(points: np.ndarray, d_c: float) -> np.ndarray:
    """(n, 2) a start vector rich in the highest mode at nodes ``points`` (n, 2): neighbouring nodes move in
    opposite directions."""
    parity = (np.floor(points[:, 0] / d_c + 0.5) + np.floor(points[:, 1] / d_c + 0.5)) % 2
    sign = 1.0 - 2.0 * parity
    return np.c_[sign, -sign] + 1e-3 * np.c_[np.cos(points[:, 0] / d_c), np.sin(points[:, 1] / d_c)]


def warm_start(mode: np.ndarray, fresh: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """(n, 2) the start of a later estimate: the last stiffest ``mode`` plus a ``fresh`` start vector
    (:func:`checkerboard`), each of unit mass-weighted norm. Why both: the last mode alone holds almost nothing of a
    stiffer mode that has since grown elsewhere (two nodes squeezed together), and a few iterations from it miss it;
    the checkerboard has every node's neighbours moving against each other. Measured at the 157 rebuilds of a
    496-node collapse against the largest eigenvalue (ARPACK), with WARM_ITERATIONS power iterations (the estimator
    of then): from the last mode alone down to 0.653 of omega_max, from this start down to 0.842 (medians 1.000
    both); LOBPCG from this start, down to 0.972 (:func:`omega_max`)."""
    unit = lambda z: z / max(float(np.sqrt(mass @ np.einsum("nd,nd->n", z, z))), 1e-300)
    return unit(mode) + unit(fresh)


def wave_speed_step(d_min: float, E: float, nu: float, density: float, factor: float = 0.4) -> float:
    """factor x d_min / c_p, with the plane-strain P-wave modulus."""
    modulus = E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))
    return factor * d_min / float(np.sqrt(modulus / density))


def smallest_spacing(x: np.ndarray) -> float:
    """The smallest distance between two of the nodes x (n, 2): d_min of :func:`wave_speed_step`."""
    d, _ = cKDTree(x).query(x, k=2)
    return float(d[:, 1].min())


class TimeStepping:
    """The stable step of an :class:`~ctmrpim.solvers.explicit.run.ExplicitRun` on its current frame (a mixin
    of it: reads the run's ``settings``, ``D``, ``mass``, ``movable`` and ``frame``; sets ``omega``, ``mode``
    (the estimate's vector, its next start), ``dt`` and ``dt_range``)."""

    def _stiffness(self, frame: Configuration) -> Callable[[np.ndarray], np.ndarray]:
        """d (n, 2) -> elastic small-strain force K d (n, 2) on the frame (for the time step)."""
        def apply(d: np.ndarray) -> np.ndarray:
            L = frame.gradient(d)
            eps = np.c_[L[:, 0] - 1.0, L[:, 3] - 1.0, L[:, 1] + L[:, 2]]
            s = eps @ self.D.T
            return frame.force(np.c_[s[:, 0], s[:, 2], s[:, 2], s[:, 1]])
        return apply

    def _time_step(self) -> None:
        """omega_max on the current frame (after the first, started from ``mode`` plus the checkerboard) and the
        step from it."""
        s = self.settings
        first = not np.isfinite(self.dt_range[0])
        start = self.mode if first else warm_start(self.mode, checkerboard(self.X, self.d_c), self.mass)
        omega, self.mode = omega_max(self._stiffness(self.frame), self.mass, start, self.movable,
                                     ITERATIONS if first else WARM_ITERATIONS)
        self.omega = omega
        self.dt = float(s.dt) if s.dt != "cfl" else stable_step(omega, s.cfl, s.viscosity)
        self.dt_range = [min(self.dt_range[0], self.dt), max(self.dt_range[1], self.dt)]
