"""The models as the paper draws them (paper Figs. 6 and 8), from the package's own benchmark definitions
(``ctmrpim/benchmarks/*.toml``) and nothing solved.

Fig. 6: the boundary the alpha shape tracks on node clouds without and with holes, as the solver tracks it
(:func:`ctmrpim.discretisation.configuration.track_boundary`): the cantilever's tensor grid (a rectangle), the
slope's generated cloud (a concave polygon: the re-entrant corner at the toe), the quarter plate with a hole
(the hole an arc of the one outer loop) and the same plate jittered with two holes cut inside it (the irregular
cloud: three loops). Nodes are dots, every tracked loop a line; each panel's title gives the loops and holes
found. Fig. 8: the cantilever (paper Table 1) on its 33 x 9 nodes as the two models of the paper, (a) the
four-node (Q1) finite-element mesh scikit-fem solves on those nodes (``reference_fem.mesh``), (b) the
CTM-RPIM model: the same nodes, the tracked boundary, the CTM integration points laid on it, the nodes whose
displacements are prescribed (the exact ones, at x = 0) and the parabolic end shear at x = L as arrows at its
boundary Gauss points.

Writes ``alpha_shapes.png`` (Fig. 6) and ``models.png`` (Fig. 8).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ctmrpim import benchmarks
from ctmrpim.discretisation.alpha_shape import Boundary
from ctmrpim.discretisation.configuration import boundary_tags, lay_points, reference_cloud
from ctmrpim.timing import Timer

from .base import new_figure, save_figure

NAME = "model_figures"
ALPHA_SHAPES = "alpha_shapes.png"
MODELS = "models.png"
#: the irregular cloud with holes: the plate-with-hole benchmark jittered, with two holes cut inside it
HOLES = ('nodes.jitter=0.3', 'nodes.seed=3',
         'geometry.subtract=[{ circle = [0, 0, "a"] }, { circle = [3, 1.8, 0.8] }, { circle = [1.6, 3.6, 0.6] }]')


@dataclass
class Cloud:
    """One panel of Fig. 6: a title, the nodes (n, 2) and their tracked boundary."""

    title: str
    nodes: np.ndarray
    boundary: Boundary


def clouds(quick: bool = True) -> list[Cloud]:
    """The four node clouds of Fig. 6 with the boundaries the solver tracks on them (quick: a coarser slope)."""
    slope_h = 1.0 if quick else 0.58
    out = []
    for title, name, overrides in (("cantilever, tensor grid", "cantilever", ()),
                                   ("slope, generated cloud", "slope", (f"parameters.h={slope_h!r}",)),
                                   ("quarter plate with a hole", "plate-hole", ()),
                                   ("plate, jittered, with two holes inside", "plate-hole", HOLES)):
        cloud = reference_cloud(benchmarks.load(name, list(overrides)), Timer())
        out.append(Cloud(title, cloud.nodes, cloud.boundary))
    return out


def _draw_cloud(ax, nodes: np.ndarray, boundary: Boundary, size: float = 2.0) -> None:
    ax.plot(nodes[:, 0], nodes[:, 1], ".", ms=size, color="0.35")
    for k, xy in enumerate(boundary.loop_coordinates()):
        ring = np.vstack([xy, xy[:1]])
        ax.plot(ring[:, 0], ring[:, 1], "-", lw=1.2, color="tab:red", label="tracked boundary" if k == 0 else None)


def alpha_shapes_figure(panels: list[Cloud]):
    """Fig. 6: each cloud's nodes and its tracked loops, one panel each (2 x 2)."""
    import matplotlib.pyplot as plt

    new_figure()                                   # the Agg backend
    plt.close("all")
    fig = plt.figure(figsize=(13, 8))
    grid = fig.add_gridspec(2, 2, height_ratios=[1.0, 2.2])
    axes = [fig.add_subplot(grid[i, j]) for i in range(2) for j in range(2)]
    for ax, c in zip(axes, panels):
        _draw_cloud(ax, c.nodes, c.boundary)
        ax.set(title=f"{c.title}: {len(c.nodes)} nodes, {len(c.boundary.loops)} loop(s), {c.boundary.n_holes} "
                     "hole(s)", xlabel="x (m)", ylabel="y (m)", aspect="equal")
        ax.title.set_fontsize(9)
        ax.legend(fontsize=7, loc="upper right")
    fig.suptitle("Boundaries tracked by the alpha shape (cf. Fig. 6)")
    fig.tight_layout()
    return fig


def models_figure(quick: bool = True):
    """Fig. 8: the cantilever's Q1 mesh and its CTM-RPIM model on the same nodes, supports and load marked."""
    from reference_fem.mesh import build_mesh

    case = benchmarks.load("cantilever")
    cloud = reference_cloud(case, Timer())
    tags = boundary_tags(case, cloud.nodes, cloud.boundary, cloud.lengths)
    quad, _ = lay_points(cloud.boundary.loop_coordinates(), cloud.lengths, case.problem.thickness)
    fem = build_mesh(case, "q1")
    fixed = np.unique(tags.fixed // 2)
    traction = tags.traction.points
    # the end shear's profile drawn beside the loaded face, its largest value 2.5 node spacings out, and one
    # arrow for its resultant (downward: P < 0)
    order = np.argsort(traction[:, 1])
    reach = 2.5 * cloud.d_c * np.abs(tags.ty[order]) / np.abs(tags.ty).max()
    face = traction[order]
    resultant = float(np.sign(np.sum(tags.ty * tags.traction.weights)))
    fig, axes = new_figure(1, 11.0, 2)
    fig.set_size_inches(11.0, 6.5)
    for ax in axes[:, 0]:
        ax.plot(cloud.nodes[fixed, 0], cloud.nodes[fixed, 1], ">", ms=6, color="tab:blue", mfc="none",
                label="prescribed ux, uy (exact)")
        ax.plot(face[:, 0], face[:, 1], "v", ms=3, color="tab:green", label="loaded face (Gauss points)")
        ax.plot(face[:, 0] + reach, face[:, 1], "-", color="tab:green", lw=1.2, label="parabolic end shear |ty|")
        for (x, y), r in zip(face[::2], reach[::2]):
            ax.plot([x, x + r], [y, y], "-", color="tab:green", lw=0.5)
        ax.annotate("", xy=(face[0, 0] + 3.5 * cloud.d_c, 3.0 * resultant), xytext=(face[0, 0] + 3.5 * cloud.d_c, 0),
                    arrowprops=dict(arrowstyle="-|>", color="tab:green", lw=1.5))
        ax.text(face[0, 0] + 3.7 * cloud.d_c, 1.5 * resultant, "P", color="tab:green")
    for cell in fem.cells:
        xy = fem.nodes[np.r_[cell, cell[:1]]]
        axes[0, 0].plot(xy[:, 0], xy[:, 1], "-", lw=0.6, color="0.5")
    axes[0, 0].plot(fem.nodes[:, 0], fem.nodes[:, 1], "k.", ms=3, label="nodes")
    axes[0, 0].set(title=f"(a) FEM model: {len(fem.cells)} four-node elements on {len(fem.nodes)} nodes")
    axes[1, 0].plot(quad.points[:, 0], quad.points[:, 1], ".", ms=0.8, color="tab:orange",
                    label="CTM integration points")
    _draw_cloud(axes[1, 0], cloud.nodes, cloud.boundary, size=4.0)
    axes[1, 0].set(title=f"(b) CTM-RPIM model: {len(cloud.nodes)} nodes, {len(quad.points)} integration points")
    grid = case.nodes.grid
    for ax in axes[:, 0]:
        ax.set(xlabel="x (m)", ylabel="y (m)", aspect="equal")
        ax.set_xlim(cloud.nodes[:, 0].min() - 2 * cloud.d_c, cloud.nodes[:, 0].max() + 5 * cloud.d_c)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.suptitle(f"Cantilever (Table 1), {grid[0]} x {grid[1]} nodes (cf. Fig. 8)")
    fig.tight_layout()
    return fig


def run(quick: bool = True, out_dir: Path = Path("reports"),
        progress: Callable[[str], object] = print) -> list[Path]:
    """Draw the tracked boundaries of four node clouds (cf. Fig. 6) and the cantilever's FEM and CTM-RPIM models
    (cf. Fig. 8) from the benchmark definitions; the two PNGs' paths."""
    progress("model figures: alpha shapes of four clouds, the cantilever's FEM and CTM-RPIM models")
    out_dir = Path(out_dir)
    return [save_figure(alpha_shapes_figure(clouds(quick)), out_dir / ALPHA_SHAPES),
            save_figure(models_figure(quick), out_dir / MODELS)]


if __name__ == "__main__":
    import sys

    from .cli import fields_main
    fields_main(sys.modules[__name__])
