"""The node cloud of a case in its reference configuration, and everything built on it (Sections 2.2-2.4).

field nodes --alpha shape--> boundary loops --CTM--> integration points and weights
            --boundary Gauss--> traction points --RPIM--> sparse shape functions
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ctmrpim.discretisation.alpha_shape import Boundary, alpha_shape, validate
from ctmrpim.discretisation.boundary_conditions import constrained_dofs, loaded_boundary
from ctmrpim.discretisation.ctm import BoundaryQuadrature, Quadrature, integration_points
from ctmrpim.discretisation.rpim import ShapeFunctions, shape_functions
from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case
from ctmrpim.problem.node_cloud import check_nodes_inside, make_nodes, mean_node_spacing
from ctmrpim.timing import Timer

#: The tracked boundary may differ from the geometry's area by this many d_c times its perimeter.
AREA_TOLERANCE = 0.05


@dataclass
class Discretisation:
    nodes: np.ndarray
    d_c: float
    boundary: Boundary
    quadrature: Quadrature


def track_boundary(case: Case, nodes: np.ndarray, d_c: float) -> Boundary:
    """The body's boundary from the node cloud (alpha shape), checked against the geometry's area."""
    geometry = case.problem.geometry
    boundary = alpha_shape(nodes, case.method.alpha * d_c, d_c)
    if len(boundary.detached):
        i = boundary.detached[0]
        raise ProblemError(f"{len(boundary.detached)} node(s) are outside the alpha shape, e.g. #{i} at "
                           f"({nodes[i, 0]:g}, {nodes[i, 1]:g}); increase method.alpha", key="method.alpha")
    validate(boundary, expected_area=geometry.area, area_tol=AREA_TOLERANCE * d_c * geometry.perimeter)
    return boundary


def discretise(case: Case, timer: Timer) -> Discretisation:
    geometry, method = case.problem.geometry, case.method
    nodes = make_nodes(geometry, case.nodes, case.base_dir)
    d_c = mean_node_spacing(geometry.area, len(nodes))
    check_nodes_inside(geometry, nodes, tol=method.match_tolerance * d_c)
    boundary = track_boundary(case, nodes, d_c)
    timer.lap("boundary")
    loops = boundary.loop_coordinates() if method.boundary == "alpha" else geometry.loops()
    r_x, r_y = (s * d_c for s in method.line_spacing)
    quad = integration_points(loops, r_x, r_y, method.gauss_points, mode="uniform")
    timer.lap("integration")
    return Discretisation(nodes=nodes, d_c=d_c, boundary=boundary, quadrature=quad)


@dataclass
class Configuration:
    """Everything built on one configuration of the node cloud: boundary, integration points, the
    constrained dofs, the loaded boundary points and the RPIM shape functions at both sets of points."""

    disc: Discretisation
    boundary_nodes: np.ndarray
    fixed: np.ndarray
    fixed_values: np.ndarray
    traction: BoundaryQuadrature
    tx: np.ndarray
    ty: np.ndarray
    rpim: dict
    sf: ShapeFunctions
    sf_traction: ShapeFunctions


def build_configuration(case: Case, timer: Timer) -> Configuration:
    problem, method = case.problem, case.method
    disc = discretise(case, timer)
    nodes, d_c = disc.nodes, disc.d_c
    tol = method.match_tolerance * d_c
    boundary_nodes = np.unique(np.concatenate(disc.boundary.loops))
    fixed, fixed_values = constrained_dofs(problem, nodes, boundary_nodes, tol)
    traction_q, tx, ty = loaded_boundary(problem, nodes, disc.boundary.edges, tol)
    timer.lap("integration")
    rpim = dict(support_radius=method.support_radius * d_c, eta=method.eta,
                polynomial_terms=method.polynomial_terms, scale=d_c, tree=cKDTree(nodes))
    sf = shape_functions(nodes, disc.quadrature.points, **rpim)
    sf_t = shape_functions(nodes, traction_q.points, derivatives=False, **rpim)
    timer.lap("shape_functions")
    return Configuration(disc, boundary_nodes, fixed, fixed_values, traction_q, tx, ty, rpim, sf, sf_t)
