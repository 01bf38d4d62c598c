"""The report's checks: every verified number and every claim of the paper against the tolerances
table (``studies/tolerances.toml``), one row per check with the reference, our value, the limit and
pass/fail."""
from __future__ import annotations

import numpy as np
import pandas as pd

from studies import claims, tolerances
from studies.column_collapse import FINAL
from studies.fitting import fitted_rate

RATE_GRIDS = ["17 x 5", "33 x 9", "65 x 17"]


def _row(key: str, value: float, variant: str = "") -> dict:
    """One check's row: ``value`` of tolerance ``key`` (for the case ``variant``) against its limit."""
    e = tolerances.entry(key)
    shown = f"{value:.4g}" if tolerances.is_dimensionless(key) else f"{100 * value:.4g} %"
    return {"check": key + (f" ({variant})" if variant else ""), "quantity": e["quantity"],
            "reference": e["reference"], "ours": shown, "limit": tolerances.describe_limit(key),
            "pass": "pass" if tolerances.passes(key, value) else "FAIL", "limit source": e["source"]}


def verification_checks(nd: pd.DataFrame, plate: pd.DataFrame, tip: pd.DataFrame,
                        moment: pd.DataFrame) -> pd.DataFrame:
    """The accuracy checks of the linear benchmarks (analytical references)."""
    nd = nd[nd.status == "ok"]

    def value(method: str, grid: str, col: str) -> float:
        return float(nd[(nd.method == method) & (nd.grid == grid)][col].iloc[0])

    def rate(method: str, col: str) -> float:
        d = nd[(nd.method == method) & nd.grid.isin(RATE_GRIDS)]
        return fitted_rate(d.h, d[col])

    rows = [_row("cantilever-ctmrpim-33x9-tip", value("ctm-rpim", "33 x 9", "tip_error")),
            _row("cantilever-ctmrpim-65x17-tip", value("ctm-rpim", "65 x 17", "tip_error")),
            _row("cantilever-ctmrpim-33x9-l2", value("ctm-rpim", "33 x 9", "l2_error")),
            _row("cantilever-ctmrpim-33x9-energy", value("ctm-rpim", "33 x 9", "energy_error")),
            _row("cantilever-fem-q1-33x9-tip", value("fem-q1", "33 x 9", "tip_error")),
            _row("cantilever-fem-p2-33x9-tip", value("fem-p2", "33 x 9", "tip_error")),
            _row("fem-q1-energy-rate", rate("fem-q1", "energy_error")),
            _row("fem-q1-l2-rate", rate("fem-q1", "l2_error")),
            _row("ctmrpim-tip-rate", rate("ctm-rpim", "tip_error"))]
    at = plate[(plate.status == "ok") & (plate.spacing == 0.25)].set_index(["plane", "method"])
    for plane in ("stress", "strain"):
        rows += [_row("plate-hole-ctmrpim-energy", at.loc[(plane, "ctm-rpim"), "energy_error"], f"plane {plane}"),
                 _row("plate-hole-ctmrpim-l2", at.loc[(plane, "ctm-rpim"), "l2_error"], f"plane {plane}"),
                 _row("plate-hole-fem-p2-energy", at.loc[(plane, "fem-p2"), "energy_error"], f"plane {plane}")]
    tip = tip[tip.status == "ok"]
    for f in ("tl", "ul"):
        ours = tip[(tip.method == "ctm-rpim") & (tip.formulation == f.upper())]
        shear, corner = ours[ours.load == "end shear"], ours[ours.load == "corner"]
        rows += [_row(f"tip-load-{f}-elastica", float(shear.w_rel_diff.abs().max()), "worst over the loads run"),
                 _row(f"tip-load-{f}-elastica-shortening", float(shear.u_rel_diff.abs().max()),
                      "worst over the loads run"),
                 _row(f"tip-load-corner-{f}-elastica", float(corner.w_rel_diff.abs().max()), "worst over the loads run")]
    quarter = moment[(moment.status == "ok") & np.isclose(moment.m, 0.25)].set_index(["formulation", "method"])
    for key, at in (("end-moment-ul-quarter", ("UL", "ctm-rpim")),
                    ("end-moment-ul-carried-quarter", ("UL carried", "ctm-rpim")),
                    ("end-moment-tl-quarter", ("TL", "ctm-rpim")), ("end-moment-fem-p2-quarter", ("TL", "fem-p2"))):
        rows.append(_row(key, float(quarter.loc[at, "tip_distance_over_L"])))
    return pd.DataFrame(rows)


def stability_checks(slopes: pd.DataFrame, footing: pd.DataFrame) -> pd.DataFrame:
    """The slopes' factor-of-safety brackets against Bishop and the footing's limit against Prandtl."""
    tag = {"ctm-rpim": "ctmrpim", "fem-p2": "fem-p2"}
    rows = []
    for _, r in slopes[slopes.status == "ok"].iterrows():
        rows.append(_row(f"{r.slope}-{tag[r.method]}-fs", r.worst_rel_diff, f"{r.nodes} nodes"))
        rows.append(_row("slope-fs-bracket-width", r.fs_failed - r.fs_stable,
                         f"{r.slope}, {r.method}, {r.nodes} nodes"))
    ok = footing[(footing.status == "ok") & footing.grid.isin(["49 x 21", "73 x 31"])]
    for _, r in ok.iterrows():
        rows.append(_row(f"footing-{tag[r.method]}-limit", r.worst_rel_diff, f"{r.grid} nodes"))
    return pd.DataFrame(rows)


def collapse_checks(df: pd.DataFrame) -> pd.DataFrame:
    """The column collapse against the experiment, and its energy ledger, for every run that reached the end of the
    flow (at rest, or FINAL; quick mode: none)."""
    rows = []
    if "end_time_s" not in df:
        return pd.DataFrame(rows)
    for _, r in df[(df.status == "ok") & (df.at_rest.astype(bool) | (df.end_time_s >= FINAL))].iterrows():
        variant = f"{r.nodes} nodes"
        rows.append(_row("column-collapse-run-out", abs(r.run_out_m / r.run_out_measured_m - 1.0), variant))
        rows.append(_row("column-collapse-height", abs(r.height_at_wall_m / 0.100 - 1.0), variant))
        rows.append(_row("column-collapse-surface", r.surface_max_dev_m, variant))
        rows.append(_row("column-collapse-slope", r.slope_deg, variant))
        # the energy ledger over the work of gravity: the bookkeeping identity and the material's accounts
        rows.append(_row("column-collapse-energy-balance", abs(r.energy_balance), f"{variant}, central differences"))
        rows.append(_row("column-collapse-energy-balance", abs(r.material_balance), f"{variant}, material"))
    return pd.DataFrame(rows)


def claims_table(tables: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """One row per claim of the paper: the statement, what we measure, our value and whether it holds."""
    values = claims.evaluate(tables)
    rows = []
    for key, (_, statement, judged_by) in claims.CLAIMS.items():
        r = _row(key, values[key])
        holds = tolerances.passes(judged_by, values[key])
        rows.append({"paper says": statement, "we measure": r["quantity"], "ours": r["ours"],
                     "paper's claim holds": "yes" if holds else "**no**", "limit": r["limit"],
                     "pass": r["pass"], "limit source": r["limit source"]})
    return pd.DataFrame(rows)


def all_checks(tables: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """Every tolerance check of the studies' ``tables``: linear and large-deformation accuracy, stability,
    column collapse."""
    return pd.concat([verification_checks(tables["node_density"], tables["plate_hole_convergence"],
                                          tables["tip_load"], tables["end_moment"]),
                      stability_checks(tables["slope_stability"], tables["footing_bearing"]),
                      collapse_checks(tables["column_collapse"])], ignore_index=True)


def console_summary(checks: pd.DataFrame, claim_rows: pd.DataFrame) -> str:
    """Checks and claims in one plain-text table (check, ours, limit, pass), for the console."""
    return pd.concat([checks[["check", "ours", "limit", "pass"]],
                      claim_rows.rename(columns={"paper says": "check"})[["check", "ours", "limit", "pass"]]]
                     ).to_string(index=False)
