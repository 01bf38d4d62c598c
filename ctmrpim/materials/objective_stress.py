"""Objective stress updates of the updated-Lagrangian path (Section 2.1.3; docs/design.md,
'Updated and total Lagrangian').

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
force and tangent are the total-Lagrangian operators on x_n (:mod:`ctmrpim.discretisation.lagrangian_operators`).
Every formula here is analytic in f, so the consistent tangent dP_n/df, the geometric (initial-stress)
part included, comes exactly from four complex steps (:func:`complex_step_tangent`); each update's ``tangent``
is that, except the neo-Hookean one's, written in closed form (a quarter of the cost).
"""
from __future__ import annotations

import numpy as np

from ctmrpim.errors import ProblemError
from ctmrpim.materials import objective_stress_kernels as kernels
from ctmrpim.materials.neo_hookean import NeoHookean

#: Complex-step size: the derivative is exact to round-off for any h this small (no subtraction).
COMPLEX_STEP = 1e-30


def det2(a: np.ndarray) -> np.ndarray:
    """(m,) determinants of (m, 2, 2) matrices (analytic: complex steps pass through)."""
    return a[:, 0, 0] * a[:, 1, 1] - a[:, 0, 1] * a[:, 1, 0]


def inv2(a: np.ndarray) -> np.ndarray:
    """Inverses of (m, 2, 2) matrices by the explicit formula (analytic: complex steps pass through)."""
    adj = np.stack([np.stack([a[:, 1, 1], -a[:, 0, 1]], -1), np.stack([-a[:, 1, 0], a[:, 0, 0]], -1)], 1)
    return adj / det2(a)[:, None, None]


def hughes_winget(f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Strain increment de = sym G and rotation Q = (I - dW/2)^-1 (I + dW/2), G = L (I + L/2)^-1, each (m, 2, 2),
    of relative deformation gradients f = I + L (m, 2, 2)."""
    eye = np.eye(2)[None]
    L = f - eye
    G = L @ inv2(eye + 0.5 * L)
    de = 0.5 * (G + G.transpose(0, 2, 1))
    half_w = 0.25 * (G - G.transpose(0, 2, 1))
    return de, inv2(eye - half_w) @ (eye + half_w)


def largest_strain(F: np.ndarray) -> float:
    """Largest |principal stretch - 1| over deformation gradients (m, 2, 2) (:func:`largest_strain_c`)."""
    return largest_strain_c(F.reshape(-1, 4))


def check_orientation(f: np.ndarray) -> np.ndarray:
    """(m,) det f of the increments f (m, 2, 2) (real part), or a ProblemError naming the first point where the
    increment inverts the material."""
    J = det2(f.real)
    if np.any(J <= 0):
        i = int(np.argmin(J))
        raise ProblemError(f"det f = {J[i]:.3g} <= 0 at integration point #{i}: the increment inverts the "
                           "material; use more load steps")
    return J


class HypoelasticUpdate:
    """Linear elastic rate law, Hughes-Winget objective (state: Cauchy sxx, syy, sxy, szz)."""

    n_state = 4

    def __init__(self, D: np.ndarray, plane: str) -> None:
        self.D = np.asarray(D, float)
        # szz increment in plane strain: lambda (de_xx + de_yy) = D[0, 1] (de_xx + de_yy)
        self.zz = self.D[0, 1] if plane == "strain" else 0.0

    def initial(self, m: int) -> np.ndarray:
        """(m, 4) the stress-free state of m points."""
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
        """(m, 2, 2) P_n = det f sigma_{n+1} f^-T relative to x_n after the increments f (m, 2, 2) from ``state``
        (m, 4), without the orientation check (analytic in f, for complex steps)."""
        sig, _ = self._update(f, state)
        return det2(f)[:, None, None] * sig @ inv2(f).transpose(0, 2, 1)

    def tangent(self, f: np.ndarray, state: np.ndarray) -> np.ndarray:
        """(m, 4, 4) dP_n / df by complex steps (the Hughes-Winget rotation has no short closed form)."""
        return complex_step_tangent(self, f, state)

    def advance(self, f: np.ndarray, state: np.ndarray) -> np.ndarray:
        """(m, 4) the state sxx, syy, sxy, szz after the increments f (m, 2, 2); a ProblemError where f inverts the
        material."""
        check_orientation(f)
        sig, szz = self._update(f, state)
        return np.c_[sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1], szz]

    def cauchy(self, state: np.ndarray) -> np.ndarray:
        """(m, 3) sxx, syy, sxy."""
        return state[:, :3].copy()


class LeftCauchyGreenUpdate:
    """Neo-Hookean in updated form (state: the left Cauchy-Green tensor b = F F^T, xx, yy, xy).

    b_{n+1} = f b_n f^T; Kirchhoff stress tau = mu (b - I) + lambda ln J I with J = sqrt(det b), the
    same material as :class:`ctmrpim.materials.neo_hookean.NeoHookean` (plane strain, F33 = 1)."""

    n_state = 3

    def __init__(self, material: NeoHookean) -> None:
        self.material = material

    def initial(self, m: int) -> np.ndarray:
        """(m, 3) the undeformed state b = I of m points."""
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
        """(m, 2, 2) P_n = det f sigma_{n+1} f^-T relative to x_n after the increments f (m, 2, 2) from ``state``
        (m, 3), without the orientation check (analytic in f, for complex steps)."""
        b = f @ self._b(state) @ f.transpose(0, 2, 1)
        return det2(f)[:, None, None] * self._cauchy(b) @ inv2(f).transpose(0, 2, 1)

    def tangent(self, f: np.ndarray, state: np.ndarray) -> np.ndarray:
        """(m, 4, 4) A[2 i + J, 2 k + L] = dP_n,iJ / df_kL in closed form. With J_n = sqrt(det b_n) and
        J = det f J_n, P_n = (mu (f b_n - f^-T) + lambda ln J f^-T) / J_n, so

            A_iJkL = (mu delta_ik b_n,LJ + lambda f^-1_Ji f^-1_Lk + (mu - lambda ln J) f^-1_Jk f^-1_Li) / J_n

        (with b_n = I, the total-Lagrangian neo-Hookean tangent); equal to :func:`complex_step_tangent` to
        round-off at a quarter of its cost."""
        b = self._b(state)
        Jn = np.sqrt(det2(b))
        finv = inv2(f)
        mu, lam = self.material.mu, self.material.lam
        lnJ = np.log(det2(f) * Jn)
        A = (mu * np.einsum("ik,pLJ->piJkL", np.eye(2), b)
             + lam * np.einsum("pJi,pLk->piJkL", finv, finv)
             + (mu - lam * lnJ)[:, None, None, None, None] * np.einsum("pJk,pLi->piJkL", finv, finv))
        return (A / Jn[:, None, None, None, None]).reshape(-1, 4, 4)

    def advance(self, f: np.ndarray, state: np.ndarray) -> np.ndarray:
        """(m, 3) b_{n+1} = f b_n f^T (xx, yy, xy) after the increments f (m, 2, 2); a ProblemError where f inverts
        the material."""
        check_orientation(f)
        b = f @ self._b(state) @ f.transpose(0, 2, 1)
        return np.c_[b[:, 0, 0], b[:, 1, 1], b[:, 0, 1]]

    def cauchy(self, state: np.ndarray) -> np.ndarray:
        """(m, 3) Cauchy stress sxx, syy, sxy of the states (m, 3)."""
        sig = self._cauchy(self._b(state))
        return np.c_[sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1]]


def complex_step_tangent(update: HypoelasticUpdate | LeftCauchyGreenUpdate, f: np.ndarray, state: np.ndarray
                         ) -> np.ndarray:
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


# -- component forms for the explicit solver's step -------------------------------------------------
# The explicit solver updates tens of thousands of points every step; numpy's batched 2 x 2 matmul is
# slow for such small matrices, so its step writes the same algebra out in components. A gradient is
# stored (m, 4) as xx, xy, yx, yy (F[:, 1] = dx/dY); a stress or strain tensor (m, 4) as xx, yy, xy, zz.
# The loops of det_c, relative_c, first_piola_c and largest_strain_c are compiled
# (:mod:`ctmrpim.materials.objective_stress_kernels`).
# tests/unit/test_objective_stress.py checks each against the matrix forms above, and the compiled loops
# against the numpy expressions bit for bit.

def _f(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)


def det_c(F: np.ndarray) -> np.ndarray:
    """(m,) det F of gradients F (m, 4: xx, xy, yx, yy)."""
    out = np.empty(len(F))
    kernels.det(_f(F), out)
    return out


def first_piola_c(stress: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(m, 4) P = det F sigma F^-T (xX, xY, yX, yY) of Cauchy stresses (m, 4) at gradients F (m, 4)."""
    out = np.empty((len(F), 4))
    kernels.first_piola(_f(stress), _f(F), out)
    return out


def relative_c(F_new: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(m, 4) f = F_new F^-1."""
    out = np.empty((len(F), 4))
    kernels.relative(_f(F_new), _f(F), out)
    return out


def hughes_winget_components(f00: np.ndarray | float, f01: np.ndarray | float, f10: np.ndarray | float,
                             f11: np.ndarray | float) -> tuple[np.ndarray | float, ...]:
    """The strain increment (exx, eyy, engineering gxy) and the rotation Q = [[c, -s], [s, c]] (c, s) of
    :func:`hughes_winget` from the components of f: G = L (I + L/2)^-1, Q = (I - W/2)^-1 (I + W/2) with
    W = skew G. Arithmetic only, so it serves arrays (:func:`hughes_winget_c`) and, compiled, one point
    at a time (:mod:`ctmrpim.materials.mohr_coulomb_kernel`)."""
    L00, L01, L10, L11 = f00 - 1.0, f01, f10, f11 - 1.0
    A00, A01, A10, A11 = 1.0 + 0.5 * L00, 0.5 * L01, 0.5 * L10, 1.0 + 0.5 * L11
    det = A00 * A11 - A01 * A10
    G00 = (L00 * A11 - L01 * A10) / det
    G01 = (L01 * A00 - L00 * A01) / det
    G10 = (L10 * A11 - L11 * A10) / det
    G11 = (L11 * A00 - L10 * A01) / det
    h = 0.25 * (G01 - G10)                 # W/2 = [[0, h], [-h, 0]]
    scale = 1.0 / (1.0 + h * h)
    return G00, G11, G01 + G10, (1.0 - h * h) * scale, -2.0 * h * scale


def hughes_winget_c(f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`hughes_winget_components` of gradients f (m, 4): the strain increments (m, 3) and (c, s)."""
    e0, e1, e2, c, s = hughes_winget_components(f[:, 0], f[:, 1], f[:, 2], f[:, 3])
    return np.stack([e0, e1, e2], axis=1), c, s


def rotate_components(xx: np.ndarray | float, yy: np.ndarray | float, xy: np.ndarray | float, c: np.ndarray | float,
                      s: np.ndarray | float) -> tuple[np.ndarray | float, np.ndarray | float, np.ndarray | float]:
    """The in-plane components of Q t Q^T for Q = [[c, -s], [s, c]] (arrays or, compiled, scalars)."""
    cc, ss, cs = c * c, s * s, c * s
    return cc * xx - 2.0 * cs * xy + ss * yy, ss * xx + 2.0 * cs * xy + cc * yy, cs * (xx - yy) + (cc - ss) * xy


def rotate_c(state: np.ndarray, c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Q t Q^T of tensors (m, 4: xx, yy, xy, zz) for Q = [[c, -s], [s, c]]; zz unchanged."""
    xx, yy, xy = rotate_components(state[:, 0], state[:, 1], state[:, 2], c, s)
    return np.stack([xx, yy, xy, state[:, 3]], axis=1)


def largest_strain_c(F: np.ndarray) -> float:
    """Largest |principal stretch - 1| over gradients (m, 4), from C = F^T F (NaN where one is not finite)."""
    return float(kernels.largest_strain(_f(F)))
