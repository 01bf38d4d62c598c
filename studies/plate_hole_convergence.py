"""Plate with a circular hole (Kirsch), quarter model, plane stress and plane strain: CTM-RPIM with the
paper's integration (``ctm-rpim``) and with the consistent one, the default (``ctm-rpim-vci``), against
scikit-fem P1 and P2 on the same nodes; L2 and energy-norm errors and the stress concentration sxx(0, a)
(exact 3 T) at the boundary node (CTM-RPIM: recovered from the integration points' stresses).
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import pandas as pd

from ctmrpim import benchmarks
from ctmrpim.problem.case import Case
from studies.schemes import CONSISTENT, SCHEMES, scheme_override
from studies.sweep import CaseSpec

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "plate_hole_convergence"
TITLE = "Plate with a hole (Kirsch)"
QUICK_SPACINGS = [0.5, 0.25]
FULL_SPACINGS = [0.5, 0.25, 0.125, 0.0625]
METHODS = [*(("ctm-rpim", None, (scheme_override(s),)) for s in SCHEMES), ("fem", "p1", ()), ("fem", "p2", ())]
PLANES = {"stress": 1, "strain": 0}   # the problem file's `ps` parameter must follow problem.plane


def overrides(plane: str, spacing: float) -> tuple[str, ...]:
    """The --set strings of a plate-hole case in ``plane`` (``stress`` or ``strain``) with node ``spacing``."""
    return (f"nodes.spacing={spacing}", f'problem.plane="{plane}"', f"parameters.ps={PLANES[plane]}")


def case(plane: str, spacing: float, scheme: str = CONSISTENT) -> Case:
    """The plate-hole benchmark in ``plane`` with node ``spacing``, integrated with ``scheme``."""
    return benchmarks.load("plate-hole", [*overrides(plane, spacing), scheme_override(scheme)])


def specs(quick: bool) -> list[CaseSpec]:
    """Each method (CTM-RPIM with either scheme, scikit-fem P1, P2) in each plane state at each node spacing."""
    return [CaseSpec("plate-hole", (*overrides(plane, h), *extra), solver, element,
                     labels=(("plane", plane), ("spacing", h)))
            for plane in PLANES for h in (QUICK_SPACINGS if quick else FULL_SPACINGS)
            for solver, element, extra in METHODS]


def extra(summary: dict) -> dict:
    """The stress sxx at the top of the hole (probe ``hole_top``; exact 3 T)."""
    return {"sxx_hole_top": summary["probes"]["hole_top"]["sxx"]}


def figure(df: pd.DataFrame) -> Figure:
    """Energy-norm error and the stress concentration sxx(0, a) / T against the node count."""
    fig, axes = new_figure(2)
    for (method, plane), d in df[df.status == "ok"].groupby(["method", "plane"], sort=False):
        axes[0, 0].loglog(d.nodes, d.energy_error, "o-" if plane == "stress" else "s--", label=f"{method}, plane {plane}")
        axes[0, 1].semilogx(d.nodes, d.sxx_hole_top / 1000.0, "o-" if plane == "stress" else "s--",
                            label=f"{method}, plane {plane}")
    axes[0, 1].axhline(3.0, color="k", lw=0.8, label="exact 3 T")
    axes[0, 0].set(xlabel="nodes", ylabel="relative energy-norm error", title=TITLE + ": energy error")
    axes[0, 1].set(xlabel="nodes", ylabel="sxx(0, a) / T", title="Stress concentration at the hole")
    return finished(fig, axes, "both", 7)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
