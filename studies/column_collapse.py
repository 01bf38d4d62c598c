"""Granular column collapse (paper Section 3.4, Figs. 26-28) against the experiment of Bui et al. (2008).

The column of aluminium rods (benchmark ``column-collapse``: its size and material are quoted below, read from
the benchmark) is brought to rest under gravity behind its gate, the gate is removed and the explicit adaptive
CTM-RPIM solver runs until the deposit is at rest (with the benchmark's viscosity beta; see
``column_collapse_viscosity`` for the run without it, the paper's model as written, whose surface keeps
sliding). Measured against the data in ``ctmrpim/benchmarks/data/bui2008-column-collapse/``: run-out (where the
surface falls below 0.01 m), height at the wall, the final free surface (largest and mean vertical distance
at the measured abscissae), the failure line (the top of the region that moved less than
``STATIC``; mean distance of the measured points from it) and the surface's inclination between x = 0.04
and 0.40 m, each measured on the experiment's surface the same way. The deposit is also measured at
``FRONT_STOPPED`` = 0.4 s, when the front has stopped. Full mode: three node counts, the middle one the
paper's; quick mode (CI): the coarsest cloud for 0.1 s only (the machinery, not the deposit).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import meshio
import numpy as np
import pandas as pd

from ctmrpim import benchmarks
from ctmrpim.io.vtu import read_pvd
from ctmrpim.reference.deposit import curve_distance, failure_line, run_out, slope_angle, surface_profile
from studies.sweep import CaseSpec

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "column_collapse"
TITLE = "Granular column collapse: final deposit against Bui et al. (2008) (cf. Fig. 28)"
DATA = "bui2008-column-collapse"
GRIDS = {"quick": [(16, 9)], "full": [(31, 16), (51, 21), (63, 32)]}
QUICK = ("explicit.duration=0.1", "explicit.save_every=0.05")
#: a run at rest, or one that reached this time (s), is compared as a final deposit
FINAL = 0.6
#: the time (s) by which the front has stopped in every run; the deposit is also measured there
FRONT_STOPPED = 0.4
#: run-out: the farthest x where the deposit is at least this thick (m; the experiment's README)
RUN_OUT_THICKNESS = 0.01
#: a node that moved less than this (m) belongs to the static region under the failure line
STATIC = 0.005
SNAPSHOTS = (0.1, 0.2, 0.3)
SLOPE_RANGE = (0.04, 0.40)


def specs(quick: bool) -> list[CaseSpec]:
    """One case per node grid, labelled by it (quick: the 16 x 9 grid for 0.1 s)."""
    grids = GRIDS["quick" if quick else "full"]
    return [CaseSpec("column-collapse", (f"nodes.grid=[{nx}, {ny}]",) + (QUICK if quick else ()),
                     labels=(("grid", f"{nx} x {ny}"),)) for nx, ny in grids]


def state_at(folder: Path, time: float | None = None) -> tuple[float, meshio.Mesh]:
    """The saved state of an explicit run's series nearest ``time`` (the last one if None): (time, mesh)."""
    states = read_pvd(Path(folder) / "result.pvd")
    t, f = states[-1] if time is None else min(states, key=lambda s: abs(s[0] - time))
    return t, meshio.read(f)


def boundary_edges(mesh: meshio.Mesh) -> np.ndarray:
    """(e, 2) the tracked boundary saved with a state (its line cells)."""
    return np.concatenate([c.data for c in mesh.cells if c.type == "line"])


def measures(mesh: meshio.Mesh, d_c: float) -> dict:
    """The deposit of one state against the experiment."""
    x = mesh.points[:, :2]
    edges = boundary_edges(mesh)
    u = mesh.point_data["u"][:, :2]
    surface, line = benchmarks.data(DATA, "final_surface"), benchmarks.data(DATA, "failure_line")
    xs = np.arange(0.0, max(x[:, 0].max(), surface[:, 0].max()) + d_c, 0.25 * d_c)
    h = surface_profile(x, edges, xs)
    wall = x[x[:, 0] < 0.5 * d_c, 1].max()
    measured = surface_profile(np.c_[surface[:, 0], surface[:, 1]], np.c_[np.arange(len(surface) - 1),
                                                                          np.arange(1, len(surface))], xs)
    along = (surface[:, 1] > 0) | (np.interp(surface[:, 0], xs, h) > 0)
    dev = np.abs(np.interp(surface[along, 0], xs, h) - surface[along, 1])
    fail = failure_line(x, u, STATIC, np.arange(0.0, 0.2 + 1e-9, 0.5 * d_c), d_c)
    dist = curve_distance(line, fail) if len(fail) > 1 else np.full(len(line), np.nan)
    lo, hi = SLOPE_RANGE
    local = np.degrees(np.arctan(-np.gradient(h, xs)))
    sel = (xs >= lo) & (xs <= min(hi, run_out(xs, h, RUN_OUT_THICKNESS)))
    return {"run_out_m": run_out(xs, h, RUN_OUT_THICKNESS),
            "run_out_measured_m": run_out(xs, measured, RUN_OUT_THICKNESS),
            "height_at_wall_m": float(wall), "surface_max_dev_m": float(dev.max()),
            "surface_mean_dev_m": float(dev.mean()), "failure_line_mean_dist_m": float(np.nanmean(dist)),
            "slope_deg": slope_angle(xs, h, lo, hi), "slope_measured_deg": slope_angle(xs, measured, lo, hi),
            "steepest_deg": float(local[sel].max()) if sel.any() else float("nan"),
            "profile": json.dumps({"x": xs.round(6).tolist(), "h": h.round(6).tolist()}),
            "failure": json.dumps(fail.round(6).tolist())}


def extra(summary: dict, folder: Path) -> dict:
    """The run's dynamics counts and energy shares, and the deposit measures (:func:`measures`) of its last saved
    state, also at ``FRONT_STOPPED`` for a final deposit, read from the run's ``folder``."""
    dyn = summary["dynamics"]
    e = dyn["energy"]
    t, mesh = state_at(folder)
    d_c = summary["parameters"]["derived"]["d_c"]
    stopped = {}
    if dyn["at_rest"] or t >= FINAL:      # a final deposit: measured also when the front had stopped
        m = measures(state_at(folder, FRONT_STOPPED)[1], d_c)
        stopped = {f"{k}_at_{FRONT_STOPPED:g}s": m[k] for k in ("run_out_m", "height_at_wall_m", "surface_max_dev_m",
                                                                  "surface_mean_dev_m", "failure_line_mean_dist_m",
                                                                  "slope_deg")}
    return {"folder": str(folder), "end_time_s": dyn["end_time"], "at_rest": dyn["at_rest"], "steps": dyn["steps"],
            "rebuilds": dyn["rebuilds"], "dt_min_s": dyn["dt"]["min"], "dt_max_s": dyn["dt"]["max"],
            "ms_per_step": 1e3 * dyn["seconds_per_step"]["total"],
            "free_particles": dyn["free_particles"]["final"],
            "energy_balance": e["central_difference_balance"], "material_balance": e["material_balance"],
            "plastic_share": e["plastic_dissipation"] / e["gravity_work"] if e["gravity_work"] else float("nan"),
            "kinetic_share": e["kinetic"] / e["gravity_work"] if e["gravity_work"] else float("nan"),
            "area_change": dyn["tracked_area"]["final"] / dyn["tracked_area"]["initial"] - 1.0,
            "mass_kg": dyn["mass"]["total"], **measures(mesh, d_c), **stopped}


def _draw(ax, mesh: meshio.Mesh, vmax: float, title: str):
    x = mesh.points[:, :2]
    sc = ax.scatter(x[:, 0], x[:, 1], c=mesh.point_data["displacement"], s=3, cmap="viridis", vmin=0, vmax=vmax)
    ax.set(aspect="equal", xlim=(-0.005, 0.46), ylim=(-0.005, 0.105), title=title, xlabel="x (m)", ylabel="y (m)")
    ax.tick_params(labelsize=7)
    return sc


def figure(df: pd.DataFrame) -> Figure:
    """The initial configuration and snapshots of the paper-resolution run (cf. Fig. 27), the final surfaces and static regions against the experiment, and
    run-out and wall height against the node count (cf. Fig. 28)."""
    import matplotlib.pyplot as plt

    ok = df[df.status == "ok"]
    ended = ok.at_rest.astype(bool) | (ok.end_time_s >= FINAL) if len(ok) else pd.Series(dtype=bool)
    surface, line = benchmarks.data(DATA, "final_surface"), benchmarks.data(DATA, "failure_line")
    shown: list = []
    if len(ok):
        main = ok.iloc[min(1, len(ok) - 1)]          # the paper's 1071 nodes in full mode
        states = read_pvd(Path(main.folder) / "result.pvd")
        final_t, final = state_at(Path(main.folder))
        vmax = float(np.nanmax(final.point_data["displacement"]))
        shown = [states[0]] + [min(states, key=lambda s: abs(s[0] - t)) for t in SNAPSHOTS if t <= final_t]
        shown = list(dict.fromkeys(shown + [states[-1]]))[:5]   # (a) the initial state, ..., the last one once
    rows = (len(shown) + 1) // 2
    fig = plt.figure(figsize=(13, 2.3 * rows + 4.5), layout="constrained")
    grid = fig.add_gridspec(rows + 1, 4, height_ratios=[1] * rows + [2.0])
    snapshots = []
    for k, (t, f) in enumerate(shown):
        ax = fig.add_subplot(grid[k // 2, 2 * (k % 2):2 * (k % 2) + 2])
        what = ("initial configuration (gate removed)" if k == 0 else
                ("final configuration" if ended.iloc[min(1, len(ok) - 1)] else "mid-flow: the run stops here, not final")
                if k == len(shown) - 1 else "")
        label = f"({'abcde'[k]}) {main.grid}: t = {t:.2f} s" + (f", {what}" if what else "")
        sc = _draw(ax, meshio.read(f), vmax, label)
        snapshots.append(ax)
    if snapshots:
        fig.colorbar(sc, ax=snapshots, shrink=0.8, label="displacement magnitude (m)", location="right")
    spare = len(shown) % 2 == 1              # an odd number of snapshots leaves a slot: the node-count panel there
    ax = fig.add_subplot(grid[rows, :] if spare else grid[rows, :3])
    ax.plot(surface[:, 0], surface[:, 1], "ko", ms=4, label="experiment: final surface")
    ax.plot(line[:, 0], line[:, 1], "ks", mfc="none", ms=4, label="experiment: failure line")
    ax.plot([0, 0.2, 0.2], [0.1, 0.1, 0], "k:", lw=0.8, label="initial column")
    for _, r in ok.iterrows():
        p, fl = json.loads(r.profile), np.array(json.loads(r.failure))
        ax.plot(p["x"], p["h"], "-", lw=1.2, label=f"{r.grid} ({r.nodes} nodes): surface at t = {r.end_time_s:.2g} s, "
                                                  f"run-out {r.run_out_m:.3f} m")
        if len(fl):
            ax.plot(fl[:, 0], fl[:, 1], "--", lw=1, color=ax.lines[-1].get_color(),
                    label=f"{r.grid}: static region (|u| < {STATIC * 1e3:g} mm)")
    title = TITLE if len(ok) and ended.all() else (
        f"Column collapse at t = {ok.end_time_s.max() if len(ok) else 0:.2g} s (mid-flow, not a deposit)\n"
        "beside the final deposit of Bui et al. (2008)")
    ax.set(xlabel="x (m)", ylabel="y (m)", xlim=(0, 0.5), ylim=(0, 0.11), aspect="equal", title=title)
    ax.legend(fontsize=6, loc="upper right")
    ax.grid(True, alpha=0.3)
    ax = fig.add_subplot(grid[rows - 1, 2:] if spare else grid[rows, 3])
    if len(ok):
        ax.plot(ok.nodes, ok.run_out_m, "o-", label="run-out (m)")
        ax.plot(ok.nodes, ok.height_at_wall_m, "s-", label="height at the wall (m)")
        ax.axhline(ok.run_out_measured_m.iloc[0], color="C0", ls=":", label="experiment")
        ax.axhline(0.1, color="C1", ls=":")
    ax.set(xlabel="number of field nodes (-)", ylabel="length (m)", title="against node count")
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    return fig


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
