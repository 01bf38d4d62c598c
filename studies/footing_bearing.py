"""Strip footing bearing capacity (paper Section 3.3.2, Figs. 22-24): the pressure on the flexible footing is
raised in increments until the soil cannot carry it; the limit pressure is the bracket [last carried, first not
carried], read from the load-settlement curve: an increment whose slope of pressure against settlement from the
last carried level falls below `loading.limit_slope` (1 %) of the elastic body's is not carried, though Newton may
converge there, and a non-convergence counts only after a re-check (Newton on the consistent tangent, 8 times its cap). Against Prandtl's
(2 + pi) c_u for the undrained footing (phi = psi ~ 0) and Prandtl-Reissner's c N_c for the frictional ones
(footing-phi20, footing-phi30). CTM-RPIM and scikit-fem P2 on the same node grids (the default 49 x 21 has the
paper's node count), with the load-settlement curve of the footing centre, beside the published values of Smith &
Griffiths and of the paper (the table below). The full run adds a coarser and a finer grid of the undrained footing,
the frictional footings on three clouds (h = B / 8, B / 12, B / 16), and at each benchmark's own resolution the
limit's sensitivity to the tangent (variant "elastic": the elastic-stiffness iteration, with a higher cap) and
to the iteration cap (variant "cap x2": Newton's max_iterations doubled); at h = B / 8 the frictional footings'
domains enlarged by half (variant "domain x1.5") show that the mechanism lies inside them.
"""
from __future__ import annotations

import json
import math
import sys
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from studies.sweep import CaseSpec, element_for

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "footing_bearing"
TITLE = "Strip footing: pressure against settlement (cf. Fig. 24)"
PRANDTL = (2.0 + math.pi) * 100.0      # kPa
GRIDS = {"quick": [(49, 21)], "full": [(37, 16), (49, 21), (73, 31)]}
#: the frictional footings' node spacings in the full run (B = 4 m: B / 8, B / 12, B / 16, the benchmarks' own; each
#: divides both domains' width and depth)
SPACINGS = [0.5, 1 / 3, 0.25]
#: the footing's width (every footing benchmark: the pressure on 0 <= x <= 2 m of the half model)
B = 4.0
#: the sensitivity variants: overrides of the benchmark's [loading]
VARIANTS = {"consistent": (), "elastic": ('loading.tangent="elastic"', "loading.max_iterations=100"),
            "cap x2": ("loading.max_iterations=30",)}
#: the frictional footings' domains enlarged by this factor in both directions (the benchmarks' W and D), at
#: h = B / 8: the limit must not move by 0.5 %
ENLARGEMENT = 1.5


def _enlarged(target: str) -> tuple[float, float]:
    """The width and depth (m) of benchmark ``target``'s domain enlarged by :data:`ENLARGEMENT`."""
    import tomllib

    from ctmrpim import benchmarks
    p = tomllib.loads(benchmarks.path(target).read_text())["parameters"]
    return ENLARGEMENT * p["W"], ENLARGEMENT * p["D"]
METHODS = ("ctm-rpim", "fem")


def _spec(target: str, overrides: tuple[str, ...], solver: str, grid: str, variant: str) -> CaseSpec:
    return CaseSpec(target, overrides + VARIANTS[variant], solver, element_for(solver, "p2"),
                    labels=(("benchmark", target), ("grid", grid), ("variant", variant)))


def specs(quick: bool) -> list[CaseSpec]:
    """CTM-RPIM and scikit-fem P2 on each node grid of the undrained footing; in the full run the frictional
    footings on three clouds and the tangent and cap variants at each benchmark's own resolution."""
    grids = GRIDS["quick" if quick else "full"]
    out = [_spec("footing", (f"parameters.nx={nx}", f"parameters.ny={ny}"), solver, f"{nx} x {ny}", "consistent")
           for nx, ny in grids for solver in METHODS]
    if quick:
        return out
    out += [_spec("footing", ("parameters.nx=49", "parameters.ny=21"), solver, "49 x 21", variant)
            for variant in ("elastic", "cap x2") for solver in METHODS]
    for target in ("footing-phi20", "footing-phi30"):
        out += [_spec(target, (f"parameters.h={h!r}",), solver, f"h = B / {B / h:g}", "consistent")
                for h in SPACINGS for solver in METHODS]
        out += [_spec(target, (f"parameters.h={SPACINGS[-1]!r}",), solver, f"h = B / {B / SPACINGS[-1]:g}", variant)
                for variant in ("elastic", "cap x2") for solver in METHODS]
        W, D = _enlarged(target)
        out += [CaseSpec(target, (f"parameters.h={SPACINGS[0]!r}", f"parameters.W={W!r}", f"parameters.D={D!r}"),
                         solver, element_for(solver, "p2"),
                         labels=(("benchmark", target), ("grid", f"h = B / {B / SPACINGS[0]:g}"),
                                 ("variant", f"domain x{ENLARGEMENT:g}")))
                for solver in METHODS]
    return out


def reference(summary: dict) -> float:
    """The benchmark's limit pressure (kPa): Prandtl's (2 + pi) c for phi ~ 0, else Prandtl-Reissner's c N_c
    (weightless soil), from the material of ``summary``."""
    m = summary["parameters"]["material"]
    c, phi = m["c"] / 1e3, m["phi"]
    if phi < 0.01:
        return (2.0 + math.pi) * c
    t = math.tan(math.radians(phi))
    return c * (math.exp(math.pi * t) * math.tan(math.radians(45.0 + phi / 2.0)) ** 2 - 1.0) / t


def extra(summary: dict) -> dict:
    """The limit-pressure bracket (kPa), the reference limit and the bracket's worst relative difference from it,
    what decided the failure and the settlement there (the load-weighted mean under the footing, and the centre's
    over B: a serviceability reading, not the criterion), the settlement at 500 kPa, the Newton iterations and the
    load-settlement curve of the centre (JSON)."""
    limit = summary["limit_pressure"]
    carried = [h for h in summary["history"] if h["converged"]]
    q_max = summary["parameters"]["parameters"]["q_max"]
    q = np.array([h["load_factor"] * q_max / 1e3 for h in carried])
    w = np.array([-h["centre"]["uy"] for h in carried])
    order = np.argsort(q)
    q, w = q[order], w[order]
    at500 = float(np.interp(500.0, q, w)) if q.max() >= 500.0 else float("nan")
    carried_kpa = limit["carried"] / 1e3
    failed_kpa = limit["failed"] / 1e3 if limit["failed"] is not None else float("nan")
    ref = reference(summary)
    criterion = summary.get("limit_criterion", {})
    loading = summary["parameters"]["loading"]
    return {"limit_carried_kPa": carried_kpa, "limit_failed_kPa": failed_kpa, "reference_kPa": ref,
            "worst_rel_diff": max(abs(carried_kpa / ref - 1), abs(failed_kpa / ref - 1)),
            "decided_by": criterion.get("decided_by"), "limit_slope": criterion.get("limit_slope"),
            "slope_ratio_at_carried": criterion.get("slope_ratio_at_carried"),
            "settlement_at_carried_m": criterion.get("settlement_at_carried"),
            "centre_settlement_over_B": float(w[-1] / B) if len(w) else float("nan"),
            "tangent": loading["tangent"], "max_iterations": loading["max_iterations"],
            "domain_W_m": summary["parameters"]["parameters"].get("W"),
            "domain_D_m": summary["parameters"]["parameters"].get("D"),
            "safeguarded_steps": summary["counts"].get("safeguarded_steps"),
            "settlement_at_500_kPa_m": at500, "newton_iterations": summary["counts"]["newton_iterations"],
            "curve": json.dumps({"q_kPa": q.round(3).tolist(), "w_m": w.tolist()})}


def _settlement_axis(ax, values: list[np.ndarray]) -> None:
    """Scale the settlement (y) axis of ``ax`` so that every one of ``values`` shows: logarithmic where the
    settlements span more than two decades (a failing footing's last iterate far beyond the carried ones;
    symmetric-log, linear below the smallest non-zero settlement, where some are zero or negative), linear from
    zero otherwise; no fixed limit clips a point."""
    from matplotlib.ticker import FuncFormatter

    every = np.concatenate(values) if values else np.zeros(0)
    positive = np.abs(every[every != 0])
    if not len(positive) or positive.max() <= 100 * positive.min():
        if len(every) and every.min() >= 0:
            ax.set_ylim(bottom=0)
        return
    if np.all(every > 0):
        ax.set_yscale("log")
    else:
        ax.set_yscale("symlog", linthresh=float(positive.min()))
    plain = FuncFormatter(lambda v, _: f"{v:g}")
    ax.yaxis.set_major_formatter(plain)


def figure(df: pd.DataFrame) -> Figure:
    """The settlement of the footing centre against the pressure for every case of the undrained footing, the
    paper's way round (maximum displacement versus bearing stress, Fig. 24), with Prandtl's limit and the
    published points; beside it, the frictional footings' settlement over B against their pressure over c N_c
    (the full run). Every point shows: the settlement axis is logarithmic where it spans decades."""
    ok = df[(df.status == "ok") & (df.get("variant", "consistent") == "consistent")]
    undrained = ok[ok.get("benchmark", "footing") == "footing"]
    frictional = ok[ok.get("benchmark", "footing") != "footing"]
    fig, axes = new_figure(2 if len(frictional) else 1, 6.0)
    ax = axes[0, 0]
    styles = {"ctm-rpim": "-", "fem-p2": "--"}
    shown = []
    for _, r in undrained.iterrows():
        c = json.loads(r.curve)
        shown.append(np.array(c["w_m"]) * 100)
        ax.plot(c["q_kPa"], shown[-1], styles[r.method], marker=".", ms=3,
                label=f"{r.method}, {r.grid}: limit {r.limit_carried_kPa:.1f}-{r.limit_failed_kPa:.1f} kPa")
    ax.axvline(PRANDTL, color="k", lw=0.8, label=f"Prandtl (2 + pi) c_u = {PRANDTL:.1f} kPa")
    from studies import tolerances  # here: drawing reads the published points, computing needs none

    published = []
    for key, marker, name in (("published-footing-smith-griffiths", "ks", "Smith & Griffiths"),
                              ("published-footing-paper", "k^", "paper: about")):
        e = tolerances.entry(key)
        published.append(100 * e["settlement_m"])
        ax.plot([e["pressure_kPa"]], [published[-1]], marker, mfc="none",
                label=f"{name} {published[-1]:g} cm at {e['pressure_kPa']:g} kPa")
    _settlement_axis(ax, [*shown, np.array(published)])
    ax.set(xlabel="bearing pressure (kPa)", ylabel="settlement of the footing centre (cm)",
           title="Strip footing: settlement against pressure (cf. Fig. 24)")
    ax.set_xlim(left=0)
    if len(frictional):
        ax = axes[0, 1]
        shown = []
        for _, r in frictional.iterrows():
            c = json.loads(r.curve)
            shown.append(np.array(c["w_m"]) / B)
            ax.plot(np.array(c["q_kPa"]) / r.reference_kPa, shown[-1], styles[r.method], marker=".",
                    ms=3, label=f"{r.benchmark}, {r.method}, {r.grid}: [{r.limit_carried_kPa:.1f}, "
                                f"{r.limit_failed_kPa:.1f}] kPa")
        ax.axvline(1.0, color="k", lw=0.8, label="Prandtl-Reissner c N_c")
        _settlement_axis(ax, shown)
        ax.set(xlabel="pressure / c N_c", ylabel="settlement of the footing centre / B",
               title="Frictional footings")
        ax.set_xlim(left=0)
    return finished(fig, axes, "both", fontsize=7)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
