"""RPIM shape functions (Eqs. 25-34): the identities they must satisfy, an independent oracle, supports widened
to a minimum node count and singular points dropped."""
from __future__ import annotations

import numpy as np
import pytest
from clouds import cloud
from scipy.interpolate import RBFInterpolator

from ctmrpim.discretisation.rpim import shape_functions
from ctmrpim.errors import ProblemError
from studies.tolerances import entry

ROUNDOFF = entry("roundoff")["max"]


@pytest.fixture(scope="module", params=[0.0, 0.3], ids=["regular", "jittered"])
def setting(request):
    geometry, nodes, d_c = cloud("plate-with-hole", jitter=request.param)
    rng = np.random.default_rng(1)
    x0, y0, x1, y1 = geometry.bounds
    pts = np.c_[rng.uniform(x0, x1, 400), rng.uniform(y0, y1, 400)]
    pts = pts[geometry.distance_outside(pts) == 0]
    return nodes, pts, d_c


@pytest.mark.parametrize("m", [3, 6])
def test_partition_of_unity_and_polynomial_reproduction(setting, m: int) -> None:
    nodes, pts, d_c = setting
    sf = shape_functions(nodes, pts, 4 * d_c, 5.0, m, d_c)
    x, y = nodes[:, 0], nodes[:, 1]
    px, py = pts[:, 0], pts[:, 1]
    fields = [(np.ones_like(x), 1.0, 0.0, 0.0), (x, px, 1.0, 0.0), (y, py, 0.0, 1.0),
              (2 * x - 3 * y + 1, 2 * px - 3 * py + 1, 2.0, -3.0)]
    if m == 6:
        fields += [(x * x, px * px, 2 * px, 0.0), (x * y, px * py, py, px), (y * y, py * py, 0.0, 2 * py)]
    for f, value, dx, dy in fields:
        scale = np.abs(f).max()
        assert np.abs(sf.N @ f - value).max() <= ROUNDOFF * scale
        assert np.abs(sf.dNdx @ f - dx).max() <= ROUNDOFF * scale / d_c
        assert np.abs(sf.dNdy @ f - dy).max() <= ROUNDOFF * scale / d_c


def test_kronecker_delta(setting) -> None:
    nodes, _, d_c = setting
    sel = np.arange(0, len(nodes), 7)
    sf = shape_functions(nodes, nodes[sel], 4 * d_c, 5.0, 3, d_c)
    expected = np.zeros((len(sel), len(nodes)))
    expected[np.arange(len(sel)), sel] = 1.0
    assert np.abs(sf.N.toarray() - expected).max() <= ROUNDOFF


def test_matches_scipy_rbf_interpolator(setting) -> None:
    """eta = 5 with quadratic augmentation is the polyharmonic r^5 interpolant with degree-2 polynomial:
    scipy's RBFInterpolator (kernel 'quintic' = -r^5, same interpolant) on the same support nodes agrees."""
    nodes, pts, d_c = setting
    sf = shape_functions(nodes, pts[:40], 3.5 * d_c, 5.0, 6, d_c)
    rng = np.random.default_rng(2)
    data = rng.standard_normal(len(nodes))
    ours = sf.N @ data
    for i in range(40):
        row = sf.N.getrow(i)
        support = row.indices
        interp = RBFInterpolator(nodes[support], data[support], kernel="quintic", degree=2)
        assert ours[i] == pytest.approx(interp(pts[i:i + 1])[0], abs=1e-8 * np.abs(data).max())


def test_invariant_to_translation_and_scale(setting) -> None:
    nodes, pts, d_c = setting
    a = shape_functions(nodes, pts, 4 * d_c, 5.0, 3, d_c)
    s, shift = 7.5, np.array([100.0, -40.0])
    b = shape_functions(nodes * s + shift, pts * s + shift, 4 * d_c * s, 5.0, 3, d_c * s)
    assert np.abs((a.N - b.N).toarray()).max() <= ROUNDOFF
    assert np.abs((a.dNdx - s * b.dNdx).toarray()).max() <= ROUNDOFF / d_c


def test_fractional_eta_below_two_has_finite_derivatives(setting) -> None:
    nodes, pts, d_c = setting
    sf = shape_functions(nodes, np.concatenate([pts, nodes[:5]]), 4 * d_c, 1.5, 3, d_c)
    assert np.isfinite(sf.dNdx.data).all() and np.isfinite(sf.dNdy.data).all()
    assert np.abs(sf.dNdx @ nodes[:, 0] - 1.0).max() <= 1e3 * ROUNDOFF  # r^1.5 is less well conditioned


def test_support_too_small_names_the_point() -> None:
    _, nodes, d_c = cloud("rectangle")
    with pytest.raises(ProblemError, match=r"point #0 at \(0\.05, 0\.05\).*support radius"):
        shape_functions(nodes, np.array([[0.05, 0.05]]), 0.5 * d_c, 5.0, 3, d_c)


def test_collinear_support_is_singular_error() -> None:
    nodes = np.c_[np.linspace(0, 1, 10), np.zeros(10)]
    with pytest.raises(ProblemError, match="singular"):
        shape_functions(nodes, np.array([[0.5, 0.0]]), 0.5, 5.0, 3, 0.1)


def test_supports_widen_to_min_nodes_and_singular_points_are_dropped():
    from ctmrpim.discretisation.rpim import shape_functions
    rng = np.random.default_rng(0)
    nodes = rng.random((60, 2))
    far = np.array([[3.0, 3.0]])                   # no node within the radius
    with pytest.raises(ProblemError):
        shape_functions(nodes, far, support_radius=0.3, eta=5.0, polynomial_terms=3, scale=0.1)
    sf = shape_functions(nodes, far, support_radius=0.3, eta=5.0, polynomial_terms=3, scale=0.1, min_nodes=12)
    assert sf.support_sizes[0] == 12
    assert sf.N.sum() == pytest.approx(1.0, abs=1e-6)
    # a point whose support nodes are collinear: dropped (empty row) instead of an error
    line = np.c_[np.linspace(0, 1, 8), np.zeros(8)]
    sf = shape_functions(line, np.array([[0.5, 0.01]]), support_radius=2.0, eta=5.0, polynomial_terms=3,
                         scale=0.1, drop_singular=True)
    assert list(sf.dropped) == [0] and sf.N.nnz == 0
