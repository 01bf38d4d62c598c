"""scikit-fem reference solution of a :class:`ctmrpim.problem.model.Problem` (linear elastostatics).

The same Case (problem, node set, match tolerance) the CTM-RPIM solver reads is meshed on the same
nodes and solved with Q1, P1 or P2 elements; the answer is a :class:`ctmrpim.result.Result` of the
same shape, so the two methods are compared point for point and with the same error norms.
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import csc_matrix
from scipy.sparse.linalg import splu
from skfem import (
    Basis,
    BilinearForm,
    ElementQuad1,
    ElementTriP1,
    ElementTriP2,
    ElementVector,
    LinearForm,
    condense,
    solve,
)
from skfem.assembly.basis import AbstractBasis

from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case
from ctmrpim.reference.error_norms import relative_errors
from ctmrpim.result import Result, out_of_plane_stress, probe_errors, probe_record
from ctmrpim.timing import Timer
from reference_fem.boundary_conditions import constrained_dofs, load_vector, locate
from reference_fem.mesh import build_mesh

SCALAR_ELEMENTS = {"q1": ElementQuad1, "p1": ElementTriP1, "p2": ElementTriP2}
#: Quadrature degree of the stiffness: exact for constant D on affine cells (Q1: 2 x 2 Gauss).
STIFFNESS_ORDER = {"q1": 2, "p1": 1, "p2": 2}
#: Independent, finer rule for the error norms and the stress projection (well above any element's need).
ERROR_ORDER = 8


def solve_fem(case: Case, element: str = "q1") -> Result:
    """Solve ``case`` with the finite element ``element`` ("q1", "p1" or "p2") on its node set."""
    timer = Timer()
    problem = case.problem
    if problem.point_loads:
        raise ProblemError("point loads are not supported by the FEM reference (yet)", key="point_load")
    fm = build_mesh(case, element)
    mesh = fm.mesh
    tol = case.method.match_tolerance * fm.d_c
    vec = ElementVector(SCALAR_ELEMENTS[element]())
    basis = Basis(mesh, vec, intorder=STIFFNESS_ORDER[element])
    timer.lap("mesh")

    D = problem.D()
    K = problem.thickness * _stiffness_form(D).assemble(basis)
    F = problem.thickness * load_vector(problem, fm, vec, tol, basis.N)
    bx, by = problem.body_force
    if bx or by:                                       # gravity: int (density g) . v dx
        F += problem.thickness * LinearForm(lambda v, w: bx * v[0] + by * v[1]).assemble(basis)
    if problem.body_load is not None:                  # [body-force]: int b(x) . v dx
        load = problem.body_load
        F += problem.thickness * LinearForm(
            lambda v, w: load.bx(w.x[0], w.x[1]) * v[0] + load.by(w.x[0], w.x[1]) * v[1]).assemble(basis)
    fixed, values = constrained_dofs(problem, fm, basis, tol)
    timer.lap("assembly")

    x = np.zeros(basis.N)
    x[fixed] = values
    u = solve(*condense(K, F, x=x, D=fixed))
    if not np.all(np.isfinite(u)):
        raise ProblemError("the stiffness matrix is singular: the constraints do not stop every rigid-body "
                           "motion", key="constraint")
    timer.lap("solve")

    fine = Basis(mesh, vec, intorder=ERROR_ORDER)
    scalar = fine.with_element(SCALAR_ELEMENTS[element]())
    uh = fine.interpolate(u)
    stress_q = np.einsum("ij,j...->i...", D, _voigt(uh.grad))          # (3, nel, nq): unprojected
    stress_dofs = _project(scalar, stress_q)                           # (scalar.N, 3)
    points = mesh.p.T.copy()
    u_nodes = u[basis.nodal_dofs].T
    stress_nodes = stress_dofs[scalar.nodal_dofs[0]]

    probes = {}
    for pr in problem.probes:  # a handful of named points
        at = locate(mesh, np.array([pr.x, pr.y]), fm.d_c, pr.name)
        u_p = (basis.probes(at) @ u).ravel()
        s_p = scalar.probes(at) @ stress_dofs
        probes[pr.name] = probe_record(pr.x, pr.y, u_p, s_p[0])

    errors: dict = {}
    if problem.exact is not None:
        xq = np.asarray(fine.global_coordinates()).reshape(2, -1).T
        wq = np.asarray(fine.dx).ravel()
        errors = relative_errors(problem, xq, wq, np.asarray(uh).reshape(2, -1).T, stress_q.reshape(3, -1).T)
        errors["probes"] = probe_errors(problem, probes)
    timer.lap("postprocess")

    return Result(
        method=f"fem-{element}", points=points, u=u_nodes, stress=stress_nodes,
        stress_zz=out_of_plane_stress(problem, stress_nodes),
        cells=[(fm.cell_type, fm.cells)], probes=probes, errors=errors,
        counts={"nodes": int(mesh.nvertices), "dofs": int(basis.N), "elements": int(mesh.nelements),
                "integration_points": int(np.asarray(basis.dx).size)},
        timings=timer.total(),
        parameters={**case.resolved, "derived": {"d_c": fm.d_c, "element": element}},
        defaults=list(case.defaults),
        outcome={"strain_energy": 0.5 * float(u @ (K @ u))})   # 1/2 u.K u (K carries the thickness)


def _voigt(grad: np.ndarray) -> np.ndarray:
    """(exx, eyy, gxy) from grad[i, j] = du_i/dx_j (engineering shear, as D expects)."""
    return np.array([grad[0, 0], grad[1, 1], grad[0, 1] + grad[1, 0]])


def _stiffness_form(D: np.ndarray) -> BilinearForm:
    @BilinearForm
    def stiffness(u, v, w):
        return np.einsum("i...,ij,j...->...", _voigt(v.grad), D, _voigt(u.grad))

    return stiffness


def _project(scalar: AbstractBasis, values: np.ndarray) -> np.ndarray:
    """L2 projection of k fields given at the quadrature points onto ``scalar`` (one factorisation)."""
    M = BilinearForm(lambda u, v, w: u * v).assemble(scalar)
    rhs = np.column_stack([LinearForm(lambda v, w: w.s * v).assemble(scalar, s=s) for s in values])
    return splu(csc_matrix(M)).solve(rhs)


