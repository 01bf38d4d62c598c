"""The compiled gradient and internal-force products equal scipy's sparse products, and give the same bits
whatever the number of threads and blocks (a resumed explicit run must repeat the uninterrupted one, a case
the same bits on one core and on two) and as a serial scatter of the force in point order."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from ctmrpim.discretisation import gradient_operator as go
from ctmrpim.discretisation import thread_blocks


def _gradients(m: int, n: int, support: int, seed: int = 0) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """(dN/dx, dN/dy) at m points with ``support`` random nodes each (one pattern, sorted columns); node 0
    belongs to no point (an empty column)."""
    rng = np.random.default_rng(seed)
    cols = np.sort(np.array([rng.choice(np.arange(1, n), support, replace=False) for _ in range(m)]), axis=1)
    indptr = np.arange(0, m * support + 1, support)
    return tuple(sp.csr_matrix((rng.normal(size=m * support), cols.ravel(), indptr), shape=(m, n)) for _ in "xy")


def _scatter(dx: sp.csr_matrix, dy: sp.csr_matrix, wP: np.ndarray) -> np.ndarray:
    """The force summed node by node in increasing point order, each term's y part first (Python floats)."""
    out = np.zeros((dx.shape[1], 2))
    for p in range(dx.shape[0]):
        for k in range(dx.indptr[p], dx.indptr[p + 1]):
            j = dx.indices[k]
            out[j, 0] = out[j, 0] + (wP[p, 1] * dy.data[k] + wP[p, 0] * dx.data[k])
            out[j, 1] = out[j, 1] + (wP[p, 3] * dy.data[k] + wP[p, 2] * dx.data[k])
    return out


@pytest.mark.parametrize("entries", [2_000, 60_000])      # one block, and split over the threads
def test_products_equal_the_sparse_products(entries: int) -> None:
    support = 20
    dx, dy = _gradients(entries // support, 400, support)
    op = go.GradientOperator(dx, dy)
    rng = np.random.default_rng(1)
    d = rng.normal(size=(400, 2))
    F = op.gradient(d)
    ref = np.c_[1 + dx @ d[:, 0], dy @ d[:, 0], dx @ d[:, 1], 1 + dy @ d[:, 1]]
    assert np.allclose(F, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    wP = rng.normal(size=(dx.shape[0], 4))
    f = op.force(wP)
    ref = np.c_[dx.T @ wP[:, 0] + dy.T @ wP[:, 1], dx.T @ wP[:, 2] + dy.T @ wP[:, 3]]
    assert np.allclose(f, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    assert np.all(f[0] == 0.0)                                # a node no point supports
    scattered = op.scatter_force(wP)
    assert np.allclose(scattered, ref, rtol=0, atol=1e-12 * np.abs(ref).max()) and np.all(scattered[0] == 0.0)


def test_the_bits_do_not_depend_on_the_threads(monkeypatch: pytest.MonkeyPatch) -> None:
    dx, dy = _gradients(3000, 500, 25, seed=2)
    rng = np.random.default_rng(3)
    d, wP = rng.normal(size=(500, 2)), rng.normal(size=(3000, 4))
    results = []
    for threads in (1, 2, 3):
        monkeypatch.setattr(thread_blocks, "THREADS", threads)
        op = go.GradientOperator(dx, dy)
        assert len(op._row_blocks) == threads
        assert len(op.scatter_blocks) == go.SCATTER_BLOCKS        # fixed, whatever the threads
        results.append((op.gradient(d), op.force(wP), op.scatter_force(wP)))
    for F, f, g in results[1:]:
        assert np.array_equal(F, results[0][0]) and np.array_equal(f, results[0][1])
        assert np.array_equal(g, results[0][2])


def test_the_force_is_a_scatter_in_point_order() -> None:
    """Sums in increasing point order per node: the round-off of the serial scatter the gather replaced (with
    fused multiply-adds where the machine has them, the gather may differ from this Python sum in the last bit)."""
    dx, dy = _gradients(300, 60, 12, seed=4)
    wP = np.random.default_rng(5).normal(size=(300, 4))
    op = go.GradientOperator(dx, dy)
    ref = _scatter(dx, dy, wP)
    assert np.allclose(op.force(wP), ref, rtol=0, atol=4 * np.finfo(float).eps * np.abs(ref).max())
    # the scattered force is that serial scatter (one block here), without fused multiply-adds: to the bit
    assert len(op.scatter_blocks) == 1 and np.array_equal(op.scatter_force(wP), ref)


def test_a_forked_process_gets_its_own_pool() -> None:
    pool = thread_blocks.executor()
    assert thread_blocks.executor() is pool
    pid, size, _ = thread_blocks._pool
    thread_blocks._pool = (-1, size, pool)               # as a forked child sees its parent's pool
    try:
        assert thread_blocks.executor() is not pool
    finally:
        thread_blocks._pool = (pid, size, pool)


def test_blocks_run_once_each_and_an_error_in_one_is_raised(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every block once, whichever thread takes it, on 1, 2 and 3 threads; a failing block is raised, and the
    blocks after it are not all started."""
    for threads in (1, 2, 3):
        monkeypatch.setattr(thread_blocks, "THREADS", threads)
        seen: list[tuple[int, int]] = []
        blocks = [(a, a + 1) for a in range(7)]
        thread_blocks.run_blocks(seen.append, blocks)
        assert sorted(seen) == blocks

        def work(ab: tuple[int, int]) -> None:
            if ab == (3, 4):
                raise ValueError("block 3")
            seen.append(ab)

        seen.clear()
        with pytest.raises(ValueError, match="block 3"):
            thread_blocks.run_blocks(work, blocks)
        assert (3, 4) not in seen and len(seen) < len(blocks)
