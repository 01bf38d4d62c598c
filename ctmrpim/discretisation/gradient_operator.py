"""The RPIM gradient at the integration points and its transpose, the internal force (compiled, numba).

With dN/dx and dN/dy of every point in one sparse pattern (a point's support), the explicit solver and the
Newton systems need two products, each step or iteration:

    F_p = I + sum_j (x_j - x_r,j) (dN_j/dx, dN_j/dy)(x_p)                        (the gradient)
    f_j = sum_p w_p P_p (dN_j/dx, dN_j/dy)(x_p)^T                              (the internal force)

As scipy products these are four passes over the matrix (two columns each way, CSR and its transpose); here each is one
pass over the shared pattern with both derivative values, split into
:data:`ctmrpim.discretisation.thread_blocks.THREADS` blocks on its threads (the kernels release the GIL). The gradient
runs over the points (rows). The force comes two ways: :meth:`GradientOperator.force` over the nodes (columns),
gathering from the pattern transposed once per operator (the Newton systems, which transpose it for their tangents
anyway), each node's force summed over its points in an order fixed by the pattern (four interleaved partial sums in
increasing point order); :meth:`GradientOperator.scatter_force` over the points, scattering each row onto its nodes,
in :data:`SCATTER_BLOCKS` fixed blocks of points each into its own nodal array (the explicit solver's: its point
pass scatters the force of the state it leaves on the way, with the same kernel, :func:`scatter_rows`). Neither's
sums depend on the number of threads, so a resumed explicit run repeats the uninterrupted one bit for bit, and a case
gives the same bits on one core and on two.

Why split: on the 1071-node column's 9600 points (about 413000 entries) the two passes were 2.3 of the
5.4 ms of a step (Python's profile of a collapse run) before they were compiled with unsigned indices and the
force in partial sums; measured now in one script on such a pattern, one thread, best of 50 calls: gradient
0.41 ms, force 0.40 ms (medians vary twofold on this shared machine). In a run the pattern (about 8 MB) is
read from memory each time, and handing both blocks to a pool made the Newton iterations slower than one
thread (waking two idle cores), hence the calling thread computes blocks too
(:mod:`ctmrpim.discretisation.thread_blocks`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit, uint64

from ctmrpim.discretisation import thread_blocks
from ctmrpim.discretisation.stiffness_kernels import transpose_pattern

#: below this many pattern entries one block does it: a pool's hand-over (tens of microseconds) would cost
#: more than the second core saves
PARALLEL_MIN_ENTRIES = 40_000
#: blocks of points a scattered force is summed in (above PARALLEL_MIN_ENTRIES), each into its own nodal array,
#: the arrays then added in block order: a count fixed whatever the threads, so the bits do not depend on them
SCATTER_BLOCKS = 8
_FAST = {"reassoc", "contract"}
_1, _2, _3, _4 = uint64(1), uint64(2), uint64(3), uint64(4)


def _blocks(starts: np.ndarray, parts: int) -> list[tuple[int, int]]:
    """``parts`` consecutive ranges of the rows of a pattern with row starts ``starts`` (rows + 1), of about
    equal numbers of entries."""
    rows = len(starts) - 1
    cuts = np.searchsorted(starts, np.linspace(0, starts[-1], parts + 1)[1:-1])
    edges = [0, *(int(c) for c in np.clip(cuts, 0, rows)), rows]
    return [(a, b) for a, b in zip(edges[:-1], edges[1:]) if b > a]


@njit(cache=True, nogil=True, fastmath=_FAST)
def gradient_rows(indptr, indices, dx, dy, d, out, identity, p0, p1):
    """out[p] = identity I + grad d at the points p0 <= p < p1 (xx, xy, yx, yy) of nodal displacements d (n, 2)."""
    # unsigned indices: a signed one is wrapped (i < 0 -> i + len) on every load, which keeps LLVM from
    # vectorising the sums (measured on the 1071-node column's pattern: 0.97 -> 0.41 ms per pass, one thread)
    for p in range(uint64(p0), uint64(p1)):
        a = b = c = e = 0.0
        for k in range(uint64(indptr[p]), uint64(indptr[p + _1])):
            j = uint64(indices[k])
            a += dx[k] * d[j, 0]
            b += dy[k] * d[j, 0]
            c += dx[k] * d[j, 1]
            e += dy[k] * d[j, 1]
        out[p, 0], out[p, 1], out[p, 2], out[p, 3] = identity + a, b, c, identity + e


@njit(cache=True, nogil=True, fastmath={"contract"})
def _force(tptr, tpoint, tdx, tdy, wP, out, j0, j1):
    # four partial sums over a node's points (t mod 4, combined pairwise): one sum would chain every fused
    # multiply-add on the last (0.88 -> 0.40 ms per pass on the column's pattern); the order is fixed by the
    # pattern alone, not by the threads or the split
    for j in range(uint64(j0), uint64(j1)):
        x0 = x1 = x2 = x3 = y0 = y1 = y2 = y3 = 0.0
        t, end = uint64(tptr[j]), uint64(tptr[j + _1])
        while t + _3 < end:
            p = uint64(tpoint[t])
            x0 += wP[p, 0] * tdx[t] + wP[p, 1] * tdy[t]
            y0 += wP[p, 2] * tdx[t] + wP[p, 3] * tdy[t]
            p = uint64(tpoint[t + _1])
            x1 += wP[p, 0] * tdx[t + _1] + wP[p, 1] * tdy[t + _1]
            y1 += wP[p, 2] * tdx[t + _1] + wP[p, 3] * tdy[t + _1]
            p = uint64(tpoint[t + _2])
            x2 += wP[p, 0] * tdx[t + _2] + wP[p, 1] * tdy[t + _2]
            y2 += wP[p, 2] * tdx[t + _2] + wP[p, 3] * tdy[t + _2]
            p = uint64(tpoint[t + _3])
            x3 += wP[p, 0] * tdx[t + _3] + wP[p, 1] * tdy[t + _3]
            y3 += wP[p, 2] * tdx[t + _3] + wP[p, 3] * tdy[t + _3]
            t += _4
        while t < end:
            p = uint64(tpoint[t])
            x0 += wP[p, 0] * tdx[t] + wP[p, 1] * tdy[t]
            y0 += wP[p, 2] * tdx[t] + wP[p, 3] * tdy[t]
            t += _1
        out[j, 0] = (x0 + x1) + (x2 + x3)
        out[j, 1] = (y0 + y1) + (y2 + y3)


@njit(cache=True, nogil=True)
def scatter_rows(indptr, indices, dx, dy, wP, out, p0, p1):
    """out[j] += sum_p wP_p (dN_j/dx, dN_j/dy)(x_p) over the points p0 <= p < p1 in increasing order: the internal
    force scattered from the points' rows. No fast-math flags: the same bits wherever it is compiled in (the
    explicit point pass scatters its points' force with it on the way, the step's own force pass with it too)."""
    flat = out.ravel()          # one index into a flat view: 0.47 -> 0.41 ms on the column's pattern, one thread
    for p in range(uint64(p0), uint64(p1)):
        a, b, c, e = wP[p, 0], wP[p, 1], wP[p, 2], wP[p, 3]
        for k in range(uint64(indptr[p]), uint64(indptr[p + _1])):
            j = _2 * uint64(indices[k])
            flat[j] += a * dx[k] + b * dy[k]
            flat[j + _1] += c * dx[k] + e * dy[k]


def add_blocks(parts: np.ndarray) -> np.ndarray:
    """(n, 2) the blocks' nodal sums ``parts`` (blocks, n, 2) added in block order."""
    out = parts[0].copy()
    for part in parts[1:]:
        out += part
    return out


class GradientOperator:
    """dN/dx and dN/dy (m points x n nodes, one sparsity pattern) as the two products above."""

    def __init__(self, dNdx: sp.csr_matrix, dNdy: sp.csr_matrix) -> None:
        if not (np.array_equal(dNdx.indptr, dNdy.indptr) and np.array_equal(dNdx.indices, dNdy.indices)):
            raise ValueError("dN/dx and dN/dy must share one sparsity pattern")
        self.shape = dNdx.shape
        self.indptr, self.indices = dNdx.indptr, dNdx.indices
        self.dx, self.dy = np.ascontiguousarray(dNdx.data, float), np.ascontiguousarray(dNdy.data, float)
        self._parts = thread_blocks.THREADS if len(self.indices) >= PARALLEL_MIN_ENTRIES else 1
        self._row_blocks = _blocks(self.indptr, self._parts)
        scatter = SCATTER_BLOCKS if len(self.indices) >= PARALLEL_MIN_ENTRIES else 1     # not THREADS: the bits
        self._scatter_blocks = [(b, p0, p1) for b, (p0, p1) in enumerate(_blocks(self.indptr, scatter))]
        self._pattern: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._columns: tuple[np.ndarray, np.ndarray, list[tuple[int, int]]] | None = None

    @property
    def scatter_blocks(self) -> list[tuple[int, int, int]]:
        """(block, first point, end) of the blocks a scattered force is summed in (:func:`scatter_force`)."""
        return self._scatter_blocks

    def transposed(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(tptr (n + 1), point (nnz), entry (nnz)): the pattern by nodes, points ascending within a node
        (:func:`ctmrpim.discretisation.stiffness_kernels.transpose_pattern`), built once."""
        if self._pattern is None:
            etype = np.int32 if len(self.indices) < 2**31 - 1 else np.int64
            point, entry = np.empty(len(self.indices), etype), np.empty(len(self.indices), etype)
            tptr = transpose_pattern(self.indptr, self.indices, self.shape[1], point, entry)
            self._pattern = (tptr, point, entry)
        return self._pattern

    def share_pattern(self, other: GradientOperator) -> None:
        """Take ``other``'s transposed pattern (the same sparsity pattern) instead of building it again."""
        if self._pattern is None and other._pattern is not None:
            self._pattern = other._pattern

    def gradient(self, d: np.ndarray, identity: float = 1.0) -> np.ndarray:
        """(m, 4) F = I + grad d (xx, xy, yx, yy) of nodal displacements d (n, 2); ``identity = 0``: grad d."""
        out = np.empty((self.shape[0], 4))
        d = np.ascontiguousarray(d, float)
        thread_blocks.run_blocks(lambda ab: gradient_rows(self.indptr, self.indices, self.dx, self.dy, d, out,
                                                          identity, *ab), self._row_blocks, kernel=gradient_rows)
        return out

    def force(self, wP: np.ndarray) -> np.ndarray:
        """(n, 2) sum_p wP_p grad N of weighted first Piola stresses wP (m, 4: xX, xY, yX, yY)."""
        tptr, point, entry = self.transposed()
        if self._columns is None:
            self._columns = (self.dx[entry], self.dy[entry], _blocks(tptr, self._parts))
        tdx, tdy, blocks = self._columns
        out = np.empty((self.shape[1], 2))
        wP = np.ascontiguousarray(wP, float)
        thread_blocks.run_blocks(lambda ab: _force(tptr, point, tdx, tdy, wP, out, *ab), blocks, kernel=_force)
        return out

    def scatter_force(self, wP: np.ndarray) -> np.ndarray:
        """(n, 2) sum_p wP_p grad N scattered from the points (:func:`scatter_rows`), each block of
        :attr:`scatter_blocks` into its own nodal array (:func:`add_blocks`): what the explicit point pass gives on
        its way, to the bit; no transposed pattern needed."""
        wP = np.ascontiguousarray(wP, float)
        parts = np.zeros((max(len(self._scatter_blocks), 1), self.shape[1], 2))
        thread_blocks.run_blocks(lambda bab: scatter_rows(self.indptr, self.indices, self.dx, self.dy, wP,
                                                          parts[bab[0]], bab[1], bab[2]),
                                 self._scatter_blocks, kernel=scatter_rows)
        return add_blocks(parts)


def rpim_layout(G: sp.bsr_matrix) -> bool:
    """Whether G (4m x 2n) is block-sparse with every 4 x 2 block [[a, 0], [b, 0], [0, a], [0, b]] (a = dN/dX,
    b = dN/dY: :func:`ctmrpim.discretisation.lagrangian_operators.gradient_operator`'s layout)."""
    if not (isinstance(G, sp.bsr_matrix) and G.blocksize == (4, 2)):
        return False
    d = G.data
    return bool(np.array_equal(d[:, 2, 1], d[:, 0, 0]) and np.array_equal(d[:, 3, 1], d[:, 1, 0])
                and not np.any(d[:, 2:, 0]) and not np.any(d[:, :2, 1]))


def from_blocks(G: sp.bsr_matrix) -> GradientOperator | None:
    """The operator of a G in :func:`rpim_layout`, or None."""
    if not rpim_layout(G):
        return None
    m, n = G.shape[0] // 4, G.shape[1] // 2
    return GradientOperator(sp.csr_matrix((G.data[:, 0, 0], G.indices, G.indptr), shape=(m, n)),
                            sp.csr_matrix((G.data[:, 1, 0], G.indices, G.indptr), shape=(m, n)))
