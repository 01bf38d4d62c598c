"""Neo-Hookean material: objectivity, consistent tangent, small-strain limit."""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from verify import check

from ctmrpim.materials.neo_hookean import NeoHookean

MAT = NeoHookean(E=2.0e5, nu=0.3)


def rotation(a: float) -> np.ndarray:
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


@given(st.floats(-np.pi, np.pi))
def test_rigid_rotation_is_stress_free(a: float) -> None:
    P, _ = MAT.stress_tangent(rotation(a)[None])
    check("roundoff", np.abs(P).max() / MAT.E)


@settings(max_examples=30)
@given(st.lists(st.floats(-0.3, 0.3), min_size=4, max_size=4), st.floats(-np.pi, np.pi))
def test_tangent_matches_finite_differences(h: list[float], a: float) -> None:
    F = rotation(a) @ (np.eye(2) + np.array(h).reshape(2, 2))
    if np.linalg.det(F) < 0.3:
        return
    _, A = MAT.stress_tangent(F[None])
    eps = 1e-6
    fd = np.zeros((2, 2, 2, 2))
    for k in range(2):
        for L in range(2):
            dF = np.zeros((2, 2))
            dF[k, L] = eps
            fd[:, :, k, L] = (MAT.stress_tangent((F + dF)[None])[0][0] - MAT.stress_tangent((F - dF)[None])[0][0]) / (2 * eps)
    check("neo-hookean-tangent-fd", np.abs(fd - A[0]).max() / np.abs(A[0]).max())


def test_small_strain_limit_is_linear_elasticity() -> None:
    eps = 1e-7 * np.array([[1.0, 0.4], [0.4, -0.7]])
    P, _ = MAT.stress_tangent((np.eye(2) + eps)[None])
    sig = MAT.D("strain") @ np.array([eps[0, 0], eps[1, 1], 2 * eps[0, 1]])
    check("neo-hookean-small-strain", np.abs(P[0][[0, 1, 0], [0, 1, 1]] - sig).max() / np.abs(sig).max())
