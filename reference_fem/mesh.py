"""Meshes on exactly the field nodes the CTM-RPIM solver uses, so both methods share their points.

On a rectangle with ``nodes.grid`` the tensor grid is meshed directly (quads, or each quad split
into two triangles); any other node cloud is Delaunay-triangulated and trimmed to the geometry.
Vertices keep the order of :func:`ctmrpim.problem.node_cloud.make_nodes`, so nodal results line up one to one
with the meshfree solver's (except for nodes of a cloud that no kept triangle uses, which are dropped).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from scipy.spatial import Delaunay
from skfem import MeshQuad, MeshTri
from skfem.mesh import Mesh

from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case
from ctmrpim.problem.node_cloud import make_nodes, mean_node_spacing

ELEMENTS = ("q1", "p1", "p2")
#: Triangles smaller than this fraction of d_c**2 are slivers of collinear points and are dropped.
SLIVER_AREA = 1e-10


@dataclass
class FemMesh:
    """A scikit-fem mesh of a case's field nodes, with those nodes and their spacing d_c."""
    mesh: Mesh
    nodes: np.ndarray      # (n, 2) the field nodes the mesh was built on (before any unused were dropped)
    d_c: float             # mean node spacing of those nodes (Eq. 36), the unit of the match tolerance
    cell_type: str         # meshio cell type of mesh.t: "quad" or "triangle"
    cells: np.ndarray      # (ncells, k) counter-clockwise vertex connectivity (meshio ordering)


def build_mesh(case: Case, element: str) -> FemMesh:
    """Mesh of ``case``'s node set for ``element`` ("q1", "p1" or "p2")."""
    if element not in ELEMENTS:
        raise ProblemError(f"element {element!r} is not supported (supported: {', '.join(ELEMENTS)})")
    geometry = case.problem.geometry
    nodes = make_nodes(geometry, case.nodes, case.base_dir)
    d_c = mean_node_spacing(geometry.area, len(nodes))
    tensor = case.nodes.grid is not None and geometry.is_rectangle()
    if element == "q1" and not tensor:
        raise ProblemError("q1 needs a rectangular body and nodes.grid = [nx, ny] (a tensor grid); "
                           "use p1 or p2 for other geometries or node sets", key="nodes")
    if tensor:
        nx, ny = case.nodes.grid
        quads = _grid_quads(nx, ny)
        if element == "q1":
            return FemMesh(MeshQuad(nodes.T.copy(), quads.T.copy()), nodes, d_c, "quad", quads)
        tris = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
        points = nodes
    else:
        points, tris = _trimmed_delaunay(geometry, nodes, d_c)
    # sort_t=False keeps our counter-clockwise vertex order in mesh.t, so cells == mesh.t.T
    mesh = MeshTri(points.T.copy(), tris.T.copy(), sort_t=False)
    return FemMesh(mesh, nodes, d_c, "triangle", tris)


def _grid_quads(nx: int, ny: int) -> np.ndarray:
    """Counter-clockwise quads of the make_nodes tensor grid (node index j*nx + i)."""
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1))
    n00 = (j * nx + i).ravel()
    return np.c_[n00, n00 + 1, n00 + nx + 1, n00 + nx]


def _trimmed_delaunay(geometry, nodes: np.ndarray, d_c: float) -> tuple[np.ndarray, np.ndarray]:
    """Delaunay triangles of the cloud whose centroid lies in the body, counter-clockwise, and the
    nodes they use (Delaunay fills holes and concave notches; the centroid test removes those)."""
    tris = Delaunay(nodes).simplices
    a, b, c = nodes[tris[:, 0]], nodes[tris[:, 1]], nodes[tris[:, 2]]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    centroid = (a + b + c) / 3.0
    keep = shapely.contains_xy(geometry.region, centroid[:, 0], centroid[:, 1])
    keep &= np.abs(area2) > 2.0 * SLIVER_AREA * d_c ** 2
    tris = tris[keep]
    flip = area2[keep] < 0
    tris[flip] = tris[flip][:, [0, 2, 1]]
    if len(tris) == 0:
        raise ProblemError("no triangle of the node cloud lies inside the geometry", key="nodes")
    used = np.unique(tris)
    if len(used) < len(nodes):  # renumber so that every vertex carries stiffness
        renumber = np.full(len(nodes), -1)
        renumber[used] = np.arange(len(used))
        return nodes[used], renumber[tris]
    return nodes, tris
