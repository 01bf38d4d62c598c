"""The stability sections (Mohr-Coulomb, Figs. 18-25): the benchmarks side by side, the slope by
strength reduction (Newton and dynamic relaxation), the strip footing, the fields and the slide."""
from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

import studies
from ctmrpim import benchmarks
from studies import stability_fields, tolerances
from studies.footing_bearing import PRANDTL
from studies.report.full_results import full_table
from studies.report.markdown import Writer, md, pct, span


def _finest(df: pd.DataFrame, method: str) -> pd.Series | None:
    """The row of ``method`` at the finest resolution of ``df`` that ran (None if none did)."""
    d = df[(df.status == "ok") & (df.method == method)]
    return None if d.empty else d.sort_values("nodes").iloc[-1]


def full_mode(out_dir: Path | None, name: str, table: pd.DataFrame) -> tuple[pd.DataFrame | None, str]:
    """The full-mode table of study ``name`` to quote: the committed one under ``out_dir/full`` with its provenance
    state in a quick report (``out_dir`` given), ``table`` itself in a full one (``out_dir`` None)."""
    if out_dir is None:
        return table, "this run"
    full, state = full_table(out_dir, name)
    return full, f"`reports/full/{name}.csv`, {state}"


def bracket_change(base: pd.Series, other: pd.Series, lo: str, hi: str) -> float:
    """The largest relative change of a bracket [``lo``, ``hi``] from row ``base`` to row ``other``."""
    return max(abs(other[lo] / base[lo] - 1), abs(other[hi] / base[hi] - 1))


def slope_refinement(full: pd.DataFrame) -> pd.DataFrame:
    """One row per slope, method and cloud of the full run (default variant): the factor-of-safety bracket, what
    decided it and how far the displacement had run away by then (the largest growth of a stable level against
    the runaway limit)."""
    ok = full[(full.status == "ok") & (full.variant.fillna("default") == "default")]
    rows = [{"slope": r.slope, "method": r.method, "h (m)": r.h, "nodes": int(r.nodes),
             "bracket": f"[{r.fs_stable:.4f}, {r.fs_failed:.4f}]",
             "vs Bishop": span([100 * (r.fs_stable / r.bishop - 1), 100 * (r.fs_failed / r.bishop - 1)], "+.2f")
             + " %", "decided by": r.decided_by,
             "largest growth / limit": f"{r.largest_stable_growth:.3g} / {r.limit_growth:g}",
             "time_s": f"{r.time_s:.0f}"}
            for _, r in ok.sort_values(["slope", "method", "h"], ascending=[True, True, False]).iterrows()]
    return pd.DataFrame(rows)


def flow_rule_table(full: pd.DataFrame) -> pd.DataFrame:
    """One row per frictional slope, method and cloud of the full run that ran both flow rules: the stable end of
    the non-associated (psi = 0, the benchmark's) and of the associated (psi = phi) bracket, each against Bishop's
    simplified method, and the flow rule's share (their difference over Bishop's): item 6 of issue 19."""
    ok = full[(full.status == "ok") & full.slope.isin(("slope", "slope-gl"))]
    rows = []
    for (slope, method, h), d in ok.groupby(["slope", "method", "h"], sort=False):
        by = d.set_index("variant")
        if "default" not in by.index or "associated" not in by.index:
            continue
        non, assoc = by.loc["default"], by.loc["associated"]
        rows.append({"slope": slope, "method": method, "h (m)": h, "nodes": int(non.nodes),
                     "stable, psi = 0": non.fs_stable,
                     "psi = 0": f"[{non.fs_stable:.4f}, {non.fs_failed:.4f}]",
                     "psi = 0 vs Bishop": non.fs_stable / non.bishop - 1,
                     "psi = phi": f"[{assoc.fs_stable:.4f}, {assoc.fs_failed:.4f}]",
                     "psi = phi vs Bishop": assoc.fs_stable / assoc.bishop - 1,
                     "flow rule's share": (assoc.fs_stable - non.fs_stable) / non.bishop})
    return pd.DataFrame(rows).sort_values(["slope", "method", "h (m)"], ascending=[True, True, False]) if rows \
        else pd.DataFrame(rows)


def variant_changes(full: pd.DataFrame, keys: list[str], base: str, lo: str, hi: str) -> pd.DataFrame:
    """The relative change of each variant's bracket from the ``base`` variant's at the same ``keys`` (the
    full run's sensitivities: tangent, cap, domain): one row per variant and case."""
    ok = full[full.status == "ok"]
    rows = []
    for _, r in ok[ok.variant != base].iterrows():
        same = ok[(ok.variant == base) & np.logical_and.reduce([ok[k] == r[k] for k in keys])]
        if len(same):
            rows.append({**{k: r[k] for k in keys}, "variant": r.variant,
                         "change": bracket_change(same.iloc[0], r, lo, hi)})
    return pd.DataFrame(rows)


def stability_side_by_side(slopes: pd.DataFrame, footing: pd.DataFrame) -> pd.DataFrame:
    """One row per stability benchmark: the paper's value, ours, scikit-fem P2's, the analytical one (the
    published values from the tolerances table, Bishop's from the study's own search)."""
    paper_fs = tolerances.entry("published-slope-fs")["values"]
    gl_fe, bm = tolerances.entry("published-slope-gl-fs")["values"]
    rows = []
    for name, paper, others in (("slope", f"stable at {paper_fs[0]:g}, failed at {paper_fs[1]:g}", ""),
                                ("slope-gl", "(the other Fig. 18 candidate)",
                                 f"; Bishop & Morgenstern {bm:g}; G & L FE {gl_fe:g}")):
        d = slopes[slopes.slope == name]
        ours, fem = _finest(d, "ctm-rpim"), _finest(d, "fem-p2")
        bishop = d[d.status == "ok"].bishop
        rows.append({"benchmark": f"{name}: factor of safety", "paper": paper,
                     "CTM-RPIM": "" if ours is None
                     else f"[{ours.fs_stable:.4f}, {ours.fs_failed:.4f}] ({ours.nodes} nodes)",
                     "scikit-fem P2": "" if fem is None else f"[{fem.fs_stable:.4f}, {fem.fs_failed:.4f}]",
                     "analytical / limit equilibrium": (f"Bishop (ours) {bishop.iloc[0]:.3f}" if len(bishop) else "")
                     + others})
    ours, fem = _finest(footing, "ctm-rpim"), _finest(footing, "fem-p2")
    paper, sg = tolerances.entry("published-footing-paper"), tolerances.entry("published-footing-smith-griffiths")
    rows.append({"benchmark": "footing: limit pressure (kPa)",
                 "paper": f"about {paper['limit_kPa'][0]:g} ({100 * paper['settlement_m']:g} cm at "
                          f"{paper['pressure_kPa']:g} kPa)",
                 "CTM-RPIM": "" if ours is None else
                 f"[{ours.limit_carried_kPa:.1f}, {ours.limit_failed_kPa:.1f}] ({ours.nodes} nodes)",
                 "scikit-fem P2": "" if fem is None else f"[{fem.limit_carried_kPa:.1f}, {fem.limit_failed_kPa:.1f}]",
                 "analytical / limit equilibrium": f"Prandtl (2 + pi) c_u = {PRANDTL:.1f}; Smith & Griffiths "
                                                   f"{sg['limit_kPa'][0]:g}-{sg['limit_kPa'][1]:g}"})
    return pd.DataFrame(rows)


def write_side_by_side(w: Writer, slopes: pd.DataFrame, footing: pd.DataFrame) -> None:
    """The paper, CTM-RPIM, finite elements and the analytical values side by side."""
    w("## Stability: the paper, CTM-RPIM, finite elements and the analytical values side by side\n\n")
    w(md(stability_side_by_side(slopes, footing)))
    w("\n\nBrackets are [last stable, first failed] SRF and [last carried, first not carried] pressure; "
      "each row is the finest resolution of this run (quick mode: coarser slopes). The published values come "
      "from the tolerances table (`published-*`), with their sources.\n\n")


def k0_yield_depth(name: str = "slope") -> tuple[float, float]:
    """The elastic at-rest ratio K0 = nu / (1 - nu) of benchmark ``name`` and the depth (m) below which that
    state (sigma_h = sigma_zz = K0 sigma_v in plane strain) reaches Mohr-Coulomb: sigma_v [(1 - K0) - (1 + K0)
    sin phi] = 2 c cos phi, from the benchmark's material and gravity."""
    b = tomllib.loads(benchmarks.path(name).read_text())
    m, g = b["material"], b["problem"]["gravity"][1]
    if isinstance(g, str):
        g = b["parameters"][g.lstrip("-")]
    k0, phi = m["nu"] / (1 - m["nu"]), math.radians(m["phi"])
    gamma = m["density"] * abs(float(g))
    return k0, 2 * m["c"] * math.cos(phi) / (gamma * ((1 - k0) - (1 + k0) * math.sin(phi)))


def write_slope_stability(w: Writer, sl: pd.DataFrame, out_dir: Path | None = None) -> None:
    """The slopes' factor of safety by strength reduction (Figs. 18-20), every number from ``sl`` and, in a quick
    report, from the committed full-mode table under ``out_dir``."""
    w("## Stability: slope by strength reduction (cf. Figs. 18-20)\n\n")
    w(f"{studies.study('slope_stability').__doc__.strip()}\n\n")
    cols = ["slope", "method", "nodes", "fs_stable", "fs_failed", "bishop", "worst_rel_diff", "levels", "iterations",
            "time_s"]
    w(md(pct(sl[[c for c in cols if c in sl] + ["status"]], ("worst_rel_diff",))
         .assign(bishop=lambda d: d.bishop.map(lambda v: f"{v:.4f}"))))
    w("\n\n![slope stability](slope_stability.png)\n\n")
    ok = sl[sl.status == "ok"]
    if "variant" in ok:   # the full run's tangent and cap variants are the sensitivities, not the results
        ok = ok[ok.variant.fillna("default") == "default"]
    ok = ok[ok.slope.isin(("slope", "slope-gl"))]
    parts, gaps, below, bishops = [], [], [], []
    for name, d in ok.groupby("slope", sort=False):
        d = d[d.nodes == d.nodes.max()].set_index("method")
        parts.append(f"`{name}` (h = {d.h.iloc[0]:g} m) " + ", ".join(
            f"{'CTM-RPIM' if m == 'ctm-rpim' else 'P2'} [{r.fs_stable:.4f}, {r.fs_failed:.4f}] in {r.time_s:.0f} s"
            for m, r in d.iterrows()))
        gaps.append((d.fs_stable.max() - d.fs_stable.min(), d.fs_failed.max() - d.fs_failed.min()))
        below += list(1 - d.fs_failed / d.bishop) + list(1 - d.fs_stable / d.bishop)
        bishops.append(d.bishop.iloc[0])
    if parts:
        paper = tolerances.entry("published-slope-fs")["values"]
        gl_fe = tolerances.entry("published-slope-gl-fs")["values"][0]
        lo, hi = ok.fs_stable.min(), ok.fs_failed.max()
        inside = paper[0] <= lo and hi <= paper[1]
        w(f"At this run's resolution: {'; '.join(parts)}: both methods agree within {max(max(g) for g in gaps):.4f} "
          f"and lie {span([100 * b for b in below], '.1f')} % below Bishop's simplified method "
          f"({', '.join(f'{b:.3f}' for b in bishops)}), {'inside' if inside else 'outside'} the paper's "
          f"[{paper[0]:g}, {paper[1]:g}] and {'below' if hi < gl_fe else 'not below'} Griffiths & Lane's "
          f"finite-element {gl_fe:g}. ")
    full, state = full_mode(out_dir, "slope_stability", sl)
    if full is None or "variant" not in full:
        w(f"The default clouds ({', '.join(f'`{n}`' for n in sorted(set(ok.slope)))} at their benchmark spacing) "
          "run in full mode only, and no full-mode table of this study is committed "
          "(`reports/full/slope_stability.csv`), so their brackets are not quoted here. ")
    else:
        write_slope_full(w, full, state)
    k0, depth = k0_yield_depth()
    decided = (", ".join(f"{n} of {len(ok)} by {k}" for k, n in ok.decided_by.value_counts().items())
               if "decided_by" in ok and ok.decided_by.notna().any() else "")
    w("A level fails when its displacement runs away (the largest displacement from the stable level below, per "
      "relative rise of the SRF, above `strength-reduction.limit_growth` times the largest at SRF = 1) or when the "
      "equilibrium iteration does not converge even on the re-check by Newton on the consistent tangent: "
      "non-convergence alone is only a symptom" + (f"; in this run's brackets {decided}" if decided else "") +
      ". The gravity stage yields a wide zone at "
      f"depth (with nu = {k0_nu():g} the elastic K0 = {k0:.2f} state lies on the Mohr-Coulomb edge sigma_xx = "
      f"sigma_zz and reaches the yield surface below {depth:.1f} m of cover, from the benchmark's c, phi and unit "
      "weight); there full Newton wanders for tens of iterations, so the slopes iterate on the elastic stiffness "
      "(factorised once for the whole search) with Anderson-mixed steps (`loading.tangent = \"elastic\"`, see "
      "`ctmrpim/solvers/plastic_system.py`); a sub-step that iteration does not converge goes to Newton on the "
      "consistent tangent from its last iterate before it is cut back, so near the limit Newton, not the "
      "elastic iteration's patience, decides (`ctmrpim/solvers/load_stepping.py`).\n\n")


def write_slope_full(w: Writer, full: pd.DataFrame, state: str) -> None:
    """The full run's slopes on three clouds each, what decided each bracket, the sensitivities to the tangent
    and the cap, and the vertical cut against Taylor (issue 19, item 6): where the gap to Bishop comes from."""
    w(f"\n\n**Full mode** ({state}): each slope on three clouds, both methods on the same nodes; the largest "
      "growth is the largest displacement growth of a stable level (its displacement from the stable level "
      "below per relative SRF rise, over the displacement at SRF = 1) against the runaway limit:\n\n")
    w(md(slope_refinement(full)) + "\n\n")
    ok = full[(full.status == "ok") & (full.variant.fillna("default") == "default")]
    slopes = ok[ok.slope.isin(("slope", "slope-gl"))]
    finest = slopes.sort_values("h").groupby(["slope", "method"]).head(1)
    coarsest = slopes.sort_values("h").groupby(["slope", "method"]).tail(1)
    if len(finest):
        by_nc = finest[finest.decided_by == "non-convergence"]
        w(f"From the coarsest to the finest cloud the stable end of the bracket falls by "
          f"{span(100 * (1 - finest.set_index(['slope', 'method']).fs_stable / coarsest.set_index(['slope', 'method']).fs_stable), '.1f')} % "
          f"(both methods, both slopes), to {span(100 * (finest.fs_stable / finest.bishop - 1), '+.1f')} % from "
          "Bishop's simplified method. ")
        if len(by_nc):
            w(f"On the finest clouds {len(by_nc)} of {len(finest)} brackets are decided by non-convergence (the "
              "equilibrium iteration fails even on the re-check) while the displacement's growth has reached at "
              f"most {(by_nc.largest_stable_growth / by_nc.limit_growth).max():.0%} of the runaway limit "
              "(`strength-reduction.limit_growth`): there the iteration stopped before the slope ran away, so those "
              "brackets' stable ends are lower bounds of the discrete factor of safety (an equilibrium was found "
              "there), not its value, and no extrapolation to h = 0 is drawn from them. ")
    changes = variant_changes(full, ["slope", "method", "h"], "default", "fs_stable", "fs_failed")
    moved = changes[changes.slope.isin(("slope", "slope-gl")) & (changes.variant != "associated")] \
        if len(changes) else changes
    for variant, d in moved.groupby("variant") if len(moved) else ():
        w(f"On the benchmarks' own clouds variant `{variant}` moves the bracket by {span(100 * d.change, '.2f')} % "
          "(both methods, both slopes). ")
    gl_fe = tolerances.entry("published-slope-gl-fs")["values"][0]
    own = full[(full.status == "ok") & full.slope.isin(("slope", "slope-gl"))
               & (full.variant.fillna("default") != "associated")]   # the benchmarks' own flow rule
    if len(own):
        best = own.loc[own.fs_stable.idxmax()]
        w(f"The highest stable level any run with the benchmarks' flow rule reached is {best.fs_stable:.4f} "
          f"({best.slope}, {best.method}, h = {best.h:g} m, variant {best.variant}), "
          f"{100 * (best.fs_stable / best.bishop - 1):+.1f} % from Bishop; Griffiths & Lane's finite-element "
          f"{gl_fe:g} for `slope-gl` (psi = 0, as ours) lies "
          f"{100 * (gl_fe / own[own.slope == 'slope-gl'].fs_failed.max() - 1):+.1f} % above the highest failed "
          "level of ours. ")
    write_flow_rule(w, full)
    cut = ok[ok.slope == "vertical-cut"].sort_values("h")
    if len(cut):
        taylor = tolerances.entry("published-taylor-vertical-cut")["value"]
        w(f"The vertical cut (Taylor's stability number: FS = {taylor:.4f}): " + "; ".join(
            f"{m} " + ", ".join(f"h = {r.h:g} m [{r.fs_stable:.4f}, {r.fs_failed:.4f}] ({r.decided_by})"
                                for _, r in d.iterrows())
            for m, d in cut.groupby("method")) + ". ")
    w("\n\n")


def write_flow_rule(w: Writer, full: pd.DataFrame) -> None:
    """Where the gap to Bishop's simplified method and to Griffiths and Lane's finite-element value comes from (issue
    19, item 6): the same slopes with an associated flow rule on the same clouds, and the trend with refinement."""
    flow = flow_rule_table(full)
    if flow.empty:
        return
    shown = flow.drop(columns="stable, psi = 0").assign(
        **{k: [f"{100 * v:+.2f} %" for v in flow[k]]
           for k in ("psi = 0 vs Bishop", "psi = phi vs Bishop", "flow rule's share")})
    w("\n\n**Where the gap comes from**: both frictional slopes again on every cloud with an associated flow "
      "rule (psi = phi, variant `associated`), the stable ends against Bishop's simplified method:\n\n")
    w(md(shown) + "\n\n")
    share = flow["flow rule's share"]
    w(f"With psi = phi the stable ends lie {span(100 * flow['psi = phi vs Bishop'], '+.2f')} % from Bishop's "
      f"simplified method, with psi = 0 (the benchmarks' flow rule) {span(100 * flow['psi = 0 vs Bishop'], '+.2f')} %: "
      f"the flow rule accounts for {span(100 * share, '.2f')} % of "
      "Bishop's value. Bishop's method is a rigid-plastic limit equilibrium on circles: it knows no dilatancy, "
      "and its factor is an estimate of the associated body's, which the associated runs reproduce; a "
      "non-associated body (psi = 0: no volume change in shear) fails at a lower strength reduction. ")
    gl = flow[flow.slope == "slope-gl"]
    if len(gl):
        coarse, fine = gl["h (m)"].max(), gl["h (m)"].min()
        stable = gl.set_index(["method", "h (m)"])["stable, psi = 0"]
        fall = [100 * (1 - stable[m, fine] / stable[m, coarse]) for m in sorted(set(gl.method))]
        w(f"Over our three clouds the non-associated stable end of `slope-gl` falls by {span(fall, '.1f')} % from "
          f"h = {coarse:g} m to h = {fine:g} m, so a coarser discretisation gives a higher non-associated factor, "
          "and Griffiths and Lane's (a coarse mesh of eight-node quadrilaterals with reduced integration, failure "
          "read as non-convergence) is expected above ours; by how much we cannot compute without their mesh. ")


def k0_nu(name: str = "slope") -> float:
    """Poisson's ratio of benchmark ``name``."""
    return tomllib.loads(benchmarks.path(name).read_text())["material"]["nu"]


def write_srf_sweep(w: Writer, sw: pd.DataFrame) -> None:
    """The slope's displacement against the strength reduction factor (Fig. 19b)."""
    w("### Displacement against SRF (cf. Fig. 19b)\n\n")
    w(f"{studies.study('slope_srf_sweep').__doc__.strip()}\n\n")
    w(md(pct(sw[[c for c in ("srf", "method", "nodes", "stable", "max_displacement", "iterations", "cutbacks",
                             "time_s", "status") if c in sw]], ())))
    w("\n\n![SRF sweep](slope_srf_sweep.png)\n\n")


def _growth(history: str, share: float = 0.25) -> float:
    """Relative growth of the maximum displacement over the last ``share`` of a level's steps (``history``: JSON
    [step, maximum displacement])."""
    h = np.array(json.loads(history))
    at = np.interp(h[-1, 0] * (1 - share), h[:, 0], h[:, 1])
    return float(h[-1, 1] / at - 1)


def write_relaxation(w: Writer, rx: pd.DataFrame) -> None:
    """The slope by dynamic relaxation (Fig. 19a), every number from ``rx``."""
    w("### Dynamic relaxation (cf. Fig. 19a)\n\n")
    w(f"{studies.study('slope_relaxation').__doc__.strip()}\n\n")
    w(md(pct(rx[[c for c in ("srf", "method", "nodes", "stable", "steps", "max_displacement", "time_s", "status")
                  if c in rx]], ())))
    w("\n\n![dynamic relaxation](slope_relaxation.png)\n\n")
    ok = rx[rx.status == "ok"]
    budget = ok.steps.max()
    ctm = ok[ok.method == "ctm-rpim"]
    rest, moving = ctm[ctm.stable.astype(bool) & (ctm.steps < budget)], ctm[~ctm.stable.astype(bool)]
    paper = tolerances.entry("published-relaxation-steps")["value"]
    if len(rest) and len(moving):
        w(f"As in the paper (which relaxes each level for {paper} steps), CTM-RPIM's displacement settles within "
          f"{span(rest.steps, 'd')} steps up to SRF = {rest.srf.max():g} and keeps growing from SRF = "
          f"{moving.srf.min():g} on ({span([100 * _growth(h) for h in moving.history], '.0f')} % over the last "
          "quarter of the budget). ")
    slow = ok[ok.stable.astype(bool) & (ok.steps >= budget)]
    if len(slow):
        r = slow.iloc[0]
        w(f"A residual-only criterion misleads: {r.method} at SRF {r.srf:g} is not at rest at the end of the budget "
          "(out-of-balance above 1e-4) while its displacement has settled, growing by "
          f"{100 * _growth(r.history):.2g} % over the last quarter of the steps, so a level counts as failed only "
          "while its displacement still grows (more than 1 % over the last quarter of the steps). ")
    w("The strength-reduction search driven by dynamic relaxation (`strength-reduction.solver = "
      "\"dynamic-relaxation\"`) is not part of this study: its bracket is not quoted.\n\n")


def write_footing(w: Writer, fo: pd.DataFrame, out_dir: Path | None = None) -> None:
    """The strip footing's limit pressure against Prandtl (Figs. 22-25), every number from ``fo``, the committed
    full-mode table under ``out_dir`` (quick report) and the published values of the tolerances table."""
    w("## Stability: strip footing (cf. Figs. 22-25)\n\n")
    w(f"{studies.study('footing_bearing').__doc__.strip()}\n\n")
    w(md(pct(fo[[c for c in ("grid", "method", "nodes", "limit_carried_kPa", "limit_failed_kPa", "worst_rel_diff",
                             "settlement_at_500_kPa_m", "newton_iterations", "time_s", "status") if c in fo]],
              ("worst_rel_diff",))))
    w("\n\n![footing](footing_bearing.png)\n\n")
    ok = fo[fo.status == "ok"]
    if "benchmark" in ok:   # the undrained footing's own cases (the frictional ones and the variants: full run)
        ok = ok[(ok.benchmark.fillna("footing") == "footing") & (ok.variant.fillna("consistent") == "consistent")]
    sg, paper = tolerances.entry("published-footing-smith-griffiths"), tolerances.entry("published-footing-paper")
    rows = [{"": "Prandtl (2 + pi) c_u", "limit pressure (kPa)": f"{PRANDTL:.1f}", "settlement (cm)": ""},
            {"": "Smith & Griffiths (coarse mesh)",
             "limit pressure (kPa)": f"{sg['limit_kPa'][0]:g}-{sg['limit_kPa'][1]:g}",
             "settlement (cm)": f"{100 * sg['settlement_m']:g} at {sg['pressure_kPa']:g} kPa"},
            {"": "the paper", "limit pressure (kPa)": f"about {paper['limit_kPa'][0]:g}",
             "settlement (cm)": f"about {100 * paper['settlement_m']:g} at {paper['pressure_kPa']:g} kPa"}]
    rows += [{"": f"{r.method}, {r.grid}", "limit pressure (kPa)": f"[{r.limit_carried_kPa:.1f}, "
              f"{r.limit_failed_kPa:.1f}] ({r.worst_rel_diff:+.1%} at worst)",
              "settlement (cm)": f"{100 * r.settlement_at_500_kPa_m:.1f} at {sg['pressure_kPa']:g} kPa"}
             for _, r in ok.iterrows()]
    w("Published and computed:\n\n" + md(pd.DataFrame(rows)) + "\n\n")
    by = {(r.grid, r.method): r for _, r in ok.iterrows()}
    same = [g for g in ok.grid.unique() if (g, "ctm-rpim") in by and (g, "fem-p2") in by]
    for g in same:
        c, f = by[(g, "ctm-rpim")], by[(g, "fem-p2")]
        w(f"At {g}, CTM-RPIM's limit lies {c.limit_carried_kPa - f.limit_carried_kPa:+.1f} kPa from P2's on the "
          f"same nodes and its solve takes {c.time_s / f.time_s:.1f} times as long (Newton with the consistent "
          "tangent: the tangent's sparse products and its factorisation, nine integration points per node). ")
    if "limit_slope" in ok and ok.limit_slope.notna().any():
        shown = ok.sort_values("nodes").groupby("method", sort=False).tail(1)
        w(f"A level counts as carried while it is in equilibrium and its pressure still rises with the settlement at "
          f"least {ok.limit_slope.iloc[0]:.0%} as steeply as the elastic body's (`loading.limit_slope`; the "
          "settlement is the load-weighted mean under the footing); a non-convergence counts only after a re-check "
          "(Newton on the consistent tangent with 8 times its cap). Small-strain perfect plasticity lets Newton converge far along the "
          "plateau, so the last converged level is not the limit: the limit is where the curve turns flat. At the "
          "carried limit " + "; ".join(
              f"{r.method} ({r.grid}) has settled {100 * r.settlement_at_carried_m:.1f} cm (mean) and its centre "
              f"{r.centre_settlement_over_B:.3f} B, the slope there {r.slope_ratio_at_carried:.2f} of the elastic one"
              for _, r in shown.iterrows()) +
          f". The paper reads failure at about {paper['limit_kPa'][0]:g} kPa with about "
          f"{100 * paper['settlement_m']:g} cm at {paper['pressure_kPa']:g} kPa; by this criterion "
          f"{paper['limit_kPa'][0]:g} kPa lies "
          f"{'above' if ok.limit_failed_kPa.max() < paper['limit_kPa'][0] else 'not above'} every computed limit. "
          "The centre's settlement over B is a serviceability reading, not the failure criterion. ")
    full, state = full_mode(out_dir, "footing_bearing", fo)
    if full is None or "benchmark" not in full:
        w("The full run's coarser and finer grids of the undrained footing and the frictional footings are not "
          "committed as a table (`reports/full/footing_bearing.csv`), so they are not quoted.\n\n")
    else:
        write_footing_full(w, full, state)


def write_footing_full(w: Writer, full: pd.DataFrame, state: str) -> None:
    """The full run's footings: the undrained one on three grids, the frictional ones on three clouds against
    c N_c, and the sensitivities to the tangent, the cap and the domain (issue 19, items 3 and 4)."""
    ok = full[full.status == "ok"]
    base = ok[ok.variant.fillna("consistent") == "consistent"]
    rows = [{"benchmark": r.benchmark, "method": r.method, "grid": r.grid, "nodes": int(r.nodes),
             "limit (kPa)": f"[{r.limit_carried_kPa:.2f}, {r.limit_failed_kPa:.2f}]",
             "reference (kPa)": f"{r.reference_kPa:.2f}",
             "difference": span([100 * (r.limit_carried_kPa / r.reference_kPa - 1),
                                 100 * (r.limit_failed_kPa / r.reference_kPa - 1)], "+.2f") + " %",
             "decided by": r.decided_by, "time_s": f"{r.time_s:.0f}"}
            for _, r in base.sort_values(["benchmark", "method", "nodes"]).iterrows()]
    w(f"\n\n**Full mode** ({state}): every footing on three clouds, against Prandtl's (2 + pi) c_u and "
      "Prandtl-Reissner's c N_c (weightless soil):\n\n" + md(pd.DataFrame(rows)) + "\n\n")
    fr = base[base.benchmark != "footing"]
    if len(fr):
        finest = fr.sort_values("nodes").groupby(["benchmark", "method"]).tail(1)
        diff = 100 * (finest.limit_carried_kPa / finest.reference_kPa - 1)
        falling = [d.sort_values("nodes").limit_carried_kPa.is_monotonic_decreasing
                   for _, d in fr.groupby(["benchmark", "method"])]
        w(f"On the finest clouds the frictional limits (carried) lie {span(diff, '+.2f')} % from c N_c (both "
          f"methods, {', '.join(sorted(set(finest.benchmark)))}); the limit falls with every refinement in "
          f"{sum(falling)} of {len(falling)} series. ")
    changes = variant_changes(full, ["benchmark", "method", "grid"], "consistent", "limit_carried_kPa",
                              "limit_failed_kPa")
    for variant, d in changes.groupby("variant") if len(changes) else ():
        w(f"Variant `{variant}` moves the limit by {span(100 * d.change, '.3f')} % ({len(d)} cases: "
          + ", ".join(f"{r.benchmark} {r.method} {r.grid}" for _, r in d.iterrows()) + "). ")
        worst = d.loc[d.change.idxmax()]
        row = ok[(ok.variant == variant) & (ok.benchmark == worst.benchmark) & (ok.method == worst.method)
                 & (ok.grid == worst.grid)].iloc[0]
        if worst.change > 0 and row.decided_by != "settlement runaway":
            w(f"Its largest ({worst.benchmark}, {worst.method}, {worst.grid}) is decided by {row.decided_by} while "
              f"the pressure still rises with the settlement at {row.slope_ratio_at_carried:.2f} of the elastic "
              f"slope (the runaway limit is {row.limit_slope:g}): the iteration's limit, not the soil's. ")
    w("\n\n")


def write_stability_fields(w: Writer) -> None:
    """The section of the stability fields figure (Figs. 20 and 25), which :func:`studies.stability_fields.run`
    draws."""
    w(f"### Fields (cf. Figs. 20 and 25)\n\n{stability_fields.__doc__.strip()}\n\n"
      "![stability fields](stability_fields.png)\n\n")


def write_slope_slide(w: Writer, ss: pd.DataFrame) -> None:
    """The slide of the slope at SRF = 1.6 (Fig. 21)."""
    w(f"### The slide at SRF = 1.6 (cf. Fig. 21)\n\n{studies.study('slope_slide').__doc__.strip()}\n\n")
    w(md(ss[[c for c in ("cloud", "nodes", "end_time_s", "steps", "rebuilds", "re_layings", "max_displacement_m",
                         "crest_settlement_m", "toe_advance_m", "ms_per_step", "time_s", "status") if c in ss]]))
    w("\n\n![slope slide](slope_slide.png)\n\n")
