"""The report's checks: every verified number against the tolerances table (``studies/tolerances.toml``) as a
regression pin, one row per check with the reference, our value, the limit and pass/fail; and the paper's claims
as findings (:mod:`studies.claims`): holds, partly, does not hold, with our number and the paper's."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ctmrpim import benchmarks
from studies import claims, provenance, tolerances
from studies.column_collapse import FINAL
from studies.fitting import fitted_rate
from studies.footing_bearing import VARIANTS as FOOTING_VARIANTS

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


def pinned_slopes(slopes: pd.DataFrame) -> pd.DataFrame:
    """The rows of a slope table that the factor-of-safety pins judge: each benchmark's default variant (its own
    flow rule, tangent and cap; the other variants are sensitivities the stability section reports) at the node
    spacing of its benchmark file, the cloud the pins are stated for, where the table holds it (a full run); a
    quick run's coarser clouds where it does not."""
    ok = slopes[slopes.status == "ok"]
    if "variant" in ok:
        ok = ok[ok.variant == "default"]
    parts = []
    for name, group in ok.groupby("slope", sort=False):
        own = group[np.isclose(group.h, benchmarks.load(name).resolved["parameters"]["h"])]
        parts.append(own if len(own) else group)
    return pd.concat(parts) if parts else ok


def stability_checks(slopes: pd.DataFrame, footing: pd.DataFrame) -> pd.DataFrame:
    """The slopes' factor-of-safety brackets against Bishop (:func:`pinned_slopes`) and the footing's limit against
    Prandtl."""
    tag = {"ctm-rpim": "ctmrpim", "fem-p2": "fem-p2"}
    rows = []
    for _, r in pinned_slopes(slopes).iterrows():
        rows.append(_row(f"{r.slope}-{tag[r.method]}-fs", r.worst_rel_diff, f"{r.nodes} nodes"))
        rows.append(_row("slope-fs-bracket-width", r.fs_failed - r.fs_stable,
                         f"{r.slope}, {r.method}, {r.nodes} nodes"))
    ok = footing[(footing.status == "ok") & footing.grid.isin(["49 x 21", "73 x 31"])]
    if "variant" in ok:   # the benchmark's own settings; the tangent and cap variants are sensitivities
        ok = ok[ok.variant == next(iter(FOOTING_VARIANTS))]
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
    """The paper's claims as findings: one row per measure of each claim (:data:`studies.claims.CLAIMS`), with
    the claim's outcome (holds, partly, does not hold), what we measure, our value, the paper's statement and its
    claim as a limit, and whether our value meets it."""
    values = claims.evaluate(tables)
    rows = []
    for c in claims.CLAIMS:
        found = claims.outcome(c, values)
        for i, m in enumerate(x for x in c.measures if x.key in values):
            r = _row(m.judged_by, values[m.key])
            rows.append({"claim": f"{c.where}: {c.statement}" if i == 0 else "", "finding": found if i == 0 else "",
                         "we measure": tolerances.entry(m.described_by)["quantity"], "ours": r["ours"],
                         "the paper": tolerances.entry(m.judged_by)["reference"], "the paper's claim as a limit":
                         r["limit"], "ours meets it": "yes" if r["pass"] == "pass" else "**no**",
                         "outcome": found, "measure": m.key})
    return pd.DataFrame(rows)


def claim_pins(tables: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """The regression pins of the claims' measures: each measured value against its pin (the paper's limit where
    the claim holds, the recorded band of our value where it does not)."""
    values = claims.evaluate(tables)
    return pd.DataFrame([_row(m.pinned_by, values[m.key]) for c in claims.CLAIMS for m in c.measures
                         if m.key in values])


def full_mode_tables(out_dir: Path) -> dict[str, pd.DataFrame]:
    """The committed full-mode tables under ``out_dir/full`` (their rows that ran), by study name."""
    full = Path(out_dir) / "full"
    out = {}
    for f in sorted(full.glob("*.csv")):
        df = pd.read_csv(f)
        out[f.stem] = df[df.status == "ok"].reset_index(drop=True) if "status" in df else df
    return out


def full_collapse_checks(out_dir: Path) -> pd.DataFrame:
    """The column collapse's checks on the committed full-mode table (``out_dir/full``), each row's case naming
    the full mode and, where the table's provenance is not current, its state (:mod:`studies.provenance`)."""
    df = full_mode_tables(out_dir).get("column_collapse")
    if df is None:
        return pd.DataFrame()
    c = collapse_checks(df)
    if c.empty:
        return c
    state = provenance.status(Path(out_dir) / "full", "column_collapse").state
    flag = "" if state == "current" else f", {state}"
    c["check"] = c.check.str.replace(r" \((\d+) nodes", rf" (full mode{flag}, \1 nodes", regex=True)
    return c


def all_checks(tables: dict[str, pd.DataFrame], out_dir: Path | None = None) -> pd.DataFrame:
    """Every regression pin: linear and large-deformation accuracy, stability, column collapse (this run's, and
    the committed full-mode table's under ``out_dir/full``), and the claims' measures."""
    parts = [verification_checks(tables["node_density"], tables["plate_hole_convergence"], tables["tip_load"],
                                 tables["end_moment"]),
             stability_checks(tables["slope_stability"], tables["footing_bearing"]),
             collapse_checks(tables["column_collapse"])]
    if out_dir is not None:
        parts.append(full_collapse_checks(out_dir))
    parts.append(claim_pins(tables))
    return pd.concat([p for p in parts if len(p)], ignore_index=True)


def evaluated_keys(checks: pd.DataFrame, claim_rows: pd.DataFrame) -> set[str]:
    """The tolerance keys the report evaluates (its pins' and the claims' limits)."""
    keys = set(checks.check.str.split(" (", regex=False).str[0])
    return keys | {claims.MEASURES[m].judged_by for m in claim_rows.measure}


def limits_in_table() -> set[str]:
    """The keys of the tolerances table that carry a limit (the published reference values carry none)."""
    return {k for k, e in tolerances.table().items() if "min" in e or "max" in e}


def console_summary(checks: pd.DataFrame, claim_rows: pd.DataFrame) -> str:
    """Pins and claims in plain text (check, ours, limit, pass; claim, finding, ours, the paper's limit), for the
    console."""
    shown = claim_rows.assign(claim=claim_rows.measure)[["claim", "outcome", "ours", "the paper's claim as a limit",
                                                         "ours meets it"]]
    return (checks[["check", "ours", "limit", "pass"]].to_string(index=False) + "\n\nThe paper's claims:\n"
            + shown.to_string(index=False))
