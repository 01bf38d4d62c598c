"""scikit-fem reference for the Mohr-Coulomb analyses: the same :class:`ctmrpim.solvers.plastic_system.PlasticSystem`
(one material class, one return mapping, one iteration, one strength-reduction driver) on a finite
element discretisation of the same Problem.

The system only needs the displacement-gradient operator G at the quadrature points and their
weights: here G is built from the element basis (``basis.basis[i][0].grad`` of each local dof), the
points are the elements' quadrature points, and the loads come from the same forms as the linear
reference. For output, stresses and plastic strains are averaged onto the vertices with the lumped
(row-sum) mass of the linear hat functions: a consistent projection onto P2 oscillates around a
localised shear band (measured: nodal plastic strain down to -0.0033 beside a peak of 0.0046), the lumped
one keeps a positive field positive. Probes read the consistent projection onto the element's space.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csc_matrix
from scipy.sparse.linalg import splu
from skfem import Basis, BilinearForm, ElementQuad1, ElementTriP1, ElementVector, FacetBasis, LinearForm

from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.problem.case import Case
from ctmrpim.result import Result, probe_record
from ctmrpim.solvers.plastic_analysis import PlasticOutput, run_elastoplastic
from ctmrpim.solvers.plastic_system import PlasticSystem
from ctmrpim.timing import Timer
from reference_fem.boundary_conditions import (
    FACET_ORDER,
    constrained_dofs,
    field_values,
    load_vector,
    locate,
    selected_facets,
)
from reference_fem.mesh import build_mesh
from reference_fem.solve import SCALAR_ELEMENTS

#: The linear element on the same cells: its hat functions average point values onto the vertices.
LINEAR_ELEMENTS = {"q1": ElementQuad1, "p1": ElementTriP1, "p2": ElementTriP1}
#: Quadrature degree: the strain of P2 is linear, so degree 2 integrates the elastic stiffness exactly.
PLASTIC_ORDER = {"q1": 2, "p1": 1, "p2": 2}


def gradient_operator(basis: Basis) -> sp.csr_matrix:
    """G (4m x N): row 4p + c (c = 2k + l) gives du_k/dx_l at quadrature point p = e * nq + q."""
    nel, nq = basis.nelems, basis.X.shape[-1]
    nloc = basis.Nbfun
    grads = np.stack([np.asarray(basis.basis[i][0].grad) for i in range(nloc)])   # (nloc, 2, 2, nel, nq)
    vals = grads.reshape(nloc, 4, nel, nq).transpose(2, 3, 1, 0)                     # (nel, nq, 4, nloc)
    rows = np.broadcast_to((4 * (np.arange(nel)[:, None] * nq + np.arange(nq))[:, :, None, None]
                            + np.arange(4)[None, None, :, None]), vals.shape)
    cols = np.broadcast_to(basis.element_dofs.T[:, None, None, :], vals.shape)
    return sp.csr_matrix((vals.ravel(), (rows.ravel(), cols.ravel())), shape=(4 * nel * nq, basis.N))


def solve_fem_elastoplastic(case: Case, element: str = "p2",
                            progress: Callable[[Any], None] = lambda level: None) -> Result:
    """:func:`ctmrpim.solvers.plastic_analysis.run_elastoplastic` with the finite element ``element``."""
    problem = case.problem
    if not isinstance(problem.material, MohrCoulomb):
        raise ProblemError("the elastoplastic FEM reference needs model = \"mohr-coulomb\"", key="material.model")
    if element not in SCALAR_ELEMENTS:
        raise ProblemError(f"element {element!r} is not supported (supported: {', '.join(SCALAR_ELEMENTS)})")
    if problem.point_loads or any(t.follower for t in problem.tractions):
        raise ProblemError("the elastoplastic FEM reference takes dead tractions, pressures and gravity only",
                           key="traction")
    timer = Timer()
    fm = build_mesh(case, element)
    mesh = fm.mesh
    tol = case.method.match_tolerance * fm.d_c
    scalar_element = SCALAR_ELEMENTS[element]()
    vec = ElementVector(scalar_element)
    basis = Basis(mesh, vec, intorder=PLASTIC_ORDER[element])
    scalar = basis.with_element(scalar_element)
    thickness = problem.thickness
    w = thickness * np.asarray(basis.dx).ravel()
    F_dead = thickness * load_vector(problem, fm, vec, tol, basis.N)
    bx, by = problem.body_force
    body = thickness * LinearForm(lambda v, w_: bx * v[0] + by * v[1]).assemble(basis)
    fixed, fixed_values = constrained_dofs(problem, fm, basis, tol)
    system = PlasticSystem(gradient_operator(basis).tobsr(blocksize=(4, 1)), w, fixed, fixed_values,
                           lambda factor: factor * F_dead, body, problem.material, tangent=case.loading.tangent)
    mass = splu(csc_matrix(BilinearForm(lambda u, v, w_: u * v).assemble(scalar)))
    nel, nq = basis.nelems, basis.X.shape[-1]
    hats = basis.with_element(LINEAR_ELEMENTS[element]())
    lumped = LinearForm(lambda f, w_: f).assemble(hats)
    probe_at = [locate(mesh, np.array([p.x, p.y]), fm.d_c, p.name) for p in problem.probes]
    probe_u = [basis.probes(at) for at in probe_at]
    probe_s = [scalar.probes(at) for at in probe_at]
    timer.lap("assembly")

    def moments(space, values: np.ndarray) -> np.ndarray:
        """(space.N, k): int f_k phi_i of point values f (m, k) against the functions of ``space``."""
        v = values.reshape(nel, nq, -1)
        return np.column_stack([LinearForm(lambda f, w_: w_.s * f).assemble(space, s=v[:, :, k])
                                for k in range(v.shape[-1])])

    def projected(values: np.ndarray) -> np.ndarray:
        """(scalar.N, k) L2 projection of point values (m, k)."""
        return mass.solve(moments(scalar, values))

    def vertex_average(values: np.ndarray) -> np.ndarray:
        """(nvertices, k) lumped-mass average of point values (m, k) onto the vertices."""
        return moments(hats, values) / lumped[:, None]

    def probe_values(U: np.ndarray, stress: np.ndarray | None) -> dict:
        s_dofs = projected(stress) if stress is not None else None
        out = {}
        for p, Pu, Ps in zip(problem.probes, probe_u, probe_s):
            s = (Ps @ s_dofs)[0] if s_dofs is not None else np.full(3, np.nan)
            out[p.name] = probe_record(p.x, p.y, (Pu @ U).ravel(), s)
        return out

    material = problem.material
    out = PlasticOutput(
        method=f"fem-{element}-mc", points=mesh.p.T.copy(), cells=[(fm.cell_type, fm.cells)],
        displacement=lambda U: U[basis.nodal_dofs].T.copy(), nodal=vertex_average, average=vertex_average,
        probe_values=probe_values, peak_traction=_peak_traction(problem, fm, vec, tol),
        counts={"nodes": int(mesh.nvertices), "dofs": int(basis.N), "elements": int(mesh.nelements),
                "integration_points": len(w)},
        parameters={**case.resolved, "derived": {"d_c": fm.d_c, "element": element, "G": material.G,
                                                 "K": material.K}})
    return run_elastoplastic(case, system, out, timer, progress)


def _peak_traction(problem, fm, vec, tol: float) -> float:
    """Largest traction or pressure magnitude on the loaded facets at full load (the limit pressure's
    scale; the meshfree solver reports the same from its loaded segments)."""
    peak = 0.0
    for where, components in ([(tr.where, (tr.tx, tr.ty)) for tr in problem.tractions]
                              + [(pr.where, (pr.p,)) for pr in problem.pressures]):
        _, facets = selected_facets(where, fm, tol)
        if len(facets) == 0:
            continue
        xq = np.asarray(FacetBasis(fm.mesh, vec, facets=facets, intorder=FACET_ORDER).global_coordinates())
        values = [field_values(f, xq[0], xq[1]) for f in components]
        peak = max(peak, float(np.sqrt(sum(v ** 2 for v in values)).max()))
    return peak
