"""The problem on the dolfinx mesh: function space, parameters, selectors, prescribed displacements and loads.

Everything is built from the problem's own text (``problem.json``): the ``where`` selectors are evaluated at
the vertices (ctmrpim's match tolerance, the scikit-fem reference's rule: a constraint holds at the selected
boundary vertices and, for quadratic elements, on the facets whose both ends are selected; a load acts on
those facets), prescribed displacements are interpolated from their expressions, and tractions, pressures
and body forces enter the forms as UFL expressions, integrated with the quadrature degrees the bridge names
(the scikit-fem reference's rules: the same points).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem
from fx_expressions import Translator
from fx_mesh import MeshData, facet_tags, select, vertex_values
from petsc4py import PETSc


class WorkerProblem(ValueError):
    """The problem cannot be solved as posed (the bridge turns it into a ProblemError: exit 2)."""


@dataclass
class Discrete:
    """The problem on the mesh: vector space ``V``, its degree, the coordinate ``X``, parameters as Constants,
    the translator, selector masks (n_input, k), the Dirichlet conditions with their full values and the
    load pieces."""
    md: MeshData
    V: fem.FunctionSpace
    degree: int
    X: object
    translate: Translator
    masks: np.ndarray
    bcs: list = field(default_factory=list)
    bc_values: list = field(default_factory=list)     # (g, its values at load factor 1)
    thickness: object = None


def discretise(md: MeshData, spec: dict) -> Discrete:
    """Function space, selectors and Dirichlet conditions of the problem ``spec`` on ``md``."""
    msh = md.mesh
    degree = int(spec["element"]["degree"])
    V = fem.VectorFunctionSpace(msh, ("Lagrange", degree))
    X = ufl.SpatialCoordinate(msh)
    consts = {k: fem.Constant(msh, PETSc.ScalarType(v)) for k, v in spec["parameters"].items()}
    translate = Translator(X, consts)
    tol = fem.Constant(msh, PETSc.ScalarType(spec["match_tolerance"]))
    wheres = [c["where"] for c in spec["constraints"]] + [t["where"] for t in spec["tractions"]] + \
        [p["where"] for p in spec["pressures"]]
    # X[0] rides along so that the vector has the mesh even where every selector is a constant
    values = vertex_values(md, [X[0]] + [ufl.conditional(translate(w, tol), 1.0, 0.0) for w in wheres],
                           len(md.input_vertex))
    masks = values[:, 1:]
    d = Discrete(md, V, degree, X, translate, masks,
                 thickness=fem.Constant(msh, PETSc.ScalarType(spec["thickness"])))
    sel = select(md, masks)
    for i, c in enumerate(spec["constraints"]):
        _dirichlet(d, sel[i], c, f"constraint[{i}]")
    return d


def _dirichlet(d: Discrete, sel, c: dict, key: str) -> None:
    """The components ``c`` prescribes on the vertices and facets of ``sel``."""
    if len(sel.vertices) == 0:
        raise WorkerProblem(f"{key}: where = {c['where']!r} selects no boundary vertex")
    for comp, name in enumerate(("ux", "uy")):
        if c.get(name) is None:
            continue
        sub = d.V.sub(comp)
        Vc, _ = sub.collapse()
        dofs = [fem.locate_dofs_topological((sub, Vc), 0, sel.vertices)]
        if d.degree > 1 and len(sel.facets):
            dofs.append(fem.locate_dofs_topological((sub, Vc), 1, sel.facets))
        dofs = [np.unique(np.concatenate([a[k] for a in dofs])) for k in (0, 1)]
        g = fem.Function(Vc)
        value = d.translate(c[name])
        if isinstance(value, float):          # a number: fem.Expression needs the mesh in the expression
            g.x.array[:] = value
        else:
            g.interpolate(fem.Expression(value, Vc.element.interpolation_points()))
        d.bcs.append(fem.dirichletbc(g, dofs, sub))
        d.bc_values.append((g, g.x.array.copy()))


def scale_dirichlet(d: Discrete, factor: float) -> None:
    """Prescribed displacements at ``factor`` of their values (load stepping)."""
    for g, full in d.bc_values:
        g.x.array[:] = factor * full


def dead_load(d: Discrete, spec: dict, v) -> object | None:
    """The form of the dead loads: tractions and pressures over their facets, the body force over the body
    (times the thickness); None without loads."""
    msh, q = d.md.mesh, spec["quadrature"]
    nc, nt = len(spec["constraints"]), len(spec["tractions"])
    sel = select(d.md, d.masks)
    loads = []          # (key, facets, traction as a UFL vector)
    n = ufl.FacetNormal(msh)
    for i, t in enumerate(spec["tractions"]):
        vec = ufl.as_vector([d.translate(t[k]) if t.get(k) is not None else 0.0 for k in ("tx", "ty")])
        loads.append((f"traction[{i}]", t["where"], sel[nc + i].facets, vec))
    for i, p in enumerate(spec["pressures"]):
        loads.append((f"pressure[{i}]", p["where"], sel[nc + nt + i].facets, -d.translate(p["p"]) * n))
    form = None
    for key, where, facets, _ in loads:
        if len(facets) == 0:
            raise WorkerProblem(f"{key}: where = {where!r} selects no boundary segment (both ends must match)")
    if loads:
        tags, combos = facet_tags(d.md, [f for _, _, f, _ in loads])
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags, metadata={"quadrature_degree": q["facet"]})
        for tag, members in enumerate(combos, start=1):
            t = sum((loads[i][3] for i in members[1:]), loads[members[0]][3])
            term = ufl.inner(t, v) * ds(tag)
            form = term if form is None else form + term
    body = _body_force(d, spec)
    if body is not None:
        dx = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": q["load"]})
        term = ufl.inner(body, v) * dx
        form = term if form is None else form + term
    return None if form is None else d.thickness * form


def _body_force(d: Discrete, spec: dict):
    """density * gravity plus the ``[body-force]`` field, as a UFL vector; None where both are absent."""
    bx, by = spec["body_force"]
    parts = []
    if bx or by:
        parts.append(ufl.as_vector([fem.Constant(d.md.mesh, PETSc.ScalarType(bx)),
                                    fem.Constant(d.md.mesh, PETSc.ScalarType(by))]))
    if spec.get("body_load"):
        parts.append(ufl.as_vector([d.translate(spec["body_load"][k]) for k in ("bx", "by")]))
    return None if not parts else sum(parts[1:], parts[0])
