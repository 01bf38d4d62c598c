"""The positive-weight nodal average (ctmrpim.discretisation.nodal_average) stays within its values' range."""
from __future__ import annotations

import numpy as np

from ctmrpim.discretisation.nodal_average import KernelAverage
from ctmrpim.discretisation.state_transfer import project_to_nodes


def test_a_sharp_non_negative_field_stays_in_range() -> None:
    """A band of plastic strain one point wide on a jittered cloud: the average is a convex combination
    (rows >= 0 summing to 1), reproduces a constant, ignores points of weight 0 and reaches a node farther
    than the radius from every point."""
    rng = np.random.default_rng(3)
    points = rng.uniform(0, 4, (2000, 2))
    weights = rng.uniform(0.5, 1.5, len(points))
    weights[:50] = 0.0
    values = np.where(np.abs(points[:, 0] - points[:, 1]) < 0.05, 1.0 + points[:, 0], 0.0)
    values[:50] = -1e3                                   # weight 0: must take no part
    x, y = np.meshgrid(np.linspace(0, 4, 21), np.linspace(0, 4, 21))
    nodes = np.r_[np.c_[x.ravel(), y.ravel()], [[9.0, 9.0]]]
    avg = KernelAverage(nodes, points, weights, 0.4)
    A = avg.matrix
    assert A.data.min() > 0 and np.allclose(np.asarray(A.sum(axis=1)).ravel(), 1.0, rtol=0, atol=1e-14)
    assert A[:, :50].nnz == 0
    out = avg(values[:, None])[:, 0]
    used = values[50:]
    assert out.min() >= used.min() and out.max() <= used.max()
    assert out.max() > 0.1
    np.testing.assert_allclose(avg(np.full((len(points), 2), 7.5)), 7.5, rtol=1e-14)
    assert A[-1].nnz > 0                                   # (9, 9): 7 away from the nearest point, still averaged


def test_the_l2_projection_it_replaces_overshoots() -> None:
    """Why: the L2 projection onto a linear finite-element-like space of the same band goes negative (the
    nodal RPIM space does the same in the footing, docs/design.md 'Output')."""
    import scipy.sparse as sp
    xs = np.linspace(0, 1, 11)
    points = np.linspace(0, 1, 201)[:, None]
    # hat functions on 11 nodes in 1-D, at the points
    h = xs[1] - xs[0]
    N = sp.csr_matrix(np.maximum(0.0, 1.0 - np.abs(points - xs[None, :]) / h))
    values = (np.abs(points[:, 0] - 0.5) < 0.02).astype(float)[:, None]
    w = np.full(len(points), 1.0 / len(points))
    assert project_to_nodes(N, w, values).min() < -0.01
    avg = KernelAverage(np.c_[xs, np.zeros(11)], np.c_[points, np.zeros(len(points))], w, 2 * h)(values)
    assert avg.min() >= 0.0
