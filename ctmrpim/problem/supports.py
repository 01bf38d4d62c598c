"""Supports checked before a static solve: prescribed values that conflict, loads that act only on
prescribed displacements, and constraints that leave a rigid-body motion free.

Shared by CTM-RPIM and the finite-element reference, which list their constrained dofs differently
(nodes; vertices and P2 mid-side dofs) but describe them the same way here: a position, a component
(0 = x, 1 = y) and a value per prescribed dof.

A static body is held when, in every part, the prescribed dofs stop the three rigid-body motions of
the plane: translations in x and y and a rotation. The velocity of a rigid motion (a, b, theta) at a
point (x, y) is (a - theta y, b + theta x), so a prescribed x-component at (x, y) contributes the row
[1, 0, -y] and a prescribed y-component the row [0, 1, x]; the motions left free are the null space of
those rows. A singular stiffness is not always noticed by a sparse factorisation (one pinned node gave
a tip displacement of 1e10 with exit 0), so this is decided from the constraints, before the solve.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from ctmrpim.errors import ProblemError
from ctmrpim.problem.model import Problem

#: singular values of the (scaled) rigid-motion rows below this share of the largest count as zero
RANK_TOLERANCE = 1e-8
#: two prescribed values of one dof closer than this share of the largest value are the same (round-off)
VALUE_TOLERANCE = 1e-9
#: analyses whose solution is an equilibrium of the supports (explicit dynamics may fly freely)
STATIC_ANALYSES = ("linear", "quasi-static", "strength-reduction", "dynamic")


@dataclass(frozen=True)
class Prescribed:
    """The dofs one constraint prescribes: its index in ``[[constraint]]``, the dof numbers (k,) in the
    method's numbering, their positions (k, 2), components (k,) and values (k,)."""

    constraint: int
    dofs: np.ndarray
    positions: np.ndarray
    components: np.ndarray
    values: np.ndarray


def merge(prescribed: list[Prescribed]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Sorted unique dofs, their values, positions (k, 2) and components from the constraints in file order.
    A dof given twice must get the same value (within VALUE_TOLERANCE of the largest value): two constraints
    that disagree at a node (the same edge, a shared corner) are refused, naming both and the node."""
    if not prescribed:
        empty = np.zeros(0)
        return empty.astype(int), empty, np.zeros((0, 2)), empty.astype(int)
    dofs = np.concatenate([p.dofs for p in prescribed])
    values = np.concatenate([p.values for p in prescribed])
    owner = np.concatenate([np.full(len(p.dofs), p.constraint) for p in prescribed])
    positions = np.concatenate([p.positions for p in prescribed])
    components = np.concatenate([p.components for p in prescribed])
    order = np.argsort(dofs, kind="stable")
    dofs, values, owner, positions, components = (a[order] for a in (dofs, values, owner, positions, components))
    first = np.r_[True, dofs[1:] != dofs[:-1]]
    start = np.flatnonzero(first)
    group = np.cumsum(first) - 1
    scale = max(float(np.abs(values).max()), 1e-300)
    clash = np.abs(values - values[start][group]) > VALUE_TOLERANCE * scale
    if clash.any():
        k = int(np.flatnonzero(clash)[0])
        j = int(start[group[k]])
        comp = "uy" if components[k] else "ux"
        x, y = positions[k]
        raise ProblemError(f"constraint[{owner[k]}] prescribes {comp} = {values[k]:g} at ({x:g}, {y:g}), where "
                           f"constraint[{owner[j]}] prescribes {comp} = {values[j]:g}: the two disagree",
                           key=f"constraint[{owner[k]}]")
    return dofs[start], values[start], positions[start], components[start]


def check_rigid_motion(problem: Problem, positions: np.ndarray, components: np.ndarray, tol: float) -> None:
    """Refuse constraints (prescribed ``components`` at ``positions`` (k, 2)) that leave a part of the body free
    to move rigidly in a static analysis, naming the part and the motion."""
    if problem.analysis not in STATIC_ANALYSES:
        return
    parts = problem.geometry.polygons
    held = shapely.points(positions) if len(positions) else None
    for k, part in enumerate(parts):
        mine = (np.zeros(0, bool) if held is None
                else np.asarray(shapely.distance(part, held) <= tol) if len(parts) > 1 else np.ones(len(positions), bool))
        free = _free_motion(part, positions[mine], components[mine])
        if free is None:
            continue
        if len(parts) > 1:
            x0, y0, x1, y1 = part.bounds
            body = f"part {k + 1} of the body, within ({x0:g}, {y0:g}) .. ({x1:g}, {y1:g}),"
        else:
            body = "the body"
        raise ProblemError(f"the constraints leave {body} free to {free}: add constraints that stop it "
                           "(a static solution would be arbitrary)", key="constraint")


def _free_motion(part: shapely.Polygon, positions: np.ndarray, components: np.ndarray) -> str | None:
    """What rigid motion the prescribed dofs leave free in ``part``, in words; None when none is."""
    if len(positions) == 0:
        return "translate in x and y and to rotate (no constrained node)"
    c = np.array(part.centroid.coords[0])
    scale = np.sqrt(part.area)
    d = (positions - c) / scale
    rows = np.where(components[:, None] == 0, np.c_[np.ones(len(d)), np.zeros(len(d)), -d[:, 1]],
                    np.c_[np.zeros(len(d)), np.ones(len(d)), d[:, 0]])
    _, s, vt = np.linalg.svd(rows, full_matrices=True)
    rank = int((s > RANK_TOLERANCE * s.max()).sum())
    if rank == 3:
        return None
    null = vt[rank:]                          # (3 - rank, 3) rigid motions (a, b, theta) left free
    words = []
    translation = _translation_in(null)
    if translation is not None:
        words.append(f"translate {translation}")
    if np.abs(null[:, 2]).max() > RANK_TOLERANCE:
        if len(null) == 1:
            a, b, theta = null[0]
            centre = c + scale * np.array([-b / theta, a / theta])
            centre = np.round(centre / (1e-9 * scale)) * (1e-9 * scale) + 0.0   # no -0 or 1e-15 from round-off
            words.append(f"rotate about ({centre[0]:.6g}, {centre[1]:.6g})")
        else:
            words.append("rotate")
    return " and to ".join(words)


def _translation_in(null: np.ndarray) -> str | None:
    """The pure translation (theta = 0) among the free motions ``null`` (k, 3), in words; None if none."""
    if len(null) == 1:
        v = null[0] if abs(null[0, 2]) <= RANK_TOLERANCE else None
    else:  # a combination of the rows with no rotation: the null vector of their theta column
        coef = np.linalg.svd(null[:, 2:].T)[2][-1]
        v = coef @ null
        if len(null) == 3:
            return "in x and y"
    if v is None:
        return None
    a, b = v[:2] / np.hypot(*v[:2])
    if abs(b) <= RANK_TOLERANCE:
        return "in x"
    if abs(a) <= RANK_TOLERANCE:
        return "in y"
    return f"along ({a:.3g}, {b:.3g})"


def check_loads_on_supports(problem: Problem, x: np.ndarray, y: np.ndarray, tol: float) -> None:
    """Refuse a traction or pressure whose every selected boundary point (``x``, ``y``: the boundary nodes or
    vertices) has the loaded component prescribed by a constraint: the load would go into the reactions and
    have no effect on the solution."""
    fixed = np.zeros((len(x), 2), bool)
    for c in problem.constraints:
        on = np.asarray(c.where(x, y, eq_tol=tol), bool)
        fixed[on, 0] |= c.ux is not None
        fixed[on, 1] |= c.uy is not None
    loads = [(f"traction[{i}]", t.where, ((0, t.tx, "tx"), (1, t.ty, "ty"))) for i, t in enumerate(problem.tractions)]
    loads += [(f"pressure[{i}]", p.where, ((0, p.p, "p"), (1, p.p, "p"))) for i, p in enumerate(problem.pressures)]
    for name, where, components in loads:
        on = np.asarray(where(x, y, eq_tol=tol), bool)
        if not on.any():
            continue
        acting = [(k, label) for k, f, label in components
                  if f is not None and np.any(np.asarray(f(x[on], y[on])) != 0)]
        if acting and all(fixed[on, k].all() for k, _ in acting):
            labels = sorted({label for _, label in acting})
            raise ProblemError(f"{' and '.join(labels)} acts only where a constraint prescribes the displacement it "
                               "would do work on: it goes into the reactions and has no effect", key=name)
