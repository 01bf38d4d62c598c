"""CTM-RPIM linear elastostatics of one configuration, end to end (Sections 2.1.3, 2.2-2.4).

field nodes --alpha shape--> boundary loops --CTM--> integration points and weights
            --boundary Gauss--> traction points --RPIM--> sparse shape functions
            --assembly--> K, F --direct constraints + sparse LU--> U --> stresses at the integration points
            --moving least squares--> nodal and probe stresses; errors
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ctmrpim.discretisation import assembly, consistent_integration
from ctmrpim.discretisation.boundary_conditions import tractions_at
from ctmrpim.discretisation.configuration import BoundaryTags, Configuration, boundary_tags, reference_configuration
from ctmrpim.discretisation.ctm import integration_points
from ctmrpim.discretisation.rpim import ShapeFunctions
from ctmrpim.discretisation.stress_recovery import recovered_stress
from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case
from ctmrpim.problem.model import Problem
from ctmrpim.reference.error_norms import relative_errors
from ctmrpim.result import Result, out_of_plane_stress, probe_errors, probe_record
from ctmrpim.solvers.linear_solver import HALF_SOLVERS, constrained_system, solve_free
from ctmrpim.timing import Timer

#: Error-norm quadrature: bands and sub-segments at most this many d_c, this many Gauss points each way.
#: Checked against 0.5 d_c cells with 4 x 4 points: the energy-norm error comes out within 1 % of its
#: value (cantilever 33 x 9: 3.14 % against 3.12 %; plate with hole: 3.40 % against 3.37 %).
ERROR_CELL = 2.0
ERROR_GAUSS = 3
ERROR_MIN_BAND = 0.25   # merge vertex ordinates closer than this (x d_c): circles have hundreds of vertices


def nodal_stiffness_and_load(case: Case, conf: Configuration, tags: BoundaryTags, D: np.ndarray
                             ) -> tuple[sp.csr_matrix, np.ndarray]:
    """K (2n x 2n) and the traction load (2n,) of ``method.integration = "scni"``
    (:mod:`ctmrpim.discretisation.nodal_integration`): K = sum_I B~_I^T D B~_I A_I minus the Dirichlet
    consistency term with the smoothed stress of each boundary cell, and the tractions on the same cell
    edges the smoothing integrates over, so that the divergence identity holds and the patch test passes."""
    if case.method.boundary != "alpha":
        raise ProblemError("method.integration = \"scni\" smooths over cells clipped by the node loops of the tracked "
                           "boundary: set method.boundary = \"alpha\"", key="method.integration")
    nodal, thickness = conf.nodal, case.problem.thickness
    q = nodal.boundary
    trial = ShapeFunctions(nodal.N_boundary, nodal.bx[nodal.owner], nodal.by[nodal.owner], np.zeros(0))
    K = assembly.stiffness(nodal.bx, nodal.by, conf.w, D)
    K = assembly.subtract(K, consistent_integration.dirichlet_consistency(len(conf.x), tags.fixed, q, trial, D,
                                                                          thickness))
    tx, ty = tractions_at(case.problem, conf.x, q, conf.lengths.match_tolerance)
    return K, assembly.load_vector(nodal.N_boundary, q.weights * thickness, tx, ty)


def _point_loads(conf: Configuration, problem: Problem) -> np.ndarray:
    """The load vector (2n,) of the point forces, the body force and the body load at the integration points."""
    F = problem.thickness * conf.point_forces(problem)
    F += assembly.body_force_vector(conf.sf.N, conf.w, problem)
    if problem.body_load is not None:
        F += assembly.load_vector(conf.sf.N, conf.w, *problem.body_load.at(conf.points).T)
    return F


def solve_ctmrpim(case: Case) -> Result:
    """Solve a linear-elastic Case with CTM-RPIM."""
    problem, method = case.problem, case.method
    timer = Timer()
    conf = reference_configuration(case, timer)
    tags = boundary_tags(case, conf.x, conf.boundary, conf.lengths)
    N_traction = conf.shape_functions_at(tags.traction.points, derivatives=False).N
    timer.lap("shape_functions", boundary_points=len(tags.traction.points))
    sf, nodes, d_c, quad, boundary = conf.sf, conf.x, conf.lengths.d_c, conf.quadrature, conf.boundary
    fixed, fixed_values, traction_q = tags.fixed, tags.fixed_values, tags.traction

    D = problem.D()
    scheme = method.integration
    if scheme == "scni":
        K, F = nodal_stiffness_and_load(case, conf, tags, D)
        F += _point_loads(conf, problem)
    else:
        F = assembly.load_vector(N_traction, traction_q.weights * problem.thickness, tags.tx, tags.ty)
        F += _point_loads(conf, problem)
        if scheme == "ctm-vci":   # Petrov-Galerkin with the corrected test gradients
            # the correction's coefficients where the compiled kernel adds them as it sums (no corrected arrays)
            q, sf_q, *test = consistent_integration.corrected_test_gradients(conf, method, problem.thickness,
                                                                             as_correction=True)
        # the values at the points have served the loads and the correction: they leave before the stiffness is
        # assembled, so that they are not held beside it through the solve (58 MB at 257 x 65)
        conf.sf.N = None
        if scheme == "ctm-vci":   # ... minus the Dirichlet consistency term
            K = assembly.stiffness(sf.dNdx, sf.dNdy, conf.w, D, test=test[0] if test[1] is None else tuple(test))
            del test
            K = assembly.subtract(K, consistent_integration.dirichlet_consistency(len(nodes), fixed, q, sf_q, D,
                                                                                  problem.thickness))
        else:
            K = assembly.stiffness(sf.dNdx, sf.dNdy, conf.w, D)
    # the counts that set the work of the solve, shown while it runs (the progress reporter)
    timer.lap("assembly", integration_points=len(conf.w), dofs=K.shape[0], nonzeros=int(K.nnz))

    # K of the consistent schemes (their Dirichlet terms) is not symmetric: no Cholesky on K itself
    symmetric = scheme in ("ctm", "cell-gauss")
    n_dofs, k_nnz = K.shape[0], int(K.nnz)
    # a symmetric free block is held by its upper triangle where the solver takes that (half the memory)
    system = constrained_system(K, F, fixed, fixed_values, half=symmetric and method.solver in HALF_SOLVERS)
    del K     # one copy of the stiffness (the free block) while it is factorised
    U = solve_free(*system, method.solver, symmetric, nodes)
    del system
    u = U.reshape(-1, 2)
    timer.lap("solve", free_dofs=n_dofs - len(fixed))

    # stresses are recovered from the integration points': a raw D B(x) u oscillates at boundaries
    point_stress = assembly.strain(sf.dNdx, sf.dNdy, u) @ D.T
    pp = np.array([[p.x, p.y] for p in problem.probes]).reshape(-1, 2)
    recovered = recovered_stress(np.r_[nodes, pp], conf.points, conf.w, point_stress, d_c)   # one fit for both
    stress, sp_ = recovered[:len(nodes)], recovered[len(nodes):]
    probes = {}
    if problem.probes:
        up = conf.shape_functions_at(pp, derivatives=False).N @ u
        probes = {p.name: probe_record(p.x, p.y, up[i], sp_[i]) for i, p in enumerate(problem.probes)}
    errors: dict = {}
    if problem.exact is not None:
        eq = integration_points(problem.geometry.loops(), ERROR_CELL * d_c, ERROR_CELL * d_c, ERROR_GAUSS,
                                mode="exact", min_band=ERROR_MIN_BAND * d_c)
        sf_e = conf.shape_functions_at(eq.points)
        u_e = sf_e.N @ u
        s_e = assembly.strain(sf_e.dNdx, sf_e.dNdy, u) @ D.T
        errors = {**relative_errors(problem, eq.points, eq.weights, u_e, s_e),
                  "probes": probe_errors(problem, probes)}
    timer.lap("postprocess")

    sizes = sf.support_sizes
    return Result(
        method="ctm-rpim", points=nodes, u=u, stress=stress, stress_zz=out_of_plane_stress(problem, stress),
        cells=[("line", boundary.edges), ("triangle", boundary.triangles)],
        probes=probes, errors=errors,
        counts={"nodes": len(nodes), "integration_points": len(conf.w),
                "integration_lines": quad.n_lines if quad is not None else 0,
                "traction_points": len(traction_q.weights), "boundary_loops": len(boundary.loops),
                "boundary_nodes": len(tags.boundary_nodes), "holes_filled": boundary.filled_holes,
                "support_size": {"min": int(sizes.min()), "mean": float(sizes.mean()), "max": int(sizes.max())},
                "dofs": 2 * len(nodes), "constrained_dofs": len(fixed), "stiffness_nonzeros": k_nnz},
        timings=timer.total(),
        parameters={**case.resolved, "derived": {**conf.lengths.derived(), "tracked_area": boundary.area,
                                                 "geometry_area": problem.geometry.area}},
        defaults=case.defaults,
    )
