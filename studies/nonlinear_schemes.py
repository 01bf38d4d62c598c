"""The paper's CTM against the consistent CTM on every nonlinear benchmark (not in the paper): the tip-loaded
cantilever and the end-moment ring (updated- and total-Lagrangian, neo-Hookean), the slope's factor of safety and
the footing's limit pressure (small-strain Mohr-Coulomb), and the column collapse (explicit). Each benchmark is
run as its own study runs it (the same cases: the paper's scheme comes from their cache) and again with
``method.integration = "ctm-vci"``; the table gives each one's distance from its reference (the elastica, the
exact arc, Bishop's factor, Prandtl's pressure), the difference between the schemes and the cost. The explicit
solver refuses the consistent scheme (its corrected test gradients do not conserve momentum): the table shows
the solver's reason instead of a run. The paper's scheme stays the default of every nonlinear path: the updated-Lagrangian path
(the paper's adaptive method) is not closer on every benchmark with the consistent scheme, the total-Lagrangian
path is its cross-check and integrates the same way unless told, and the Mohr-Coulomb paths gain little
against their searches' resolution; the paragraph below the table gives the numbers.
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from studies import column_collapse, end_moment, footing_bearing, slope_stability, tip_load
from studies.schemes import CONSISTENT, PAPER, SCHEMES, scheme_override
from studies.sweep import CaseSpec

from .base import finished, new_figure

if TYPE_CHECKING:
    from pathlib import Path

    from matplotlib.figure import Figure

NAME = "nonlinear_schemes"
TITLE = "Integration schemes on the nonlinear benchmarks"
#: benchmark -> (what its distance from the reference measures, the reference)
MEASURES = {"tip-load": ("w/L, relative", "exact elastica"),
            "end-moment": ("tip distance / L", "exact arc, Eq. (37)"),
            "slope": ("factor of safety, worst relative", "Bishop's simplified method"),
            "footing": ("limit pressure, worst relative", "Prandtl, Eq. (40)"),
            "column-collapse": ("run-out / experiment - 1 (at the run's end)", "Bui et al. (2008)")}


def _base_cases(quick: bool) -> list[tuple[str, CaseSpec]]:
    """(formulation, the case as its own study runs it) for each benchmark: the tip load (end shear) at the
    study's largest load, the ring at its first moment fraction, each with UL and TL; the slope, the footing and
    the collapse at their first resolution."""
    out = []
    tips = [s for s in tip_load.specs(quick) if s.solver == "ctm-rpim" and s.label_dict()["load"] == "end shear"]
    lam = max(s.label_dict()["lam"] for s in tips)
    out += [(s.label_dict()["formulation"], s) for s in tips if s.label_dict()["lam"] == lam]
    rings = [s for s in end_moment.specs(quick) if s.solver == "ctm-rpim" and s.label_dict()["formulation"] != "UL carried"]
    m = min(s.label_dict()["m"] for s in rings)
    out += [(s.label_dict()["formulation"], s) for s in rings if s.label_dict()["m"] == m]
    slope = next(s for s in slope_stability.specs(quick) if s.solver == "ctm-rpim" and s.target == "slope")
    footing = next(s for s in footing_bearing.specs(quick) if s.solver == "ctm-rpim")
    out += [("small strain", slope), ("small strain", footing), ("explicit", column_collapse.specs(quick)[0])]
    return out


def specs(quick: bool) -> list[CaseSpec]:
    """Every benchmark case with the paper's scheme (its study's own case: the nonlinear analyses' default) and
    with the consistent one."""
    return [CaseSpec(base.target, base.overrides + (() if scheme == PAPER else (scheme_override(scheme),)),
                     labels=(("benchmark", base.target), ("formulation", formulation), ("scheme", scheme)))
            for formulation, base in _base_cases(quick) for scheme in SCHEMES
            if scheme == PAPER or refusal(base.target) is None]


def refusal(benchmark: str) -> str | None:
    """Why the solver refuses the consistent scheme on ``benchmark`` (its one-line message), None where it runs
    it: asked of the solver's own check, without a run."""
    from ctmrpim import benchmarks
    from ctmrpim.errors import ProblemError
    from ctmrpim.solvers.meshfree import check_integration

    try:
        check_integration(benchmarks.load(benchmark, [scheme_override(CONSISTENT)]))
    except ProblemError as err:
        return err.reason
    return None


def extra(summary: dict, folder: Path) -> dict:
    """The benchmark's distance from its reference (``rel_diff``, see MEASURES) and the Newton iterations."""
    name = summary["parameters"]["problem"]["name"]
    iterations = summary["counts"].get("newton_iterations", np.nan)
    if name == "tip-load":
        value = tip_load.extra(summary)["w_rel_diff"]
    elif name == "end-moment":
        value = end_moment.extra(summary)["tip_distance_over_L"]
    elif name == "slope":
        value = slope_stability.extra(summary)["worst_rel_diff"]
    elif name == "footing":
        value = footing_bearing.extra(summary)["worst_rel_diff"]
    else:
        row = column_collapse.extra(summary, folder)
        value = row["run_out_m"] / row["run_out_measured_m"] - 1.0
    return {"rel_diff": value, "newton_iterations": iterations}


def comparison(df: pd.DataFrame) -> pd.DataFrame:
    """Per benchmark and formulation: the distance from the reference with each scheme, their difference and the
    time ratio ctm-vci / ctm (NaN where the solver refuses the consistent scheme), with the solver's reason."""
    rows = []
    for (benchmark, formulation), d in df.groupby(["benchmark", "formulation"], sort=False):
        by = d.set_index("scheme")
        paper = by.loc[PAPER]
        if str(paper.method).endswith("-vci"):   # the paper's case is its study's, on the analysis' default
            raise ValueError(f"{benchmark}: the case labelled {PAPER!r} ran {CONSISTENT!r}: a default changed; "
                             "name the scheme in specs()")
        ran = CONSISTENT in by.index
        vci = by.loc[CONSISTENT] if ran else None
        measure, reference = MEASURES[benchmark]
        rows.append({"benchmark": benchmark, "formulation": formulation, "measure": measure, "reference": reference,
                     PAPER: paper.rel_diff, CONSISTENT: vci.rel_diff if ran else np.nan,
                     "difference": (vci.rel_diff - paper.rel_diff) if ran else np.nan,
                     "ctm_time_s": paper.time_s, "time_ratio": vci.time_s / paper.time_s if ran else np.nan,
                     "refused": "" if ran else (refusal(benchmark) or "")})
    return pd.DataFrame(rows)


def figure(df: pd.DataFrame) -> Figure:
    """|distance from the reference| of each benchmark with each scheme, and the consistent scheme's time ratio
    (the benchmarks that refuse it are in the table only)."""
    table = comparison(df)
    table = table[table.refused == ""].reset_index(drop=True)
    fig, axes = new_figure(2, 6.5)
    labels = [f"{b}\n{f}" for b, f in zip(table.benchmark, table.formulation)]
    x = np.arange(len(table))
    for k, scheme in enumerate(SCHEMES):
        axes[0, 0].bar(x + (k - 0.5) * 0.38, 100 * np.abs(table[scheme]), 0.38, label=scheme)
    axes[0, 0].set_yscale("log")
    axes[0, 0].set(ylabel="|distance from the reference| [%]", title="Each benchmark against its reference")
    axes[0, 1].bar(x, table.time_ratio, 0.5, color="C1", label=f"{CONSISTENT} / {PAPER}")
    axes[0, 1].axhline(1.0, color="k", lw=0.8)
    axes[0, 1].set(ylabel="wall-time ratio [-]", title="Cost of the consistent scheme")
    for ax in axes[0]:
        ax.set_xticks(x, labels, fontsize=7)
    return finished(fig, axes)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
