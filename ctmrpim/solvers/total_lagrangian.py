"""Quasi-static total-Lagrangian CTM-RPIM with a hyperelastic material (Section 2.1.3, TL form).

The cross-check of the adaptive updated-Lagrangian path (docs/design.md, 'Updated and total Lagrangian'):
boundary, CTM points, RPIM supports and shape functions all live on the reference configuration and are
built once. Loads are applied in increments (:mod:`ctmrpim.solvers.load_stepping`); each increment is
solved by Newton-Raphson on F_ext - F_int with a residual and a displacement criterion. An increment that
does not converge is cut in half and retried (and the history says so, never silently), and grows back
after easy increments. Loads are dead or follower (:mod:`ctmrpim.discretisation.boundary_loads`).

    F_int[I, i] = sum_p w_p P_iJ(p) dN_I/dX_J(p)
    K[(I, i), (K, k)] = sum_p w_p dN_I/dX_J A_iJkL dN_K/dX_L        (G^T diag(w A) G, sparse)
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ctmrpim.discretisation import consistent_integration
from ctmrpim.discretisation.boundary_loads import reference_loads
from ctmrpim.discretisation.configuration import BoundaryTags, Configuration, boundary_tags, reference_configuration
from ctmrpim.discretisation.lagrangian_operators import gradient_operator
from ctmrpim.errors import ProblemError
from ctmrpim.materials.neo_hookean import NeoHookean
from ctmrpim.problem.case import Case
from ctmrpim.result import Result, probe_record
from ctmrpim.solvers.linear_solver import solve_constrained
from ctmrpim.solvers.load_stepping import step_loads
from ctmrpim.solvers.weak_form import internal_force, tangent
from ctmrpim.timing import Timer


def _cauchy(material: NeoHookean, G: sp.csr_matrix, U: np.ndarray) -> np.ndarray:
    """(m, 4) Cauchy stress sxx, syy, sxy = P F^T / J and szz at the rows of G (stored on the reference points);
    with F33 = 1, P33 = mu + (lambda ln J - mu) = lambda ln J, so szz = lambda ln J / J."""
    F = np.eye(2)[None] + (G @ U).reshape(-1, 2, 2)
    P, _ = material.stress_tangent(F)
    J = np.linalg.det(F)
    sig = P @ F.transpose(0, 2, 1) / J[:, None, None]
    return np.c_[sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1], material.lam * np.log(J) / J]


def _consistent(case: Case, conf: Configuration, tags: BoundaryTags
                ) -> tuple[sp.bsr_matrix, consistent_integration.LagrangianDirichletTerm]:
    """``method.integration = "ctm-vci"`` on the reference configuration: G~^T of the corrected test gradients
    (the integration constraints hold against the boundary's Gauss points) and the Dirichlet consistency term
    (:mod:`ctmrpim.discretisation.consistent_integration`); K = G~^T diag(w A) G is Petrov-Galerkin."""
    thickness = case.problem.thickness
    boundary, sf_b, test_dx, test_dy = consistent_integration.corrected_test_gradients(conf, case.method, thickness)
    term = consistent_integration.LagrangianDirichletTerm(len(conf.x), tags.fixed, boundary, sf_b, thickness)
    return gradient_operator(test_dx, test_dy).T.tobsr(), term


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
    if any(problem.body_force):
        raise ProblemError("gravity is not in the large-deformation solvers yet (a Mohr-Coulomb or linear "
                           "analysis takes it)", key="problem.gravity")
    timer = Timer()
    conf = reference_configuration(case, timer)
    tags = boundary_tags(case, conf.x, conf.boundary, conf.lengths)
    nodes, sf, w = conf.x, conf.sf, conf.w
    fixed, fixed_values = tags.fixed, tags.fixed_values
    probe_xy = np.array([[p.x, p.y] for p in problem.probes]).reshape(-1, 2)
    sf_p = conf.shape_functions_at(probe_xy) if len(probe_xy) else None
    timer.lap("shape_functions")
    G = conf.block_gradient()
    GT = G.T
    dirichlet = None
    if method.integration == "ctm-vci":   # corrected test gradients, and the traction of u_h on constrained edges
        GT, dirichlet = _consistent(case, conf, tags)
    follower = tags.traction.follower
    loads = reference_loads(conf, tags, problem.thickness, conf.point_forces(problem))

    timer.lap("assembly")

    n = len(nodes)
    series: list[dict] = []
    sf_n = conf.shape_functions_at(nodes)
    G_nodes = gradient_operator(sf_n.dNdx, sf_n.dNdy)

    def assemble(U: np.ndarray, factor: float):
        f_ext, K_load = loads.forces(nodes + U.reshape(-1, 2), factor)
        P, A = material.stress_tangent(np.eye(2)[None] + (G @ U).reshape(-1, 2, 2))
        K = tangent(G, A, w, GT)
        f_int = internal_force(G, P, w, GT)
        if dirichlet is not None and dirichlet.active:
            f_d, K_d = dirichlet(U, material.stress_tangent)
            f_int, K = f_int - f_d, K - K_d
        return f_ext, f_int, (K if K_load is None else K + K_load)

    # follower loads and the consistent scheme make the tangent non-symmetric: no Cholesky then
    linear_solver = "superlu" if follower.any() or dirichlet is not None else method.solver

    def solve(K, residual):
        return solve_constrained(K, residual, fixed, np.zeros(len(fixed)), linear_solver)

    def on_converged(factor: float, U: np.ndarray) -> dict:
        u = U.reshape(-1, 2)
        sig = _cauchy(material, G_nodes, U)
        series.append({"load_factor": factor, "u": u.copy(), "stress": sig[:, :3], "stress_zz": sig[:, 3]})
        if sf_p is None:
            return {}
        up = sf_p.N @ u
        return {p.name: {"x": p.x, "y": p.y, "ux": float(up[i, 0]), "uy": float(up[i, 1])}
                for i, p in enumerate(problem.probes)}

    path = step_loads(2 * n, case.loading, fixed, fixed_values, assemble, solve, on_converged)
    U, history = path.U, path.history
    timer.lap("solve")

    u = U.reshape(-1, 2)
    stress = np.c_[series[-1]["stress"], series[-1]["stress_zz"]] if series else _cauchy(material, G_nodes, U)
    probes = {}
    if sf_p is not None:
        up = sf_p.N @ u
        sig = _cauchy(material, gradient_operator(sf_p.dNdx, sf_p.dNdy), U)
        probes = {p.name: probe_record(p.x, p.y, up[i], sig[i, :3]) for i, p in enumerate(problem.probes)}
    timer.lap("postprocess")
    sizes = sf.support_sizes
    return Result(
        method="ctm-rpim-tl", points=nodes, u=u, stress=stress[:, :3], stress_zz=stress[:, 3],
        cells=[("line", conf.boundary.edges), ("triangle", conf.boundary.triangles)], probes=probes, errors={},
        counts={"nodes": n, "integration_points": len(w), "load_increments": sum(h["converged"] for h in history),
                "cutbacks": path.cutbacks, "newton_iterations": path.newton_iterations,
                "support_size": {"min": int(sizes.min()), "mean": float(sizes.mean()), "max": int(sizes.max())}},
        timings=timer.total(), history=history, series=series,
        parameters={**case.resolved, "derived": {"d_c": conf.lengths.d_c, "mu": material.mu, "lambda": material.lam}},
        defaults=case.defaults)
