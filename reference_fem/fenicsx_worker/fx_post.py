"""What the bridge reads back from a dolfinx solution: nodal values in the input's vertex order, stresses
L2-projected onto the element's own continuous scalar space (the scikit-fem reference's evaluation rule:
P2 stresses are discontinuous at nodes, their projection is not), values at probe points, the relative
L2 and energy-norm errors against the exact solution and integrals such as the strain energy.
"""
from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem, geometry
from dolfinx.fem import petsc as fem_petsc
from fx_mesh import REFERENCE_VERTICES, MeshData
from petsc4py import PETSc


def lu(A: PETSc.Mat) -> PETSc.KSP:
    """A direct solver of ``A``: PETSc preonly with the LU factorisation of MUMPS."""
    ksp = PETSc.KSP().create(PETSc.COMM_SELF)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    return ksp


def voigt_strain(u):
    """(exx, eyy, gxy) of the displacement ``u``, engineering shear (as D expects)."""
    g = ufl.grad(u)
    return ufl.as_vector([g[0, 0], g[1, 1], g[0, 1] + g[1, 0]])


def project(md: MeshData, degree: int, fields: list, quadrature: int) -> fem.Function:
    """L2 projection of the scalar UFL ``fields`` onto continuous Lagrange elements of ``degree`` (one vector
    function of len(fields) components; mass matrix and right-hand side with the rule of ``quadrature``)."""
    W = fem.VectorFunctionSpace(md.mesh, ("Lagrange", degree), dim=len(fields))
    dx = ufl.Measure("dx", domain=md.mesh, metadata={"quadrature_degree": quadrature})
    b = fem_petsc.assemble_vector(fem.form(ufl.inner(ufl.as_vector(fields), ufl.TestFunction(W)) * dx))
    # one scalar mass matrix, factorised once, for every component (k times smaller than the blocked one)
    scalar, _ = W.sub(0).collapse()
    p, w = ufl.TrialFunction(scalar), ufl.TestFunction(scalar)
    M = fem_petsc.assemble_matrix(fem.form(p * w * dx))
    M.assemble()
    solver = lu(M)
    rhs, x = M.createVecRight(), M.createVecRight()
    out = fem.Function(W)
    for c in range(len(fields)):
        rows = np.asarray(W.sub(c).collapse()[1])       # the component's dofs in W, in the scalar order
        rhs.array[:] = b.array[rows]
        solver.solve(rhs, x)
        out.x.array[rows] = x.array
    out.x.scatter_forward()
    return out


def at_vertices(md: MeshData, f: fem.Function) -> np.ndarray:
    """(n_input, components) values of the Lagrange function ``f`` at the vertices, in the input's order."""
    V = f.function_space
    bs = V.dofmap.index_map_bs
    k = len(REFERENCE_VERTICES[md.cell])
    layout = V.dofmap.dof_layout
    local = [layout.entity_dofs(0, j)[0] for j in range(k)]
    tdim = md.mesh.topology.dim
    cell_dofs = V.dofmap.list.array.reshape(md.mesh.topology.index_map(tdim).size_local, -1)
    c2v = md.mesh.topology.connectivity(tdim, 0).array.reshape(-1, k)
    vertex_dof = np.empty(len(md.input_vertex), dtype=np.int64)
    for j in range(k):
        vertex_dof[c2v[:, j]] = cell_dofs[:, local[j]]
    out = np.empty((len(md.input_vertex), bs))
    out[md.input_vertex] = f.x.array.reshape(-1, bs)[vertex_dof]
    return out


class Probes:
    """Evaluation of functions at fixed points (k, 2): the cell holding each is found once."""

    def __init__(self, md: MeshData, points: np.ndarray, names: list[str]) -> None:
        msh = md.mesh
        self.points = np.c_[np.asarray(points, float).reshape(-1, 2), np.zeros(len(points))]
        tree = geometry.BoundingBoxTree(msh, msh.topology.dim)
        colliding = geometry.compute_colliding_cells(msh, geometry.compute_collisions(tree, self.points),
                                                     self.points)
        self.cells = []
        for i, name in enumerate(names):
            cells = colliding.links(i)
            if len(cells) == 0:
                raise ValueError(f"probe {name!r} at {tuple(points[i])} lies in no cell")
            self.cells.append(int(cells[0]))

    def __call__(self, f: fem.Function) -> np.ndarray:
        """(k, components) values of ``f`` at the points."""
        return np.array([f.eval(p, [c]) for p, c in zip(self.points, self.cells)])


def integral(md: MeshData, integrand, quadrature: int) -> float:
    """The integral of the scalar UFL ``integrand`` over the body, with the rule of ``quadrature``."""
    dx = ufl.Measure("dx", domain=md.mesh, metadata={"quadrature_degree": quadrature})
    return float(fem.assemble_scalar(fem.form(integrand * dx)))


def relative_errors(md: MeshData, translate, exact: dict | None, uh, stress, D: np.ndarray,
                    quadrature: int) -> dict[str, float]:
    """||u_h - u|| / ||u|| in L2 where ux, uy are given; sqrt(int e:C^-1:e) / sqrt(int s:C^-1:s) with
    e = s_h - s where sxx, syy, sxy are (``stress`` the Voigt stress of u_h, C = D^-1); NaN where the exact
    field vanishes."""
    out: dict[str, float] = {}
    if not exact:
        return out
    zero = 0.0 * ufl.SpatialCoordinate(md.mesh)[0]
    if exact.get("ux") is not None and exact.get("uy") is not None:
        ue = ufl.as_vector([translate(exact["ux"]) + zero, translate(exact["uy"]) + zero])
        out["l2"] = _ratio(integral(md, ufl.inner(uh - ue, uh - ue), quadrature),
                           integral(md, ufl.inner(ue, ue), quadrature))
    if all(exact.get(k) is not None for k in ("sxx", "syy", "sxy")):
        se = ufl.as_vector([translate(exact[k]) + zero for k in ("sxx", "syy", "sxy")])
        C = ufl.as_matrix(np.linalg.inv(D).tolist())
        de = stress - se
        out["energy"] = _ratio(integral(md, ufl.inner(de, C * de), quadrature),
                               integral(md, ufl.inner(se, C * se), quadrature))
    return out


def _ratio(num: float, den: float) -> float:
    return float(np.sqrt(num) / np.sqrt(den)) if den > 0 else float("nan")
