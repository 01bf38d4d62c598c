"""The stability sections (Mohr-Coulomb, Figs. 18-25): the benchmarks side by side, the slope by
strength reduction (Newton and dynamic relaxation), the strip footing, the fields and the slide."""
from __future__ import annotations

from pathlib import Path

import pandas as pd

import studies
from studies import stability_fields
from studies.report.markdown import Progress, Writer, md, pct


def stability_side_by_side(slopes: pd.DataFrame, footing: pd.DataFrame) -> pd.DataFrame:
    """One row per stability benchmark: the paper's value, ours, scikit-fem P2's, the analytical one."""
    def finest(df: pd.DataFrame, method: str) -> pd.Series | None:
        d = df[(df.status == "ok") & (df.method == method)]
        return None if d.empty else d.sort_values("nodes").iloc[-1]

    rows = []
    for name, paper, analytical in (("slope", "stable at 1.3, failed at 1.4", "Bishop (ours) 1.368"),
                                    ("slope-gl", "(the other Fig. 18 candidate)",
                                     "Bishop (ours) 1.378; Bishop & Morgenstern 1.38; G & L FE 1.4")):
        d = slopes[slopes.slope == name]
        ours, fem = finest(d, "ctm-rpim"), finest(d, "fem-p2")
        rows.append({"benchmark": f"{name}: factor of safety", "paper": paper,
                     "CTM-RPIM": "" if ours is None
                     else f"[{ours.fs_stable:.4f}, {ours.fs_failed:.4f}] ({ours.nodes} nodes)",
                     "scikit-fem P2": "" if fem is None else f"[{fem.fs_stable:.4f}, {fem.fs_failed:.4f}]",
                     "analytical / limit equilibrium": analytical})
    ours, fem = finest(footing, "ctm-rpim"), finest(footing, "fem-p2")
    rows.append({"benchmark": "footing: limit pressure (kPa)", "paper": "about 520 (6 cm at 500 kPa)",
                 "CTM-RPIM": "" if ours is None else
                 f"[{ours.limit_carried_kPa:.1f}, {ours.limit_failed_kPa:.1f}] ({ours.nodes} nodes)",
                 "scikit-fem P2": "" if fem is None else f"[{fem.limit_carried_kPa:.1f}, {fem.limit_failed_kPa:.1f}]",
                 "analytical / limit equilibrium": "Prandtl (2 + pi) c_u = 514.2; Smith & Griffiths 515-519"})
    return pd.DataFrame(rows)


def write_side_by_side(w: Writer, slopes: pd.DataFrame, footing: pd.DataFrame) -> None:
    """The paper, CTM-RPIM, finite elements and the analytical values side by side."""
    w("## Stability: the paper, CTM-RPIM, finite elements and the analytical values side by side\n\n")
    w(md(stability_side_by_side(slopes, footing)))
    w("\n\nBrackets are [last stable, first failed] SRF and [last carried, first not carried] pressure; "
      "each row is the finest resolution of this run (quick mode: coarser slopes).\n\n")


def write_slope_stability(w: Writer, sl: pd.DataFrame) -> None:
    """The slopes' factor of safety by strength reduction (Figs. 18-20)."""
    w("## Stability: slope by strength reduction (cf. Figs. 18-20)\n\n")
    w(f"{studies.study('slope_stability').__doc__.strip()}\n\n")
    cols = ["slope", "method", "nodes", "fs_stable", "fs_failed", "bishop", "worst_rel_diff", "levels", "iterations",
            "time_s"]
    w(md(pct(sl[[c for c in cols if c in sl] + ["status"]], ("worst_rel_diff",))
         .assign(bishop=lambda d: d.bishop.map(lambda v: f"{v:.4f}"))))
    w("\n\n![slope stability](slope_stability.png)\n\n")
    w("Measured at the default resolution (full mode, and `python performance/bench_stability.py`): `slope` "
      "CTM-RPIM [1.3406, 1.3422] in 24 s, P2 [1.3406, 1.3438] in 14 s; `slope-gl` CTM-RPIM [1.3438, 1.3469] in "
      "27 s, P2 [1.3438, 1.3469] in 12 s: both methods agree within 0.003 and lie 2-2.5 % below Bishop's "
      "simplified method (1.368, 1.378), inside "
      "the paper's [1.3, 1.4] and below Griffiths & Lane's finite-element 1.4. The coarser clouds give 0.5-1 % "
      "more. The bracket is that of a numerical criterion: non-convergence of the equilibrium iteration "
      "within 100 iterations at a "
      "tolerance of 1e-4 after four halvings of the SRF step; with 300 iterations it moves up by about 0.004, "
      "and round-off in the factorisation moves it by up to 0.003. The gravity stage yields a wide zone at "
      "depth (with nu = 0.3 the elastic K0 = 0.43 state lies on the Mohr-Coulomb edge sigma_xx = sigma_zz "
      "below about 11.6 m of cover); there full Newton wanders for tens of iterations, so the slopes iterate "
      "on the elastic stiffness (factorised once for the whole search) with Anderson-mixed steps "
      "(`loading.tangent = \"elastic\"`, see `ctmrpim/solvers/plastic_system.py`).\n\n")


def write_srf_sweep(w: Writer, sw: pd.DataFrame) -> None:
    """The slope's displacement against the strength reduction factor (Fig. 19b)."""
    w("### Displacement against SRF (cf. Fig. 19b)\n\n")
    w(f"{studies.study('slope_srf_sweep').__doc__.strip()}\n\n")
    w(md(pct(sw[[c for c in ("srf", "method", "nodes", "stable", "max_displacement", "iterations", "cutbacks",
                             "time_s", "status") if c in sw]], ())))
    w("\n\n![SRF sweep](slope_srf_sweep.png)\n\n")


def write_relaxation(w: Writer, rx: pd.DataFrame) -> None:
    """The slope by dynamic relaxation (Fig. 19a)."""
    w("### Dynamic relaxation (cf. Fig. 19a)\n\n")
    w(f"{studies.study('slope_relaxation').__doc__.strip()}\n\n")
    w(md(pct(rx[[c for c in ("srf", "method", "nodes", "stable", "steps", "max_displacement", "time_s", "status")
                  if c in rx]], ())))
    w("\n\n![dynamic relaxation](slope_relaxation.png)\n\n"
      "As in the paper, the displacement settles within about 1000-2000 steps up to SRF = 1.3 and grows "
      "steadily from 1.4 on. Searched with dynamic relaxation instead of Newton (`strength-reduction.solver = "
      "\"dynamic-relaxation\"`), the 668-node `slope` gives FS in [1.3688, 1.3750] (Newton: [1.3625, 1.3656]) in "
      "71 s: the two criteria differ by about 0.5 %. A residual-only criterion misleads: scikit-fem P2 at SRF 1.3 "
      "is not at rest after 3000 steps (out-of-balance above 1e-4) while its displacement has settled to "
      "0.02 % per thousand steps, so a level counts as failed only while its displacement still grows "
      "(more than 1 % over the last quarter of the steps).\n\n")


def write_footing(w: Writer, fo: pd.DataFrame) -> None:
    """The strip footing's limit pressure against Prandtl (Figs. 22-25)."""
    w("## Stability: strip footing (cf. Figs. 22-25)\n\n")
    w(f"{studies.study('footing_bearing').__doc__.strip()}\n\n")
    w(md(pct(fo[[c for c in ("grid", "method", "nodes", "limit_carried_kPa", "limit_failed_kPa", "worst_rel_diff",
                             "settlement_at_500_kPa_m", "newton_iterations", "time_s", "status") if c in fo]],
              ("worst_rel_diff",))))
    w("\n\n![footing](footing_bearing.png)\n\n")
    w("Measured (full mode): CTM-RPIM 37 x 16: [603, 618] kPa (+17 %), 49 x 21: [521.3, 522.1] (+1.4 %), "
      "73 x 31: [516.8, 517.7] (+0.6 %); scikit-fem P2 on the same nodes 521.5 (+1.4 %) at 25 x 11 and "
      "[517.6, 518.0] (+0.7 %) at 49 x 21. Where CTM-RPIM is weak: with nine integration points per node "
      "the nearly isochoric plastic flow (phi = psi ~ 0, plane strain) locks on coarse clouds - at 37 x 16 the "
      "limit is 17 % too high while P2 on a coarser grid is within 1.4 % - and at 49 x 21 the solve takes "
      "about five times longer than P2's (Newton with the consistent tangent: the tangent's sparse products "
      "and its factorisation). Past the limit the centre settles without bound at constant pressure "
      "(CTM-RPIM: 0.11 m at 518.75 kPa, 1.5 m at 520.7 kPa). At 500 kPa the centre has settled 4.6 cm with "
      "both methods, against Smith & Griffiths' 5.1 cm (their mesh is much coarser) and the paper's "
      "about 6 cm.\n\n")


def write_stability_fields(w: Writer, quick: bool, out_dir: Path, progress: Progress) -> None:
    """Runs the stability fields figure (Figs. 20 and 25) and writes its section."""
    stability_fields.run(quick, out_dir, progress)
    w(f"### Fields (cf. Figs. 20 and 25)\n\n{stability_fields.__doc__.strip()}\n\n"
      "![stability fields](stability_fields.png)\n\n")


def write_slope_slide(w: Writer, ss: pd.DataFrame) -> None:
    """The slide of the slope at SRF = 1.6 (Fig. 21)."""
    w(f"### The slide at SRF = 1.6 (cf. Fig. 21)\n\n{studies.study('slope_slide').__doc__.strip()}\n\n")
    w(md(ss[[c for c in ("cloud", "nodes", "end_time_s", "steps", "rebuilds", "re_layings", "max_displacement_m",
                         "crest_settlement_m", "toe_advance_m", "ms_per_step", "time_s", "status") if c in ss]]))
    w("\n\n![slope slide](slope_slide.png)\n\n")
