"""Quasi-static total-Lagrangian CTM-RPIM with a hyperelastic material (Section 2.1.3, TL form).

The cross-check of the adaptive updated-Lagrangian path (DESIGN.md): boundary, CTM points, RPIM
supports and shape functions all live on the reference configuration and are built once. Loads are
applied in increments; each increment is solved by Newton-Raphson on F_ext - F_int with a residual
and a displacement criterion and a backtracking line search on the residual norm. An increment that does not converge is cut in half and retried (and
the history says so, never silently), and grows back after easy increments; loads are dead (nominal
tractions on the reference boundary).

    F_int[I, i] = sum_p w_p P_iJ(p) dN_I/dX_J(p)
    K[(I, i), (K, k)] = sum_p w_p dN_I/dX_J A_iJkL dN_K/dX_L        (G^T diag(w A) G, sparse)
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from . import assembly
from .errors import ProblemError
from .hyperelastic import NeoHookean
from .linear_solver import solve_constrained
from .load_stepping import step_loads
from .linear_static import Timer, build_configuration
from .problem_file import Case
from .result import Result, probe_record
from .rpim import shape_functions


def gradient_operator(dNdx: sp.csr_matrix, dNdy: sp.csr_matrix) -> sp.csr_matrix:
    """G (4m x 2n): row 4p + c, c = xX, xY, yX, yY, gives du_i/dX_J at point p from interleaved dofs.
    ``dNdx`` and ``dNdy`` share one sparsity pattern (they come from one RPIM solve)."""
    m, n = dNdx.shape
    counts = np.repeat(np.diff(dNdx.indptr), 4)                  # each point's support, once per row c
    indptr = np.concatenate([[0], np.cumsum(counts)])
    gather = np.repeat(np.repeat(dNdx.indptr[:-1], 4) - indptr[:-1], counts) + np.arange(indptr[-1])
    c = np.repeat(np.tile(np.arange(4), m), counts)
    data = np.where(c % 2 == 0, dNdx.data[gather], dNdy.data[gather])   # J = X for c = 0, 2
    indices = 2 * dNdx.indices[gather] + (c >= 2)                      # i = y for c = 2, 3
    return sp.csr_matrix((data, indices, indptr), shape=(4 * m, 2 * n))


def _value_operator(N: sp.csr_matrix) -> sp.csr_matrix:
    """(2m x 2n): rows (p, i) give u_i at point p from interleaved dofs."""
    m, n = N.shape
    counts = np.repeat(np.diff(N.indptr), 2)
    indptr = np.concatenate([[0], np.cumsum(counts)])
    gather = np.repeat(np.repeat(N.indptr[:-1], 2) - indptr[:-1], counts) + np.arange(indptr[-1])
    i = np.repeat(np.tile(np.arange(2), m), counts)
    return sp.csr_matrix((N.data[gather], 2 * N.indices[gather] + i, indptr), shape=(2 * m, 2 * n))


def _difference_operator(ends: np.ndarray, n_nodes: int) -> sp.csr_matrix:
    """(2m x 2n): rows (p, j) give u_j(end 1) - u_j(end 0) of the segment point p lies on."""
    m = len(ends)
    rows = np.repeat(np.arange(2 * m), 2)
    j = np.tile(np.repeat(np.arange(2), 2), m)
    cols = 2 * np.stack([ends[:, 1], ends[:, 0]], axis=1).repeat(2, axis=0).ravel() + j
    vals = np.tile([1.0, -1.0], 2 * m)
    return sp.csr_matrix((vals, (rows, cols)), shape=(2 * m, 2 * n_nodes))


def _internal_force(G: sp.csr_matrix, P: np.ndarray, w: np.ndarray) -> np.ndarray:
    return G.T @ (P.reshape(-1, 4) * w[:, None]).ravel()


def _tangent(G: sp.csr_matrix, A: np.ndarray, w: np.ndarray) -> sp.csr_matrix:
    m = len(w)
    blocks = A.reshape(m, 4, 4) * w[:, None, None]
    WA = sp.bsr_matrix((blocks, np.arange(m), np.arange(m + 1)), shape=(4 * m, 4 * m))
    return (G.T @ (WA @ G)).tocsr()


def _cauchy(material: NeoHookean, G: sp.csr_matrix, U: np.ndarray) -> np.ndarray:
    """(m, 3) Cauchy stress sxx, syy, sxy = P F^T / J at the rows of G (stored on the reference points)."""
    F = np.eye(2)[None] + (G @ U).reshape(-1, 2, 2)
    P, _ = material.stress_tangent(F)
    sig = P @ F.transpose(0, 2, 1) / np.linalg.det(F)[:, None, None]
    return np.c_[sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1]]


def solve_total_lagrangian(case: Case) -> Result:
    """Load-stepped Newton solve of a hyperelastic Case (``case.loading``); ``Result.history`` has one
    entry per increment (and one per cut-back)."""
    problem, method = case.problem, case.method
    material = problem.material
    if not isinstance(material, NeoHookean):
        raise ProblemError("the total-Lagrangian solver needs model = \"neo-hookean\"", key="material.model")
    if problem.plane != "strain":
        raise ProblemError("the neo-Hookean model is implemented in plane strain; set problem.plane = \"strain\"",
                           key="problem.plane")
    timer = Timer()
    conf = build_configuration(case, timer)
    disc, rpim, sf, sf_t = conf.disc, conf.rpim, conf.sf, conf.sf_traction
    nodes, d_c, quad = disc.nodes, disc.d_c, disc.quadrature
    fixed, fixed_values, traction_q, tx, ty = conf.fixed, conf.fixed_values, conf.traction, conf.tx, conf.ty
    probe_xy = np.array([[p.x, p.y] for p in problem.probes]).reshape(-1, 2)
    sf_p = shape_functions(nodes, probe_xy, **rpim) if len(probe_xy) else None
    timer.lap("shape_functions")
    G = gradient_operator(sf.dNdx, sf.dNdy)
    w = quad.weights * problem.thickness
    wt = traction_q.weights * problem.thickness
    follower = traction_q.follower
    d0 = nodes[traction_q.ends[:, 1]] - nodes[traction_q.ends[:, 0]]

    len0 = np.linalg.norm(d0, axis=1)
    e0, p0 = d0 / len0[:, None], np.c_[-d0[:, 1], d0[:, 0]] / len0[:, None]
    Bn = _value_operator(sf_t.N)
    Ed = _difference_operator(traction_q.ends, n_nodes=len(nodes))

    def external(U: np.ndarray, factor: float) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Load vector and its stiffness -dF_ext/dU. Dead tractions keep their direction; follower
        tractions turn with their segment: t = R(theta) t0 per unit reference length, with
        cos theta = e0 . e and sin theta = (e0 x e) of the reference and current unit directions."""
        if not follower.any():
            return factor * F_dead, None
        u = U.reshape(-1, 2)
        d = d0 + u[traction_q.ends[:, 1]] - u[traction_q.ends[:, 0]]
        length = np.linalg.norm(d, axis=1)
        e = d / length[:, None]
        c, s_ = (e0 * e).sum(1), (p0 * e).sum(1)
        rx = np.where(follower, c * tx - s_ * ty, tx)
        ry = np.where(follower, s_ * tx + c * ty, ty)
        # d(c, s)/dd = (e0, p0)^T (I - e e^T) / |d|; d(R t0)/dd for each point, zero for dead loads
        proj = (np.eye(2)[None] - e[:, :, None] * e[:, None, :]) / length[:, None, None]
        dc, ds = np.einsum("pi,pij->pj", e0, proj), np.einsum("pi,pij->pj", p0, proj)
        M = np.stack([tx[:, None] * dc - ty[:, None] * ds, tx[:, None] * ds + ty[:, None] * dc], axis=1)
        M *= (follower * wt * factor)[:, None, None]
        MB = sp.bsr_matrix((M, np.arange(len(M)), np.arange(len(M) + 1)), shape=(2 * len(M), 2 * len(M)))
        return factor * (assembly.load_vector(sf_t.N, wt, rx, ry) + F_points), -(Bn.T @ (MB @ Ed)).tocsr()

    F_points = problem.thickness * assembly.point_load_vector(nodes, problem, rpim)
    F_dead = assembly.load_vector(sf_t.N, wt, tx, ty) + F_points

    timer.lap("assembly")

    n = len(nodes)
    series: list[dict] = []
    sf_n = shape_functions(nodes, nodes, **rpim)
    G_nodes = gradient_operator(sf_n.dNdx, sf_n.dNdy)

    def assemble(U: np.ndarray, factor: float):
        f_ext, K_load = external(U, factor)
        P, A = material.stress_tangent(np.eye(2)[None] + (G @ U).reshape(-1, 2, 2))
        K = _tangent(G, A, w)
        return f_ext, _internal_force(G, P, w), (K if K_load is None else K + K_load)

    # follower loads make the tangent non-symmetric: no Cholesky then
    linear_solver = "superlu" if follower.any() else method.solver

    def solve(K, residual):
        return solve_constrained(K, residual, fixed, np.zeros(len(fixed)), linear_solver)

    def on_converged(factor: float, U: np.ndarray) -> dict:
        u = U.reshape(-1, 2)
        series.append({"load_factor": factor, "u": u.copy(), "stress": _cauchy(material, G_nodes, U)})
        if sf_p is None:
            return {}
        up = np.c_[sf_p.N @ u[:, 0], sf_p.N @ u[:, 1]]
        return {p.name: {"x": p.x, "y": p.y, "ux": float(up[i, 0]), "uy": float(up[i, 1])}
                for i, p in enumerate(problem.probes)}

    path = step_loads(2 * n, case.loading, fixed, fixed_values, assemble, solve, on_converged)
    U, history = path.U, path.history
    timer.lap("solve")

    u = U.reshape(-1, 2)
    stress = series[-1]["stress"] if series else _cauchy(material, G_nodes, U)
    probes = {}
    if sf_p is not None:
        up = np.c_[sf_p.N @ u[:, 0], sf_p.N @ u[:, 1]]
        sig = _cauchy(material, gradient_operator(sf_p.dNdx, sf_p.dNdy), U)
        probes = {p.name: probe_record(p.x, p.y, up[i], sig[i]) for i, p in enumerate(problem.probes)}
    timer.lap("postprocess")
    sizes = sf.support_sizes
    return Result(
        method="ctm-rpim-tl", points=nodes, u=u, stress=stress,
        cells=[("line", disc.boundary.edges)], probes=probes, errors={},
        counts={"nodes": n, "integration_points": len(w), "load_increments": sum(h["converged"] for h in history),
                "cutbacks": path.cutbacks, "newton_iterations": path.newton_iterations,
                "support_size": {"min": int(sizes.min()), "mean": float(sizes.mean()), "max": int(sizes.max())}},
        timings=timer.total(), history=history, series=series,
        parameters={**case.resolved, "derived": {"d_c": d_c, "mu": material.mu, "lambda": material.lam}},
        defaults=case.defaults)
