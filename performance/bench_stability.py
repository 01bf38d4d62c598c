"""Wall time of the stability benchmarks, CTM-RPIM beside scikit-fem P2 in the same run:

    python performance/bench_stability.py [--only slope|slope-gl|footing] [--csv FILE]

For each run: the wall time, the answer (factor-of-safety bracket or limit-pressure bracket), the
iterations and factorisations it took, the time per iteration, and where the iteration time goes
(return mapping, internal force, tangent, factorisation, substitution) as shares of the wall time;
the rest is set-up (boundary, CTM points, RPIM shape functions or the mesh) and output projections.
The targets: the slope's factor-of-safety search and the footing's limit load (with the limit-load criteria)
at most 12 s each on this 2-core machine, CTM-RPIM on the benchmarks' own clouds.
"""
from __future__ import annotations

import argparse
import time

import pandas as pd

from ctmrpim import benchmarks
from ctmrpim.methods import solve

TARGETS = {"slope": 12.0, "slope-gl": 12.0, "footing": 12.0}     # seconds allowed


def run(target: str, solver: str) -> dict:
    case = benchmarks.load(target)
    t0 = time.perf_counter()
    r = solve(case, solver, None if solver == "ctm-rpim" else "p2")
    wall = time.perf_counter() - t0
    c = r.counts
    if "factor_of_safety" in r.outcome:
        fos = r.outcome["factor_of_safety"]
        answer = f"FS in [{fos['stable']:.4f}, {fos['failed']:.4f}]"
    else:
        lim = r.outcome["limit_pressure"]
        answer = f"q_limit in [{lim['carried'] / 1e3:.1f}, {lim['failed'] / 1e3:.1f}] kPa"
    row = {"case": target, "method": r.method, "nodes": c["nodes"], "points": c["integration_points"],
           "wall_s": round(wall, 2), "target_s": TARGETS[target], "answer": answer,
           "iterations": c["newton_iterations"], "factorisations": c["factorisations"],
           "ms_per_iteration": round(1e3 * wall / c["newton_iterations"], 1)}
    row.update({f"{k} %": round(100 * v / wall, 1) for k, v in c["iteration_seconds"].items()})
    row["set-up and output %"] = round(100 - sum(100 * v / wall for v in c["iteration_seconds"].values()), 1)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", choices=list(TARGETS))
    ap.add_argument("--csv", help="also write the table here")
    a = ap.parse_args()
    rows = []
    for target in ([a.only] if a.only else TARGETS):
        for solver in ("ctm-rpim", "fem"):
            rows.append(run(target, solver))
            print(pd.DataFrame(rows[-1:]).to_string(index=False), flush=True)
    df = pd.DataFrame(rows)
    pd.set_option("display.width", 250)
    print("\n" + df.to_string(index=False))
    for target in df.case.unique():
        d = df[df.case == target].set_index("method")
        ours = d[d.index.str.startswith("ctm")].iloc[0]
        fem = d[d.index.str.startswith("fem")].iloc[0]
        print(f"{target}: CTM-RPIM {ours.wall_s:.1f} s (target {ours.target_s:.0f} s: "
              f"{'met' if ours.wall_s < ours.target_s else 'MISSED'}), scikit-fem P2 {fem.wall_s:.1f} s, "
              f"ratio {ours.wall_s / fem.wall_s:.1f}")
    if a.csv:
        df.to_csv(a.csv, index=False)


if __name__ == "__main__":
    main()
