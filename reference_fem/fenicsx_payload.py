"""A Case as plain data for the FEniCSx worker: the scikit-fem reference's mesh of the case's nodes, the
problem's expressions as the text the user wrote, and the quadrature degrees that give dolfinx the scikit-fem
reference's points.

Nothing the worker solves with is computed here: loads, prescribed displacements, the exact solution and the
``where`` selectors travel as expressions (the worker translates them to UFL). What is computed here is the
mesh (the same object the scikit-fem reference solves on, so both codes have the same vertices and cells),
the probe points located in it (a probe on a curved boundary moves onto the chord, as in the scikit-fem
reference), and the refusals of the scikit-fem reference (a selector that picks nothing, conflicting
constraints, a rigid-body motion, a load that only acts on supports), made by its own checks on the same mesh.
"""
from __future__ import annotations

import numpy as np
from skfem import Basis, ElementQuad2, ElementTriP3, ElementVector

from ctmrpim.errors import ProblemError
from ctmrpim.materials.linear_elastic import LinearElastic
from ctmrpim.materials.neo_hookean import NeoHookean
from ctmrpim.problem.case import Case
from ctmrpim.problem.expressions import Field
from reference_fem import hyperelastic, solve
from reference_fem.boundary_conditions import FACET_ORDER, constrained_dofs, locate, selected_facets
from reference_fem.mesh import FemMesh, build_mesh

#: elements of the FEniCSx method, the first the default (as the scikit-fem reference's: q1 on a tensor grid)
ELEMENTS = ("q1", "p1", "p2", "q2", "p3")
DEGREE = {"p1": 1, "p2": 2, "q1": 1, "q2": 2, "p3": 3}
#: the element whose scikit-fem mesh an element without a scikit-fem counterpart uses
MESH_OF = {"q2": "q1", "p3": "p1"}
#: rules of the elements the scikit-fem reference lacks: exact for the stiffness and the mass matrix (twice the
#: degree), the hyperelastic tangent one order above that
EXTRA_ORDERS = {"q2": {"stiffness": 4, "tangent": 4, "projection": 4},
                "p3": {"stiffness": 4, "tangent": 6, "projection": 6}}
PROTOCOL = 1


def fem_mesh(case: Case, element: str) -> FemMesh:
    """The scikit-fem reference's mesh of ``case``'s nodes for ``element`` (q2: the q1 mesh of quads, p3: the p1
    mesh of triangles)."""
    try:
        return build_mesh(case, MESH_OF.get(element, element))
    except ProblemError as exc:
        if element in MESH_OF:        # name the element asked for, not the one whose mesh it borrows
            raise ProblemError(exc.reason.replace(MESH_OF[element], element, 1), key=exc.key) from None
        raise


def _degree(cell_type: str, order: int) -> int:
    """The basix quadrature degree whose points are scikit-fem's rule of ``order`` on ``cell_type``: the same
    Gauss-Legendre and triangle rules, except that scikit-fem's triangle rule of order 1 is its 3-point rule
    of degree 2 (basix's degree 1 is the centroid)."""
    return 2 if cell_type == "triangle" and order == 1 else order


def quadrature(element: str, cell_type: str, analysis: str) -> dict[str, int]:
    """The quadrature degrees of each integral, the scikit-fem reference's (:mod:`reference_fem.solve`,
    :mod:`reference_fem.hyperelastic`)."""
    extra = EXTRA_ORDERS.get(element)
    if analysis == "linear":
        stiffness = extra["stiffness"] if extra else solve.STIFFNESS_ORDER[element]
        projection = solve.ERROR_ORDER
    else:
        stiffness = extra["tangent"] if extra else hyperelastic.TANGENT_ORDER[element]
        projection = extra["projection"] if extra else hyperelastic.PROJECTION_ORDER
    return {"stiffness": _degree(cell_type, stiffness), "load": _degree(cell_type, stiffness),
            "projection": _degree(cell_type, projection), "error": _degree(cell_type, solve.ERROR_ORDER),
            "facet": FACET_ORDER}


def _text(f: Field | None) -> str | None:
    return None if f is None else f.text


def _material(case: Case) -> dict:
    """The material as numbers: D for linear elasticity, mu and lambda for the neo-Hookean model."""
    problem = case.problem
    m = problem.material
    if problem.analysis == "linear" and type(m) is LinearElastic:
        return {"model": "linear-elastic", "D": problem.D().tolist()}
    if problem.analysis == "quasi-static" and isinstance(m, NeoHookean):
        if problem.plane != "strain":
            raise ProblemError("the neo-Hookean model is implemented in plane strain; set problem.plane = "
                               "\"strain\"", key="problem.plane")
        return {"model": "neo-hookean", "mu": m.mu, "lambda": m.lam}
    raise ProblemError(f"--solver fenicsx solves linear elasticity (analysis = \"linear\") and the neo-Hookean "
                       f"quasi-static analysis; not a {problem.analysis!r} analysis of a {type(m).__name__} body",
                       key="--solver")


def payload(case: Case, element: str) -> tuple[dict, dict[str, np.ndarray], FemMesh]:
    """``problem.json`` content, ``arrays.npz`` content and the mesh, for solving ``case`` with ``element``."""
    if element not in ELEMENTS:
        raise ProblemError(f"element {element!r} is not supported (supported: {', '.join(ELEMENTS)})",
                           key="--element")
    problem = case.problem
    material = _material(case)
    if problem.point_loads:
        raise ProblemError("point loads are not supported by the FE references (yet)", key="point_load")
    if any(t.follower for t in problem.tractions):
        raise ProblemError("follower tractions are not in the FEniCSx bridge (dead tractions and pressures are)",
                           key="traction")
    fm = fem_mesh(case, element)
    tol = case.method.match_tolerance * fm.d_c
    validate(case, fm, element, tol)
    exact = problem.exact
    spec = {
        "protocol": PROTOCOL, "analysis": problem.analysis, "element": {"name": element, "degree": DEGREE[element]},
        "cell_type": fm.cell_type, "plane": problem.plane, "thickness": problem.thickness, "material": material,
        "parameters": dict(problem.parameters), "match_tolerance": tol, "body_force": list(problem.body_force),
        "body_load": None if problem.body_load is None else {"bx": problem.body_load.bx.text,
                                                             "by": problem.body_load.by.text},
        "constraints": [{"where": c.where.text, "ux": _text(c.ux), "uy": _text(c.uy)} for c in problem.constraints],
        "tractions": [{"where": t.where.text, "tx": _text(t.tx), "ty": _text(t.ty)} for t in problem.tractions],
        "pressures": [{"where": p.where.text, "p": p.p.text} for p in problem.pressures],
        "probes": [{"name": p.name, "x": p.x, "y": p.y,
                    "at": locate(fm.mesh, np.array([p.x, p.y]), fm.d_c, p.name).ravel().tolist()}
                   for p in problem.probes],
        "exact": None if exact is None else {k: _text(getattr(exact, k)) for k in ("ux", "uy", "sxx", "syy", "sxy")},
        "quadrature": quadrature(element, fm.cell_type, problem.analysis),
        "loading": {k: getattr(case.loading, k) for k in ("steps", "tolerance", "max_iterations", "max_cutbacks")},
    }
    arrays = {"points": fm.mesh.p.T.copy(), "cells": fm.cells.astype(np.int64)}
    return spec, arrays, fm


def selectors(case: Case) -> list[Field]:
    """The ``where`` selectors in the worker's order: constraints, tractions, pressures."""
    p = case.problem
    return [c.where for c in p.constraints] + [t.where for t in p.tractions] + [q.where for q in p.pressures]


def validate(case: Case, fm: FemMesh, element: str, tol: float) -> None:
    """The scikit-fem reference's refusals on this mesh: conflicting constraints, rigid-body motions, loads
    acting only on supports, selectors that pick no vertex or no segment."""
    problem = case.problem
    from reference_fem.solve import SCALAR_ELEMENTS
    scalar = {"q2": ElementQuad2, "p3": ElementTriP3}.get(element, SCALAR_ELEMENTS.get(element))()
    constrained_dofs(problem, fm, Basis(fm.mesh, ElementVector(scalar), intorder=1), tol)
    loads = [(f"traction[{i}]", t.where) for i, t in enumerate(problem.tractions)] + \
        [(f"pressure[{i}]", p.where) for i, p in enumerate(problem.pressures)]
    for key, where in loads:
        if len(selected_facets(where, fm, tol)[1]) == 0:
            raise ProblemError(f"where = {where.text!r} selects no boundary segment (both ends must match)", key=key)


def check_masks(case: Case, fm: FemMesh, masks: np.ndarray) -> None:
    """The worker's selector values at the vertices (n, k) against ctmrpim's: a selector that the two evaluate
    differently would give the two FE codes different problems, so it is refused by name."""
    points = fm.mesh.p
    tol = case.method.match_tolerance * fm.d_c
    for j, where in enumerate(selectors(case)):
        ours = np.asarray(where(points[0], points[1], eq_tol=tol), dtype=bool)
        differ = np.flatnonzero(ours != (masks[:, j] > 0.5))
        if len(differ):
            x, y = points[:, differ[0]]
            raise ProblemError(f"where = {where.text!r}: ctmrpim and the FEniCSx worker (UFL) disagree at the "
                               f"vertex ({x:g}, {y:g}) ({len(differ)} vertices); move the selector's bound off the "
                               "nodes", key="where")
