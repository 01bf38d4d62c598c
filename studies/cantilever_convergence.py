"""Cantilever (paper Section 3.1, Eq. 35) at growing node density, cf. Fig. 9: CTM-RPIM against
scikit-fem Q1, P1 and P2 on the same node grids; tip, L2 and energy-norm errors, wall time.

Writes ``cantilever_convergence.csv`` and ``cantilever_convergence.png``.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from ctmrpim import benchmarks
from ctmrpim.output import atomic_write, atomic_write_text
from ctmrpim.solvers import solve

QUICK_GRIDS = [(17, 5), (33, 9), (65, 17)]
FULL_GRIDS = QUICK_GRIDS + [(129, 33), (257, 65)]
METHODS = [("ctm-rpim", None), ("fem", "q1"), ("fem", "p1"), ("fem", "p2")]
LENGTH = 48.0


def run(quick: bool = True, out_dir: Path = Path("reports"), progress=print) -> pd.DataFrame:
    grids = QUICK_GRIDS if quick else FULL_GRIDS
    progress(f"cantilever convergence ({'quick' if quick else 'full'}): {len(grids)} grids x {len(METHODS)} methods")
    rows = []
    for nx, ny in grids:
        case = benchmarks.load("cantilever", [f"nodes.grid=[{nx}, {ny}]"])
        for solver, element in METHODS:
            r = solve(case, solver, element)
            rows.append({"grid": f"{nx} x {ny}", "nodes": r.counts["nodes"], "h": LENGTH / (nx - 1),
                         "method": r.method, "integration_points": r.counts["integration_points"],
                         "tip_error": r.errors["probes"]["tip"]["uy"], "l2_error": r.errors["l2"],
                         "energy_error": r.errors["energy"], "time_s": r.timings["total"]})
            progress(f"  cantilever {nx:>3} x {ny:<3} {r.method:9s} tip error {100 * rows[-1]['tip_error']:9.4f} %"
                     f"  energy {100 * rows[-1]['energy_error']:8.4f} %  {rows[-1]['time_s']:7.3f} s")
    df = pd.DataFrame(rows)
    atomic_write_text(Path(out_dir) / "cantilever_convergence.csv", df.to_csv(index=False))
    figure(df, Path(out_dir) / "cantilever_convergence.png")
    return df


def figure(df: pd.DataFrame, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for method, d in df.groupby("method", sort=False):
        axes[0].loglog(d.nodes, d.tip_error, "o-", label=method)
        axes[1].loglog(d.nodes, d.energy_error, "o-", label=method)
    axes[0].set(xlabel="nodes", ylabel="relative tip-deflection error", title="Cantilever: tip error (cf. Fig. 9b)")
    axes[1].set(xlabel="nodes", ylabel="relative energy-norm error", title="Cantilever: energy-norm error")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.tight_layout()
    atomic_write(path, lambda p: fig.savefig(p, format="png", dpi=120))
    plt.close(fig)


if __name__ == "__main__":
    from studies.cli import main
    main(run, __doc__)
