"""Boundary conditions on a node cloud: `where` selectors evaluated into node and segment tags.

Selectors are evaluated once, on the reference configuration: constraints select boundary nodes,
tractions and pressures select boundary segments whose two end nodes both match (so a corner node
alone never loads the adjacent face). A selector that matches nothing is an error, and so is a
prescribed value that is not a finite number (``9**9**9`` evaluates to inf), and so are supports that
conflict or leave a rigid-body motion free (:mod:`ctmrpim.problem.supports`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import shapely
from scipy.sparse.csgraph import connected_components

from ctmrpim.discretisation.assembly import dof
from ctmrpim.discretisation.ctm import BoundaryQuadrature, boundary_points
from ctmrpim.errors import ProblemError
from ctmrpim.problem import supports
from ctmrpim.problem.expressions import Field
from ctmrpim.problem.model import Problem

TRACTION_GAUSS_POINTS = 3  # per boundary segment; exact for the cantilever's parabolic shear


def constrained_dofs(problem: Problem, nodes: np.ndarray, boundary_nodes: np.ndarray,
                     tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Fixed dofs (interleaved: 2 node + component) and their values. Constraints that disagree at a node,
    a load that acts only on prescribed displacements, and (static analyses) constraints that leave a part of
    the body a rigid-body motion are refused (:mod:`ctmrpim.problem.supports`)."""
    prescribed = []
    bx, by = nodes[boundary_nodes, 0], nodes[boundary_nodes, 1]
    for i, c in enumerate(problem.constraints):
        sel = boundary_nodes[np.asarray(c.where(bx, by, eq_tol=tol), bool)]
        if len(sel) == 0:
            raise ProblemError(f"where = {c.where.text!r} selects no boundary node", key=f"constraint[{i}].where")
        for comp, f in ((0, c.ux), (1, c.uy)):
            if f is not None:
                v = _values(f, nodes[sel, 0], nodes[sel, 1], f"constraint[{i}].{'uy' if comp else 'ux'}")
                prescribed.append(supports.Prescribed(i, dof(sel, comp), nodes[sel], np.full(len(sel), comp), v))
    dofs, vals, positions, components = supports.merge(prescribed)
    supports.check_loads_on_supports(problem, bx, by, tol)
    if problem.analysis in supports.STATIC_ANALYSES:
        supports.check_rigid_motion(problem, positions, components, tol)
    else:
        _check_parts_held(problem, nodes[np.unique(dofs // 2)], tol)
    return dofs, vals


def _check_parts_held(problem: Problem, held_nodes: np.ndarray, tol: float) -> None:
    """Explicit dynamics may hold a body by walls alone, but a part without any constrained node among
    constrained ones is a mistake of the selectors (a detached piece would fall through the supports)."""
    parts = problem.geometry.polygons
    if len(parts) > 1:  # one loop per part of the body, not per node
        held = shapely.points(held_nodes)
        for k, part in enumerate(parts):
            if not (shapely.distance(part, held) <= tol).any():
                x0, y0, x1, y1 = part.bounds
                raise ProblemError(f"part {k + 1} of the body, within ({x0:g}, {y0:g}) .. ({x1:g}, {y1:g}), has no "
                                   "constrained node: it is free to move rigidly", key="constraint")


def loaded_boundary(problem: Problem, nodes: np.ndarray, edges: np.ndarray, tol: float
                    ) -> tuple[BoundaryQuadrature, np.ndarray, np.ndarray]:
    """Gauss points on every loaded boundary segment and the traction (tx, ty) at each point."""
    x, y = nodes[:, 0], nodes[:, 1]
    pts, wts, nrm, tx_all, ty_all, ends, follow, face = [], [], [], [], [], [], [], []
    loads = [("traction", i, t.where) for i, t in enumerate(problem.tractions)] + \
            [("pressure", i, p.where) for i, p in enumerate(problem.pressures)]
    for kind, i, where in loads:
        match = np.asarray(where(x, y, eq_tol=tol), bool)
        seg = edges[match[edges[:, 0]] & match[edges[:, 1]]]
        if len(seg) == 0:
            raise ProblemError(f"where = {where.text!r} selects no boundary segment", key=f"{kind}[{i}].where")
        q = boundary_points(nodes[seg], TRACTION_GAUSS_POINTS)
        px, py = q.points[:, 0], q.points[:, 1]
        ends.append(np.repeat(seg, TRACTION_GAUSS_POINTS, axis=0))
        follow.append(np.full(len(px), kind == "traction" and problem.tractions[i].follower))
        face.append(np.full(len(px), kind == "traction" and problem.tractions[i].follower
                            and problem.tractions[i].turn == "face"))
        if kind == "traction":
            t = problem.tractions[i]
            tx = _values(t.tx, px, py, f"traction[{i}].tx") if t.tx is not None else np.zeros(len(px))
            ty = _values(t.ty, px, py, f"traction[{i}].ty") if t.ty is not None else np.zeros(len(px))
        else:
            p = _values(problem.pressures[i].p, px, py, f"pressure[{i}].p")
            tx, ty = -p * q.normals[:, 0], -p * q.normals[:, 1]
        pts.append(q.points); wts.append(q.weights); nrm.append(q.normals); tx_all.append(tx); ty_all.append(ty)
    if not pts:
        empty = BoundaryQuadrature(np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)), np.zeros(0, int),
                                   np.zeros((0, 2), int), np.zeros(0, bool), np.zeros((0, 2), int))
        return empty, np.zeros(0), np.zeros(0)
    ends_all, face_all = np.concatenate(ends), np.concatenate(face)
    q = BoundaryQuadrature(np.concatenate(pts), np.concatenate(wts), np.concatenate(nrm), np.zeros(0, int),
                           ends_all, np.concatenate(follow), _turn_ends(ends_all, face_all, len(nodes)))
    return q, np.concatenate(tx_all), np.concatenate(ty_all)


def tractions_at(problem: Problem, nodes: np.ndarray, q: BoundaryQuadrature, tol: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The dead tractions tx, ty (k,) of the problem's tractions and pressures at boundary points ``q`` of
    another rule than :func:`loaded_boundary`'s (SCNI's cell edges), each point loaded where both ends of the
    segment it lies on (``q.ends``) are selected, as there."""
    x, y = nodes[:, 0], nodes[:, 1]
    px, py = q.points[:, 0], q.points[:, 1]
    tx, ty = np.zeros(len(px)), np.zeros(len(px))
    for i, t in enumerate(problem.tractions):
        if t.follower:
            raise ProblemError("follower loads need a large-deformation analysis", key=f"traction[{i}].follower")
        match = np.asarray(t.where(x, y, eq_tol=tol), bool)
        on = match[q.ends[:, 0]] & match[q.ends[:, 1]]
        if t.tx is not None:
            tx[on] += _values(t.tx, px[on], py[on], f"traction[{i}].tx")
        if t.ty is not None:
            ty[on] += _values(t.ty, px[on], py[on], f"traction[{i}].ty")
    for i, pr in enumerate(problem.pressures):
        match = np.asarray(pr.where(x, y, eq_tol=tol), bool)
        on = match[q.ends[:, 0]] & match[q.ends[:, 1]]
        p = _values(pr.p, px[on], py[on], f"pressure[{i}].p")
        tx[on] -= p * q.normals[on, 0]
        ty[on] -= p * q.normals[on, 1]
    return tx, ty


def _turn_ends(ends: np.ndarray, face: np.ndarray, n_nodes: int) -> np.ndarray:
    """The node pair each loaded point's follower load turns with: its own segment, or for
    ``turn = "face"`` the two end nodes of the connected stretch of face-follower boundary it lies on
    (segments of several tractions that share a node form one face)."""
    turn = ends.copy()
    if not face.any():
        return turn
    seg = np.unique(ends[face], axis=0)
    adj = sp.coo_matrix((np.ones(len(seg)), (seg[:, 0], seg[:, 1])), shape=(n_nodes, n_nodes))
    _, label = connected_components(adj, directed=False)
    degree = np.bincount(seg.ravel(), minlength=n_nodes)
    for comp in np.unique(label[seg[:, 0]]):
        tips = np.flatnonzero((label == comp) & (degree == 1))
        if len(tips) != 2:
            raise ProblemError("a follower = \"face\" traction must act on an open stretch of boundary "
                               f"(found {len(tips)} ends instead of 2); use follower = \"segment\" on closed loops",
                               key="traction")
        # orient the chord like the boundary (body on the left): from the stretch's start to its end
        start = tips[0] if np.isin(tips[0], seg[:, 0]) else tips[1]
        mine = face & (label[ends[:, 0]] == comp)
        turn[mine] = [start, tips[1] if start == tips[0] else tips[0]]
    return turn


def _values(f: Field, x: np.ndarray, y: np.ndarray, key: str) -> np.ndarray:
    """``f`` at the points; a value that is not a finite number is an error naming ``key`` and the
    first such point (the solver would otherwise report a singular matrix, or return inf)."""
    v = f(x, y)
    bad = np.flatnonzero(~np.isfinite(v))
    if len(bad):
        j = bad[0]
        raise ProblemError(f"{f.text!r} is {v[j]} at ({x[j]:g}, {y[j]:g}) ({len(bad)} of {len(v)} points)", key=key)
    return v
