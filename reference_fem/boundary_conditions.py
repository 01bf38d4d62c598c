"""Boundary conditions of the finite-element reference: the facets and vertices a problem's ``where``
selectors pick on a mesh, the dead tractions and pressures integrated over them, constrained dofs, and
probe points located in the mesh. Shared by the linear, hyperelastic and elastoplastic FE solvers."""
from __future__ import annotations

from typing import Callable

import numpy as np
from skfem import FacetBasis, LinearForm
from skfem.assembly.basis import AbstractBasis
from skfem.mesh import Mesh

from ctmrpim.errors import ProblemError
from ctmrpim.problem import supports
from ctmrpim.problem.expressions import Field
from ctmrpim.problem.model import Problem
from reference_fem.mesh import FemMesh

#: Boundary loads: exact for polynomial tractions up to degree 6 against P2 traces.
FACET_ORDER = 8


@LinearForm
def traction_form(v, w):
    return w.tx * v[0] + w.ty * v[1]


def selected_facets(where: Field, fm: FemMesh, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Boundary vertices satisfying ``where``, and the boundary facets whose both ends do."""
    mesh = fm.mesh
    bfacets = mesh.boundary_facets()
    bverts = np.unique(mesh.facets[:, bfacets])
    hit = np.asarray(where(mesh.p[0, bverts], mesh.p[1, bverts], eq_tol=tol), dtype=bool)
    vmask = np.zeros(mesh.nvertices, dtype=bool)
    vmask[bverts[hit]] = True
    both = vmask[mesh.facets[0, bfacets]] & vmask[mesh.facets[1, bfacets]]
    return bverts[hit], bfacets[both]


def load_vector(problem: Problem, fm: FemMesh, vec, tol: float, ndofs: int) -> np.ndarray:
    """Dead tractions and pressures, integrated over the boundary facets they select (follower
    tractions are the large-deformation solver's: :mod:`reference_fem.hyperelastic`)."""
    F = np.zeros(ndofs)
    loads: list[tuple[str, Field, Callable[[np.ndarray, np.ndarray, np.ndarray], tuple]]] = []
    for i, tr in enumerate(problem.tractions):
        if tr.follower:
            continue
        loads.append((f"traction[{i}]", tr.where,
                      lambda x, y, n, tr=tr: (field_values(tr.tx, x, y), field_values(tr.ty, x, y))))
    for i, pr in enumerate(problem.pressures):
        # p pushes into the body: t = -p n with n the outward normal
        loads.append((f"pressure[{i}]", pr.where,
                      lambda x, y, n, pr=pr: (-pr.p(x, y) * n[0], -pr.p(x, y) * n[1])))
    for key, where, traction in loads:
        _, facets = selected_facets(where, fm, tol)
        if len(facets) == 0:
            raise ProblemError(f"where = {where.text!r} selects no boundary segment (both ends must match)",
                               key=key)
        fb = FacetBasis(fm.mesh, vec, facets=facets, intorder=FACET_ORDER)
        xq = np.asarray(fb.global_coordinates())
        tx, ty = traction(xq[0], xq[1], np.asarray(fb.normals))
        F += traction_form.assemble(fb, tx=tx, ty=ty)
    return F


def field_values(f: Field | None, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Values (k,) of an optional field at the points x, y (k,): zero where the field is not given."""
    return np.zeros_like(x) if f is None else f(x, y)


def constrained_dofs(problem: Problem, fm: FemMesh, basis: AbstractBasis,
                     tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Fixed DOFs and their values: vertex DOFs at selected boundary vertices, plus (P2) the midside
    DOFs of facets whose both ends are selected. Constraints that disagree at a DOF, a load that acts only
    on prescribed displacements and (static analyses) constraints that leave a part of the body a rigid-body
    motion are refused, as for CTM-RPIM (:mod:`ctmrpim.problem.supports`)."""
    prescribed = []
    for i, c in enumerate(problem.constraints):
        verts, facets = selected_facets(c.where, fm, tol)
        if len(verts) == 0:
            raise ProblemError(f"where = {c.where.text!r} selects no boundary node", key=f"constraint[{i}]")
        for comp, f in enumerate((c.ux, c.uy)):
            if f is None:
                continue
            # nodal_dofs / facet_dofs rows follow dofnames u^1, u^2 of the vector element
            d = basis.nodal_dofs[comp, verts]
            if basis.facet_dofs.size:
                d = np.concatenate([d, basis.facet_dofs[comp, facets]])
            at = basis.doflocs[:, d]
            prescribed.append(supports.Prescribed(i, d, at.T, np.full(len(d), comp), f(at[0], at[1])))
    fixed, values, positions, components = supports.merge(prescribed)
    mesh = fm.mesh
    bverts = np.unique(mesh.facets[:, mesh.boundary_facets()])
    supports.check_loads_on_supports(problem, mesh.p[0, bverts], mesh.p[1, bverts], tol)
    supports.check_rigid_motion(problem, positions, components, tol)
    return fixed, values


def locate(mesh: Mesh, point: np.ndarray, d_c: float, name: str) -> np.ndarray:
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
