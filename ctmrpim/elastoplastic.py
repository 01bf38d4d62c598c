"""Quasi-static small-strain elastoplastic CTM-RPIM (Section 2.1.3) with the Mohr-Coulomb material.

Small strain (DESIGN.md: the slope and the footing at small strain never re-track): boundary, CTM
points and RPIM shape functions are built once on the reference configuration. The stress history
lives at the CTM points. Loads are applied in increments (:mod:`ctmrpim.load_stepping`); within an
increment Newton-Raphson iterates on the strain increment from the last converged state,

    sigma = return_map(sigma_n, B (U - U_n)),   F_int = B^T (w sigma),   K = B^T diag(w D_ep) B,

with D_ep the consistent tangent of the return map (:mod:`ctmrpim.mohr_coulomb`), non-symmetric for a
non-associated flow (psi < phi), so the linear solves use SuperLU. The history is committed only when
an increment converges; a cut-back restarts from the committed state.
"""
from __future__ import annotations

import numpy as np

from . import assembly
from .boundary_loads import BoundaryLoads
from .errors import ProblemError
from .lagrangian_operators import gradient_operator, internal_force, tangent
from .linear_solver import solve_constrained
from .linear_static import Timer, build_configuration
from .load_stepping import step_loads
from .mohr_coulomb import ELASTIC, MohrCoulomb
from .problem_file import Case
from .result import Result, probe_record
from .rpim import shape_functions

#: (4 x 3): the first Piola stress layout (xX, xY, yX, yY) from (sxx, syy, sxy) - small strain, P = sigma
TO_P = np.array([[1.0, 0, 0], [0, 0, 1], [0, 0, 1], [0, 1, 0]])
#: (3 x 4): the engineering strain (exx, eyy, gxy) from the displacement gradient (xX, xY, yX, yY)
FROM_GRAD = np.array([[1.0, 0, 0, 0], [0, 0, 0, 1], [0, 1, 1, 0]])


def solve_elastoplastic(case: Case) -> Result:
    """Load-stepped Newton solve of a quasi-static Mohr-Coulomb Case at small strain."""
    problem = case.problem
    material = problem.material
    if not isinstance(material, MohrCoulomb):
        raise ProblemError("the elastoplastic solver needs model = \"mohr-coulomb\"", key="material.model")
    if any(t.follower for t in problem.tractions):
        raise ProblemError("follower loads need a large-deformation material; the Mohr-Coulomb solver is "
                           "small-strain", key="traction")
    timer = Timer()
    conf = build_configuration(case, timer)
    nodes, quad, sf = conf.disc.nodes, conf.disc.quadrature, conf.sf
    n = len(nodes)
    w = quad.weights * problem.thickness
    G = gradient_operator(sf.dNdx, sf.dNdy)
    GT = G.T
    q = conf.traction
    loads = BoundaryLoads(conf.sf_traction.N, q.weights * problem.thickness, conf.tx, conf.ty, q.ends, q.follower,
                          nodes[q.ends[:, 1]] - nodes[q.ends[:, 0]],
                          problem.thickness * assembly.point_load_vector(nodes, problem, conf.rpim))
    F_body = assembly.body_force_vector(sf.N, w, problem)          # gravity, ramped with the load factor
    probe_xy = np.array([[p.x, p.y] for p in problem.probes]).reshape(-1, 2)
    sf_p = shape_functions(nodes, probe_xy, derivatives=False, **conf.rpim) if len(probe_xy) else None
    timer.lap("assembly")

    committed = {"U": np.zeros(2 * n), "stress": np.zeros((len(w), 4))}
    region = np.zeros(len(w), dtype=np.int8)
    series: list[dict] = []

    def strain_increment(U: np.ndarray) -> np.ndarray:
        return (G @ (U - committed["U"])).reshape(-1, 4) @ FROM_GRAD.T

    def assemble(U: np.ndarray, factor: float):
        de = strain_increment(U)
        stress, _ = material.update(committed["stress"], de)
        Dt = material.tangent(committed["stress"], de)
        A = TO_P[None] @ Dt @ FROM_GRAD[None]                       # (m, 4, 4) = dP / d grad u
        f_ext = loads.forces(nodes, factor)[0] + factor * F_body
        P = stress[:, :3] @ TO_P.T
        return f_ext, internal_force(G, P, w, GT), tangent(G, A, w, GT)

    def solve(K, residual):
        return solve_constrained(K, residual, conf.fixed, np.zeros(len(conf.fixed)), "superlu")

    def nodal(values: np.ndarray) -> np.ndarray:
        from .state_transfer import project_to_nodes
        return project_to_nodes(sf.N, w, values)

    def on_converged(factor: float, U: np.ndarray) -> dict:
        nonlocal region
        stress, region = material.update(committed["stress"], strain_increment(U))   # at the converged U
        committed.update(U=U.copy(), stress=stress)
        plastic = int((region != ELASTIC).sum())
        u = U.reshape(-1, 2)
        series.append({"load_factor": factor, "u": u.copy(), "stress": nodal(stress[:, :3])})
        out = {"plastic_points": plastic}
        if sf_p is not None:
            up = sf_p.N @ u
            out.update({p.name: {"x": p.x, "y": p.y, "ux": float(up[i, 0]), "uy": float(up[i, 1])}
                        for i, p in enumerate(problem.probes)})
        return out

    path = step_loads(2 * n, case.loading, conf.fixed, conf.fixed_values, assemble, solve, on_converged)
    timer.lap("solve")
    U = path.U
    u = U.reshape(-1, 2)
    stress_nodes = nodal(committed["stress"][:, :3])
    probes = {}
    if sf_p is not None:
        up, sp_ = sf_p.N @ u, sf_p.N @ stress_nodes
        probes = {p.name: probe_record(p.x, p.y, up[i], sp_[i]) for i, p in enumerate(problem.probes)}
    timer.lap("postprocess")
    sizes = sf.support_sizes
    return Result(
        method="ctm-rpim-mc", points=nodes, u=u, stress=stress_nodes, cells=[("line", conf.disc.boundary.edges)],
        probes=probes, errors={},
        counts={"nodes": n, "integration_points": len(w), "load_increments": sum(h["converged"] for h in path.history),
                "cutbacks": path.cutbacks, "newton_iterations": path.newton_iterations,
                "plastic_points": int((region != ELASTIC).sum()),
                "support_size": {"min": int(sizes.min()), "mean": float(sizes.mean()), "max": int(sizes.max())}},
        timings=timer.total(), history=path.history, series=series,
        parameters={**case.resolved, "derived": {"d_c": conf.disc.d_c, "G": material.G, "K": material.K}},
        defaults=case.defaults)
