"""Per-phase wall time and peak memory of CTM-RPIM and scikit-fem (Q1, P2) on the cantilever, at growing n.

    python performance/bench_linear.py [--grids 17x5,33x9,65x17,129x33,257x65] [--repeat 3] [--csv FILE]

Prints, for each grid and method, the best-of-N time of every phase, the end-to-end total (after
import), the peak traced memory, then the fitted scaling exponent of each phase (time ~ n^p over the
grids from 33 x 9 up) and the CTM-RPIM / FEM time ratio at equal n, all measured in this one run.
BLAS threads follow the environment (set OMP_NUM_THREADS to pin them).
"""
from __future__ import annotations

import argparse
import time
import tracemalloc

import numpy as np
import pandas as pd

from ctmrpim import benchmarks
from ctmrpim.solvers.linear_static import solve_ctmrpim
from reference_fem import solve_fem
from studies.fitting import fitted_rate

DEFAULT_GRIDS = "17x5,33x9,65x17,129x33,257x65"


def run(grid: tuple[int, int], method: str, repeat: int) -> dict:
    case = benchmarks.load("cantilever", [f"nodes.grid=[{grid[0]}, {grid[1]}]"])
    solve = (lambda: solve_ctmrpim(case)) if method == "ctm-rpim" else (lambda: solve_fem(case, method[4:]))
    best = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = solve()
        wall = time.perf_counter() - t0
        if best is None or wall < best[0]:
            best = (wall, r)
    tracemalloc.start()
    solve()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    wall, r = best
    return {"grid": f"{grid[0]}x{grid[1]}", "n": r.counts["nodes"], "method": r.method,
            "points": r.counts["integration_points"], "tip_error": r.errors["probes"]["tip"]["uy"],
            "wall": wall, "peak_MB": peak / 2**20, **{f"t_{k}": v for k, v in r.timings.items()}}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grids", default=DEFAULT_GRIDS)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--csv")
    a = ap.parse_args()
    grids = [tuple(int(v) for v in g.split("x")) for g in a.grids.split(",")]
    solve_ctmrpim(benchmarks.load("cantilever", ["nodes.grid=[9, 3]"]))  # warm up imports and caches
    rows = []
    for g in grids:
        for method in ("ctm-rpim", "fem-q1", "fem-p2"):
            rows.append(run(g, method, a.repeat if g[0] * g[1] < 20000 else 1))
            r = rows[-1]
            phases = "  ".join(f"{k[2:]} {v:.3f}" for k, v in r.items() if k.startswith("t_") and k != "t_total")
            print(f"{r['grid']:>7} {r['method']:9s} n={r['n']:6d} points={r['points']:7d} total {r['t_total']:7.3f} s "
                  f"peak {r['peak_MB']:7.1f} MB  tip error {100 * r['tip_error']:.4f} %  | {phases}", flush=True)
    df = pd.DataFrame(rows)
    if a.csv:
        df.to_csv(a.csv, index=False)
    print("\nscaling exponent p in time ~ n^p (grids from 33 x 9 up):")
    for method, d in df.groupby("method"):
        d = d[d.n >= 297]
        if len(d) < 2:
            continue
        cols = [c for c in d.columns if c.startswith("t_") and d[c].notna().all() and (d[c] > 0).all()]
        fits = {c[2:]: fitted_rate(d.n, d[c]) for c in cols}
        print(f"  {method:9s} " + "  ".join(f"{k} {v:.2f}" for k, v in fits.items()))
    print("\nCTM-RPIM / FEM at equal n (total time; tip error):")
    piv = df.pivot(index="grid", columns="method", values=["t_total", "tip_error"])
    for g in df.grid.unique():
        t, e = piv.loc[g, "t_total"], piv.loc[g, "tip_error"]
        print(f"  {g:>7}: " + "; ".join(f"/ {m}: time x{t['ctm-rpim'] / t[m]:.1f}, error x{e['ctm-rpim'] / e[m]:.3g}"
                                       for m in ("fem-q1", "fem-p2")))
    print("\nCTM-RPIM / FEM at equal accuracy (FEM time interpolated to CTM-RPIM's tip error):")
    ours = df[df.method == "ctm-rpim"]
    for m in ("fem-q1", "fem-p2"):
        fem = df[df.method == m].sort_values("tip_error")
        for _, r in ours.iterrows():
            le, lt = np.log(fem.tip_error.to_numpy()), np.log(fem.t_total.to_numpy())
            x = np.log(r.tip_error)
            if le.min() <= x <= le.max():
                t_fem = float(np.exp(np.interp(x, le, lt)))
                print(f"  {m} at {100 * r.tip_error:.4f} % ({r.grid} CTM-RPIM): time x{r.t_total / t_fem:.1f}")
            else:
                print(f"  {m} at {100 * r.tip_error:.4f} % ({r.grid} CTM-RPIM): outside the FEM grids of this run")


if __name__ == "__main__":
    main()
