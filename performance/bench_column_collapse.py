"""Wall time of the granular column collapse (the 1071-node collapse to rest in at most 60 s on this 2-core
machine, the 2016-node one in at most 240 s: ``--set "nodes.grid=[63, 32]"`` for that cloud):

    python performance/bench_column_collapse.py [--set SECTION.KEY=VALUE ...] [--out DIR]

Runs the `column-collapse` benchmark (gravity stage behind the gate, then the collapse until the
deposit is at rest) and prints the wall time, the simulated time, the steps, the time step range,
the rebuilds (RPIM on the current nodes) and re-layings (new boundary, CTM points, state transfer),
the time per step, and where the time goes (forces, material update, rebuilds, transfers, time-step
estimates, output, checkpoints) as shares of the wall time. There is no FEM counterpart (the
reference FEM has no explicit dynamic solver): the numbers stand alone.
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import pandas as pd

from ctmrpim import benchmarks
from ctmrpim.solvers.explicit.run import solve_explicit

PHASES = ("forces", "material", "rebuild", "transfer", "time_step", "output", "checkpoint")
#: (largest node count, wall-time target in s): the paper's 1071-node cloud, the 2016-node one
TARGETS = ((1100, 60.0), (2100, 240.0))


def target(nodes: int) -> float | None:
    """The wall-time target of a cloud of ``nodes`` (None beyond the targets' clouds)."""
    return next((t for most, t in TARGETS if nodes <= most), None)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE")
    ap.add_argument("--out", help="keep the run's series here (default: a temporary folder)")
    a = ap.parse_args()
    case = benchmarks.load("column-collapse", a.set)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        r = solve_explicit(case, Path(a.out or tmp), progress=True)
        wall = time.perf_counter() - t0
    d, t = r.outcome["dynamics"], r.timings
    row = {"nodes": r.counts["nodes"], "points": r.counts["integration_points"], "wall_s": round(wall, 1),
           "target_s": target(r.counts["nodes"]), "simulated_s": round(d["end_time"], 4), "at_rest": d["at_rest"],
           "steps": d["steps"] + d["stage_steps"], "dt_min_s": f"{d['dt']['min']:.3g}",
           "dt_max_s": f"{d['dt']['max']:.3g}", "rebuilds": d["rebuilds"], "re-layings": d["state_transfers"],
           "ms_per_step": round(1e3 * wall / (d["steps"] + d["stage_steps"]), 2)}
    row.update({f"{k} %": round(100 * t.get(k, 0.0) / wall, 1) for k in PHASES})
    pd.set_option("display.width", 250)
    print(pd.DataFrame([row]).to_string(index=False))
    goal = target(r.counts["nodes"])
    if goal is not None:
        print(f"\n{'met' if wall <= goal else 'NOT met'}: {wall:.0f} s against {goal:.0f} s")


if __name__ == "__main__":
    main()
