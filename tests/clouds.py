"""Canonical node clouds, geometries and overrides reused by the tests (cf. meshio's test helpers)."""
from __future__ import annotations

import numpy as np
import shapely

from ctmrpim.problem.geometry import Geometry, Shape
from ctmrpim.problem.node_cloud import NodeSpec, make_nodes, mean_node_spacing

GEOMETRIES = {
    "rectangle": Geometry([Shape("rectangle", (0.0, 0.0, 4.0, 1.0))]),
    "l-shape": Geometry([Shape("polygon", ((0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)))]),
    "plate-with-hole": Geometry([Shape("rectangle", (0.0, 0.0, 4.0, 2.0))], [Shape("circle", (2.0, 1.0, 0.5))]),
    "slope": Geometry([Shape("polygon", ((0, 0), (60, 0), (60, 5), (40, 5), (20, 15), (0, 15)))]),
}
#: holes of each geometry
HOLES = {"rectangle": 0, "l-shape": 0, "plate-with-hole": 1, "slope": 0}
SPACING = {"rectangle": 0.1, "l-shape": 0.1, "plate-with-hole": 0.1, "slope": 1.0}


def cloud(name: str, jitter: float = 0.0, seed: int = 0) -> tuple[Geometry, np.ndarray, float]:
    """(geometry, nodes, d_c); with jitter > 0 the interior nodes move by up to jitter * spacing."""
    geometry = GEOMETRIES[name]
    h = SPACING[name]
    nodes = make_nodes(geometry, NodeSpec(spacing=h))
    if jitter:
        rng = np.random.default_rng(seed)
        interior = geometry.distance_to_boundary(nodes) > 1e-3 * h  # circle nodes sit on the arc, off the chords
        nodes[interior] += rng.uniform(-jitter * h, jitter * h, (interior.sum(), 2))
        assert shapely.contains_xy(geometry.region, nodes[interior, 0], nodes[interior, 1]).all()
    return geometry, nodes, mean_node_spacing(geometry.area, len(nodes))

#: overrides of the column-collapse benchmark for a quick explicit run: its coarsest cloud
QUICK_COLUMN = ["nodes.grid=[16, 9]", "method.alpha=2.0"]
