"""scikit-fem reference for quasi-static hyperelastic problems: total-Lagrangian Newton with load stepping.

The finite element counterpart of :func:`ctmrpim.solvers.total_lagrangian.solve_total_lagrangian`: the same
Case (neo-Hookean material in plane strain, dead tractions and pressures on the reference boundary,
follower tractions turning with their segment or with their whole face, prescribed displacements
scaled by the load factor) on a mesh of the same field nodes, optionally
refined ``refine`` times for a much finer reference. Loads are stepped by the same driver as the
meshfree solver (:func:`ctmrpim.solvers.load_stepping.step_loads`: Newton-Raphson, reported cut-backs).

    f_int = t * int P_iJ(F) dv_i/dX_J dX,        K = t * int dv_i/dX_J A_iJkL(F) ddu_k/dX_L dX,

with F = I + grad u, and P, A = dP/dF from :meth:`ctmrpim.materials.neo_hookean.NeoHookean.stress_tangent`
evaluated at the quadrature points. The Cauchy stress P F^T / J is L2-projected onto the scalar space
for the nodal and probe values.
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix, csc_matrix
from scipy.sparse.linalg import splu
from skfem import Basis, BilinearForm, ElementVector, FacetBasis, LinearForm, condense, solve

from ctmrpim.errors import ProblemError
from ctmrpim.materials.neo_hookean import NeoHookean
from ctmrpim.problem.case import Case
from ctmrpim.problem.model import Problem
from ctmrpim.result import Result, probe_record
from ctmrpim.solvers.load_stepping import step_loads
from ctmrpim.timing import Timer
from reference_fem.boundary_conditions import (
    FACET_ORDER,
    constrained_dofs,
    field_values,
    load_vector,
    locate,
    selected_facets,
    traction_form,
)
from reference_fem.mesh import FemMesh, build_mesh
from reference_fem.solve import SCALAR_ELEMENTS

#: Quadrature degree of f_int and K (P, A are not polynomial: one order above the linear need for P2).
TANGENT_ORDER = {"q1": 2, "p1": 1, "p2": 4}
#: Quadrature degree of the stress projection (exact mass matrices for every element).
PROJECTION_ORDER = 4


@BilinearForm
def _tangent_form(u, v, w):
    return np.einsum("iJ...,iJkL...,kL...->...", v.grad, w.A, u.grad)


@LinearForm
def _internal_form(v, w):
    return np.einsum("iJ...,iJ...->...", w.P, v.grad)


def _follower_traction(w, dd=None):
    """Follower traction R(theta) t0 at facet points (per unit reference length), or with ``dd`` (the
    change of the current tangent d = F e0) its derivative. e0 is the reference tangent with the body
    on its left, p0 = -n its normal towards the body; cos theta = e0 . e, sin theta = p0 . e."""
    n = w.n
    e0 = np.stack([-n[1], n[0]])
    p0 = -n
    G = w.u.grad
    d = e0 + np.einsum("iJ...,J...->i...", G, e0)
    length = np.sqrt(d[0] ** 2 + d[1] ** 2)
    e = d / length
    tx, ty = w.tx, w.ty
    if dd is None:
        c, s = (e0 * e).sum(0), (p0 * e).sum(0)
    else:   # d(c, s) = (e0, p0) . (I - e e^T) dd / |d|
        dperp = (dd - e * (e * dd).sum(0)) / length
        c, s = (e0 * dperp).sum(0), (p0 * dperp).sum(0)
    return c * tx - s * ty, s * tx + c * ty


@LinearForm
def _follower_form(v, w):
    rx, ry = _follower_traction(w)
    return rx * v[0] + ry * v[1]


@BilinearForm
def _follower_stiffness_form(u, v, w):
    """-d(F_ext)/du of the follower traction (the load stiffness; not symmetric)."""
    n = w.n
    e0 = np.stack([-n[1], n[0]])
    drx, dry = _follower_traction(w, dd=np.einsum("iJ...,J...->i...", u.grad, e0))
    return -(drx * v[0] + dry * v[1])


def _follower_tractions(problem, fm: FemMesh, vec, tol: float, turn: str
                        ) -> list[tuple[np.ndarray, FacetBasis, np.ndarray, np.ndarray]]:
    """Facets, facet basis and nominal tractions of the follower tractions that turn as ``turn``."""
    out = []
    for i, tr in enumerate(problem.tractions):
        if not (tr.follower and tr.turn == turn):
            continue
        _, facets = selected_facets(tr.where, fm, tol)
        if len(facets) == 0:
            raise ProblemError(f"where = {tr.where.text!r} selects no boundary segment", key=f"traction[{i}]")
        fb = FacetBasis(fm.mesh, vec, facets=facets, intorder=FACET_ORDER)
        xq = np.asarray(fb.global_coordinates())
        out.append((facets, fb, field_values(tr.tx, xq[0], xq[1]), field_values(tr.ty, xq[0], xq[1])))
    return out


@LinearForm
def _rotated_traction_form(v, w):
    return -w.ty * v[0] + w.tx * v[1]          # t0 turned by 90 degrees


class FaceFollower:
    """Follower tractions that turn with the chord of their connected face (``turn = "face"``).

    All tractions on one face turn by the same angle, so F_ext = c F0 + s F90 with F0 the dead
    vector of t0, F90 that of t0 turned by 90 degrees, and (c, s) = (e0 . e, p0 . e) of the chord
    between the face's two end vertices; the load stiffness is the rank-2 term
    -(F0 dc/dU + F90 ds/dU), non-zero in the four dofs of those vertices only."""

    def __init__(self, problem: Problem, fm: FemMesh, vec: ElementVector, basis: Basis, tol: float) -> None:
        self.faces: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        facets_all, F0, F90 = [], np.zeros(basis.N), np.zeros(basis.N)
        for facets, fb, tx, ty in _follower_tractions(problem, fm, vec, tol, "face"):
            F0 += problem.thickness * traction_form.assemble(fb, tx=tx, ty=ty)
            F90 += problem.thickness * _rotated_traction_form.assemble(fb, tx=tx, ty=ty)
            facets_all.append(facets)
        if not facets_all:
            return
        ends = fm.mesh.facets[:, np.unique(np.concatenate(facets_all))]
        degree = np.bincount(ends.ravel(), minlength=fm.mesh.nvertices)
        tips = np.flatnonzero(degree == 1)
        if len(tips) != 2:
            raise ProblemError("follower = \"face\" tractions must load one open stretch of boundary in the FEM "
                               f"reference (found {len(tips)} ends)", key="traction")
        a, b = tips
        self.faces.append((basis.nodal_dofs[:, a], basis.nodal_dofs[:, b], fm.mesh.p[:, b] - fm.mesh.p[:, a], F0, F90))

    def forces(self, U: np.ndarray, factor: float) -> tuple[np.ndarray | float, coo_matrix | None]:
        """F_ext (N,) of the face followers at dofs U (N,) and load factor ``factor`` and its stiffness -dF_ext/dU
        (N x N); 0.0 and None without face followers."""
        F, K = 0.0, None
        for da, db, d0, F0, F90 in self.faces:
            d = d0 + U[db] - U[da]
            length = np.linalg.norm(d)
            e0 = d0 / np.linalg.norm(d0)
            p0 = np.array([-e0[1], e0[0]])
            e = d / length
            proj = (np.eye(2) - np.outer(e, e)) / length
            dc, ds = e0 @ proj, p0 @ proj                    # derivatives w.r.t. d
            F = F + factor * ((e0 @ e) * F0 + (p0 @ e) * F90)
            cols = np.concatenate([db, da])
            rows = np.flatnonzero((F0 != 0) | (F90 != 0))
            block = -factor * (np.outer(F0[rows], np.r_[dc, -dc]) + np.outer(F90[rows], np.r_[ds, -ds]))
            Kf = coo_matrix((block.ravel(), (np.repeat(rows, 4), np.tile(cols, len(rows)))), shape=(len(U), len(U)))
            K = Kf if K is None else K + Kf
        return F, K


def _deformation_gradients(basis: Basis, U: np.ndarray) -> np.ndarray:
    """F = I + grad u at the quadrature points, as (nel * nq, 2, 2)."""
    grad = np.asarray(basis.interpolate(U).grad)                 # (2, 2, nel, nq)
    return np.eye(2)[None] + grad.transpose(2, 3, 0, 1).reshape(-1, 2, 2)


def _stress_tangent(material: NeoHookean, basis: Basis, U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """P (2, 2, nel, nq) and A (2, 2, 2, 2, nel, nq) at the quadrature points of ``basis``."""
    nel, nq = basis.nelems, basis.X.shape[-1]
    P, A = material.stress_tangent(_deformation_gradients(basis, U))
    return (P.reshape(nel, nq, 2, 2).transpose(2, 3, 0, 1),
            A.reshape(nel, nq, 2, 2, 2, 2).transpose(2, 3, 4, 5, 0, 1))


def _cauchy(material: NeoHookean, basis: Basis, U: np.ndarray) -> np.ndarray:
    """(4, nel, nq) Cauchy stress sxx, syy, sxy = P F^T / J and szz = lambda ln J / J (plane strain, F33 = 1)
    at the quadrature points of ``basis``."""
    F = _deformation_gradients(basis, U)
    P, _ = material.stress_tangent(F)
    J = np.linalg.det(F)
    sig = P @ F.transpose(0, 2, 1) / J[:, None, None]
    nel, nq = basis.nelems, basis.X.shape[-1]
    return np.stack([sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1], material.lam * np.log(J) / J]).reshape(4, nel, nq)


def _strain_energy(material: NeoHookean, basis: Basis, U: np.ndarray) -> float:
    """int W(F) dX with W = mu/2 (tr C + 1 - 3) - mu ln J + lambda/2 (ln J)^2 (the module's neo-Hookean model
    in plane strain), by the rule of ``basis``."""
    F = _deformation_gradients(basis, U)
    lnJ = np.log(np.linalg.det(F))
    W = material.mu / 2 * ((F * F).sum((1, 2)) - 2) - material.mu * lnJ + material.lam / 2 * lnJ ** 2
    return float(W @ np.asarray(basis.dx).ravel())


def _split(stress: np.ndarray) -> dict[str, np.ndarray]:
    """``stress`` (n, 3) and ``stress_zz`` (n,) of nodal stresses (n, 4: sxx, syy, sxy, szz)."""
    return {"stress": stress[:, :3], "stress_zz": stress[:, 3]}


def solve_fem_hyperelastic(case: Case, element: str = "p2", refine: int = 0) -> Result:
    """Load-stepped total-Lagrangian Newton solve of a quasi-static neo-Hookean ``case`` with the finite
    element ``element`` ("q1", "p1" or "p2") on its node set, the mesh refined ``refine`` times."""
    timer = Timer()
    problem = case.problem
    material = problem.material
    if problem.analysis != "quasi-static" or not isinstance(material, NeoHookean):
        raise ProblemError("the hyperelastic FEM reference needs analysis = \"quasi-static\" and "
                           "model = \"neo-hookean\"", key="material.model")
    if problem.plane != "strain":
        raise ProblemError("the neo-Hookean model is implemented in plane strain; set problem.plane = \"strain\"",
                           key="problem.plane")
    if element not in SCALAR_ELEMENTS:
        raise ProblemError(f"element {element!r} is not supported (supported: {', '.join(SCALAR_ELEMENTS)})")
    if not (isinstance(refine, int) and refine >= 0):
        raise ProblemError(f"refine = {refine!r} must be an integer >= 0")
    if problem.point_loads:
        raise ProblemError("point loads are not supported by the FEM reference (yet)", key="point_load")

    fm = build_mesh(case, element)
    if refine:
        mesh = fm.mesh.refined(refine)
        fm = FemMesh(mesh, fm.nodes, fm.d_c, fm.cell_type, mesh.t.T.copy())
    mesh = fm.mesh
    tol = case.method.match_tolerance * fm.d_c
    scalar_element = SCALAR_ELEMENTS[element]()
    vec = ElementVector(scalar_element)
    basis = Basis(mesh, vec, intorder=TANGENT_ORDER[element])
    pbasis = Basis(mesh, vec, intorder=PROJECTION_ORDER)
    scalar = pbasis.with_element(scalar_element)
    timer.lap("mesh")

    thickness = problem.thickness
    F_dead = thickness * load_vector(problem, fm, vec, tol, basis.N)
    fixed, fixed_values = constrained_dofs(problem, fm, basis, tol)
    probe_at = [locate(mesh, np.array([p.x, p.y]), fm.d_c, p.name) for p in problem.probes]
    probe_u = [basis.probes(at) for at in probe_at]                  # (2, N) each
    mass = splu(csc_matrix(BilinearForm(lambda u, v, w: u * v).assemble(scalar)))

    def nodal_stress(U: np.ndarray) -> np.ndarray:
        """(scalar.N, 4) L2 projection of the Cauchy stress (sxx, syy, sxy, szz)."""
        s = _cauchy(material, pbasis, U)
        rhs = np.column_stack([LinearForm(lambda v, w: w.s * v).assemble(scalar, s=c) for c in s])
        return mass.solve(rhs)

    series: list[dict] = []

    followers = [(fb, tx, ty) for _, fb, tx, ty in _follower_tractions(problem, fm, vec, tol, "segment")]
    faces = FaceFollower(problem, fm, vec, basis, tol)

    def assemble(U: np.ndarray, factor: float):
        P, A = _stress_tangent(material, basis, U)      # an inverted material cuts the increment back
        f_ext = factor * F_dead
        K = thickness * _tangent_form.assemble(basis, A=A)
        for fb, tx, ty in followers:
            kw = dict(u=fb.interpolate(U), tx=factor * tx, ty=factor * ty)
            f_ext = f_ext + thickness * _follower_form.assemble(fb, **kw)
            K = K + thickness * _follower_stiffness_form.assemble(fb, **kw)
        F_face, K_face = faces.forces(U, factor)
        if K_face is not None:
            f_ext, K = f_ext + F_face, K + K_face
        return f_ext, thickness * _internal_form.assemble(basis, P=P), K

    def solve_increment(K, residual):
        return solve(*condense(K, residual, D=fixed))

    def on_converged(factor: float, U: np.ndarray) -> dict:
        series.append({"load_factor": factor, "u": U[basis.nodal_dofs].T.copy(),
                       **_split(nodal_stress(U)[scalar.nodal_dofs[0]])})
        out = {}
        for p, Pu in zip(problem.probes, probe_u):
            up = (Pu @ U).ravel()
            out[p.name] = {"x": p.x, "y": p.y, "ux": float(up[0]), "uy": float(up[1])}
        return out

    path = step_loads(basis.N, case.loading, fixed, fixed_values, assemble, solve_increment, on_converged)
    U, history = path.U, path.history
    timer.lap("solve")

    stress_dofs = nodal_stress(U)
    probes = {}
    for p, at, Pu in zip(problem.probes, probe_at, probe_u):
        probes[p.name] = probe_record(p.x, p.y, (Pu @ U).ravel(), (scalar.probes(at) @ stress_dofs)[0, :3])
    timer.lap("postprocess")

    return Result(
        method=f"fem-{element}-tl", points=mesh.p.T.copy(), u=U[basis.nodal_dofs].T.copy(),
        **_split(stress_dofs[scalar.nodal_dofs[0]]), cells=[(fm.cell_type, fm.cells)], probes=probes, errors={},
        counts={"nodes": int(mesh.nvertices), "dofs": int(basis.N), "elements": int(mesh.nelements),
                "integration_points": int(np.asarray(basis.dx).size),
                "load_increments": sum(h["converged"] for h in history), "newton_iterations": path.newton_iterations,
                "cutbacks": path.cutbacks},
        timings=timer.total(),
        history=history, series=series,
        parameters={**case.resolved, "derived": {"d_c": fm.d_c, "element": element, "refine": refine,
                                                 "mu": material.mu, "lambda": material.lam}},
        defaults=list(case.defaults), outcome={"strain_energy": thickness * _strain_energy(material, basis, U)})
