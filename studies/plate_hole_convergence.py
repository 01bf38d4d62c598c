"""Plate with a circular hole (Kirsch), quarter model, plane stress and plane strain: CTM-RPIM
against scikit-fem P1 and P2 on the same nodes; L2 and energy-norm errors and the stress
concentration sxx(0, a) (exact 3 T).

Writes ``plate_hole_convergence.csv``.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from ctmrpim import benchmarks
from ctmrpim.output import atomic_write_text
from ctmrpim.solvers import solve

QUICK_SPACINGS = [0.5, 0.25]
FULL_SPACINGS = [0.5, 0.25, 0.125, 0.0625]
METHODS = [("ctm-rpim", None), ("fem", "p1"), ("fem", "p2")]
PLANES = {"stress": 1, "strain": 0}   # the problem file's `ps` parameter must follow problem.plane


def case(plane: str, spacing: float):
    return benchmarks.load("plate-hole", [f"nodes.spacing={spacing}", f'problem.plane="{plane}"',
                                          f"parameters.ps={PLANES[plane]}"])


def run(quick: bool = True, out_dir: Path = Path("reports"), progress=print) -> pd.DataFrame:
    spacings = QUICK_SPACINGS if quick else FULL_SPACINGS
    progress(f"plate with hole ({'quick' if quick else 'full'}): spacings {spacings}, plane stress and strain")
    rows = []
    for plane in PLANES:
        for h in spacings:
            c = case(plane, h)
            for solver, element in METHODS:
                r = solve(c, solver, element)
                top = r.probes["hole_top"]
                rows.append({"plane": plane, "spacing": h, "nodes": r.counts["nodes"], "method": r.method,
                             "l2_error": r.errors["l2"], "energy_error": r.errors["energy"],
                             "sxx_hole_top": top["sxx"], "time_s": r.timings["total"]})
                progress(f"  plate-hole plane {plane:6s} h = {h:<6g} {r.method:9s} L2 {100 * r.errors['l2']:8.4f} %"
                         f"  energy {100 * r.errors['energy']:8.4f} %  sxx(0, a) = {top['sxx']:8.1f} (exact 3000)")
    df = pd.DataFrame(rows)
    atomic_write_text(Path(out_dir) / "plate_hole_convergence.csv", df.to_csv(index=False))
    return df


if __name__ == "__main__":
    from studies.cli import main
    main(run, __doc__)
