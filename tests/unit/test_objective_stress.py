"""Objective stress updates (ctmrpim.materials.objective_stress): the explicit step's component algebra
against the matrix forms, Hughes-Winget for rotations, and the complex-step tangent."""
from __future__ import annotations

import numpy as np
import pytest

from ctmrpim.materials.neo_hookean import NeoHookean
from ctmrpim.materials.objective_stress import (
    HypoelasticUpdate,
    LeftCauchyGreenUpdate,
    complex_step_tangent,
    det2,
    det_c,
    first_piola_c,
    hughes_winget,
    hughes_winget_c,
    inv2,
    largest_strain,
    largest_strain_c,
    relative_c,
    rotate_c,
)

E = 1.0e9


def rotation(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


def _matrices(F4: np.ndarray) -> np.ndarray:
    return F4.reshape(-1, 2, 2)


@pytest.fixture
def gradients():
    rng = np.random.default_rng(3)
    return np.tile([1.0, 0.0, 0.0, 1.0], (50, 1)) + 0.2 * rng.standard_normal((50, 4))


def test_component_forms_match_the_matrix_forms(gradients):
    """The explicit step's component algebra is the matrix algebra of objective_stress, to round-off."""
    rng = np.random.default_rng(4)
    F, G = gradients, gradients[::-1].copy()
    Fm, Gm = _matrices(F), _matrices(G)
    stress = rng.standard_normal((50, 4))
    sig = np.zeros((50, 2, 2))
    sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1], sig[:, 1, 0] = stress[:, 0], stress[:, 1], stress[:, 2], stress[:, 2]
    assert np.allclose(det_c(F), det2(Fm))
    P = det2(Fm)[:, None, None] * sig @ inv2(Fm).transpose(0, 2, 1)
    assert np.allclose(first_piola_c(stress, F), P.reshape(-1, 4), atol=1e-13)
    assert np.allclose(relative_c(G, F), (Gm @ inv2(Fm)).reshape(-1, 4), atol=1e-13)
    de, Q = hughes_winget(Fm)
    strain, c, s = hughes_winget_c(F)
    assert np.allclose(strain, np.c_[de[:, 0, 0], de[:, 1, 1], 2 * de[:, 0, 1]], atol=1e-13)
    assert np.allclose(np.stack([c, -s, s, c], axis=1), Q.reshape(-1, 4), atol=1e-13)
    rotated = Q @ sig @ Q.transpose(0, 2, 1)
    r = rotate_c(stress, c, s)
    assert np.allclose(r[:, :3], np.c_[rotated[:, 0, 0], rotated[:, 1, 1], rotated[:, 0, 1]], atol=1e-13)
    assert np.array_equal(r[:, 3], stress[:, 3])
    assert largest_strain_c(F) == pytest.approx(largest_strain(Fm), rel=1e-12)


def test_hughes_winget_of_a_rigid_rotation_is_that_rotation():
    theta = 0.3
    f = np.array([[np.cos(theta), -np.sin(theta), np.sin(theta), np.cos(theta)]])
    strain, c, s = hughes_winget_c(f)
    assert np.abs(strain).max() < 1e-15
    assert (c[0], s[0]) == pytest.approx((np.cos(theta), np.sin(theta)), abs=1e-15)


def test_hughes_winget_is_exact_for_a_rotation_increment() -> None:
    for theta in (1e-3, 0.3, 1.2):
        de, Q = hughes_winget(rotation(theta)[None])
        assert np.abs(de).max() < 1e-15
        assert np.abs(Q[0] - rotation(theta)).max() < 1e-15


@pytest.mark.parametrize("update", [HypoelasticUpdate(NeoHookean(E, 0.3).D("strain"), "strain"),
                                    LeftCauchyGreenUpdate(NeoHookean(E, 0.3))], ids=["hypoelastic", "neo-hookean"])
def test_complex_step_tangent_matches_finite_differences(update) -> None:
    rng = np.random.default_rng(3)
    f = np.eye(2)[None] + 0.05 * rng.standard_normal((8, 2, 2))
    scale = 1.0 if isinstance(update, LeftCauchyGreenUpdate) else E
    state = update.initial(8) + 0.05 * rng.standard_normal((8, update.n_state)) * scale
    A = complex_step_tangent(update, f, state)
    h = 1e-6
    for k in range(4):
        i, J = divmod(k, 2)
        fp, fm = f.copy(), f.copy()
        fp[:, i, J] += h
        fm[:, i, J] -= h
        fd = (update.first_piola(fp, state) - update.first_piola(fm, state)).reshape(8, 4) / (2 * h)
        assert np.abs(A[:, :, k] - fd).max() <= 1e-7 * np.abs(A).max()


def test_neo_hookean_closed_form_tangent_is_the_complex_step_one() -> None:
    """The updated neo-Hookean tangent in closed form against complex steps, from strained states b_n (up to
    30 % strain) and increments of 10 %."""
    update = LeftCauchyGreenUpdate(NeoHookean(E, 0.3))
    rng = np.random.default_rng(5)
    f = np.eye(2)[None] + 0.1 * rng.standard_normal((200, 2, 2))
    F0 = np.eye(2)[None] + 0.1 * rng.standard_normal((200, 2, 2))
    b = F0 @ F0.transpose(0, 2, 1)
    state = np.c_[b[:, 0, 0], b[:, 1, 1], b[:, 0, 1]]
    A, reference = update.tangent(f, state), complex_step_tangent(update, f, state)
    assert np.abs(A - reference).max() <= 1e-12 * np.abs(reference).max()


def test_compiled_component_loops_are_the_numpy_expressions_bit_for_bit(gradients):
    """The compiled loops (objective_stress_kernels) do the numpy forms' arithmetic operation for operation: an
    explicit run gives the same bits as before they were compiled; a gradient that is not finite is no small
    strain (NaN, as numpy's max gives)."""
    F = gradients
    G = gradients[::-1].copy()
    stress = np.random.default_rng(5).standard_normal((50, 4))
    F00, F01, F10, F11 = F.T
    J = F00 * F11 - F01 * F10
    assert np.array_equal(det_c(F), J)
    sxx, syy, sxy = stress[:, 0], stress[:, 1], stress[:, 2]
    assert np.array_equal(first_piola_c(stress, F), np.stack(
        [sxx * F11 - sxy * F01, sxy * F00 - sxx * F10, sxy * F11 - syy * F01, syy * F00 - sxy * F10], axis=1))
    i00, i01, i10, i11 = F11 / J, -F01 / J, -F10 / J, F00 / J
    a00, a01, a10, a11 = G.T
    assert np.array_equal(relative_c(G, F), np.stack(
        [a00 * i00 + a01 * i10, a00 * i01 + a01 * i11, a10 * i00 + a11 * i10, a10 * i01 + a11 * i11], axis=1))
    C00, C11, C01 = F00 ** 2 + F10 ** 2, F01 ** 2 + F11 ** 2, F00 * F01 + F10 * F11
    mean, half = 0.5 * (C00 + C11), np.hypot(0.5 * (C00 - C11), C01)
    big, small = np.sqrt(mean + half), np.sqrt(np.maximum(mean - half, 0.0))
    assert largest_strain_c(F) == max(np.abs(big - 1.0).max(), np.abs(small - 1.0).max())
    assert largest_strain_c(F[:, ::-1][:, ::-1]) == largest_strain_c(F)      # a strided view
    assert largest_strain_c(np.zeros((0, 4))) == 0.0
    bad = F.copy()
    bad[7, 2] = np.nan
    assert np.isnan(largest_strain_c(bad))
    bad[7, 2] = np.inf
    assert np.isnan(largest_strain_c(bad))
