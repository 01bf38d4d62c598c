"""Adaptive updated-Lagrangian CTM-RPIM, quasi-static (paper Sections 2.1.2-2.1.3, 3.2).

The paper's adaptive method: after every converged load increment the field nodes have moved, and
the boundary is re-tracked on the current node positions (the reference triangulation carried while it
stays valid, so corners are kept; the alpha shape once it is not: :func:`carried_boundary`), the CTM lines and their
integration points are laid over the new boundary and the RPIM shape functions are rebuilt there.
No mesh exists, so none distorts.

Within an increment (nodes at x_n, gradients dN/dx_n and weights w_n of the last rebuild), Newton-
Raphson solves F_ext - F_int = 0 for the displacement increment du with

    F_int = G_n^T (w_n P_n),   K = G_n^T diag(w_n dP_n/df) G_n + (follower-load stiffness),

P_n = det f sigma f^-T the first Piola-Kirchhoff stress relative to x_n, f = I + d(du)/dx_n. This is
F_int = sum_p w_{n+1} sigma grad N_{n+1} on x_{n+1} (grad N_{n+1} = grad N_n f^-1, w_{n+1} = w_n det f)
written without a rebuild. The stress update is objective (:mod:`ctmrpim.materials.objective_stress`: Hughes-
Winget rotation for the rate form of linear elasticity, the left Cauchy-Green tensor for neo-
Hookean) and the tangent its exact derivative (closed form for neo-Hookean, complex steps for the rate law),
geometric part included.

With ``method.integration = "ctm-vci"`` each configuration gets the corrected test gradients of its points
and boundary (the constraints must hold on x_n, where F_int is integrated): F_int = G~_n^T (w_n P_n), K = G~_n^T
diag(w_n A) G_n, and the Dirichlet term with P_n n_n recovered at the boundary points from the points', where
the state lives (:mod:`ctmrpim.discretisation.consistent_integration`, ``RecoveredDirichletTerm``).

Where state lives (docs/design.md, 'State under re-tracking'): at the integration points. On a rebuild it
is L2-projected onto the nodes over the old points and evaluated at the new points
(:mod:`ctmrpim.discretisation.state_transfer`); the number of transfers is reported. After the last
increment nothing is rebuilt (nothing is solved there), and where the alpha shape cannot separate parts
that touch (the tip face reaching the root at the full end moment) the rebuild is skipped and the history
says so: the points then move with the body and keep their shape functions, which is exact (it is the
total-Lagrangian form relative to the last rebuild). Tags are fixed on the reference configuration:
constrained dofs, loaded boundary segments (node pairs, each Gauss point at its fraction along its
segment), probes and point loads (material points, carried by the RPIM interpolation of du). Alpha
triangles and RPIM supports only join nodes that were neighbours in the reference configuration (within 2
alpha and 2 r_c), so parts of the body that come together (the ends of the rolled-up beam) are not
welded. The tracked area is compared with the previous configuration's after every rebuild; a jump of
more than AREA_JUMP means the alpha shape opened or closed a gap, and the solve stops saying so.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ctmrpim.discretisation import assembly, consistent_integration, rpim
from ctmrpim.discretisation.alpha_shape import Boundary, alpha_shape, carried_boundary
from ctmrpim.discretisation.boundary_loads import BoundaryLoads
from ctmrpim.discretisation.configuration import BoundaryTags, boundary_tags, build, lay_points, reference_cloud
from ctmrpim.discretisation.point_products import PointProducts
from ctmrpim.discretisation.rpim import ShapeFunctions
from ctmrpim.discretisation.state_transfer import project_to_nodes, transfer
from ctmrpim.errors import ProblemError
from ctmrpim.materials.linear_elastic import LinearElastic
from ctmrpim.materials.neo_hookean import NeoHookean
from ctmrpim.materials.objective_stress import (
    HypoelasticUpdate,
    LeftCauchyGreenUpdate,
    check_orientation,
    det2,
    largest_strain,
)
from ctmrpim.problem.case import Case
from ctmrpim.problem.settings import ScaledMethod
from ctmrpim.result import Result, probe_record
from ctmrpim.solvers.load_stepping import step_loads
from ctmrpim.solvers.pattern_solver import PatternSolver
from ctmrpim.solvers.weak_form import internal_force, tangent
from ctmrpim.timing import Timer

#: Largest relative change of the tracked area from one configuration to the next (docs/design.md,
#: 'Boundary tracking').
AREA_JUMP = 0.02
#: Alpha triangles and RPIM supports join only nodes this many alpha / r_c apart in the reference.
REFERENCE_NEIGHBOURS = 2.0


def stress_update(case: Case) -> HypoelasticUpdate | LeftCauchyGreenUpdate:
    """The objective update of the case's material: neo-Hookean by its left Cauchy-Green tensor,
    linear elasticity as a Hughes-Winget rate law."""
    material, problem = case.problem.material, case.problem
    if isinstance(material, NeoHookean):
        if problem.plane != "strain":
            raise ProblemError("the neo-Hookean model is implemented in plane strain; set problem.plane = \"strain\"",
                               key="problem.plane")
        return LeftCauchyGreenUpdate(material)
    if isinstance(material, LinearElastic):
        return HypoelasticUpdate(problem.D(), problem.plane)
    raise ProblemError(f"the updated-Lagrangian solver has no stress update for {type(material).__name__}",
                       key="material.model")


@dataclass
class TractionTags:
    """Loaded boundary Gauss points as tags: segment node pair, fraction along it, nominal load, and
    the node pair (reference vector d0) a follower load turns with."""

    ends: np.ndarray
    fraction: np.ndarray
    weights: np.ndarray
    tx: np.ndarray
    ty: np.ndarray
    follower: np.ndarray
    turn_ends: np.ndarray
    d0: np.ndarray

    def positions(self, x: np.ndarray) -> np.ndarray:
        """(t, 2) where the tagged points are on their segments with the nodes at ``x`` (n, 2)."""
        a, b = x[self.ends[:, 0]], x[self.ends[:, 1]]
        return a + self.fraction[:, None] * (b - a)


class AdaptiveBody:
    """The node cloud in its current configuration with everything built on it, and the state at its
    integration points. ``trial`` evaluates an increment, ``commit`` accepts it and rebuilds."""

    def __init__(self, case: Case, X: np.ndarray, lengths: ScaledMethod,
                 update: HypoelasticUpdate | LeftCauchyGreenUpdate, traction: TractionTags,
                 material_points: np.ndarray, point_forces: np.ndarray, timer: Timer,
                 reference_triangles: np.ndarray, fixed: np.ndarray | None = None) -> None:
        self.case, self.X, self.lengths, self.update, self.traction, self.timer = (case, X, lengths, update, traction,
                                                                                 timer)
        self.reference_triangles = reference_triangles   # the reference boundary's (corners kept)
        self.tracking = [0, 0]                           # boundaries tracked: carried topology, alpha shape
        self.x = X.copy()
        self.U = np.zeros(X.size)                    # total displacement, interleaved
        self.far = REFERENCE_NEIGHBOURS * lengths.support_radius
        self.material_X = material_points.copy()   # probes, then point loads
        self.material_x = material_points.copy()
        self.point_forces = point_forces
        self.thickness = case.problem.thickness
        self.rebuilds = 0
        self.transfers = 0
        self.skipped_rebuilds = 0
        self.areas: list[float] = []
        self.regeneration = case.method.point_regeneration
        self.fixed = np.zeros(0, int) if fixed is None else fixed       # constrained dofs (the Dirichlet term's)
        self.dirichlet: consistent_integration.RecoveredDirichletTerm | None = None
        # a configuration is built at least once per increment: numba's start, paid once per process, is spread
        # over them, so the compiled shape functions take over from fewer points (measured on the ring's 3658
        # points: 0.55 s against 1.6 s over 16 increments); from the input alone, so a run repeats itself
        self.compiled_from = max(1, rpim.COMPILED_MIN_POINTS // case.loading.steps)
        self._build()
        self.state = update.initial(len(self.w))
        self.nodal_state = update.initial(len(X))
        self.strained = np.tile(np.eye(2), (len(self.w), 1, 1))   # deformation since the points were laid

    # -- configuration -------------------------------------------------------------------------------
    def _track(self) -> tuple[Boundary, float]:
        # the reference triangulation, carried, keeps the corners; the alpha shape once it is no longer valid
        boundary = carried_boundary(self.x, self.reference_triangles, self.X, self.lengths.alpha)
        self.tracking[boundary is None] += 1
        if boundary is None:
            boundary = alpha_shape(self.x, self.lengths.alpha, self.lengths.d_c, reference=self.X,
                                   max_reference_edge=REFERENCE_NEIGHBOURS * self.lengths.alpha)
        if len(boundary.detached):
            i = boundary.detached[0]
            raise ProblemError(f"{len(boundary.detached)} node(s) left the alpha shape after rebuild {self.rebuilds}, "
                               f"e.g. #{i} at ({self.x[i, 0]:g}, {self.x[i, 1]:g}); increase method.alpha",
                               key="method.alpha")
        area = boundary.area
        if self.areas and abs(area - self.areas[-1]) > AREA_JUMP * self.areas[-1]:
            raise ProblemError(
                f"the tracked area jumped from {self.areas[-1]:.6g} to {area:.6g} ({100 * (area / self.areas[-1] - 1):+.2f} %) "
                f"at rebuild {self.rebuilds}: the alpha shape opened or closed a gap (now {len(boundary.loops)} "
                "loop(s)); change method.alpha or use smaller load steps", key="method.alpha")
        return boundary, area

    def _reference_positions(self, points: np.ndarray, boundary: Boundary) -> np.ndarray:
        """Reference positions of points inside the body, mapped through their alpha triangle."""
        tri = boundary.triangles
        a, b, c = (self.x[tri[:, k]] for k in range(3))
        # barycentric coordinates in the kept triangles, found with a k-d tree on their centroids
        centroid = (a + b + c) / 3.0
        k = min(8, len(tri))
        _, cand = cKDTree(centroid).query(points, k=k)
        cand = cand.reshape(len(points), k)
        A, B, C = a[cand], b[cand], c[cand]
        v0, v1, v2 = B - A, C - A, points[:, None, :] - A
        den = v0[..., 0] * v1[..., 1] - v0[..., 1] * v1[..., 0]
        l1 = (v2[..., 0] * v1[..., 1] - v2[..., 1] * v1[..., 0]) / den
        l2 = (v0[..., 0] * v2[..., 1] - v0[..., 1] * v2[..., 0]) / den
        l0 = 1.0 - l1 - l2
        inside = np.minimum(np.minimum(l0, l1), l2)
        best = np.argmax(inside, axis=1)
        rows = np.arange(len(points))
        t = tri[cand[rows, best]]
        lam = np.stack([l0[rows, best], l1[rows, best], l2[rows, best]], axis=1)
        return np.einsum("pk,pkd->pd", lam, self.X[t])

    def _build(self, carried: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> None:
        """Everything on the current node positions; all or nothing (a failure changes no attribute).
        New CTM points over the re-tracked boundary, or, with ``carried = (points, weights, reference
        positions)``, the integration points the body carried through the increment."""
        boundary, area = self._track()
        self.timer.lap("boundary")
        quad = None
        if carried is None:
            quad, w = lay_points(boundary.loop_coordinates(), self.lengths, self.thickness)
            points = quad.points
            ref = self._reference_positions(points, boundary)
        else:
            points, w, ref = carried
        self.timer.lap("integration")
        conf = build(self.x, boundary, points, w, self.lengths, quadrature=quad, reference=(self.X, ref, self.far),
                     compiled_from=self.compiled_from)
        tr = self.traction
        Nt = conf.shape_functions_at(tr.positions(self.x), derivatives=False,
                                     reference=(self.X, tr.positions(self.X), self.far)).N
        N_material = conf.shape_functions_at(self.material_x, derivatives=False,
                                             reference=(self.X, self.material_X, self.far)).N
        n_probe = len(self.material_X) - len(self.point_forces)
        F_points = assembly.load_vector(N_material[n_probe:], np.full(len(self.point_forces), self.thickness),
                                        self.point_forces[:, 0], self.point_forces[:, 1]) \
            if len(self.point_forces) else np.zeros(2 * len(self.x))
        self.conf, self.N_material, self.points_X = conf, N_material, ref
        self.areas.append(area)
        self._set_gradient()
        self.loads = BoundaryLoads(Nt, tr.weights, tr.tx, tr.ty, tr.turn_ends, tr.follower, tr.d0, F_points)
        self.timer.lap("shape_functions")

    def _set_gradient(self, carried: bool = False) -> None:
        """G of the current configuration and the transpose of the test gradients' (G^T, or with ``ctm-vci`` the
        corrected ones', and the Dirichlet term), kept across the Newton iterations; a ``carried`` configuration
        (moved without a rebuild) keeps its shape functions, so their values at the boundary points too."""
        self.G = self.conf.block_gradient()
        self.GT = self.G.T
        test = None
        if self.case.method.integration == "ctm-vci":
            test, term, self.N_boundary = consistent_integration.recovered_consistency(
                self.conf, self.case.method, self.thickness, self.fixed, self.N_boundary if carried else None)
            self.GT, self.dirichlet = test.T.tobsr(), (term if term.active else None)
        # the tangent as one compiled pass over the points (G^T diag(w A) G by sparse products was 44 % of a tip-load run)
        self.products = PointProducts.build(self.G, test, self.w)

    @property
    def boundary(self) -> Boundary:
        """The tracked boundary of the current configuration."""
        return self.conf.boundary

    @property
    def points(self) -> np.ndarray:
        """(m, 2) the integration points."""
        return self.conf.points

    @property
    def w(self) -> np.ndarray:
        """(m,) their weights (thickness included)."""
        return self.conf.w

    @property
    def sf(self) -> ShapeFunctions:
        """The RPIM shape functions at the current integration points, (m, n) sparse rows."""
        return self.conf.sf

    # -- increments ----------------------------------------------------------------------------------
    def relative_gradient(self, du: np.ndarray) -> np.ndarray:
        """(m, 2, 2) f = I + grad du at the points, of the increment du (2n,) (interleaved) from the current
        configuration."""
        return np.eye(2)[None] + (self.G @ du).reshape(-1, 2, 2)

    def trial(self, U: np.ndarray, factor: float) -> tuple[np.ndarray, np.ndarray, sp.csr_matrix]:
        """F_ext, F_int and the tangent at the total displacement ``U`` (interleaved)."""
        du = U - self.U
        f = self.relative_gradient(du)
        check_orientation(f)
        P = self.update.first_piola(f, self.state)
        A = self.update.tangent(f, self.state)
        f_ext, K_load = self.loads.forces(self.x + du.reshape(-1, 2), factor)
        K = tangent(self.G, A, self.w, self.GT) if self.products is None else self.products.tangent(A)
        f_int = internal_force(self.G, P, self.w, self.GT)
        if self.dirichlet is not None:    # ctm-vci: the traction of the recovered stress on constrained edges
            f_int = f_int - self.dirichlet.force(P.reshape(-1, 4))
            K = K - self.dirichlet.stiffness(self.G, A)
        return f_ext, f_int, (K if K_load is None else K + K_load)

    def commit(self, U: np.ndarray, rebuild: bool = True) -> str | None:
        """Accept the increment: advance the state, move nodes and points, re-track, rebuild.

        The CTM points are laid anew over the re-tracked boundary (and the state transferred to them)
        every increment, or, with ``method.point_regeneration = s > 0``, only once a point has been
        strained by more than s since the points were laid; until then the points move with the body
        and keep their state, and only the boundary and the RPIM shape functions are rebuilt.
        Without ``rebuild`` (the last increment), or when the re-tracking cannot separate parts of the
        body that have come into contact (nodes left out of the alpha shape, or an area jump), the
        points move with the body and keep their shape functions, the gradients mapped to the new
        configuration (grad N_{n+1} = grad N_n f^-1, w_{n+1} = w_n det f); the reason is returned so
        the history can say so. ``U`` is the total displacement (interleaved)."""
        du = U - self.U
        f = self.relative_gradient(du)
        state = self.update.advance(f, self.state)
        d = du.reshape(-1, 2)
        w_moved = self.w * det2(f)
        N_old = self.sf.N
        moved = self.points + N_old @ d
        strained = f @ self.strained
        self.U = U.copy()
        self.x = self.X + U.reshape(-1, 2)       # from the total, so prescribed values come out exact
        self.material_x = self.material_x + self.N_material @ d
        self.timer.lap("solve")
        skipped = None
        if rebuild:
            regenerate = self.regeneration == 0.0 or largest_strain(strained) > self.regeneration
            try:
                self._build(None if regenerate else (moved, w_moved, self.points_X))
            except ProblemError as err:
                skipped = f"rebuild skipped, the previous points carried: {err}"
            else:
                self.rebuilds += 1
                if regenerate:
                    self.state, self.nodal_state = transfer(N_old, w_moved, state, self.sf.N)
                    self.strained = np.tile(np.eye(2), (len(self.w), 1, 1))
                    self.transfers += 1
                else:
                    self.state, self.strained = state, strained
                    self.nodal_state = project_to_nodes(self.sf.N, self.w, state)
                self.timer.lap("transfer")
                return None
        self.state, self.strained = state, strained
        self.conf = self.conf.carried(self.x, moved, w_moved, f)
        self._set_gradient(carried=True)
        self.nodal_state = project_to_nodes(N_old, w_moved, state)
        self.skipped_rebuilds += skipped is not None
        self.timer.lap("transfer")
        return skipped

    @property
    def u(self) -> np.ndarray:
        """(n, 2) the total nodal displacements."""
        return self.U.reshape(-1, 2).copy()

    def stress_nodes(self) -> np.ndarray:
        """(n, 3) Cauchy stress sxx, syy, sxy at the nodes (:meth:`_nodal_stress`)."""
        return self._nodal_stress()[:, :3]

    def stress_zz_nodes(self) -> np.ndarray:
        """(n,) out-of-plane Cauchy stress szz at the nodes: the rate law's state holds it; neo-Hookean (plane
        strain, F33 = 1) has szz = lambda ln J / J with J = sqrt(det b)."""
        return self._nodal_stress()[:, 3]

    def _nodal_stress(self) -> np.ndarray:
        """(n, 4) sxx, syy, sxy, szz at the nodes. The rate law's state is the stress: its projection. For
        neo-Hookean the stress is computed at the points and then projected: the projection of b itself can
        lose positive definiteness at a boundary node (det b < 0 gave NaN stresses in series steps)."""
        if isinstance(self.update, HypoelasticUpdate):
            return np.asarray(self.nodal_state[:, :4], float).copy()
        b = self.state
        J = np.sqrt(b[:, 0] * b[:, 1] - b[:, 2] ** 2)
        at_points = np.c_[self.update.cauchy(b), self.update.material.lam * np.log(J) / J]
        return project_to_nodes(self.sf.N, self.w, at_points)

    def step_output(self) -> dict[str, np.ndarray]:
        """A series step's nodal output on the current configuration: ``u``, ``stress``, ``stress_zz``, the tracked
        ``boundary`` edges and the ``triangles`` of the body inside them."""
        stress = self._nodal_stress()      # one projection for the in-plane and the out-of-plane stress
        return {"u": self.u, "stress": stress[:, :3], "stress_zz": stress[:, 3],
                "boundary": self.boundary.edges.copy(), "triangles": self.boundary.triangles.copy()}


def _traction_tags(nodes: np.ndarray, tags: BoundaryTags, thickness: float) -> TractionTags:
    q = tags.traction
    a, b = nodes[q.ends[:, 0]], nodes[q.ends[:, 1]]
    fraction = np.einsum("pd,pd->p", q.points - a, b - a) / np.einsum("pd,pd->p", b - a, b - a)
    turn = q.turn_ends
    return TractionTags(q.ends, fraction, q.weights * thickness, tags.tx, tags.ty, q.follower, turn,
                        nodes[turn[:, 1]] - nodes[turn[:, 0]])


def adaptive_body(case: Case, timer: Timer | None = None) -> tuple[AdaptiveBody, BoundaryTags]:
    """The case's node cloud as an :class:`AdaptiveBody` in its reference configuration, and the tags
    the problem's selectors put on the reference cloud (constrained dofs and the rest)."""
    problem = case.problem
    update = stress_update(case)
    if case.method.boundary != "alpha":
        raise ProblemError("the updated-Lagrangian solver integrates over the tracked boundary; "
                           "set method.boundary = \"alpha\"", key="method.boundary")
    timer = timer or Timer()
    cloud = reference_cloud(case, timer)         # with the checks of a linear run
    tags = boundary_tags(case, cloud.nodes, cloud.boundary, cloud.lengths)
    probes_X = np.array([[p.x, p.y] for p in problem.probes]).reshape(-1, 2)
    loads_X = np.array([[p.x, p.y] for p in problem.point_loads]).reshape(-1, 2)
    forces = np.array([[p.fx, p.fy] for p in problem.point_loads]).reshape(-1, 2)
    body = AdaptiveBody(case, cloud.nodes, cloud.lengths, update, _traction_tags(cloud.nodes, tags, problem.thickness),
                        np.r_[probes_X, loads_X], forces, timer, cloud.boundary.triangles, tags.fixed)
    return body, tags


def solve_updated_lagrangian(case: Case) -> Result:
    """Adaptive load-stepped Newton solve of a quasi-static Case; ``Result.history`` has one entry per
    increment (and one per cut-back), ``Result.series`` the configuration after each increment with
    its tracked boundary."""
    problem = case.problem
    if any(problem.body_force):
        raise ProblemError("gravity is not in the large-deformation solvers yet (a Mohr-Coulomb or linear "
                           "analysis takes it)", key="problem.gravity")
    timer = Timer()
    body, tags = adaptive_body(case, timer)
    update, X = body.update, body.X
    probes_X = body.material_X[:len(problem.probes)]
    n = len(X)
    fixed, fixed_values = tags.fixed, tags.fixed_values
    series: list[dict] = []

    # the rate-form and follower tangents are not symmetric; a configuration's tangents share its pattern
    solve = PatternSolver(2 * n, fixed, nodes=lambda: body.x)

    def probe_values() -> dict:
        u = body.material_x[:len(probes_X)] - probes_X
        return {p.name: {"x": p.x, "y": p.y, "ux": float(u[i, 0]), "uy": float(u[i, 1])}
                for i, p in enumerate(problem.probes)}

    def on_converged(factor: float, U: np.ndarray) -> dict:
        # nothing is solved on the final configuration: no rebuild there (at the full end moment the
        # tip face touches the root face, where no alpha shape separates them)
        skipped = body.commit(U, rebuild=factor < 1.0 - 1e-12)
        series.append({"load_factor": factor, **body.step_output()})
        return {**probe_values(), "tracked_area": body.areas[-1], "boundary_loops": len(body.boundary.loops),
                **({"note": skipped} if skipped else {})}

    path = step_loads(2 * n, case.loading, fixed, fixed_values, body.trial, solve, on_converged)
    history = path.history

    probes = {}
    if len(probes_X):
        rows = body.N_material[:len(probes_X)]
        sig = update.cauchy(np.asarray(rows @ body.nodal_state))
        u = body.material_x[:len(probes_X)] - probes_X
        probes = {p.name: probe_record(p.x, p.y, u[i], sig[i]) for i, p in enumerate(problem.probes)}
    timer.lap("postprocess")
    sizes = body.sf.support_sizes
    areas = np.array(body.areas)
    return Result(
        method="ctm-rpim-ul", points=X, u=body.u, stress=body.stress_nodes(), stress_zz=body.stress_zz_nodes(),
        cells=[("line", body.boundary.edges), ("triangle", body.boundary.triangles)], probes=probes, errors={},
        counts={"nodes": n, "integration_points": len(body.w), "load_increments": sum(h["converged"] for h in history),
                "cutbacks": path.cutbacks, "newton_iterations": path.newton_iterations,
                "rebuilds": body.rebuilds, "state_transfers": body.transfers,
                "rebuilds_skipped": body.skipped_rebuilds,
                "boundaries_tracked": {"carried": body.tracking[0], "alpha_shape": body.tracking[1]},
                "boundary_loops": len(body.boundary.loops),
                "tracked_area": {"initial": float(areas[0]), "final": float(areas[-1]),
                                 "largest_step_change": float(np.abs(np.diff(areas) / areas[:-1]).max())
                                 if len(areas) > 1 else 0.0},
                "support_size": {"min": int(sizes.min()), "mean": float(sizes.mean()), "max": int(sizes.max())}},
        timings=timer.total(), history=history, series=series,
        parameters={**case.resolved, "derived": {"d_c": body.lengths.d_c, "alpha": body.lengths.alpha,
                                                 "support_radius": body.lengths.support_radius}},
        defaults=case.defaults)
