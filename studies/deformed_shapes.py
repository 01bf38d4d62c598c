"""Deformed configurations of the large-deflection beams (paper Figs. 15 and 17): the node cloud and
the boundary the alpha shape tracked on it, drawn from the per-increment series of one adaptive
updated-Lagrangian run each (these runs are not cached: they need the displacement fields, not only the
summaries). The ring at four moment levels; the tip-loaded cantilever at the two force levels of the
paper's Fig. 15 (lambda = P L^2 / (E I) = 2.4 and 3.6, its largest loads, ``FULL_LOADS_KN``) in full mode,
and at two of its lower loads (``QUICK_LOADS_KN``) in quick mode: the figure gives each P in kN and says
which mode drew it.

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
#: The tip loads (kN) drawn on the cantilever: the paper's Fig. 15 in full mode, two of its lower loads in quick mode.
FULL_LOADS_KN = (2000.0, 3000.0)
QUICK_LOADS_KN = (1000.0, 1500.0)


def load_steps(loads_kn: tuple[float, ...]) -> int:
    """The increments of a run up to the largest of ``loads_kn``: the most, up to max(6, 4 per unit of lambda) as
    in the tip-load study, with every load reached at an increment's end (more only where none is)."""
    top = max(loads_kn)
    most = max(6, int(np.ceil(4 * elastica.paper_lambda(top))))
    fits = [n for n in range(1, 4 * most) if all(abs(p / top * n - round(p / top * n)) < 1e-9 for p in loads_kn)]
    return max((n for n in fits if n <= most), default=min(fits))


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
    """Solve the end-moment ring and the tip-loaded cantilever (UL) and draw their clouds and tracked boundaries,
    the ring at four moment levels, the cantilever at two tip loads (the paper's Fig. 15's in full mode), with the
    exact tips (cf. Figs. 15 and 17); the PNG's path."""
    m_full = 0.5 if quick else 1.0
    loads = QUICK_LOADS_KN if quick else FULL_LOADS_KN
    lam = elastica.paper_lambda(max(loads))
    steps = load_steps(loads)
    progress(f"deformed shapes: end moment up to m = {m_full}, tip load up to P = {max(loads):g} kN "
             f"(lambda = {lam:.3g}, {steps} increments)")
    ul = 'method.formulation="updated-lagrangian"'
    ring = solve(benchmarks.load("end-moment", [f"parameters.m={m_full}", f"loading.steps={int(64 * m_full)}", ul]))
    tip = solve(benchmarks.load("tip-load", [f"parameters.lam={lam!r}", f"loading.steps={steps}", ul]))
    fig, axes = new_figure(2, 5.5)
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    for stage, colour in zip(STAGES, colours):
        step = min(ring.series, key=lambda s: abs(s["load_factor"] - stage))
        m = step["load_factor"] * m_full
        _draw(axes[0, 0], ring, step, colour, f"M = {m:.3g} x 2 pi EI/L")
        ex, ey = elastica.end_moment_tip(2 * np.pi * m)
        axes[0, 0].plot(10 * ex, 10 * ey, "kx")
    ax = axes[0, 1]
    ax.plot([0, 10, 10, 0, 0], [-0.5, -0.5, 0.5, 0.5, -0.5], "-", lw=0.8, color="0.6", label="initial configuration")
    for p_kn, colour in zip(loads, ("tab:blue", "tab:red")):
        step = min(tip.series, key=lambda s: abs(s["load_factor"] - p_kn / max(loads)))
        at = step["load_factor"] * lam
        _draw(ax, tip, step, colour, f"P = {at / elastica.paper_lambda(1.0):.0f} kN (lambda = {at:.3g})")
        exact = elastica.tip_load_elliptic(at)
        ax.plot(10 * (1 - exact.u_over_L), -10 * exact.w_over_L, "kx")
    ax.plot([], [], "kx", label="exact tip (elastica)")
    axes[0, 0].plot([], [], "kx", label="exact tip (Eq. 37)")
    axes[0, 0].set(title="End moment (cf. Fig. 17)", xlabel="x (m)", ylabel="y (m)", aspect="equal")
    what = ("full mode: the paper's two force levels" if not quick else
            f"quick mode: P = {', '.join(f'{p:g}' for p in loads)} kN (the paper's: 2000, 3000 kN)")
    ax.set(title=f"Tip load, final configurations (cf. Fig. 15)\n{what}", xlabel="x (m)", ylabel="y (m)",
           aspect="equal")
    finished(fig, axes, "major", 7)
    return save_figure(fig, Path(out_dir) / f"{NAME}.png")


if __name__ == "__main__":
    import sys

    from .cli import fields_main
    fields_main(sys.modules[__name__])
