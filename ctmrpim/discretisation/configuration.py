"""One configuration of the node cloud and everything built on it (Sections 2.2-2.4), for every solver.

    field nodes --alpha shape--> boundary loops --CTM--> integration points and weights
                --RPIM--> sparse shape functions and gradients at the points

A :class:`Configuration` is what scikit-fem calls a basis: the node positions it was built on, the
method's lengths for the cloud's spacing (:meth:`ctmrpim.problem.settings.Method.scaled`), the
tracked boundary, the integration points with their weights (thickness included) and the RPIM shape
functions there. The linear, total-Lagrangian and elastoplastic solvers build one on the reference
cloud (:func:`reference_configuration`); the updated-Lagrangian and explicit solvers build one at
every rebuild (:func:`build`), on the current node positions, at new CTM points laid over the
re-tracked boundary (:func:`lay_points`) or at the points the body carried.

The reference configuration also fixes the tags that travel with the nodes (:class:`BoundaryTags`):
constrained dofs and the loaded boundary's Gauss points, selected once by the problem's ``where``
expressions.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ctmrpim.discretisation import assembly
from ctmrpim.discretisation.alpha_shape import Boundary, alpha_shape, validate
from ctmrpim.discretisation.background_cells import cell_points
from ctmrpim.discretisation.boundary_conditions import constrained_dofs, loaded_boundary
from ctmrpim.discretisation.ctm import BoundaryQuadrature, Quadrature, integration_points
from ctmrpim.discretisation.gradient_operator import GradientOperator
from ctmrpim.discretisation.lagrangian_operators import gradient_operator
from ctmrpim.discretisation.nodal_integration import NodalIntegration, smoothed_gradients
from ctmrpim.discretisation.rpim import COMPILED_MIN_POINTS, ShapeFunctions, shape_functions
from ctmrpim.discretisation.rpim_kernels import use_compiled
from ctmrpim.errors import ProblemError
from ctmrpim.materials.objective_stress import inv2
from ctmrpim.problem.case import Case
from ctmrpim.problem.model import Problem
from ctmrpim.problem.node_cloud import check_nodes_inside, make_nodes, mean_node_spacing
from ctmrpim.problem.settings import ScaledMethod
from ctmrpim.timing import Timer

#: The tracked boundary may differ from the geometry's area by this many d_c times its perimeter.
AREA_TOLERANCE = 0.05


@dataclass
class Configuration:
    """Everything built on one configuration ``x`` of the node cloud.

    ``x`` (n, 2) node positions; ``points`` (m, 2) integration points and ``w`` (m,) their weights,
    thickness included; ``sf`` the RPIM shape functions there, (m, n) sparse rows; ``active`` the
    nodes of the body (the others are free particles that the shape functions never touch; None:
    all); ``quadrature`` the CTM lines the points were laid on (None for points the body carried)."""

    x: np.ndarray
    lengths: ScaledMethod
    boundary: Boundary
    points: np.ndarray
    w: np.ndarray
    sf: ShapeFunctions
    tree: cKDTree
    active: np.ndarray | None = None
    quadrature: Quadrature | None = None
    nodal: NodalIntegration | None = None     # SCNI: the smoothing cells' boundary rule (points = the nodes)
    _G: sp.bsr_matrix | None = field(default=None, repr=False)
    _grad: GradientOperator | None = field(default=None, repr=False)
    #: the force's test gradients where they are not the trial ones (a measurement's corrected gradients;
    #: None: the RPIM gradients, the only ones of a solver)
    tested: GradientOperator | None = field(default=None, repr=False)
    #: :meth:`shape_functions_at`'s ``compiled_from``: 0 where the configuration's own points took the compiled
    #: kernels (numba has started: a few thousand error points or probes then cost a tenth of their numpy time),
    #: else the build's (by the sizes of the input alone, as every such choice)
    compiled_from: int | None = None

    @property
    def N(self) -> sp.csr_matrix:
        """(m, n) shape-function values at the points."""
        return self.sf.N

    @property
    def free(self) -> np.ndarray:
        """(n,) bool: the free particles (nodes outside the body)."""
        out = np.zeros(len(self.x), bool)
        if self.active is not None:
            out[:] = True
            out[self.active] = False
        return out

    def shape_functions_at(self, points: np.ndarray, derivatives: bool = True, **options: Any) -> ShapeFunctions:
        """RPIM of this configuration's nodes at other ``points`` (k, 2): probes, tractions, error points
        (``options``: ``reference`` or the other keywords of :func:`~ctmrpim.discretisation.rpim.shape_functions`)."""
        options.setdefault("compiled_from", self.compiled_from)
        return shape_functions(self.x, points, derivatives=derivatives, tree=self.tree, **options,
                               **self.lengths.rpim())

    def point_forces(self, problem: Problem) -> np.ndarray:
        """(2n,) interleaved: the problem's concentrated forces per unit thickness, F = sum_p N(x_p)^T f_p
        (the Kronecker delta property puts a load at a node on that node alone)."""
        F = np.zeros(2 * len(self.x))
        if problem.point_loads:
            xy = np.array([[p.x, p.y] for p in problem.point_loads])
            F += assembly.load_vector(self.shape_functions_at(xy, derivatives=False).N, np.ones(len(xy)),
                                      np.array([p.fx for p in problem.point_loads]),
                                      np.array([p.fy for p in problem.point_loads]))
        return F

    def block_gradient(self) -> sp.bsr_matrix:
        """G (4m x 2n), the weak form's gradient operator (:mod:`ctmrpim.solvers.weak_form`), built once."""
        if self._G is None:
            self._G = gradient_operator(self.sf.dNdx, self.sf.dNdy)
        return self._G

    def compiled_gradient(self) -> GradientOperator:
        """The compiled gradient and force products of explicit dynamics, built once."""
        if self._grad is None:
            self._grad = GradientOperator(self.sf.dNdx, self.sf.dNdy)
        return self._grad

    def carried(self, x: np.ndarray, points: np.ndarray, w: np.ndarray, f: np.ndarray) -> Configuration:
        """This configuration moved with the body, without a rebuild: nodes at ``x`` (n, 2), points at
        ``points`` (m, 2) with weights ``w`` (m,), and the gradients mapped by the relative deformation
        gradients ``f`` (m, 2, 2) of the move, grad N_{n+1} = grad N_n f^-1; the values N do not change
        (the total-Lagrangian form relative to this configuration)."""
        finv = inv2(f)
        dx, dy = self.sf.dNdx, self.sf.dNdy
        rows = np.repeat(np.arange(dx.shape[0]), np.diff(dx.indptr))
        data_x = dx.data * finv[rows, 0, 0] + dy.data * finv[rows, 1, 0]
        data_y = dx.data * finv[rows, 0, 1] + dy.data * finv[rows, 1, 1]
        sf = ShapeFunctions(self.sf.N, sp.csr_matrix((data_x, dx.indices, dx.indptr), shape=dx.shape),
                            sp.csr_matrix((data_y, dx.indices, dx.indptr), shape=dx.shape),
                            self.sf.support_sizes, self.sf.dropped)
        return replace(self, x=x, points=points, w=w, sf=sf, _G=None, _grad=None, tested=None)

    def moved_points(self, x: np.ndarray) -> np.ndarray:
        """(m, 2) where the points are when the nodes have moved from this configuration's positions to ``x``."""
        return self.points + np.asarray(self.sf.N @ (x - self.x))

    def gradient(self, d: np.ndarray) -> np.ndarray:
        """(m, 4) F = I + grad d (xx, xy, yx, yy) of nodal displacements d (n, 2) relative to ``x``."""
        return self.compiled_gradient().gradient(d)

    def force(self, P: np.ndarray) -> np.ndarray:
        """(n, 2) sum_p w_p P_p grad N of first Piola stresses P (m, 4: xX, xY, yX, yY) relative to ``x``."""
        return self.weighted_force(P * self.w[:, None])

    def weighted_force(self, wP: np.ndarray) -> np.ndarray:
        """(n, 2) sum_p wP_p grad N of first Piola stresses already weighted, wP = w P (m, 4), scattered from the
        points (the explicit point pass's bits); with ``tested`` gradients, sum_p wP_p grad~N."""
        if self.tested is not None:
            return self.tested.force(wP)
        return self.compiled_gradient().scatter_force(wP)


def build(x: np.ndarray, boundary: Boundary, points: np.ndarray, w: np.ndarray, lengths: ScaledMethod, *,
          quadrature: Quadrature | None = None, active: np.ndarray | None = None,
          reference: tuple[np.ndarray, np.ndarray, float] | None = None, min_nodes: int = 0,
          drop_singular: bool = False, compiled_from: int | None = None) -> Configuration:
    """The RPIM shape functions of the nodes ``x`` (n, 2) at ``points`` (m, 2) with weights ``w`` (m,):
    a :class:`Configuration`. ``active`` limits the RPIM cloud to those nodes (the shape functions are
    still indexed by all n); ``reference``, ``min_nodes``, ``drop_singular`` and ``compiled_from`` are passed to
    :func:`~ctmrpim.discretisation.rpim.shape_functions`."""
    cloud = x if active is None else x[active]
    tree = cKDTree(cloud)
    sf = shape_functions(cloud, points, tree=tree, reference=reference, min_nodes=min_nodes,
                         drop_singular=drop_singular, compiled_from=compiled_from, **lengths.rpim())
    if active is not None:
        shape = (len(points), len(x))
        N, dx, dy = (sp.csr_matrix((M.data, active[M.indices], M.indptr), shape=shape)
                     for M in (sf.N, sf.dNdx, sf.dNdy))
        sf = ShapeFunctions(N, dx, dy, sf.support_sizes, sf.dropped)
    compiled = use_compiled(len(points), COMPILED_MIN_POINTS if compiled_from is None else compiled_from)
    return Configuration(x, lengths, boundary, points, w, sf, tree, active, quadrature,
                         compiled_from=0 if compiled else compiled_from)


def lay_points(loops: list[np.ndarray], lengths: ScaledMethod, thickness: float) -> tuple[Quadrature, np.ndarray]:
    """The paper's CTM points over closed ``loops`` (each (k, 2)): lines every r_y, sub-segments of r_x
    (Eqs. 12-24); the quadrature and the weights (m,) times the thickness."""
    quad = integration_points(loops, lengths.r_x, lengths.r_y, lengths.gauss_points, mode="uniform")
    return quad, quad.weights * thickness


@dataclass
class ReferenceCloud:
    """The case's field nodes (n, 2) in the reference configuration, their method lengths and boundary."""

    nodes: np.ndarray
    lengths: ScaledMethod
    boundary: Boundary

    @property
    def d_c(self) -> float:
        """Mean node spacing d_c of the reference cloud (Eq. 36)."""
        return self.lengths.d_c


def track_boundary(case: Case, nodes: np.ndarray, lengths: ScaledMethod) -> Boundary:
    """The body's boundary from the node cloud (alpha shape restricted to the geometry, so corners are
    kept), checked against the geometry's area."""
    geometry = case.problem.geometry
    boundary = alpha_shape(nodes, lengths.alpha, lengths.d_c, inside=geometry.contains)
    if len(boundary.detached):
        i = boundary.detached[0]
        raise ProblemError(f"{len(boundary.detached)} node(s) are outside the alpha shape, e.g. #{i} at "
                           f"({nodes[i, 0]:g}, {nodes[i, 1]:g}); increase method.alpha", key="method.alpha")
    validate(boundary, expected_area=geometry.area, area_tol=AREA_TOLERANCE * lengths.d_c * geometry.perimeter)
    return boundary


def reference_cloud(case: Case, timer: Timer) -> ReferenceCloud:
    """The case's nodes, d_c (Eq. 36) and the method's lengths, and the tracked boundary."""
    geometry = case.problem.geometry
    nodes = make_nodes(geometry, case.nodes, case.base_dir)
    lengths = case.method.scaled(mean_node_spacing(geometry.area, len(nodes)))
    check_nodes_inside(geometry, nodes, tol=lengths.match_tolerance)
    boundary = track_boundary(case, nodes, lengths)
    expected = len(geometry.loops())
    if len(boundary.loops) < expected:
        raise ProblemError(f"the geometry has {expected} boundary loops, the node cloud resolves "
                           f"{len(boundary.loops)}: a hole about the node spacing ({lengths.d_c:.3g}) across or "
                           "smaller is lost; refine the nodes or remove the hole", key="nodes")
    timer.lap("boundary", nodes=len(nodes), loops=len(boundary.loops))
    return ReferenceCloud(nodes, lengths, boundary)


def reference_configuration(case: Case, timer: Timer) -> Configuration:
    """The :class:`Configuration` of the reference cloud, integrated over the tracked boundary
    (``method.boundary = "alpha"``) or the exact geometry (``"geometry"``) by ``method.integration``: CTM
    points (``"ctm"``, ``"ctm-vci"``), background cells (``"cell-gauss"``) or the nodes' smoothing cells
    (``"scni"``: the configuration's points are the nodes and its gradients the smoothed ones)."""
    cloud = reference_cloud(case, timer)
    loops = cloud.boundary.loop_coordinates() if case.method.boundary == "alpha" else case.problem.geometry.loops()
    thickness, scheme, lengths = case.problem.thickness, case.method.integration, cloud.lengths
    if scheme == "scni":
        return _nodal_configuration(cloud, loops, thickness, timer)
    quad = None
    if scheme == "cell-gauss":
        points, w = cell_points(loops, lengths.r_x, lengths.r_y, lengths.gauss_points)
        w = w * thickness
    else:
        quad, w = lay_points(loops, lengths, thickness)
        points = quad.points
    timer.lap("integration", integration_points=len(w))
    conf = build(cloud.nodes, cloud.boundary, points, w, lengths, quadrature=quad)
    timer.lap("shape_functions", integration_points=len(w), nonzeros=int(conf.sf.N.nnz))
    return conf


def _nodal_configuration(cloud: ReferenceCloud, loops: list[np.ndarray], thickness: float,
                         timer: Timer) -> Configuration:
    """SCNI (:mod:`ctmrpim.discretisation.nodal_integration`): the nodes as integration points with their
    smoothing cells' areas, N = I there (the Kronecker delta property), the smoothed gradients."""
    nodes, lengths = cloud.nodes, cloud.lengths
    tree = cKDTree(nodes)
    values = lambda pts: shape_functions(nodes, pts, derivatives=False, tree=tree, **lengths.rpim()).N
    nodal = smoothed_gradients(nodes, loops, cloud.boundary.edges, values)
    timer.lap("integration", integration_points=len(nodes))
    sf = ShapeFunctions(sp.identity(len(nodes), format="csr"), nodal.bx, nodal.by, np.diff(nodal.bx.indptr))
    timer.lap("shape_functions")
    return Configuration(nodes, lengths, cloud.boundary, nodes.copy(), nodal.areas * thickness, sf, tree,
                         nodal=nodal)


@dataclass
class BoundaryTags:
    """What the problem's selectors picked on the reference configuration: the boundary nodes, the
    constrained dofs (interleaved) with their values, and the loaded boundary's Gauss points (t of
    them) with the traction components (t,) there."""

    boundary_nodes: np.ndarray
    fixed: np.ndarray
    fixed_values: np.ndarray
    traction: BoundaryQuadrature
    tx: np.ndarray
    ty: np.ndarray


def boundary_tags(case: Case, nodes: np.ndarray, boundary: Boundary, lengths: ScaledMethod) -> BoundaryTags:
    """Evaluate the case's constraints and loads on the ``boundary`` of the reference ``nodes`` (n, 2),
    once: the tags then travel with the nodes."""
    tol = lengths.match_tolerance
    boundary_nodes = np.unique(np.concatenate(boundary.loops))
    fixed, fixed_values = constrained_dofs(case.problem, nodes, boundary_nodes, tol)
    traction, tx, ty = loaded_boundary(case.problem, nodes, boundary.edges, tol)
    return BoundaryTags(boundary_nodes, fixed, fixed_values, traction, tx, ty)
