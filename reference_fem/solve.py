"""scikit-fem reference solution of a :class:`ctmrpim.problem.model.Problem` (linear elastostatics).

The same Case (problem, node set, match tolerance) the CTM-RPIM solver reads is meshed on the same
nodes and solved with Q1, P1 or P2 elements; the answer is a :class:`ctmrpim.result.Result` of the
same shape, so the two methods are compared point for point and with the same error norms.
"""
from __future__ import annotations

import time
from typing import Callable

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
    FacetBasis,
    LinearForm,
    condense,
    solve,
)
from skfem.assembly.basis import AbstractBasis
from skfem.mesh import Mesh

from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case
from ctmrpim.problem.expressions import Field
from ctmrpim.problem.model import Problem
from ctmrpim.reference.error_norms import relative_errors
from ctmrpim.result import Result, probe_errors, probe_record

from .mesh import FemMesh, build_mesh

SCALAR_ELEMENTS = {"q1": ElementQuad1, "p1": ElementTriP1, "p2": ElementTriP2}
#: Quadrature degree of the stiffness: exact for constant D on affine cells (Q1: 2 x 2 Gauss).
STIFFNESS_ORDER = {"q1": 2, "p1": 1, "p2": 2}
#: Boundary loads: exact for polynomial tractions up to degree 6 against P2 traces.
FACET_ORDER = 8
#: Independent, finer rule for the error norms and the stress projection (well above any element's need).
ERROR_ORDER = 8


def solve_fem(case: Case, element: str = "q1") -> Result:
    """Solve ``case`` with the finite element ``element`` ("q1", "p1" or "p2") on its node set."""
    t0 = time.perf_counter()
    problem = case.problem
    if problem.point_loads:
        raise ProblemError("point loads are not supported by the FEM reference (yet)", key="point_load")
    fm = build_mesh(case, element)
    mesh = fm.mesh
    tol = case.method.match_tolerance * fm.d_c
    vec = ElementVector(SCALAR_ELEMENTS[element]())
    basis = Basis(mesh, vec, intorder=STIFFNESS_ORDER[element])
    t1 = time.perf_counter()

    D = problem.D()
    K = problem.thickness * _stiffness_form(D).assemble(basis)
    F = problem.thickness * _load_vector(problem, fm, vec, tol, basis.N)
    bx, by = problem.body_force
    if bx or by:                                       # gravity: int (density g) . v dx
        F += problem.thickness * LinearForm(lambda v, w: bx * v[0] + by * v[1]).assemble(basis)
    fixed, values = _constrained_dofs(problem, fm, basis, tol)
    t2 = time.perf_counter()

    x = np.zeros(basis.N)
    x[fixed] = values
    u = solve(*condense(K, F, x=x, D=fixed))
    if not np.all(np.isfinite(u)):
        raise ProblemError("the stiffness matrix is singular: the constraints do not stop every rigid-body "
                           "motion", key="constraint")
    t3 = time.perf_counter()

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
        at = _locate(mesh, np.array([pr.x, pr.y]), fm.d_c, pr.name)
        u_p = (basis.probes(at) @ u).ravel()
        s_p = scalar.probes(at) @ stress_dofs
        probes[pr.name] = probe_record(pr.x, pr.y, u_p, s_p[0])

    errors: dict = {}
    if problem.exact is not None:
        xq = np.asarray(fine.global_coordinates()).reshape(2, -1).T
        wq = np.asarray(fine.dx).ravel()
        errors = relative_errors(problem, xq, wq, np.asarray(uh).reshape(2, -1).T, stress_q.reshape(3, -1).T)
        errors["probes"] = probe_errors(problem, probes)
    t4 = time.perf_counter()

    return Result(
        method=f"fem-{element}", points=points, u=u_nodes, stress=stress_nodes,
        cells=[(fm.cell_type, fm.cells)], probes=probes, errors=errors,
        counts={"nodes": int(mesh.nvertices), "dofs": int(basis.N), "elements": int(mesh.nelements),
                "integration_points": int(np.asarray(basis.dx).size)},
        timings={"mesh": t1 - t0, "assembly": t2 - t1, "solve": t3 - t2, "postprocess": t4 - t3,
                 "total": t4 - t0},
        parameters={**case.resolved, "derived": {"d_c": fm.d_c, "element": element}},
        defaults=list(case.defaults))


def _voigt(grad: np.ndarray) -> np.ndarray:
    """(exx, eyy, gxy) from grad[i, j] = du_i/dx_j (engineering shear, as D expects)."""
    return np.array([grad[0, 0], grad[1, 1], grad[0, 1] + grad[1, 0]])


def _stiffness_form(D: np.ndarray) -> BilinearForm:
    @BilinearForm
    def stiffness(u, v, w):
        return np.einsum("i...,ij,j...->...", _voigt(v.grad), D, _voigt(u.grad))

    return stiffness


@LinearForm
def _traction_form(v, w):
    return w.tx * v[0] + w.ty * v[1]


def _selected_facets(where: Field, fm: FemMesh, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Boundary vertices satisfying ``where``, and the boundary facets whose both ends do."""
    mesh = fm.mesh
    bfacets = mesh.boundary_facets()
    bverts = np.unique(mesh.facets[:, bfacets])
    hit = np.asarray(where(mesh.p[0, bverts], mesh.p[1, bverts], eq_tol=tol), dtype=bool)
    vmask = np.zeros(mesh.nvertices, dtype=bool)
    vmask[bverts[hit]] = True
    both = vmask[mesh.facets[0, bfacets]] & vmask[mesh.facets[1, bfacets]]
    return bverts[hit], bfacets[both]


def _load_vector(problem: Problem, fm: FemMesh, vec, tol: float, ndofs: int) -> np.ndarray:
    """Dead tractions and pressures, integrated over the boundary facets they select (follower
    tractions are the large-deformation solver's: :mod:`reference_fem.hyperelastic`)."""
    F = np.zeros(ndofs)
    loads: list[tuple[str, Field, Callable[[np.ndarray, np.ndarray, np.ndarray], tuple]]] = []
    for i, tr in enumerate(problem.tractions):
        if tr.follower:
            continue
        loads.append((f"traction[{i}]", tr.where,
                      lambda x, y, n, tr=tr: (_value(tr.tx, x, y), _value(tr.ty, x, y))))
    for i, pr in enumerate(problem.pressures):
        # p pushes into the body: t = -p n with n the outward normal
        loads.append((f"pressure[{i}]", pr.where,
                      lambda x, y, n, pr=pr: (-pr.p(x, y) * n[0], -pr.p(x, y) * n[1])))
    for key, where, traction in loads:
        _, facets = _selected_facets(where, fm, tol)
        if len(facets) == 0:
            raise ProblemError(f"where = {where.text!r} selects no boundary segment (both ends must match)",
                               key=key)
        fb = FacetBasis(fm.mesh, vec, facets=facets, intorder=FACET_ORDER)
        xq = np.asarray(fb.global_coordinates())
        tx, ty = traction(xq[0], xq[1], np.asarray(fb.normals))
        F += _traction_form.assemble(fb, tx=tx, ty=ty)
    return F


def _value(f: Field | None, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.zeros_like(x) if f is None else f(x, y)


def _constrained_dofs(problem: Problem, fm: FemMesh, basis: AbstractBasis,
                      tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Fixed DOFs and their values: vertex DOFs at selected boundary vertices, plus (P2) the midside
    DOFs of facets whose both ends are selected; a later constraint overrides an earlier one."""
    dofs, vals = [], []
    for i, c in enumerate(problem.constraints):
        verts, facets = _selected_facets(c.where, fm, tol)
        if len(verts) == 0:
            raise ProblemError(f"where = {c.where.text!r} selects no boundary node", key=f"constraint[{i}]")
        for comp, f in enumerate((c.ux, c.uy)):
            if f is None:
                continue
            # nodal_dofs / facet_dofs rows follow dofnames u^1, u^2 of the vector element
            d = basis.nodal_dofs[comp, verts]
            if basis.facet_dofs.size:
                d = np.concatenate([d, basis.facet_dofs[comp, facets]])
            dofs.append(d)
            vals.append(f(basis.doflocs[0, d], basis.doflocs[1, d]))
    dofs_all = np.concatenate(dofs)[::-1]
    vals_all = np.concatenate(vals)[::-1]
    fixed, first = np.unique(dofs_all, return_index=True)   # first of the reversed = last given
    return fixed, vals_all[first]


def _project(scalar: AbstractBasis, values: np.ndarray) -> np.ndarray:
    """L2 projection of k fields given at the quadrature points onto ``scalar`` (one factorisation)."""
    M = BilinearForm(lambda u, v, w: u * v).assemble(scalar)
    rhs = np.column_stack([LinearForm(lambda v, w: w.s * v).assemble(scalar, s=s) for s in values])
    return splu(csc_matrix(M)).solve(rhs)


def _locate(mesh: Mesh, point: np.ndarray, d_c: float, name: str) -> np.ndarray:
    """``point`` as a (2, 1) array inside the mesh: a probe on a curved boundary may fall just outside
    the chords of a triangulation, and is then moved onto the nearest boundary facet."""
    at = point.reshape(2, 1)
    try:
        mesh.element_finder()(at[0], at[1])
        return at
    except ValueError:
        pass
    f = mesh.boundary_facets()
    a, b = mesh.p[:, mesh.facets[0, f]].T, mesh.p[:, mesh.facets[1, f]].T
    ab = b - a
    s = np.clip(((point - a) * ab).sum(1) / (ab * ab).sum(1), 0.0, 1.0)
    near = a + s[:, None] * ab
    k = np.argmin(np.linalg.norm(near - point, axis=1))
    if np.linalg.norm(near[k] - point) > 0.5 * d_c:
        raise ProblemError(f"probe {name!r} at ({point[0]:g}, {point[1]:g}) lies outside the mesh", key="probe")
    centroid = mesh.p[:, mesh.t[:, mesh.f2t[0, f[k]]]].mean(axis=1)
    return (near[k] + 1e-9 * (centroid - near[k])).reshape(2, 1)
