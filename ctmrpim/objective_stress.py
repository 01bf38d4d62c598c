"""Objective stress updates of the updated-Lagrangian path (Section 2.1.3; DESIGN.md "Updated Lagrangian").

An increment moves the body from the configuration x_n (the last rebuild, where the gradients live)
to x_{n+1} = x_n + du. At each integration point, with L = d(du)/dx_n and the relative deformation
gradient f = I + L:

* :class:`HypoelasticUpdate` (a rate law, the one plasticity will use): the midpoint gradient
  G = L (I + L/2)^-1 gives the strain increment de = sym G and the spin dW = skew G; the
  Hughes-Winget rotation Q = (I - dW/2)^-1 (I + dW/2) rotates the old stress,

      sigma_{n+1} = Q sigma_n Q^T + D de.

  For a rigid rotation increment f = R, G = 2 (R - I)(R + I)^-1 is exactly skew (de = 0) and Q = R
  exactly, so a rigid rotation in any number of increments leaves a stress-free body stress-free and
  turns a pre-stressed body's stress with it, to round-off. The stress state is Cauchy
  (sxx, syy, sxy, szz); szz follows the plane-strain increment (zero in plane stress).
* :class:`LeftCauchyGreenUpdate` (neo-Hookean in updated form): the state is the left Cauchy-Green
  tensor, b_{n+1} = f b_n f^T, and the stress the hyperelastic one of b; objective by construction.
  b is transferred across rebuilds like any state; it is I plus strain-sized terms in the current
  frame, where the total deformation gradient F also carries the O(1) rotation, which varies along
  a bent beam. (Transferring F instead gave the same end-moment results to within their scatter;
  recovering F from the nodes' reference positions, (dX/dx)^-1 on the new cloud, is not the
  gradient of the discrete field and was dropped: it moved the end-moment tip by up to 0.03 L.)

Both return the first Piola-Kirchhoff stress relative to x_n, P_n = det f sigma f^-T, so the internal
force and tangent are the total-Lagrangian operators on x_n (:mod:`ctmrpim.lagrangian_operators`).
Every formula here is analytic in f, so the consistent tangent dP_n/df, the geometric (initial-stress)
part included, comes exactly from four complex steps (:func:`complex_step_tangent`).
"""
from __future__ import annotations

import numpy as np

from .errors import ProblemError
from .hyperelastic import NeoHookean

#: Complex-step size: the derivative is exact to round-off for any h this small (no subtraction).
COMPLEX_STEP = 1e-30


def det2(a: np.ndarray) -> np.ndarray:
    return a[:, 0, 0] * a[:, 1, 1] - a[:, 0, 1] * a[:, 1, 0]


def inv2(a: np.ndarray) -> np.ndarray:
    """Inverses of (m, 2, 2) matrices by the explicit formula (analytic: complex steps pass through)."""
    adj = np.stack([np.stack([a[:, 1, 1], -a[:, 0, 1]], -1), np.stack([-a[:, 1, 0], a[:, 0, 0]], -1)], 1)
    return adj / det2(a)[:, None, None]


def hughes_winget(f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Strain increment de = sym G and rotation Q = (I - dW/2)^-1 (I + dW/2), G = L (I + L/2)^-1."""
    eye = np.eye(2)[None]
    L = f - eye
    G = L @ inv2(eye + 0.5 * L)
    de = 0.5 * (G + G.transpose(0, 2, 1))
    half_w = 0.25 * (G - G.transpose(0, 2, 1))
    return de, inv2(eye - half_w) @ (eye + half_w)


def check_orientation(f: np.ndarray) -> np.ndarray:
    """det f, or a ProblemError naming the first point where the increment inverts the material."""
    J = det2(f.real)
    if np.any(J <= 0):
        i = int(np.argmin(J))
        raise ProblemError(f"det f = {J[i]:.3g} <= 0 at integration point #{i}: the increment inverts the "
                           "material; use more load steps")
    return J


class HypoelasticUpdate:
    """Linear elastic rate law, Hughes-Winget objective (state: Cauchy sxx, syy, sxy, szz)."""

    n_state = 4

    def __init__(self, D: np.ndarray, plane: str):
        self.D = np.asarray(D, float)
        # szz increment in plane strain: lambda (de_xx + de_yy) = D[0, 1] (de_xx + de_yy)
        self.zz = self.D[0, 1] if plane == "strain" else 0.0

    def initial(self, m: int) -> np.ndarray:
        return np.zeros((m, 4))

    def _update(self, f: np.ndarray, state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        de, Q = hughes_winget(f)
        s0 = np.empty((len(state), 2, 2), dtype=state.dtype)
        s0[:, 0, 0], s0[:, 1, 1] = state[:, 0], state[:, 1]
        s0[:, 0, 1] = s0[:, 1, 0] = state[:, 2]
        eps = np.stack([de[:, 0, 0], de[:, 1, 1], 2.0 * de[:, 0, 1]], -1)   # engineering shear
        ds = eps @ self.D.T
        sig = Q @ s0 @ Q.transpose(0, 2, 1)
        sig[:, 0, 0] += ds[:, 0]
        sig[:, 1, 1] += ds[:, 1]
        sig[:, 0, 1] += ds[:, 2]
        sig[:, 1, 0] += ds[:, 2]
        szz = state[:, 3] + self.zz * (de[:, 0, 0] + de[:, 1, 1])
        return sig, szz

    def first_piola(self, f: np.ndarray, state: np.ndarray) -> np.ndarray:
        sig, _ = self._update(f, state)
        return det2(f)[:, None, None] * sig @ inv2(f).transpose(0, 2, 1)

    def advance(self, f: np.ndarray, state: np.ndarray) -> np.ndarray:
        check_orientation(f)
        sig, szz = self._update(f, state)
        return np.c_[sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1], szz]

    def cauchy(self, state: np.ndarray) -> np.ndarray:
        """(m, 3) sxx, syy, sxy."""
        return state[:, :3].copy()


class LeftCauchyGreenUpdate:
    """Neo-Hookean in updated form (state: the left Cauchy-Green tensor b = F F^T, xx, yy, xy).

    b_{n+1} = f b_n f^T; Kirchhoff stress tau = mu (b - I) + lambda ln J I with J = sqrt(det b), the
    same material as :class:`ctmrpim.hyperelastic.NeoHookean` (plane strain, F33 = 1)."""

    n_state = 3

    def __init__(self, material: NeoHookean):
        self.material = material

    def initial(self, m: int) -> np.ndarray:
        return np.tile([1.0, 1.0, 0.0], (m, 1))

    @staticmethod
    def _b(state: np.ndarray) -> np.ndarray:
        b = np.empty((len(state), 2, 2), dtype=state.dtype)
        b[:, 0, 0], b[:, 1, 1] = state[:, 0], state[:, 1]
        b[:, 0, 1] = b[:, 1, 0] = state[:, 2]
        return b

    def _cauchy(self, b: np.ndarray) -> np.ndarray:
        J = np.sqrt(det2(b))
        mu, lam = self.material.mu, self.material.lam
        tau = mu * (b - np.eye(2)[None]) + (lam * np.log(J))[:, None, None] * np.eye(2)[None]
        return tau / J[:, None, None]

    def first_piola(self, f: np.ndarray, state: np.ndarray) -> np.ndarray:
        b = f @ self._b(state) @ f.transpose(0, 2, 1)
        return det2(f)[:, None, None] * self._cauchy(b) @ inv2(f).transpose(0, 2, 1)

    def advance(self, f: np.ndarray, state: np.ndarray) -> np.ndarray:
        check_orientation(f)
        b = f @ self._b(state) @ f.transpose(0, 2, 1)
        return np.c_[b[:, 0, 0], b[:, 1, 1], b[:, 0, 1]]

    def cauchy(self, state: np.ndarray) -> np.ndarray:
        sig = self._cauchy(self._b(state))
        return np.c_[sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1]]


def complex_step_tangent(update, f: np.ndarray, state: np.ndarray) -> np.ndarray:
    """(m, 4, 4) A[c, k] = dP_n[c] / df[k], components c, k = 2 i + J, exact to round-off."""
    m = len(f)
    A = np.empty((m, 4, 4))
    fc = f.astype(complex)
    for k in range(4):
        i, J = divmod(k, 2)
        fc[:, i, J] += 1j * COMPLEX_STEP
        A[:, :, k] = update.first_piola(fc, state).reshape(m, 4).imag / COMPLEX_STEP
        fc[:, i, J] = f[:, i, J]
    return A
