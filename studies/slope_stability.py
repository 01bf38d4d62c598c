"""Slope stability by strength reduction (paper Section 3.3.1, Figs. 18-20): the factor of safety of
the two candidate geometries of Fig. 18 - `slope` (Smith & Griffiths 6.4 embankment) and `slope-gl`
(Griffiths & Lane 1999, Example 1) - as a bracket [last stable SRF, first failed SRF], CTM-RPIM and
scikit-fem P2 on the same nodes with the same PlasticSystem, return mapping and search (bracket by
0.1 from SRF = 1 continuing from the last stable state, then bisection to 0.01; a level fails when its
displacement runs away - the largest displacement from the stable level below, per unit relative SRF rise, above
`strength-reduction.limit_growth` times the largest at SRF = 1 - or when the equilibrium iteration does not converge even on the re-check (Newton on the consistent tangent),
see ctmrpim.solvers.strength_reduction), against Bishop's simplified method computed by us
for each geometry (critical circle searched), and the published values (the side-by-side table above).
Node spacing h: the default clouds (0.58 m for `slope`, close to the paper's node count; 0.35 m for
`slope-gl`) in the full run, beside a coarser (1.0 m, 0.6 m) and a finer one (0.42 m, 0.25 m): three clouds that
show the trend with resolution; quick mode runs the coarser ones only. The full run adds the vertical cut in undrained clay (against Taylor's
stability number and our Bishop search) on three clouds and, on each benchmark's own cloud, the sensitivity of the
factor of safety to the tangent (variant "consistent": Newton with its own cap) and to the iteration cap
(variant "cap x2": the elastic-stiffness iteration's max_iterations doubled), and both slopes on all three clouds
with an associated flow rule (variant "associated": psi = phi), the flow rule's share of the gap to Bishop.
"""
from __future__ import annotations

import sys
from functools import cache
from typing import TYPE_CHECKING

import pandas as pd

from ctmrpim import benchmarks
from ctmrpim.reference.limit_equilibrium import problem_factor_of_safety
from studies.sweep import CaseSpec, element_for

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "slope_stability"
TITLE = "Slope factor of safety by strength reduction (cf. Figs. 18-19)"
SPACING = {"slope": {"quick": [1.0], "full": [1.0, 0.58, 0.42]},
           "slope-gl": {"quick": [0.6], "full": [0.6, 0.35, 0.25]},
           "vertical-cut": {"quick": [], "full": [1.0, 0.5, 0.35]}}
#: each benchmark's own node spacing (its file's), where the full run adds the sensitivity variants
OWN_SPACING = {"slope": 0.58, "slope-gl": 0.35, "vertical-cut": 0.35}
PAPER = (1.3, 1.4)
#: the sensitivity variants (full run, each benchmark's own cloud): overrides of the benchmark's [loading]
VARIANTS = {"default": (), "consistent": ('loading.tangent="consistent"', "loading.max_iterations=15"),
            "cap x2": ("loading.max_iterations=200",)}
#: the frictional slopes run associated as well (psi = phi) on all three clouds: the flow rule's share of the gap to
#: Bishop's simplified method, a rigid-plastic limit equilibrium that knows no dilatancy (full run)
ASSOCIATED = ("slope", "slope-gl")


def _associated(target: str) -> tuple[str, ...]:
    """The override that makes benchmark ``target``'s flow associated: psi = its phi."""
    return (f"material.psi={benchmarks.load(target).problem.material.phi!r}",)


@cache
def bishop(target: str) -> float:
    """Bishop's simplified factor of safety of benchmark ``target``'s critical circle."""
    return problem_factor_of_safety(benchmarks.load(target).problem).fs


def specs(quick: bool) -> list[CaseSpec]:
    """CTM-RPIM and scikit-fem P2 on each slope geometry at each node spacing (and, in the full run, the
    variants on the finest)."""
    mode = "quick" if quick else "full"
    out = []
    for target, hs in SPACING.items():
        for h in hs[mode]:
            variants = ("default",) if quick or h != OWN_SPACING[target] else tuple(VARIANTS)
            overrides = {v: VARIANTS[v] for v in variants}
            if not quick and target in ASSOCIATED:
                overrides["associated"] = _associated(target)
            out += [CaseSpec(target, (f"parameters.h={h!r}",) + extra, solver, element_for(solver, "p2"),
                             labels=(("slope", target), ("h", h), ("variant", v)))
                    for v, extra in overrides.items() for solver in ("ctm-rpim", "fem")]
    return out


def extra(summary: dict) -> dict:
    """The factor-of-safety bracket, Bishop's, their worst relative difference, the levels and iterations, what
    decided the failure, the tangent and the cap, and how far the displacement had run away when the search
    stopped: the largest growth of a stable level (its displacement from the stable level below per relative SRF
    rise, over the displacement at SRF = 1) against the runaway limit ``limit_growth``, and the displacement at the
    last stable level over the one at SRF = 1. A bracket decided by non-convergence far below the runaway limit
    is the iteration's, not the slope's."""
    fos = summary["factor_of_safety"]
    target = summary["parameters"]["problem"]["name"]
    reference = bishop(target)
    worst = max(abs(fos["stable"] / reference - 1), abs(fos["failed"] / reference - 1))
    stable = [h for h in summary.get("history", []) if h.get("stable")]
    growth = max((h["growth"] for h in stable if h.get("growth") is not None), default=float("nan"))
    first = min(stable, key=lambda h: h["srf"]) if stable else None
    last = max(stable, key=lambda h: h["srf"]) if stable else None
    return {"fs_stable": fos["stable"], "fs_failed": fos["failed"], "bishop": reference,
            "worst_rel_diff": worst, "levels": summary["counts"]["levels"],
            "iterations": summary["counts"]["newton_iterations"], "decided_by": fos.get("decided_by"),
            "largest_stable_growth": growth, "limit_growth": fos.get("limit_growth"),
            "displacement_ratio_at_stable": (last["max_displacement"] / first["max_displacement"]
                                             if first and first["max_displacement"] else float("nan")),
            "tangent": summary["parameters"]["loading"]["tangent"],
            "max_iterations": summary["parameters"]["loading"]["max_iterations"]}


def figure(df: pd.DataFrame) -> Figure:
    """The factor-of-safety bracket of every case against its node count, one panel per benchmark: both methods with
    the benchmark's flow rule and (full run) with an associated one, Bishop's simplified method and the paper's range
    (cf. Figs. 18-19)."""
    variant = df["variant"] if "variant" in df else pd.Series("default", index=df.index)
    ok = df[(df.status == "ok") & variant.isin(("default", "associated"))].assign(variant=variant)
    slopes = list(dict.fromkeys(ok.slope))
    fig, axes = new_figure(max(len(slopes), 1), 4.2)
    styles = {("ctm-rpim", "default"): ("tab:blue", -0.04, "CTM-RPIM, psi as the benchmark's"),
              ("fem-p2", "default"): ("tab:orange", -0.015, "scikit-fem P2, psi as the benchmark's"),
              ("ctm-rpim", "associated"): ("tab:green", 0.015, "CTM-RPIM, associated (psi = phi)"),
              ("fem-p2", "associated"): ("tab:olive", 0.04, "scikit-fem P2, associated (psi = phi)")}
    for ax, slope in zip(axes[0], slopes):
        d = ok[ok.slope == slope]
        for (method, v), (colour, shift, label) in styles.items():
            e = d[(d.method == method) & (d.variant == v)].sort_values("nodes")
            if len(e):
                x = e.nodes * 10 ** shift
                ax.vlines(x, e.fs_stable, e.fs_failed, color=colour, lw=5, label=label)
                ax.plot(x, 0.5 * (e.fs_stable + e.fs_failed), ":", color=colour, lw=1)
        ax.axhline(d.bishop.iloc[0], color="k", lw=1, label="Bishop's simplified method (ours)")
        if slope != "vertical-cut":
            ax.axhspan(*PAPER, color="0.92", label="paper: stable at 1.3, failed at 1.4", zorder=0)
        ax.set(xscale="log", xlabel="nodes", ylabel="factor of safety (SRF)", title=f"`{slope}`")
    axes[0, 0].legend(fontsize=7, loc="upper right")
    fig.suptitle(TITLE)
    return finished(fig, axes)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
