"""The dolfinx mesh of the bridge's vertices and cells, and the boundary the problem's selectors pick on it.

dolfinx renumbers vertices and cells when it builds a mesh; :class:`MeshData` keeps the map from its vertices
back to the input's (the scikit-fem mesh's order) so that every nodal output is written in that order.
Quadrilaterals arrive counter-clockwise (meshio's order) and are handed to dolfinx in its tensor-product order.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

#: dolfinx's reference vertices, in its local vertex order
REFERENCE_VERTICES = {"triangle": [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
                      "quadrilateral": [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]}


@dataclass
class MeshData:
    """The dolfinx mesh, its cell name, for each dolfinx vertex the input vertex it is, and the exterior facets
    with their two vertices (input numbering)."""
    mesh: mesh.Mesh
    cell: str
    input_vertex: np.ndarray      # (nv,) input index of each dolfinx vertex
    facets: np.ndarray            # (nf,) exterior facets (dolfinx numbering)
    facet_vertices: np.ndarray    # (nf, 2) their end vertices, input numbering


def build(points: np.ndarray, cells: np.ndarray, cell_type: str) -> MeshData:
    """The dolfinx mesh of ``points`` (n, 2) and counter-clockwise ``cells`` ("triangle" or "quad")."""
    cell = "quadrilateral" if cell_type == "quad" else "triangle"
    cells = np.asarray(cells, dtype=np.int64)
    if cell == "quadrilateral":           # counter-clockwise 0 1 2 3 -> dolfinx's tensor order 0 1 3 2
        cells = cells[:, [0, 1, 3, 2]]
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", cell, 1))
    msh = mesh.create_mesh(MPI.COMM_SELF, cells, np.ascontiguousarray(points, dtype=np.float64), domain)
    tdim = msh.topology.dim
    for d in (0, 1):
        msh.topology.create_connectivity(d, tdim)
    msh.topology.create_connectivity(1, 0)
    input_vertex = _input_vertices(msh)
    facets = mesh.exterior_facet_indices(msh.topology)
    f2v = msh.topology.connectivity(1, 0).array.reshape(-1, 2)
    return MeshData(msh, cell, input_vertex, facets, input_vertex[f2v[facets]])


def _input_vertices(msh: mesh.Mesh) -> np.ndarray:
    """Input index of each topology vertex: a cell's k-th vertex is its k-th geometry node (degree-1 geometry),
    whose input index dolfinx keeps."""
    k = len(REFERENCE_VERTICES[msh.topology.cell_name()])
    c2v = msh.topology.connectivity(msh.topology.dim, 0).array.reshape(-1, k)
    nodes = msh.geometry.dofmap.array.reshape(-1, k)
    out = np.full(msh.topology.index_map(0).size_local, -1, dtype=np.int64)
    out[c2v.ravel()] = np.asarray(msh.geometry.input_global_indices)[nodes.ravel()]
    return out


def vertex_values(md: MeshData, values, n_input: int) -> np.ndarray:
    """(n_input, k) UFL ``values`` (a vector of k scalar expressions) at every vertex, in input order."""
    msh = md.mesh
    k = len(REFERENCE_VERTICES[md.cell])
    expr = fem.Expression(ufl.as_vector(values), np.array(REFERENCE_VERTICES[md.cell]))
    ncells = msh.topology.index_map(msh.topology.dim).size_local
    at = expr.eval(np.arange(ncells, dtype=np.int32)).reshape(ncells, k, len(values))
    c2v = msh.topology.connectivity(msh.topology.dim, 0).array.reshape(-1, k)
    out = np.empty((n_input, len(values)))
    out[md.input_vertex[c2v.ravel()]] = at.reshape(-1, len(values))
    return out


@dataclass
class Selection:
    """What a selector picks: boundary vertices (dolfinx numbering) and exterior facets whose both ends it picks
    (the scikit-fem reference's rule), and its value at every vertex (input order, for the bridge's check)."""
    vertices: np.ndarray
    facets: np.ndarray
    mask: np.ndarray


def select(md: MeshData, masks: np.ndarray) -> list[Selection]:
    """The selections of the selector masks (n_input, k) (1.0 where a vertex satisfies the expression)."""
    picked = masks > 0.5
    boundary = np.zeros(len(masks), dtype=bool)
    boundary[md.facet_vertices.ravel()] = True
    to_dolfinx = np.empty(len(md.input_vertex), dtype=np.int32)      # input index -> dolfinx vertex
    to_dolfinx[md.input_vertex] = np.arange(len(md.input_vertex), dtype=np.int32)
    out = []
    for j in range(masks.shape[1]):
        hit = picked[:, j]
        verts = np.flatnonzero(hit & boundary)
        both = hit[md.facet_vertices[:, 0]] & hit[md.facet_vertices[:, 1]]
        out.append(Selection(to_dolfinx[verts], md.facets[both].astype(np.int32), hit))
    return out


def facet_tags(md: MeshData, groups: list[np.ndarray]) -> tuple[mesh.MeshTags, list[list[int]]]:
    """Tags of the facets of ``groups`` (one array of facets per load): each facet is tagged with the set of
    loads that act on it (one tag per distinct set, counted from 1), so that one form integrates every load over
    its own facets; also the loads of each tag."""
    loads_of: dict[int, list[int]] = {}
    for i, facets in enumerate(groups):
        for f in facets:
            loads_of.setdefault(int(f), []).append(i)
    combos: dict[tuple[int, ...], int] = {}
    for f in sorted(loads_of):
        combos.setdefault(tuple(loads_of[f]), len(combos) + 1)
    facets = np.array(sorted(loads_of), dtype=np.int32)
    tags = np.array([combos[tuple(loads_of[int(f)])] for f in facets], dtype=np.int32)
    tdim = md.mesh.topology.dim
    return mesh.meshtags(md.mesh, tdim - 1, facets, tags), [list(c) for c in combos]
