"""Per-phase wall time and maximum resident memory of CTM-RPIM and scikit-fem (Q1, P2) on the cantilever.

    python performance/bench_linear.py [--grids 33x9,129x33,257x65] [--repeat 3] [--csv FILE]

Every case (grid x method) runs in its own process, as a user's ``ctmrpim run`` would: it imports the
package, solves a 9 x 3 cantilever of the same method to warm up, then solves the case ``--repeat`` times.
Printed for each case, all measured in this one run: the first solve's total (numba's cached kernels are
loaded there), the best total of the repeats and its phases, and the process's maximum resident memory
(``ru_maxrss`` of the child) after all the repeats and after the first solve (a process that solves once, as
``ctmrpim run`` does; the repeats add the allocator's fragmentation). Also printed: numba's start alone
(:func:`numba_start`). Methods: CTM-RPIM with the default integration (``ctm-vci``) and with the paper's ``ctm``,
scikit-fem Q1 and P2. Then the CTM-RPIM / FEM time ratios at equal grid (best and first solves), and, with three
grids or more, the scaling exponent of each phase (time ~ n^p), the ratios at equal tip error and each method's
time to 0.1 % tip error (log-log between the bracketing grids, from the best and from the first solve). BLAS
threads follow the environment. Timings on a shared machine are noisy: the minimum over repeats is the
figure to compare.
"""
from __future__ import annotations

import argparse
import json
import re
import resource
import subprocess
import sys
import time

import numpy as np
import pandas as pd

DEFAULT_GRIDS = "33x9,129x33,257x65"
TIME_TO_TARGET = 1e-3   # the tip error whose time to reach is printed (issue target: CTM-RPIM / Q1 <= 1.5)
#: (label, solver, element or integration)
METHODS = (("ctm-rpim", "ctm-rpim", None), ("ctm-rpim/ctm", "ctm-rpim", "ctm"),
           ("fem-q1", "fem", "q1"), ("fem-p2", "fem", "p2"))


def child(grid: str, label: str, repeat: int) -> None:
    """Run one case in this process; print one JSON line."""
    from ctmrpim import benchmarks
    from ctmrpim.solvers.linear_static import solve_ctmrpim
    from reference_fem import solve_fem

    solver, option = next((s, o) for name, s, o in METHODS if name == label)
    nx, ny = (int(v) for v in grid.split("x"))

    def load(g: tuple[int, int]):
        sets = [f"nodes.grid=[{g[0]}, {g[1]}]"]
        if solver == "ctm-rpim" and option:
            sets.append(f'method.integration="{option}"')
        return benchmarks.load("cantilever", sets)

    def solve(case):
        return solve_ctmrpim(case) if solver == "ctm-rpim" else solve_fem(case, option)

    warm = load((9, 3))
    t0 = time.perf_counter()
    solve(warm)
    warm_time = time.perf_counter() - t0   # numba's kernels are loaded here, once per process
    case = load((nx, ny))
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = solve(case)
        runs.append((time.perf_counter() - t0, r))
        if len(runs) == 1:   # a process that solves the case once, as `ctmrpim run` does (after the warm-up)
            rss_first = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    first = runs[0][1].timings["total"]
    wall, r = min(runs, key=lambda x: x[0])
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024   # kB on Linux
    out = {"grid": grid, "method": label, "n": r.counts["nodes"],
           "points": r.counts.get("integration_points", 0), "tip_error": r.errors["probes"]["tip"]["uy"],
           "warmup": warm_time, "first": first, "wall": wall, "rss_MB": rss, "rss_first_MB": rss_first,
           **{f"t_{k}": v for k, v in r.timings.items()}}
    print(json.dumps(out))


def numba_start() -> float:
    """Seconds numba's CPU target takes to initialise (its typing and lowering registries) in a fresh process,
    after the imports of the command line: the fixed part of what a first compiled call costs."""
    code = ("import time, ctmrpim.cli; from numba.core.registry import cpu_target; t = time.perf_counter(); "
            "cpu_target.typing_context.refresh(); cpu_target.target_context.refresh(); "
            "print(time.perf_counter() - t)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return float(proc.stdout.strip().splitlines()[-1])


def run_case(grid: str, label: str, repeat: int) -> dict:
    proc = subprocess.run([sys.executable, __file__, "--child", grid, label, str(repeat)],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{grid} {label}: {proc.stderr.strip()[-500:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grids", default=DEFAULT_GRIDS, help="comma-separated NXxNY (default %(default)s)")
    ap.add_argument("--repeat", type=int, default=3, help="solves per case (the largest grid: 2 at most)")
    ap.add_argument("--methods", default=",".join(m[0] for m in METHODS),
                    help="comma-separated, of: %(default)s")
    ap.add_argument("--csv")
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        child(a.child[0], a.child[1], int(a.child[2]))
        return
    labels = a.methods.split(",")
    unknown = [m for m in labels if m not in {m[0] for m in METHODS}]
    if unknown:
        ap.error(f"unknown method(s) {', '.join(unknown)}: choose from {', '.join(m[0] for m in METHODS)}")
    grids = a.grids.split(",")
    if not all(re.fullmatch(r"[1-9][0-9]*x[1-9][0-9]*", g) for g in grids):
        ap.error(f"--grids {a.grids!r}: expected NXxNY[,NXxNY...], e.g. 33x9,129x33")
    sizes = [int(g.split("x")[0]) * int(g.split("x")[1]) for g in grids]
    rows = []
    for g, size in zip(grids, sizes, strict=True):
        for label in labels:
            rows.append(run_case(g, label, min(a.repeat, 2) if size > 10000 else a.repeat))
            r = rows[-1]
            phases = "  ".join(f"{k[2:]} {v:.3f}" for k, v in r.items() if k.startswith("t_") and k != "t_total")
            print(f"{r['grid']:>7} {r['method']:13s} n={r['n']:6d} total {r['t_total']:7.3f} s "
                  f"(first {r['first']:.3f}) max RSS {r['rss_MB']:6.0f} MB (one solve {r['rss_first_MB']:4.0f})  "
                  f"tip error {100 * r['tip_error']:.4f} %  | {phases}", flush=True)
    df = pd.DataFrame(rows)
    if a.csv:
        df.to_csv(a.csv, index=False)
    if any(m.startswith("ctm-rpim") for m in labels):   # the FE references run no compiled kernel
        print("\nnumba's start in a fresh process after the package's imports (its target initialisation, paid by "
              "the first compiled call whatever the kernels are; inside the first solve's total): "
              f"{numba_start():.3f} s")
    print("\nCTM-RPIM / FEM at equal grid (best total time of each, and the first solves' as `ctmrpim run` counts "
          "them; tip error):")
    for g in grids:
        d = df[df.grid == g].set_index("method")
        for ours in (m for m in d.index if m.startswith("ctm-rpim")):
            print(f"  {g:>7} {ours:13s}: " + "; ".join(
                f"/ {m}: time x{d.t_total[ours] / d.t_total[m]:.2f} "
                f"(first solves x{d['first'][ours] / d['first'][m]:.2f}), "
                f"error x{d.tip_error[ours] / d.tip_error[m]:.3g}"
                for m in d.index if m.startswith("fem")))
    if len(grids) >= 3:
        from studies.fitting import fitted_rate
        print("\nscaling exponent p in time ~ n^p (grids from 33 x 9 up):")
        for method, d in df.groupby("method"):
            d = d[d.n >= 297]
            if len(d) < 2:
                continue
            cols = [c for c in d.columns if c.startswith("t_") and d[c].notna().all() and (d[c] > 0).all()]
            print(f"  {method:13s} " + "  ".join(f"{c[2:]} {fitted_rate(d.n, d[c]):.2f}" for c in cols))
        print("\nCTM-RPIM / FEM at equal accuracy (FEM time interpolated to CTM-RPIM's tip error):")
        for ours in (m for m in df.method.unique() if m.startswith("ctm-rpim")):
            for m in (m for m in df.method.unique() if m.startswith("fem")):
                fem = df[df.method == m].sort_values("tip_error")
                le, lt = np.log(fem.tip_error.to_numpy()), np.log(fem.t_total.to_numpy())
                for _, r in df[df.method == ours].iterrows():
                    x = np.log(r.tip_error)
                    if le.min() <= x <= le.max():
                        t_fem = float(np.exp(np.interp(x, le, lt)))
                        print(f"  {ours} / {m} at {100 * r.tip_error:.4f} % ({r.grid}): time x{r.t_total / t_fem:.2f}")
        print_time_to(df, TIME_TO_TARGET)


def print_time_to(df: pd.DataFrame, target: float) -> None:
    """Each method's time to ``target`` tip error, interpolated in log-log between the grids that bracket it
    (the time-to-accuracy study's rule), from the best total and from the first solve (a process that solves
    once), and CTM-RPIM's ratios to the FEM references."""
    from studies.time_to_accuracy import time_to_reach

    print(f"\ntime to {100 * target:g} % tip error (log-log between the bracketing grids; best total, first solve):")
    times = {m: {k: time_to_reach(d.rename(columns={"n": "nodes", col: "time_s"}), target)
                 for k, col in (("best", "t_total"), ("first", "first"))}
             for m, d in df.groupby("method")}
    for m, t in times.items():
        ratios = "" if not m.startswith("ctm-rpim") else "  " + "; ".join(
            f"/ {f}: x{t['best'] / times[f]['best']:.2f} (first x{t['first'] / times[f]['first']:.2f})"
            for f in times if f.startswith("fem"))
        print(f"  {m:13s} {t['best']:.3f} s (first {t['first']:.3f} s){ratios}")


if __name__ == "__main__":
    main()
