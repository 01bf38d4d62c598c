"""The compiled Mohr-Coulomb point updates (ctmrpim.materials.mohr_coulomb_kernel): the explicit step's, the
small-strain return of the implicit solvers' residuals and the consistent tangent of their Newton iterations."""
from __future__ import annotations

import numpy as np
import pytest

from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import APEX, ELASTIC, LEFT, MAIN, RIGHT, MohrCoulomb, plastic_strain_increment
from ctmrpim.materials.mohr_coulomb_kernel import consistent_tangent, point_update, small_strain_update
from ctmrpim.materials.objective_stress import hughes_winget_c, rotate_c


@pytest.mark.parametrize("c, psi", [(0.0, 0.0), (2.0e3, 10.0)])
def test_compiled_point_update_matches_the_numpy_forms(c, psi):
    """The compiled per-point step is the numpy algebra (Hughes-Winget, rotation, Box 8.4 return, plastic
    strain increment, dissipation) point for point, in every return region, to round-off."""
    material = MohrCoulomb(E=0.84e6, nu=0.3, c=c, phi=19.8, psi=psi, density=2650.0)
    rng = np.random.default_rng(5)
    m = 4000
    p = rng.uniform(-500.0, 4000.0, m)          # some tensile: the apex is reached where c = 0
    stress = np.c_[-p * rng.uniform(0.3, 1.2, m), -p, p * rng.uniform(-0.4, 0.4, m), -p * rng.uniform(0.5, 1.0, m)]
    stress, _ = material.update(stress, np.zeros((m, 3)))          # admissible starting states
    plastic = 1e-3 * rng.standard_normal((m, 4))
    f = np.tile([1.0, 0.0, 0.0, 1.0], (m, 1)) + 10.0 ** rng.uniform(-5, -2, (m, 1)) * rng.standard_normal((m, 4))
    dead = rng.random(m) < 0.02
    w = rng.uniform(0.5, 1.5, m)
    got, got_plastic, region, dissipation, viscous, work = point_update(material, f, stress, plastic, dead, w,
                                                                        np.ones((m, 4)), 2.0)
    assert {ELASTIC, MAIN, RIGHT, LEFT} <= set(region[~dead]) and (c > 0 or APEX in set(region))
    strain, cq, sq = hughes_winget_c(f)
    rotated, rotated_plastic = rotate_c(stress, cq, sq), rotate_c(plastic, cq, sq)
    want, want_region = material.update(rotated, strain)
    dp = plastic_strain_increment(material, strain, want - rotated)
    want[dead], dp[dead], rotated_plastic[dead] = 0.0, 0.0, 0.0
    scale = np.abs(stress).max()
    assert np.abs(got - want).max() < 1e-10 * scale
    assert np.array_equal(region[~dead], want_region[~dead])
    assert np.abs(got_plastic - (rotated_plastic + dp)).max() < 1e-13
    density = 0.5 * ((rotated + want) * dp * [1.0, 1.0, 2.0, 1.0]).sum(axis=1)
    assert dissipation == pytest.approx(w @ density, rel=1e-10, abs=1e-12 * scale)
    D = material.D("strain")          # viscous stress beta D de / dt (beta / dt = 2 here), zz from plane strain
    want_viscous = 2.0 * np.c_[strain @ D.T, D[0, 1] * (strain[:, 0] + strain[:, 1])][:, [0, 1, 2, 3]]
    want_viscous[dead] = 0.0
    assert np.abs(viscous - want_viscous).max() < 1e-12 * np.abs(want_viscous).max()
    # half the work of the old (unit) viscous stress and half of the new one on this step's strain (each viscous
    # stress acts over two half steps in the central-difference ledger)
    both = strain.sum(axis=1) + (want_viscous[:, :3] * strain).sum(axis=1)
    assert work == pytest.approx(0.5 * w[~dead] @ both[~dead], rel=1e-12)


def _admissible_states(material: MohrCoulomb, seed: int, m: int = 5000) -> tuple[np.ndarray, np.ndarray]:
    """m admissible stresses (m, 4), compressive mostly, and strain increments (m, 3) from 1e-6 to 3e-3 that take
    them to every return region (within the edges where phi = 0: a Tresca body has no apex to return to)."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(-500.0, 4e4, m)
    stress = np.c_[-p * rng.uniform(0.3, 1.2, m), -p, p * rng.uniform(-0.4, 0.4, m), -p * rng.uniform(0.5, 1.0, m)]
    stress, _ = material.update(stress, np.zeros((m, 3)))
    de = 10.0 ** rng.uniform(-6, -2.5, (m, 1)) * rng.standard_normal((m, 3))
    return stress, de * (1e-2 if material.phi == 0 else 1.0)


@pytest.mark.parametrize("c, phi, psi", [(0.0, 30.0, 0.0), (2.0e3, 19.8, 10.0), (1.0e4, 30.0, 30.0), (1.0e4, 0.0, 0.0)])
def test_compiled_small_strain_return_matches_the_numpy_form(c, phi, psi):
    """The implicit solvers' compiled return is MohrCoulomb.update point for point, every region (the apex where
    phi > 0), to round-off; beyond both edges with phi = 0 (no apex) it refuses as the numpy form does; the
    tension cut-off is not compiled and says so."""
    material = MohrCoulomb(E=1e7, nu=0.3, c=c, phi=phi, psi=psi, density=2000.0)
    stress, de = _admissible_states(material, seed=11)
    try:
        want, want_region = material.update(stress, de)
    except ProblemError:
        with pytest.raises(ProblemError, match="no apex"):
            small_strain_update(material, stress, de)
        return
    got, region = small_strain_update(material, stress, de)
    assert {ELASTIC, MAIN, RIGHT, LEFT} <= set(region) and (c > 0 or phi == 0 or APEX in set(region))
    assert np.array_equal(region, want_region)
    assert np.abs(got - want).max() < 1e-10 * np.abs(stress).max()
    with pytest.raises(ValueError, match="tension cut-off"):
        small_strain_update(MohrCoulomb(E=1e7, nu=0.3, c=c, phi=phi, psi=psi, density=2000.0, tension=1e3),
                            stress, de)


@pytest.mark.parametrize("c, phi, psi", [(0.0, 30.0, 0.0), (2.0e3, 19.8, 10.0), (1.0e4, 30.0, 30.0), (1.0e4, 0.0, 0.0)])
def test_compiled_consistent_tangent_matches_the_numpy_form(c, phi, psi):
    """The compiled tangent is MohrCoulomb.tangent (the same complex steps) in every return region, to round-off of
    the elastic moduli: D itself where elastic, symmetric on the main plane with associated flow (psi = phi),
    singular at the apex; the tension cut-off is not compiled and says so."""
    material = MohrCoulomb(E=1e7, nu=0.3, c=c, phi=phi, psi=psi, density=2000.0)
    stress, de = _admissible_states(material, seed=3)
    _, region = small_strain_update(material, stress, de)
    assert {ELASTIC, MAIN, RIGHT, LEFT} <= set(region) and (c > 0 or phi == 0 or APEX in set(region))
    got, want = consistent_tangent(material, stress, de), material.tangent(stress, de)
    D = material.D("strain")
    assert np.abs(got - want).max() < 1e-13 * np.abs(D).max()
    assert np.abs(got[region == ELASTIC] - D).max() < 1e-13 * np.abs(D).max()
    if phi == psi:
        main = got[region == MAIN]
        assert np.abs(main - main.transpose(0, 2, 1)).max() < 1e-12 * np.abs(D).max()
    if APEX in set(region):
        assert np.abs(got[region == APEX]).max() < 1e-12 * np.abs(D).max()
    with pytest.raises(ValueError, match="tension cut-off"):
        consistent_tangent(MohrCoulomb(E=1e7, nu=0.3, c=c, phi=phi, psi=psi, density=2000.0, tension=1e3), stress, de)
