"""Linear elastostatics with dolfinx: K u = F with the problem's D (plane stress or strain), a direct solve
(PETSc preonly + LU with MUMPS), then what the bridge reads back (probes, nodal fields, errors, energy).

    K = t * int eps(v)^T D eps(u) dx,   F = t * (int t . v ds + int b . v dx),

the quadrature degrees those of the scikit-fem reference (``spec["quadrature"]``), so that both integrate
the same points: the stiffness exactly, the loads with the same rule.
"""
from __future__ import annotations

import time

import basix
import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from fx_mesh import MeshData
from fx_post import Probes, at_vertices, integral, lu, project, relative_errors, voigt_strain
from fx_problem import Discrete, WorkerProblem, dead_load, discretise
from petsc4py import PETSc


def solve(md: MeshData, spec: dict, timings: dict) -> tuple[dict, dict]:
    """Solve the linear problem ``spec`` on ``md``: the result record and its nodal arrays."""
    start = time.perf_counter()
    d = discretise(md, spec)
    q = spec["quadrature"]
    V = d.V
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    D = fem.Constant(md.mesh, PETSc.ScalarType(np.asarray(spec["material"]["D"], float)))
    dx = ufl.Measure("dx", domain=md.mesh, metadata={"quadrature_degree": q["stiffness"]})
    a = fem.form(d.thickness * ufl.inner(D * voigt_strain(u), voigt_strain(v)) * dx)
    L = dead_load(d, spec, v)
    timings["setup"] = time.perf_counter() - start

    start = time.perf_counter()
    A = fem_petsc.assemble_matrix(a, bcs=d.bcs)
    A.assemble()
    if L is None:
        b = A.createVecRight()
        b.zeroEntries()
    else:
        b = fem_petsc.assemble_vector(fem.form(L))
    fem_petsc.apply_lifting(b, [a], bcs=[d.bcs])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    fem_petsc.set_bc(b, d.bcs)
    timings["assembly"] = time.perf_counter() - start

    start = time.perf_counter()
    uh = fem.Function(V)
    lu(A).solve(b, uh.vector)
    uh.x.scatter_forward()
    if not np.all(np.isfinite(uh.x.array)):
        raise WorkerProblem("the stiffness matrix is singular: the constraints do not stop every rigid-body motion")
    timings["solve"] = time.perf_counter() - start

    start = time.perf_counter()
    record, arrays = _postprocess(d, spec, uh, D)
    ncells = int(md.mesh.topology.index_map(2).size_local)
    points = len(basix.make_quadrature(getattr(basix.CellType, md.cell), q["stiffness"])[1])
    record["counts"] = {"nodes": len(md.input_vertex), "dofs": int(V.dofmap.index_map.size_local * 2),
                        "elements": ncells, "integration_points": ncells * points}
    timings["postprocess"] = time.perf_counter() - start
    return record, arrays


def _postprocess(d: Discrete, spec: dict, uh: fem.Function, D) -> tuple[dict, dict]:
    """Probes, nodal displacement and projected stress, errors and strain energy of the solution ``uh``."""
    md, q = d.md, spec["quadrature"]
    stress = D * voigt_strain(uh)
    projected = project(md, d.degree, [stress[i] for i in range(3)], q["projection"])
    probes = spec["probes"]
    at = Probes(md, np.array([p["at"] for p in probes]).reshape(-1, 2), [p["name"] for p in probes])
    u_p, s_p = (at(uh), at(projected)) if probes else ([], [])
    record = {
        "probes": {p["name"]: {"x": p["x"], "y": p["y"], "ux": float(u_p[i][0]), "uy": float(u_p[i][1]),
                               **{k: float(s_p[i][j]) for j, k in enumerate(("sxx", "syy", "sxy"))}}
                   for i, p in enumerate(probes)},
        "errors": relative_errors(md, d.translate, spec.get("exact"), uh, stress, np.asarray(spec["material"]["D"]),
                                  q["error"]),
        # 1/2 int eps:D:eps t dx with the stiffness's rule (exact: the same number as 1/2 u.K u)
        "strain_energy": 0.5 * spec["thickness"] * integral(md, ufl.inner(stress, voigt_strain(uh)),
                                                            q["stiffness"]),
    }
    return record, {"u": at_vertices(md, uh), "stress": at_vertices(md, projected), "masks": d.masks}
