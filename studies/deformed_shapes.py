"""Deformed configurations of the large-deflection beams (paper Figs. 15 and 17): the node cloud and
the boundary the alpha shape tracked on it at several load levels, drawn from the per-increment series
of one adaptive updated-Lagrangian run each (these runs are not cached: they need the displacement
fields, not only the summaries).

Writes ``deformed_shapes.png``.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from ctmrpim import benchmarks
from ctmrpim.methods import solve
from ctmrpim.reference import elastica

from .base import finished, new_figure, save_figure

NAME = "deformed_shapes"
STAGES = (0.25, 0.5, 0.75, 1.0)


def _draw(ax, result, step, colour, label):
    xy = result.points + step["u"]
    ax.plot(xy[:, 0], xy[:, 1], ".", ms=1.5, color=colour)
    edges = step.get("boundary")
    if edges is None:
        edges = next(c for k, c in result.cells if k == "line")
    for a, b in edges:
        ax.plot(xy[[a, b], 0], xy[[a, b], 1], "-", lw=0.8, color=colour)
    ax.plot([], [], "-", color=colour, label=label)


def run(quick: bool = True, out_dir: Path = Path("reports"), progress: Callable[[str], object] = print) -> Path:
    """Solve the end-moment ring and the tip-loaded cantilever (UL) and draw their clouds and tracked boundaries
    at four load levels, with the exact tips (cf. Figs. 15 and 17); the PNG's path."""
    m_full = 0.5 if quick else 1.0
    lam = 1.8 if quick else 3.6
    progress(f"deformed shapes: end moment up to m = {m_full}, tip load up to lambda = {lam}")
    ul = 'method.formulation="updated-lagrangian"'
    ring = solve(benchmarks.load("end-moment", [f"parameters.m={m_full}", f"loading.steps={int(64 * m_full)}", ul]))
    tip = solve(benchmarks.load("tip-load", [f"parameters.lam={lam}", f"loading.steps={max(6, int(np.ceil(4 * lam)))}",
                                             ul]))
    fig, axes = new_figure(2, 5.5)
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    for stage, colour in zip(STAGES, colours):
        step = min(ring.series, key=lambda s: abs(s["load_factor"] - stage))
        m = step["load_factor"] * m_full
        _draw(axes[0, 0], ring, step, colour, f"M = {m:.3g} x 2 pi EI/L")
        ex, ey = elastica.end_moment_tip(2 * np.pi * m)
        axes[0, 0].plot(10 * ex, 10 * ey, "kx")
        step = min(tip.series, key=lambda s: abs(s["load_factor"] - stage))
        _draw(axes[0, 1], tip, step, colour, f"lambda = {step['load_factor'] * lam:.3g}")
        exact = elastica.tip_load_elliptic(step["load_factor"] * lam)
        axes[0, 1].plot(10 * (1 - exact.u_over_L), -10 * exact.w_over_L, "kx")
    axes[0, 0].set(title="End moment (cf. Fig. 17); x: exact tip", xlabel="x (m)", ylabel="y (m)", aspect="equal")
    axes[0, 1].set(title="Tip load (cf. Fig. 15); x: exact tip", xlabel="x (m)", ylabel="y (m)", aspect="equal")
    finished(fig, axes, "major", 7)
    return save_figure(fig, Path(out_dir) / f"{NAME}.png")


if __name__ == "__main__":
    import sys

    from .cli import fields_main
    fields_main(sys.modules[__name__])
